"""Closed-form and semi-analytic reference solutions of contact mechanics, plain library functions that
the tests, the benchmarks and the docs call alike (units and conventions: :mod:`~tengsim.references.common`).

- :mod:`~tengsim.references.sphere`: Hertz, JKR and DMT spheres;
- :mod:`~tengsim.references.maugis`: the Maugis–Dugdale sphere (the JKR–DMT transition, Tabor parameter);
- :mod:`~tengsim.references.indenters`: Sneddon's cone and the flat punch (no adhesion);
- :mod:`~tengsim.references.sinusoid`: Westergaard's sinusoid and Johnson's adhesive one;
- :mod:`~tengsim.references.patch`: the displacement under a uniformly loaded rectangle (Love).
"""
from tengsim.references.common import effective_modulus
from tengsim.references.indenters import (cone_theta_from_half_angle, flat_punch_force, flat_punch_pressure,
                                          sneddon_cone_contact_radius, sneddon_cone_force, sneddon_cone_indentation,
                                          sneddon_cone_pressure)
from tengsim.references.maugis import (MDCurve, MDPoint, MDScales, maugis_dugdale_curve, maugis_dugdale_m,
                                       maugis_dugdale_pulloff, maugis_dugdale_pulloff_from_tabor,
                                       maugis_dugdale_pulloff_point, md_lambda, md_lambda_from_tabor, md_scales,
                                       tabor_parameter)
from tengsim.references.patch import rectangle_displacement
from tengsim.references.sinusoid import (johnson_sinusoid_alpha, johnson_sinusoid_mean_pressure,
                                         westergaard_complete_contact_pressure, westergaard_contact_half_width,
                                         westergaard_mean_pressure, westergaard_pressure)
from tengsim.references.sphere import (JKRPoint, dmt_contact_radius, dmt_force, dmt_pulloff_force, hertz_contact_radius,
                                       hertz_contact_radius_from_force, hertz_force, hertz_indentation,
                                       hertz_peak_pressure, hertz_pressure, jkr_contact_radius, jkr_force,
                                       jkr_indentation, jkr_pulloff, jkr_pulloff_fixed_grips, jkr_zero_load_radius)

__all__ = [
    "effective_modulus",
    "hertz_contact_radius", "hertz_force", "hertz_indentation",
    "hertz_contact_radius_from_force", "hertz_peak_pressure", "hertz_pressure",
    "JKRPoint", "jkr_force", "jkr_indentation", "jkr_contact_radius",
    "jkr_pulloff", "jkr_pulloff_fixed_grips", "jkr_zero_load_radius",
    "dmt_force", "dmt_contact_radius", "dmt_pulloff_force",
    "MDScales", "MDCurve", "MDPoint", "md_scales", "md_lambda",
    "maugis_dugdale_m", "maugis_dugdale_curve", "maugis_dugdale_pulloff",
    "maugis_dugdale_pulloff_point", "tabor_parameter", "md_lambda_from_tabor",
    "maugis_dugdale_pulloff_from_tabor",
    "cone_theta_from_half_angle", "sneddon_cone_contact_radius",
    "sneddon_cone_indentation", "sneddon_cone_force", "sneddon_cone_pressure",
    "flat_punch_force", "flat_punch_pressure",
    "westergaard_complete_contact_pressure", "westergaard_contact_half_width",
    "westergaard_mean_pressure", "westergaard_pressure",
    "johnson_sinusoid_alpha", "johnson_sinusoid_mean_pressure",
    "rectangle_displacement",
]

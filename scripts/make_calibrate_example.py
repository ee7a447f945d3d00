"""Writes examples/calibrate/: a small pyramid design (pyramid_1um.toml) and a stand-in "measurement"
(measured.csv): tengsim's own V_OC (Eq. 12) of that design at σ = 8 µC/m², W = 25 mJ/m² (ε = 50 nm, E* = 10 MPa as
in the TOML), 2 to 30 kPa, with 2.5 % relative noise (seed 7).  `tengsim calibrate` should find σ and W back.

    python scripts/make_calibrate_example.py [OUT_DIR]
"""
import sys
from pathlib import Path

import numpy as np

from tengsim.calibrate.data import write_curve
from tengsim.design import plan_design, run_design

TABLE = {"shape": "pyramid", "pitch": "1um", "base": "0.5um", "height": "0.2um", "E_star": "10MPa", "eps": "50nm",
         "tol": 0.05}


def main(out: Path) -> None:
    out.mkdir(parents=True, exist_ok=True)
    (out / "pyramid_1um.toml").write_text(
        "# the design the stand-in measurement was made on (W and sigma are what calibrate fits)\n[design]\n"
        + "".join(f"{k} = {v!r}\n".replace("'", '"') for k, v in TABLE.items()), encoding="utf-8")
    r = run_design(plan_design({**TABLE, "W": "25mJ/m2", "sigma": "8uC/m2", "p_max": "30kPa", "p_step": "2kPa",
                                "maps": False}))
    P = r.dataset["pressure"].values
    V = r.dataset["voc_eq12"].sel(branch="approach").values
    keep = P >= 2e3
    rng = np.random.default_rng(7)
    write_curve(out / "measured.csv", P[keep], V[keep] * (1 + 0.025 * rng.standard_normal(int(keep.sum()))),
                comment="stand-in measurement: tengsim's V_OC of pyramid_1um.toml at sigma 8 uC/m2, W 25 mJ/m2, "
                        "2.5 % noise (scripts/make_calibrate_example.py)")


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path("examples/calibrate"))

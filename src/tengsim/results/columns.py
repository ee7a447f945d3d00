"""The columns of a contact result's table, in output order."""

CURVE_COLUMNS = ["branch", "D", "F", "contact_length", "area_repulsive", "charged_fraction", "converged", "residual",
                 "iterations", "n_conv", "on_grid", "jump", "min_gap", "max_pressure",
                 "min_pressure", "energy", "seconds", "in_law_range", "process_zone", "status"]
PHYSICAL_COLUMNS = ["F_N", "pressure_Pa", "contact_length_m"]
FLAGS = ("converged", "on_grid", "jump", "in_law_range")

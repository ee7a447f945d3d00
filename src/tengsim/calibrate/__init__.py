"""Fit the model to a measured device: σ, W, ε (and E*) from measured V_OC(P), with profile-likelihood intervals,
identifiability in words, and a material file whose predictions carry bands::

    from tengsim.calibrate import plan_calibration, calibrate, write_calibration
    prob = plan_calibration(["pyramid.toml"], ["measured.csv"], free="sigma,W,eps")
    cal = calibrate(prob, "fit")          # designs kept in fit/designs; a frozen Calibration
    write_calibration(cal, "fit")         # report.md, fit.nc, fit.csv, figures, material.toml
"""
from tengsim.calibrate.data import Curve, read_curve, write_curve
from tengsim.calibrate.run import Calibration, calibrate, plan_calibration
from tengsim.calibrate.write import write_calibration

__all__ = ["Calibration", "Curve", "calibrate", "plan_calibration", "read_curve", "write_calibration", "write_curve"]

"""Physical constants (SI), defined once for every layer: the device model, the design's V_OC, calibration."""

EPS0 = 8.8541878128e-12
"""Vacuum permittivity (F/m, CODATA 2018); the paper rounds it to 8.85e-12."""

"""Viscoelastic contact on a time axis: each time step one elastic equilibrium of the existing kind at the
material's instantaneous modulus, with the history's gap offset (docs/viscoelastic.md)."""
from tengsim.visco.history import (FixedTimeSteps, GeometricTimeSteps, History, SegmentSteps, ramp_hold, read_history,
                                   square_wave, triangle)
from tengsim.visco.memory import MaxwellMemory, StepOperator
from tengsim.visco.result import TimeResult
from tengsim.visco.drive import TimeDrive
from tengsim.visco.simulate import simulate_history

__all__ = ["FixedTimeSteps", "GeometricTimeSteps", "History", "SegmentSteps", "ramp_hold", "read_history", "square_wave",
           "triangle", "MaxwellMemory", "StepOperator", "TimeResult", "TimeDrive", "simulate_history"]

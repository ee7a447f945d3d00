"""Viscoelastic contact on a time axis: each time step one elastic equilibrium of the existing kind at the
material's instantaneous modulus, with the history's gap offset (docs/viscoelastic.md)."""
from tengsim.visco.history import (FixedTimeSteps, GeometricTimeSteps, History, SegmentSteps, ramp_hold, read_history,
                                   square_wave, triangle)
from tengsim.visco.memory import MaxwellMemory, StepOperator
from tengsim.visco.result import TimeResult
from tengsim.visco.drive import DriveEnd, TimeDrive
from tengsim.visco.periodic import PeriodicCycles, periodic_cycles
from tengsim.visco.simulate import build_drive, simulate_history, simulate_periodic

__all__ = ["FixedTimeSteps", "GeometricTimeSteps", "History", "SegmentSteps", "ramp_hold", "read_history", "square_wave",
           "triangle", "MaxwellMemory", "StepOperator", "TimeResult", "DriveEnd", "TimeDrive",
           "PeriodicCycles", "periodic_cycles", "build_drive", "simulate_history", "simulate_periodic"]

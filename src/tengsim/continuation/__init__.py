"""Continuation: the paths a contact run walks, in one package.

- :mod:`~tengsim.continuation.specs`: the path specifications, :class:`PathSpec` (D controlled) and
  :class:`LoadPathSpec` (load controlled), frozen and validated at construction;
- :mod:`~tengsim.continuation.walker`: the branch walker (predictor, solve, continuation past a cap,
  jump test) and :mod:`~tengsim.continuation.steps`, the step control it is given;
- :mod:`~tengsim.continuation.recorder`: each equilibrium as a row of the result table;
- :mod:`~tengsim.continuation.path` (:func:`run_path`, :func:`walk_states`) and
  :mod:`~tengsim.continuation.load` (:func:`run_load_path`): the two drivers;
- :mod:`~tengsim.continuation.compare`: how far one path's force curve is from another's.
"""
from tengsim.continuation.compare import compare_paths
from tengsim.continuation.load import run_load_path
from tengsim.continuation.path import run_path, walk_states
from tengsim.continuation.recorder import Recorder
from tengsim.continuation.specs import BRANCHES, LoadPathSpec, PathSpec
from tengsim.continuation.steps import AdaptiveSteps, FixedSteps
from tengsim.continuation.walker import PERSIST_FACTOR, Walker, persist, secant

__all__ = ["AdaptiveSteps", "BRANCHES", "FixedSteps", "LoadPathSpec", "PERSIST_FACTOR", "PathSpec", "Recorder",
           "Walker", "compare_paths", "persist", "run_load_path", "run_path", "secant", "walk_states"]

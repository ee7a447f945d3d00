"""Surface interaction laws P(g), Φ(g) of the gap g = h/ε (paper Eq. 2/8), one module per law.

Importing this package registers the built-in laws in :data:`tengsim.registry.LAWS`, exactly as a
plugin's module registers its own.
"""
from tengsim.laws.base import LJ_PEAK_TENSION, Law, make_law
from tengsim.laws.lj93 import LJ93
from tengsim.laws.repulsive import Repulsive
from tengsim.laws.maugis_dugdale import MaugisDugdale
from tengsim.laws.exponential import Exponential
from tengsim.laws.safe import SafeLaw, safe

__all__ = ["LJ93", "LJ_PEAK_TENSION", "Exponential", "Law", "MaugisDugdale", "Repulsive", "SafeLaw", "make_law", "safe"]

"""Numbers as a designer reads them: lengths in nm/µm/mm, pressures in Pa/kPa/MPa (for messages, reports, plots);
defined once in :mod:`tengsim.units`, where the run layer's lines use them too."""
from __future__ import annotations

from tengsim.units import bytes_text, length_text, pressure_text, time_text  # noqa: F401

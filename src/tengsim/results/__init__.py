"""Results of a contact run: the value, how it is written and how it is read back.

- :mod:`~tengsim.results.result`: :class:`ContactResult` (frozen: curves, maps, events, parameters) and
  :class:`Jump`; :mod:`~tengsim.results.columns`: the table's columns;
- :mod:`~tengsim.results.write`: CSV and CF-1.10 NetCDF;
- :mod:`~tengsim.results.stream`: the rows of a run written as it goes (``OUT.partial.csv``), resumed;
- :mod:`~tengsim.results.read`: any tengsim result file read back (contact, device, load sweep).

Atomic writes are :mod:`tengsim.io`'s, below them all.
"""
from tengsim.results.columns import CURVE_COLUMNS, PHYSICAL_COLUMNS
from tengsim.results.read import REQUIRED_CONTACT, incomplete_note, load_result, read_partial
from tengsim.results.result import ContactResult, Jump
from tengsim.results.stream import RowStream, checkpoint_path, partial_maps_path, partial_path, run_digest

__all__ = ["CURVE_COLUMNS", "PHYSICAL_COLUMNS", "REQUIRED_CONTACT", "ContactResult", "Jump", "RowStream",
           "checkpoint_path", "incomplete_note", "load_result", "partial_maps_path", "partial_path",
           "read_partial", "run_digest"]

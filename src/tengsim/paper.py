"""Re-export only (old import path): the paper's contact cases live in :mod:`tengsim.cases.paper.contact`."""
from tengsim.cases.paper.contact import (FIG3_D, GROUPS, PAPER_TRANSITION_D, RunSettings, area_table,  # noqa: F401
                                         area_table_from_result, contact_summary, group_shape, run_group)
from tengsim.device.params import AreaTable  # noqa: F401

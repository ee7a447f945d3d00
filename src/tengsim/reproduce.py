"""Re-export only (old import path): ``reproduce`` lives in :mod:`tengsim.cases.paper.reproduce`."""
from tengsim.cases.paper.reproduce import FIG5_EPS_R, FIG5_SIGMA, FIG5_T, reproduce, summary_text  # noqa: F401

"""``tengsim reproduce``: the paper's Figs. 3, 4, 5, 7, 8 with data and summary.json."""
from __future__ import annotations

import sys

SUMMARY = "reproduce the paper's figures 3, 4, 5, 7, 8"  # its line in `tengsim --help`


def register(sub):
    p = sub.add_parser("reproduce", help=SUMMARY,
                       description="Run the three pyramid groups and the two device cases; write "
                       "fig3..fig8 (PNG and PDF), their data (CSV, NetCDF) and summary.json.")
    p.add_argument("--out", default="tengsim-paper", help="output folder (default ./tengsim-paper)")
    p.add_argument("--quick", action="store_true", help="coarse grids: a couple of minutes on 2 cores")
    p.add_argument("--quiet", action="store_true", help="no progress output")
    p.set_defaults(func=run)


def run(args) -> int:
    from tengsim.outfolder import check_folder, folder_lock

    check_folder(args.out)  # an existing file or an unwritable folder: refused before the numerical imports
    from tengsim.cases.paper.reproduce import reproduce, summary_text
    from tengsim.progress import Progress

    log = None if args.quiet else (lambda m: print(m, file=sys.stderr, flush=True))
    with folder_lock(args.out, holder="tengsim reproduce"):  # no other run on it meanwhile
        summary = reproduce(args.out, quick=args.quick, log=log,
                            progress_factory=lambda label: Progress(args.quiet))
    if not args.quiet:
        for line in summary_text(summary):
            print(line, file=sys.stderr)
        print(f"wrote {args.out}/ (summary.json, fig3..fig8) in {summary['seconds']:.0f} s", file=sys.stderr)
    return 0

"""``tengsim run CONFIG.toml``: repeat any run described in a TOML file.

The file holds one table naming the run: ``[contact]`` (the options of ``tengsim contact``, plus
``out`` and optional ``plot``), ``[reproduce]`` (``out``, ``quick``) or ``[device]``: a device file may
also hold ``[waveform]``, ``[run]`` (``case`` = fig7/fig8/run/sweep, ``out``, ...), ``[solver]`` and
``[sweep]`` (``tengsim device fields`` lists every key).  Results carry the configuration and the
package version.
"""
from __future__ import annotations

import dataclasses
import sys
from pathlib import Path

from tengsim.errors import TengsimError

SUMMARY = 'run what a TOML config file describes'  # its line in `tengsim --help`


def register(sub):
    p = sub.add_parser("run", help=SUMMARY,
                       description=__doc__.split("\n\n", 1)[1])
    p.add_argument("config", help="TOML file with a [contact], [device] or [reproduce] table")
    p.add_argument("--quiet", action="store_true", help="no progress output")
    p.add_argument("--resume", action="store_true",
                   help="[contact] only: continue the interrupted run from OUT.partial.csv (as tengsim contact --resume)")
    p.set_defaults(func=run)


def run(args) -> int:
    from tengsim.schema import check_tables, read_config

    cfg = read_config(args.config)
    if getattr(args, "resume", False) and "contact" not in cfg:
        raise TengsimError(f"--resume continues a [contact] run; {args.config} has no [contact] table")
    if "device" in cfg:  # a device file: [device], [waveform], [run], [solver], [sweep] (tengsim device fields)
        from tengsim.cli import device as device_cli

        return device_cli.run_config(cfg, args)
    check_tables(cfg, ("contact", "device", "reproduce"), where=str(args.config))
    kinds = [k for k in ("contact", "reproduce") if k in cfg]
    if len(kinds) != 1:
        raise TengsimError(f"{args.config}: needs exactly one of [contact], [device], [reproduce]")
    kind = kinds[0]
    section = dict(cfg[kind])
    if kind == "contact":
        return _contact(section, args)
    if kind == "reproduce":
        from tengsim.cases.paper.reproduce import reproduce
        from tengsim.schema import Field, Table

        vals = Table("reproduce", [Field("out", "str", "tengsim-paper", help="output folder"),
                                   Field("quick", "bool", False, help="coarse grids (minutes)")]).parse(section)
        out, quick = vals["out"], vals["quick"]
        from tengsim.outfolder import output_folder

        with output_folder(out, [args.config], what="out =", holder="tengsim run"):
            reproduce(out, quick=quick, log=None if args.quiet else (lambda m: print(m, file=sys.stderr)))
        return 0


def _contact(section, args) -> int:
    from tengsim.cli.contact import open_stream, run_streamed, write_contact
    from tengsim.run.plan import plan_contact
    from tengsim.run.resolve import resolve
    from tengsim.run.simulate import simulate

    plan = plan_contact(section)  # every key checked before anything is written; the one plan of the run
    run_contact = simulate if plan.resolve is None else resolve  # one grid, or refined until converged
    out = section.get("out")
    if not out:
        raise TengsimError("[contact] needs out = 'FILE.csv' or 'FILE.nc'")
    if not isinstance(out, str):
        raise TengsimError(f"[contact] out must be a file name, got {out!r}")
    if Path(out).suffix.lower() not in (".csv", ".nc"):
        raise TengsimError(f"out = {out!r}: use a .csv or .nc file")
    plot = section.get("plot")
    if plot and (not isinstance(plot, str) or Path(plot).suffix.lower() not in (".png", ".pdf", ".svg")):
        raise TengsimError(f"plot = {plot!r}: use a .png, .pdf or .svg file")
    from tengsim.io import check_output

    inputs = [args.config, *(v for k, v in section.items() if k not in ("out", "plot"))]
    check_output(out, inputs, what="out =")
    if plot:
        check_output(plot, inputs, what="plot =")
    stream = open_stream(out, getattr(args, "resume", False), args.quiet)
    res = run_streamed(lambda bar: run_contact(plan, progress=bar, sink=stream), stream, args.quiet)
    if res is None:
        return 130
    res = dataclasses.replace(res, params={**res.params, "config_file": str(args.config)})
    return write_contact(res, out, plot, args.quiet, stream)

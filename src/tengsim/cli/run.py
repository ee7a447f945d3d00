"""``tengsim run CONFIG.toml``: repeat any run described in a TOML file.

The file holds one table naming the run: ``[contact]`` (the options of ``tengsim contact``, plus
``out`` and optional ``plot``), ``[reproduce]`` (``out``, ``quick``) or ``[device]``: a device file may
also hold ``[waveform]``, ``[run]`` (``case`` = fig7/fig8/run/sweep, ``out``, ...), ``[solver]`` and
``[sweep]`` (``tengsim device fields`` lists every key).  Results carry the configuration and the
package version.
"""
from __future__ import annotations

import sys
from pathlib import Path

from tengsim.errors import TengsimError


def register(sub):
    p = sub.add_parser("run", help="run what a TOML config file describes",
                       description=__doc__.split("\n\n", 1)[1])
    p.add_argument("config", help="TOML file with a [contact], [device] or [reproduce] table")
    p.add_argument("--quiet", action="store_true", help="no progress output")
    p.set_defaults(func=run)


def run(args) -> int:
    from tengsim.config import load_toml

    cfg = load_toml(args.config)
    if "device" in cfg:  # a device file: [device], [waveform], [run], [solver], [sweep] (tengsim device fields)
        from tengsim.cli import device as device_cli

        return device_cli.run_config(cfg, args)
    kinds = [k for k in ("contact", "device", "reproduce") if k in cfg]
    extra = set(cfg) - {"contact", "device", "reproduce"}
    if extra:
        raise TengsimError(f"{args.config}: unknown table(s) {', '.join(sorted(extra))}")
    if len(kinds) != 1:
        raise TengsimError(f"{args.config}: needs exactly one of [contact], [device], [reproduce]")
    kind = kinds[0]
    section = dict(cfg[kind])
    if kind == "contact":
        return _contact(section, args)
    if kind == "reproduce":
        from tengsim.reproduce import reproduce

        out = section.pop("out", "tengsim-paper")
        quick = bool(section.pop("quick", False))
        if section:
            raise TengsimError(f"unknown reproduce option(s): {', '.join(sorted(section))}")
        reproduce(out, quick=quick, log=None if args.quiet else (lambda m: print(m, file=sys.stderr)))
        return 0


def _contact(section, args) -> int:
    from tengsim.cli.contact import write_contact
    from tengsim.config import run_contact
    from tengsim.progress import Progress

    out = section.get("out")
    if not out:
        raise TengsimError("[contact] needs out = 'FILE.csv' or 'FILE.nc'")
    if Path(out).suffix.lower() not in (".csv", ".nc"):
        raise TengsimError(f"out = {out!r}: use a .csv or .nc file")
    from tengsim.io import check_writable

    check_writable(out)
    bar = Progress(args.quiet)
    try:
        res = run_contact(section, progress=bar)
    finally:
        bar.close()
    res.params["config_file"] = str(args.config)
    return write_contact(res, out, section.get("plot"), args.quiet)

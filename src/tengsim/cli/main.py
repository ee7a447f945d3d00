"""Entry point ``tengsim``: dispatches to one module per subcommand.

Each subcommand module defines ``register(subparsers)`` which adds its parser and sets
``func`` (called with the parsed namespace, returns an exit code).
"""
from __future__ import annotations

import argparse
import importlib
import sys

from tengsim.errors import TengsimError

SUBCOMMANDS = ["contact", "device", "reproduce", "run", "plot", "sweep", "optimize"]


def build_parser() -> argparse.ArgumentParser:
    from tengsim._version import __version__

    p = argparse.ArgumentParser(
        prog="tengsim",
        description="Adhesive contact of micro-structured TENG interfaces and the device output.",
    )
    p.add_argument("--version", action="version", version=f"tengsim {__version__}")
    sub = p.add_subparsers(dest="command", metavar="COMMAND")
    for name in SUBCOMMANDS:
        try:
            mod = importlib.import_module(f"tengsim.cli.{name}")
        except ModuleNotFoundError as exc:  # subcommand not built yet
            if exc.name != f"tengsim.cli.{name}":
                raise
            continue
        mod.register(sub)
    return p


def main(argv=None) -> int:
    from tengsim.plugins import load_plugins

    try:
        load_plugins()  # user shapes, laws, kernels, solvers, observers: before the parser lists them
    except TengsimError as exc:
        print(f"tengsim: error: {exc}", file=sys.stderr)
        return 2
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "func", None):
        parser.print_help()
        return 2
    try:
        return int(args.func(args) or 0)
    except TengsimError as exc:
        print(f"tengsim: error: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:  # a file that cannot be read or written: one line, no traceback
        where = f" {exc.filename}" if getattr(exc, "filename", None) else ""
        print(f"tengsim: error:{where}: {exc.strerror or exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("tengsim: interrupted; no partial output was written", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())

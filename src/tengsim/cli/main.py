"""Entry point ``tengsim``: dispatches to one module per subcommand.

Each subcommand module defines ``register(subparsers)`` which adds its parser and sets
``func`` (called with the parsed namespace, returns an exit code), and ``SUMMARY`` (its one-line help).
Only the subcommand named on the command line is registered in full; the others appear in
``tengsim --help`` by their ``SUMMARY`` alone, so neither ``--version`` nor ``--help`` imports a
subcommand's numerical modules (a module without ``SUMMARY`` is registered in full).
"""
from __future__ import annotations

import argparse
import importlib
import os
import re
import sys

# One BLAS thread unless the user says otherwise, set before NumPy loads: tengsim's BLAS calls are the L-BFGS
# products over a few stored rows and dot products, where OpenBLAS' threads double the CPU time and gain no wall
# time (the README pyramid at tol 0.05: 116 s of CPU against 56 s, 65 s of wall against 57 s; docs/benchmarks.md).
# The FFTs' threads are set apart (TENGSIM_FFT_WORKERS).
for _name in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_name, "1")

from tengsim.errors import TengsimError  # noqa: E402  (after the BLAS threads are set)

SUBCOMMANDS = ["design", "calibrate", "contact", "device", "reproduce", "run", "plot", "sweep", "optimize"]


class Parser(argparse.ArgumentParser):
    """argparse with tengsim's manners: a bad option is one line naming it (no usage wall), and a negative
    number in any notation ('-1e+16', '-.5'), with or without a unit ('-5kPa', '-1%'), is a value, not an option;
    any other value starting with '-' is given as --option=VALUE, which "expected one argument" says."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        # a negative number, or a negative quantity ('-0.59MPa', '-2 kPa', '-5um'): a value, not an option
        self._negative_number_matcher = re.compile(
            r"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?(\s*(%|[A-Za-zµμΩ][A-Za-zµμΩ/^²0-9]*))?$|^-(inf|nan)$", re.I)

    argv: list = []
    """The command line being parsed (set by :func:`_main`): a wrong key points to its command's help."""

    def error(self, message):
        # a hostile value echoed by argparse ('invalid int value: ...') is cut, as tengsim's own messages cut it
        if message.endswith("expected one argument"):
            message += " (a value starting with '-' is given as --option=VALUE)"
        self.exit(2, f"tengsim: error: {cut(message, 60)} (see '{help_for(Parser.argv, self.prog)}')\n")


def help_for(argv, prog: str = "tengsim") -> str:
    """The help that lists the keys a command line may use: 'tengsim design pyramid --help' for a design of
    a shape, 'tengsim contact --help' for a command, else ``prog --help``."""
    words = [str(w) for w in argv or ()]
    command = chosen_command(words)
    if command is None:
        return f"{prog} --help"
    rest = words[words.index(command) + 1:]
    if command == "design" and rest and not rest[0].startswith("-") and not rest[0].lower().endswith(".toml") \
            and len(rest[0]) < 40 and rest[0].isidentifier():
        return f"tengsim design {rest[0]} --help"
    return f"tengsim {command} --help"


def cut(message: str, longest: int = 300) -> str:
    """``message`` with every run of more than ``longest`` non-blank characters cut to 60 plus '…': the
    last guard (at the edge) against echoing a hostile value whole; a path of ordinary length is kept."""
    from tengsim.errors import SHOWN

    return re.sub(r"\S{%d,}" % (longest + 1), lambda m: m.group(0)[:SHOWN] + "…", str(message))


def chosen_command(argv) -> str | None:
    """The subcommand named in ``argv`` (the first word that is not an option), or None."""
    for word in argv:
        if not word.startswith("-"):
            return word if word in SUBCOMMANDS else None
    return None


def build_parser(command: str | None = "*") -> argparse.ArgumentParser:
    """The parser; ``command``: the one subcommand to register in full ('*': every one, None: none)."""
    from tengsim._version import __version__

    p = Parser(
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
        summary = getattr(mod, "SUMMARY", None)
        if command in ("*", name) or summary is None:
            mod.register(sub)
        else:
            sub.add_parser(name, help=summary, add_help=False)
    return p


INTERNAL_ERROR = 70  # exit code of a fault inside tengsim (EX_SOFTWARE of sysexits.h); bad input is 2


def crash_log_dir():
    """Where the traceback of an internal error goes: $XDG_CACHE_HOME/tengsim (default ~/.cache/tengsim)."""
    import os
    from pathlib import Path

    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "tengsim"


def _log_internal_error(exc, argv) -> str:
    """Write the traceback of ``exc`` (with the command line and versions) to a new log file; returns
    'traceback in PATH', or why none was written (the cache folder, then the temp folder, are tried)."""
    import os
    import platform
    import tempfile
    import time
    import traceback
    from pathlib import Path

    from tengsim._version import __version__

    text = (f"tengsim {__version__}, Python {platform.python_version()} on {platform.platform()}\n"
            f"command: tengsim {' '.join(sys.argv[1:] if argv is None else map(str, argv))}\n"
            f"time: {time.strftime('%Y-%m-%d %H:%M:%S %z')}\n\n"
            + "".join(traceback.format_exception(type(exc), exc, exc.__traceback__)))
    name = f"crash-{time.strftime('%Y%m%d-%H%M%S')}-{os.getpid()}.log"
    why = "no folder to write it in"
    for folder in (crash_log_dir(), Path(tempfile.gettempdir()) / "tengsim"):
        try:
            folder.mkdir(parents=True, exist_ok=True)
            path = folder / name
            with open(path, "x", encoding="utf-8") as fh:
                fh.write(text)
            return f"traceback in {path}"
        except OSError as err:
            why = f"{folder}: {err.strerror or err}"
    return f"traceback not saved: {why}"


def main(argv=None) -> int:
    """Run one command; any fault that is not a user's error is one line plus the path of a log holding
    its traceback (exit code :data:`INTERNAL_ERROR`)."""
    _printable_streams()
    try:
        return _main(argv)
    except Exception as exc:  # noqa: BLE001 - a bug of tengsim or of a plugin: no traceback on the terminal
        where = _log_internal_error(exc, argv)
        msg = " ".join(str(exc).split()) or "(no message)"
        print(f"tengsim: internal error: {type(exc).__name__}: {msg} ({where})", file=sys.stderr)
        return INTERNAL_ERROR


def _printable_streams() -> None:
    """stdout and stderr that never fail on a character their encoding lacks (LC_ALL=C with PYTHONUTF8=0:
    ASCII): 'µm' is printed as '\\xb5m' instead of a crash after the results were computed."""
    for stream in (sys.stdout, sys.stderr):
        enc = str(getattr(stream, "encoding", "") or "").lower().replace("-", "")
        if enc and enc != "utf8" and hasattr(stream, "reconfigure"):
            try:
                stream.reconfigure(errors="backslashreplace")
            except (ValueError, OSError):  # pragma: no cover - a stream that cannot change
                pass


def _main(argv=None) -> int:
    command = chosen_command(sys.argv[1:] if argv is None else [str(a) for a in argv])
    if command is not None:
        from tengsim.plugins import load_plugins

        try:
            load_plugins()  # user shapes, laws, kernels, solvers, observers: before the parser lists them
        except TengsimError as exc:
            print(f"tengsim: error: {cut(exc)}", file=sys.stderr)
            return 2
    parser = build_parser(command)
    Parser.argv = sys.argv[1:] if argv is None else [str(a) for a in argv]
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # a bad option: one line already printed (--help and --version exit as usual)
        if exc.code in (0, None):
            raise
        return int(exc.code)
    if not getattr(args, "func", None):
        parser.print_help()
        return 2
    try:
        return int(args.func(args) or 0)
    except TengsimError as exc:
        print(f"tengsim: error: {cut(exc)}", file=sys.stderr)
        return 2
    except OSError as exc:  # a file that cannot be read or written (ENOSPC, EACCES, EROFS): one line naming it
        where = f" {exc.filename}" if getattr(exc, "filename", None) else ""
        print(cut(f"tengsim: error:{where}: {exc.strerror or exc}"), file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("tengsim: interrupted before its results were written (a run that keeps finished work says "
              "where above)", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())

r"""``tengsim calibrate``: fit σ, W, ε (and E*) to measured V_OC(P), with uncertainty (thin shell over
:mod:`tengsim.calibrate`).

Examples::

    tengsim calibrate pyramid.toml --data measured.csv --free sigma,W,eps --out fit/
    tengsim calibrate a.toml b.toml --data a.csv b.csv --free sigma,W,eps,E_star --bounds eps=50nm:300nm --out fit/
    tengsim design new.toml --material fit/material.toml --out new/     # the prediction, with bands
"""
from __future__ import annotations

import sys
from pathlib import Path

from tengsim.errors import TengsimError

SUMMARY = "fit σ, W, ε (and E*) to measured V_OC(P): intervals, identifiability, a material for design"

USAGE = ("tengsim calibrate DESIGN.toml [DESIGN2.toml ...] --data measured.csv [measured2.csv ...] "
         "[--free sigma,W,eps] [--bounds W=20mJ/m2:200mJ/m2,...] --out DIR")
DESCRIPTION = (
    "Fits the material (σ, W, ε and optionally E*) to measured open-circuit voltage against pressure, one design "
    "(a TOML that tengsim design accepts) per measured curve, all curves jointly. σ is profiled in closed form; W "
    "and ε come from converged designs on a grid in (W, ε), interpolated, their error reported; E* scales the "
    "pressure. Writes DIR/report.md, fit.nc, fit.csv, fit.png, residuals.png, profiles.png and material.toml "
    "(tengsim design --material); every solved design is kept in DIR/designs (a rerun takes them back). "
    "CSV: a header, pressure_kPa or pressure_Pa, voc_V, optional branch and voc_err_V, '#' comments; ',' ';' or "
    "a tab between columns, a decimal point (6.1, never 6,1), at most 10 000 points.")


def register(sub):
    p = sub.add_parser("calibrate", allow_abbrev=False, usage=USAGE, description=DESCRIPTION,
                       help="fit the material to measured V_OC(P), with 95 %% intervals")
    p.add_argument("designs", nargs="+", metavar="DESIGN.toml", help="the design each curve was measured on (one, "
                   "or one per --data file)")
    p.add_argument("--data", nargs="+", required=True, metavar="CSV", help="measured curves (CSV)")
    p.add_argument("--free", default="sigma,W,eps", help="the parameters to fit among sigma, W, eps, E_star "
                   "(default sigma,W,eps; the others as the designs give them)")
    p.add_argument("--bounds", default=None, help="NAME=LOW:HIGH,... with units (defaults: sigma 0.01uC/m2:500uC/m2, "
                   "W 10mJ/m2:1000mJ/m2, eps 20nm:400nm, E_star 0.1MPa:10MPa)")
    p.add_argument("--noise", default="relative", choices=("relative", "absolute"),
                   help="noise model when no voc_err_V column is given (default relative; its scale is estimated)")
    p.add_argument("--voc", default="eq12", choices=("eq12", "eq17"),
                   help="the V_OC model the data are compared with (default eq12: σ (A/S) T/(ε_r ε0))")
    p.add_argument("--nodes", type=_whole, default=4, help="designs per free axis of each (W, ε) grid (default 4)")
    p.add_argument("--zooms", type=_whole, default=2, help="new grids on the region that fits, at most (default 2)")
    p.add_argument("--refine", type=_whole, default=3, help="rounds after the zooms in which the checks (designs at the "
                   "best fit and the interval ends) become designs of the interpolation, while its error is above "
                   "half the noise (default 3)")
    p.add_argument("--solver", default=None, help="the designs' solver, as a design's solver key (auto, numpy, "
                   "gpu, ...; default: as the design files say)")
    p.add_argument("--expected-noise", default=None, metavar="NOISE",
                   help="the data's noise as known beforehand (relative noise: e.g. 2%%; absolute: e.g. 0.5V or "
                        "50mV): the report warns when the fitted noise is more than twice it")
    p.add_argument("--out", required=True, help="output folder (created; not on bad input)")
    p.add_argument("--quiet", action="store_true", help="no progress lines")
    p.set_defaults(func=run)


WRITES = ("report.md", "fit.nc", "fit.csv", "fit.png", "residuals.png", "profiles.png", "material.toml")
"""The files a calibration writes in --out (beside the designs/ folder it keeps its solved designs in)."""


def run(args) -> int:
    from tengsim.calibrate import plan_calibration
    from tengsim.calibrate.surrogate import input_files
    from tengsim.outfolder import check_folder, folder_lock

    if not 2 <= args.nodes <= 9:
        raise TengsimError(f"--nodes {args.nodes}: 2 to 9 designs per axis")
    if not 0 <= args.zooms <= 5:
        raise TengsimError(f"--zooms {args.zooms}: 0 to 5")
    if not 0 <= args.refine <= 10:
        raise TengsimError(f"--refine {args.refine}: 0 to 10")
    expected = _expected_noise(args.expected_noise, args.noise)
    prob = plan_calibration(_designs(args.designs), args.data, args.free, args.bounds, args.noise, args.voc,
                            args.solver)
    if expected is not None and prob.known_errors:
        raise TengsimError(f"--expected-noise {args.expected_noise}: the data give voc_err_V, their stated errors are "
                           "the noise; leave it out")
    out = Path(args.out)
    inputs = [*args.designs, *args.data, *(f for t in prob.tables for f in input_files(t))]
    check_folder(out, inputs, [out / name for name in WRITES])  # never over (or around) an input
    with folder_lock(out, holder="tengsim calibrate"):  # the whole run: no design or calibration here meanwhile
        return _run_locked(args, prob, out, expected)


def _run_locked(args, prob, out, expected) -> int:
    from tengsim.calibrate import calibrate, write_calibration
    from tengsim.calibrate.run import say_to_stderr

    say = say_to_stderr(args.quiet)
    try:
        cal = calibrate(prob, out, n_nodes=args.nodes, zooms=args.zooms, progress=say, refine=args.refine,
                        expected_noise=expected)
    except KeyboardInterrupt:
        kept = sorted((out / "designs").glob("*.nc")) if (out / "designs").is_dir() else []
        kept = [p for p in kept if not p.name.endswith(".resolve.nc")]
        print("tengsim: interrupted: " + (f"the {len(kept)} finished design(s) are kept in {out / 'designs'}; run "
              "the same command again and it takes them back (and goes on from the interrupted design's finished "
              "grids)" if kept else f"no design had finished; the interrupted design's finished grids, if any, "
              f"are kept in {out / 'designs'} for a rerun"), file=sys.stderr)
        return 130
    paths = write_calibration(cal, out)
    if say:
        for w in cal.fit.words:
            say(w)
        say(f"wrote {len(paths)} files in {out} (report: {out / 'report.md'})")
    if not cal.surrogate_ok:
        from tengsim.calibrate.fit import residual_text

        print(f"tengsim: warning: the interpolation's error ({residual_text(cal.surrogate_error, prob)}) is above "
              f"half the noise ({residual_text(cal.fit.scale, prob)}): see {out / 'report.md'}", file=sys.stderr)
    return 0


def _whole(text) -> int:
    """--nodes, --zooms, --refine: a whole number read by :func:`tengsim.units.read_number` (no underscores:
    '0_4' is refused, not read as 4); argparse names the option."""
    import argparse

    from tengsim.errors import NumberError, shown
    from tengsim.units import read_number

    try:
        n = read_number(text, "value")
    except NumberError as exc:
        raise argparse.ArgumentTypeError(exc.named(None)) from None
    except ValueError:
        n = float("nan")
    if not (n == n and n == int(n)):
        raise argparse.ArgumentTypeError(f"{shown(text)} is not a whole number")
    return int(n)


_VOLTS = {"V": 1.0, "mV": 1e-3, "uV": 1e-6, "µV": 1e-6}


def _expected_noise(text, noise):
    """--expected-noise in the noise model's unit: a fraction of V_OC from "2%" (relative), volts from "0.5V" or
    "50mV" (absolute); None when not given.  The number is read by :func:`tengsim.units.read_number` ('0_5%' is
    refused, not read as 5 %)."""
    import re

    from tengsim.errors import NumberError
    from tengsim.units import read_number

    if text is None:
        return None
    t = str(text).strip()
    units = {"%": 1e-2} if noise == "relative" else _VOLTS
    m = re.fullmatch(r"(.*?)\s*(%|V|mV|uV|µV)", t)
    try:
        if not m or m.group(2) not in units:
            raise ValueError
        value = read_number(m.group(1), f"--expected-noise {t}") * units[m.group(2)]
    except NumberError as exc:
        raise TengsimError(exc.named(f"--expected-noise {t}", value=False)) from None
    except ValueError:
        raise TengsimError(f"--expected-noise {text}: give it with its unit, e.g. "
                           f"{'2%' if noise == 'relative' else '0.5V'} ({noise} noise)") from None
    if not (value > 0 and value < (1 if noise == "relative" else float("inf"))):
        raise TengsimError(f"--expected-noise {text}: a positive noise{' below 100 %' if noise == 'relative' else ''}")
    return value


def _designs(paths) -> list:
    """[(path, table)] of the design files, read at the edge (:func:`tengsim.schema.read_config`) and taken by the
    one reading of a design's tables (:func:`tengsim.design.design_table`, as ``tengsim design`` reads them)."""
    from tengsim.design import design_table
    from tengsim.schema import read_config

    out = []
    for p in paths:
        if not Path(p).is_file():
            raise TengsimError(f"{p}: no such file (give a design TOML that tengsim design accepts)")
        out.append((p, design_table(read_config(p), p)))
    return out

r"""``tengsim design``: a designer's question in one command (thin shell over :mod:`tengsim.design`).

Examples::

    tengsim design pyramid --pitch 10um --base 5um --height 3.5um --E-star 1MPa --W 50mJ/m2 --eps 200nm \
        --p-max 100kPa --p-step 5kPa --out d1/
    tengsim design d1.toml --out d1/                  # the same keys in a TOML file ([design] or top level)
    tengsim design a.toml b.toml --out cmp/           # each in cmp/NAME/, plus cmp/compare.csv and compare.png
"""
from __future__ import annotations

import os
import sys
from pathlib import Path

from tengsim.errors import TengsimError

SUMMARY = "your own design: charged area, V_OC and pull-off against pressure, in physical units"  # its line in `tengsim --help`


def _keys() -> dict:
    """{key: help} of every option: the design's own keys, then every shape's physical [contact] keys that a
    design leaves to the user (from the registry and the schema)."""
    from tengsim.run.keys import contact_table
    from tengsim.design.plan import CONTROLLED, design_fields
    from tengsim.registry import SHAPES

    out = {f.name: f.help for f in design_fields()}
    for s in SHAPES.names():
        for k, f in contact_table(s, "physical").fields.items():
            if k in CONTROLLED or k in out or k == "shape":
                continue
            out[k] = f.help or k
    return out


DESCRIPTION = (
    "One design (a registered shape with its sizes, E*, W and the interaction range eps, and the pressures) or "
    "several TOML files: the charged area A/S, V_OC (Eq. 12; Eq. 17 at the rest gap) and dV_OC/dP per pressure "
    "on approach and retraction, and the jump-in, pull-off, full-contact pressure, linear range and hysteresis; "
    "the grid is chosen and refined until the numbers converge to --tol. Writes OUT/design.nc, design.csv, "
    "design.png, maps.png, report.md (several designs: OUT/NAME/..., OUT/compare.csv, compare.png).")
USAGE = "tengsim design SHAPE --KEY VALUE ... --out DIR  |  tengsim design FILE.toml [FILE.toml ...] --out DIR"


def register(sub):
    p = sub.add_parser("design", allow_abbrev=False, add_help=False, usage=USAGE, description=DESCRIPTION,
                       help="a micro-structure's A/S, V_OC and sensitivity against pressure, converged, in "
                       "physical units")
    p.add_argument("inputs", nargs="*", metavar="SHAPE|FILE.toml")
    p.add_argument("-h", "--help", action="store_true", dest="help")
    for k, h in _keys().items():
        p.add_argument("--" + k.replace("_", "-"), dest=k, help=str(h).replace("%", "%%"))
    p.add_argument("--out", help="output folder (created; several designs: one subfolder each)")
    p.add_argument("--material", help="a material.toml (tengsim calibrate): its E_star, W, eps, sigma replace the "
                   "design's; with its uncertainty points, also bands.csv, bands.png (95 %% band of A/S, V_OC)")
    p.add_argument("--relaxation", help="a TOML file with a [relaxation] table: the design also pressed and released "
                   "at 0.5, 2 and 10 Hz on that viscoelastic material (visco.csv, visco_table.csv, visco.png, a "
                   "report section)")
    p.add_argument("--visco-sine", action="store_true", help="with --relaxation: also record the sine press "
                   "(p_max/2)(1 - cos 2 pi f t) with its memory, for `tengsim device design` with that sine (as many "
                   "periods again as the square press)")
    p.add_argument("--quiet", action="store_true", help="no progress lines")
    p.set_defaults(func=run)


BOUNDARY_HELP = ("periodic (a design's default): the periodic array of cells the shape's cell describes, every "
                 "cell beside its neighbours; free: one isolated cell on a half-space, Eq. (9) (a single "
                 "structure, or an array whose pitch is large against each contact); either on a film")
"""--boundary in a design's help: a design's default is periodic (:func:`tengsim.design.plan.plan_design`), not
tengsim contact's free."""


def help_text(shape: str | None = None) -> str:
    """The command's help: the design's keys, the material, then the keys of ``shape`` (all shapes' names if
    None) and the contact options a design leaves to the user."""
    import textwrap

    from tengsim.run.keys import common_fields, contact_table, law_key_help, law_keys
    from tengsim.design.plan import CONTROLLED, design_fields
    from tengsim.registry import SHAPES

    def line(k, h):
        flag = "--" + k.replace("_", "-")
        return textwrap.fill(f"{h}", width=110, initial_indent=f"  {flag:<24}", subsequent_indent=" " * 26)

    out = [f"usage: {USAGE}", "", textwrap.fill(DESCRIPTION, 110), "",
           "the design (pressures with a unit, e.g. 100kPa; a bare number is SI):"]
    out += [line(f.name, f.help) for f in design_fields()]
    own = {f.name for f in design_fields()}
    common = {f.name: f for f in common_fields()}
    laws = law_keys()
    out += ["", "the material (required: E_star, W, eps):"]
    out += [line(k, common[k].help.replace("; or give tabor", "")) for k in ("E_star", "W", "eps")]  # no tabor
    if shape is None:
        out += ["", f"the shape: one of {', '.join(SHAPES.names())}; its keys: tengsim design SHAPE --help"]
    else:
        name = SHAPES.canonical(shape)
        table = contact_table(name, "physical").fields
        mine = [k for k in table if k not in common and k not in laws and k not in CONTROLLED and k not in own]
        out += ["", f"the shape {name}:"] + [line(k, table[k].help) for k in mine]
    rest = [k for k in common if k not in CONTROLLED and k not in own and k not in ("E_star", "W", "eps", "shape")
            and not k.startswith("roughness_")]
    out += ["", "contact options (defaults as tengsim contact, but the boundary):"]
    out += [line(k, BOUNDARY_HELP if k == "boundary" else common[k].help) for k in rest]
    out += ["", "keys of the law (plain numbers in units of W and ε):"]
    out += [line(k, law_key_help(v)) for k, v in laws.items()]
    out += ["  --roughness-*            a roughness on the shape (keys as tengsim contact)",
            "  --out DIR                output folder (required; not created on bad input)",
            "  --quiet                  no progress lines"]
    return "\n".join(out) + "\n"


def _tables(args) -> list:
    """[(label, table)] of the designs the command line names."""
    from tengsim.design import read_design
    from tengsim.errors import shown
    from tengsim.registry import SHAPES

    opts = {k: getattr(args, k) for k in _keys() if getattr(args, k, None) not in (None, "")}
    names = [s.lower() for s in SHAPES.names()]
    first = args.inputs[0]
    if not first.lower().endswith(".toml"):
        if first.lower() not in names:
            raise TengsimError(f"unknown shape {shown(first)} (shapes: {', '.join(SHAPES.names())}; or give TOML "
                               "files)")
        if len(args.inputs) > 1:
            raise TengsimError("give one shape with its options, or TOML files: got "
                               f"{shown(' '.join(args.inputs), 200)}")
        return [("", {"shape": first, **opts})]
    bad = [x for x in args.inputs if not x.lower().endswith(".toml")]
    if bad:
        raise TengsimError(f"{shown(bad[0])}: several inputs must all be TOML files")
    return [(f"{x}: ", {**read_design(x), **opts}) for x in args.inputs]


def _check_out(out: Path) -> None:
    """Refuse an output folder that could not be written, without creating anything."""
    if out.exists() and not out.is_dir():
        raise TengsimError(f"--out {out}: exists and is not a folder")
    parent = out
    while not parent.exists():
        parent = parent.parent
    if not os.access(parent, os.W_OK):
        raise TengsimError(f"--out {out}: {parent} is not writable")


RESERVED = ("compare.csv", "compare.png")
"""A comparison's own files in --out: no design's folder may take their names."""
DESIGN_FILES = ("design.nc", "design.csv", "design.png", "maps.png", "report.md", "bands.csv", "bands.png")
"""The files of one design's folder (bands.csv, bands.png: with --material's uncertainty points)."""


def _folders(plans) -> list:
    """The folder (relative to --out) of each design: '' for one design; for several, a safe name made from
    each design's name (:func:`tengsim.io.safe_name`: never '..', '.', a hidden or reserved name), chosen
    before anything runs; a design named as the comparison's own files (compare.csv) is refused."""
    from tengsim.io import safe_name

    if len(plans) == 1:
        return [""]
    for p in plans:
        if p.name.strip().lower() in RESERVED:
            raise TengsimError(f"design name {p.name!r} is the name of the comparison's own file in --out: "
                               "choose another name")
    taken: set = set()
    return [safe_name(p.name, taken, RESERVED) for p in plans]


def _guard(out: Path, folders, inputs) -> None:
    """Every file the command will write, checked before anything is computed (:func:`tengsim.outfolder.check_folder`:
    no input (a topography file, a TOML file, the material) is --out, lies in it or is linked to a file written
    there), each lies inside --out and can be written."""
    from tengsim.outfolder import check_folder

    files = [out / f / name for f in folders for name in DESIGN_FILES]
    if len(folders) > 1:
        files += [out / name for name in RESERVED]
    check_folder(out, inputs, files)
    root = out.resolve()
    for f in files:
        if root != f.resolve().parent and root not in f.resolve().parents:  # pragma: no cover - safe_name
            raise TengsimError(f"--out {out}: {f} would lie outside it")


class _Say:
    """Progress that also prints whole lines (the grids, memory and time before a run starts)."""

    def __init__(self, quiet: bool):
        from tengsim.progress import Progress

        self.bar, self.quiet = Progress(quiet), quiet

    def __call__(self, *a):
        return self.bar(*a)

    def monitor(self, *a, **k):
        return self.bar.monitor(*a, **k)

    def say(self, text):
        if not self.quiet:
            self.bar.close()
            print(f"tengsim: {text}", file=sys.stderr)

    def close(self):
        self.bar.close()


def run(args) -> int:
    from tengsim.design import plan_design, read_material
    from tengsim.registry import SHAPES

    if args.help:
        first = args.inputs[0] if args.inputs else None
        print(help_text(first if first and first.lower() in [n.lower() for n in SHAPES.names()] else None), end="")
        return 0
    if not args.inputs:
        raise TengsimError("give a shape with its keys, or TOML files (tengsim design --help)")
    if not args.out:
        raise TengsimError("--out DIR is required (the folder the design's files go to)")
    tables = _tables(args)
    material = None
    if getattr(args, "material", None):  # the fitted material replaces the design's own (options given win)
        material = read_material(args.material)
        material = material.without(k for k in material.values if getattr(args, k, None) not in (None, ""))
    relaxation = None
    if getattr(args, "relaxation", None):  # read before anything runs: a bad file is one line
        from tengsim.relaxation import read_relaxation

        relaxation = read_relaxation(args.relaxation)
    elif getattr(args, "visco_sine", False):
        raise TengsimError("--visco-sine records the sine press of the viscoelastic cycles: give --relaxation FILE")
    # every design, and every band point of the material, checked before anything runs
    plans = [plan_design(t, where, material) for where, t in tables]
    out = Path(args.out)
    _check_out(out)
    folders = _folders(plans)
    inputs = [*(x for x in args.inputs if x.lower().endswith(".toml")), *([args.material] if material else []),
              *([args.relaxation] if relaxation is not None else []),
              *(v for _, t in tables for v in t.values() if isinstance(v, str))]
    _guard(out, folders, inputs)
    from tengsim.design.run import preflight
    from tengsim.outfolder import folder_lock

    refinements = []  # each design's checked refinement plan: checked once, here
    for (where, _), plan in zip(tables, plans):  # every design's grids, memory, budget, solver, before any runs
        seen = set()
        for k, p in enumerate((plan, *plan.bands)):  # the band points' designs too, each distinct one once
            if (p.E_star, p.W, p.eps) in seen:
                continue
            seen.add((p.E_star, p.W, p.eps))
            try:
                checked = preflight(p)
            except TengsimError as exc:
                point = f"--material {args.material} [[uncertainty.point]] {k}: " if k else ""
                raise TengsimError(f"{where}{point}{exc}") from None
            if k == 0:
                refinements.append(checked)
    with folder_lock(out, holder="tengsim design"):  # the whole run: no second run on this folder meanwhile
        return _run_locked(args, plans, folders, out, relaxation, refinements)


def _run_locked(args, plans, folders, out, relaxation=None, refinements=None) -> int:
    from tengsim.design import predict_bands, run_design, write_bands, write_comparison, write_design

    say = _Say(args.quiet)
    results = []
    try:
        for k, plan in enumerate(plans):  # each finished grid kept in OUT: a killed run resumes from it
            results.append(run_design(plan, progress=say, keep=out / f".design-{k}.resolve.nc",
                                      refinement=refinements[k] if refinements else None))
    except KeyboardInterrupt:
        say.close()
        kept = [out / f".design-{k}.resolve.nc" for k in range(len(plans))]
        kept = [str(p) for p in kept if p.exists()]
        print("tengsim: interrupted: " + (f"the finished grids are kept in {', '.join(kept)}; run the same "
              "command again to resume from them" if kept else "nothing was kept (no grid had finished)"),
              file=sys.stderr)
        return 130
    finally:
        say.close()
    if len(results) == 1:
        paths = write_design(results[0], out)
    else:
        paths = []
        for r, f in zip(results, folders):
            paths += write_design(r, out / f)
        paths += write_comparison(results, out)
    for r, f in zip(results, folders):  # the prediction's band: the design at each of the material's points
        if r.plan.bands:
            paths += write_bands(predict_bands(r, say.say), out / f, r.plan.name)
    if relaxation is not None:  # the viscoelastic cycles at the stated frequencies (tengsim.design.visco)
        from tengsim.design.visco import visco_cycles
        from tengsim.design.visco_write import write_visco

        for r, f in zip(results, folders):
            presses = ("square", "sine") if getattr(args, "visco_sine", False) else ("square",)
            paths += write_visco(visco_cycles(r.plan, relaxation, progress=say.say, presses=presses), out / f)
    for k in range(len(plans)):  # the results are saved: the kept grids are no longer needed
        (out / f".design-{k}.resolve.nc").unlink(missing_ok=True)
    if not args.quiet:
        for r in results:
            s = r.summary
            print(f"tengsim: {r.plan.name}: status {s['status']}, Tabor {s['tabor']:.3g}, grids {s['grids']}, "
                  f"A/S at p_max {s['area_at_p_max']:.4g}, V_OC {s['voc_eq12_at_p_max_V']:.4g} V (Eq. 12), "
                  f"{s['seconds']:.0f} s", file=sys.stderr)
        print(f"tengsim: wrote {len(paths)} files in {out} (report: {out / 'report.md' if len(results) == 1 else out})",
              file=sys.stderr)
    from tengsim.status.levels import Status

    for r in results:
        if r.status != Status.OK:
            print(f"tengsim: warning: {r.plan.name}: status {r.status} (see its report.md)", file=sys.stderr)
    return 0

"""Sphinx configuration: the API reference is generated from the docstrings of every public module.

Build (warnings are errors, as in CI)::

    pip install -e '.[docs]'
    python -m sphinx -W --keep-going -b html docs docs/_build/html

``api/index.rst`` asks autosummary for the package ``tengsim`` recursively, so a new module appears in the
reference without being listed anywhere; modules whose name starts with ``_`` are private and left out.
"""
from __future__ import annotations

import importlib
import os
import pkgutil
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))  # document this checkout, not an installed copy
os.environ.setdefault("MPLBACKEND", "Agg")

import tengsim  # noqa: E402

project = "tengsim"
author = "tengsim contributors"
copyright = "tengsim contributors"
release = version = tengsim.__version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "myst_parser",
]
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
templates_path = ["_templates"]
exclude_patterns = ["_build", "data", "api/generated/*.tmp", "**.ipynb_checkpoints"]
root_doc = "index"

# autodoc / autosummary: one page per module, members in source order, imported names documented where
# they are defined (no duplicates); ``__all__`` lists of re-exports are ignored for the same reason.
autosummary_generate = True
autosummary_imported_members = False
autosummary_ignore_module_all = True
autodoc_default_options = {
    "members": True,
    "undoc-members": True,
    "show-inheritance": True,
    "member-order": "bysource",
    "ignore-module-all": True,
}
autodoc_typehints = "description"
autodoc_typehints_format = "short"
autoclass_content = "both"
napoleon_numpy_docstring = True
napoleon_google_docstring = False
napoleon_use_rtype = False


def _public_api() -> dict:
    """{package: [(name, canonical dotted path), ...]} for every package that re-exports names by hand.

    The package pages list these first, linked to where each name is defined, so the curated API in
    ``__init__.py`` is the reader's entry point; computed at build time, never written down twice.
    """
    out = {}
    packages = ["tengsim"] + [m.name for m in pkgutil.walk_packages(tengsim.__path__, "tengsim.")
                              if m.ispkg and not any(p.startswith("_") for p in m.name.split("."))]
    for pkg_name in packages:
        pkg = importlib.import_module(pkg_name)
        names = getattr(pkg, "__all__", None) or [n for n in vars(pkg) if not n.startswith("_")]
        rows = []
        for n in names:
            obj = getattr(pkg, n, None)
            mod = getattr(obj, "__module__", None)
            if obj is None or mod is None or not callable(obj) or mod == pkg_name:
                continue
            if not mod.startswith("tengsim") or any(p.startswith("_") for p in mod.split(".")):
                continue
            rows.append((n, f"{mod}.{getattr(obj, '__qualname__', n)}"))
        if rows:
            out[pkg_name] = sorted(rows, key=lambda r: r[0].lower())
    return out


autosummary_context = {"public_api": _public_api()}

# MyST for the hand-written pages in docs/*.md.
myst_enable_extensions = ["dollarmath", "colon_fence"]
myst_heading_anchors = 3

html_theme = "alabaster"
html_title = f"tengsim {release}"
html_static_path: list[str] = []


# Docstrings write absolute values and norms the way the paper does, |X − Y| or |q|; in reStructuredText
# a pair of bars is a substitution reference. Escape such pairs in prose (not inside ``literals`` or
# literal blocks) so the docstrings stay readable as plain text and ``help()`` output.
import re  # noqa: E402

_BARS = re.compile(r"(?<![\\|\w])\|(?=[^\s|])([^|`\n]*?[^\s|\\])\|(?![|\w])")


def _escape_bars(line: str) -> str:
    parts = line.split("``")
    for i in range(0, len(parts), 2):  # even parts are outside inline literals
        parts[i] = _BARS.sub(r"\\|\1\\|", parts[i])
    return "``".join(parts)


def _process_docstring(app, what, name, obj, options, lines):
    literal_indent = None
    for i, line in enumerate(lines):
        stripped = line.lstrip()
        indent = len(line) - len(stripped)
        if literal_indent is not None:
            if stripped and indent <= literal_indent:
                literal_indent = None
            else:
                continue
        lines[i] = _escape_bars(line)
        if line.rstrip().endswith("::"):
            literal_indent = indent


def setup(app):
    app.connect("autodoc-process-docstring", _process_docstring)

# A short name documented on two classes (e.g. ``table``, ``value``) makes Sphinx warn "more than one target found"
# where autodoc cross-references it by that name alone; those references are not ours to qualify.
suppress_warnings = ["ref.python"]

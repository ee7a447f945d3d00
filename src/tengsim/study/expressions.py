"""The expression language of a study's tables: a value '=…' is + - * / and parentheses over numbers,
the point's [var] variables and other [contact] keys, computed in SI with its dimension checked
(:func:`evaluate`)."""
from __future__ import annotations

import math

from tengsim.errors import TengsimError, shown


def evaluate(contact: dict, var: dict) -> dict:
    """Evaluate the expression values of a [contact] table: strings starting with '='.

    An expression is + - * / and parentheses over numbers, the point's [var] variables, and other
    [contact] keys (quantities such as '5um' in SI, expressions first evaluated themselves).  It is
    computed in SI with its dimension: a unit string's, a physical run's key's (a bare number on E_star,
    W, eps or a shape's length is SI), none for [var]s and plain numbers (a plain number added to a
    quantity is read in its SI unit).  The value gets the key's own unit: in a physical run dx,
    thickness, f_min, f_max and f_step (whose bare numbers are in X units or F) get their SI unit
    appended ('0.0004m', '-2000Pa'), SI keys keep the number in SI, dimensionless keys (d_*, tabor, law
    parameters, every key of a dimensionless run) a plain number.  A value of the wrong dimension is
    refused (``d_max = "=2*eps"`` is a length, ``dx = "=E_star/2"`` a pressure), as is a bare dx,
    thickness or load used as an operand in a physical run (it is not SI).
    E.g. ``height = "=aspect*0.5*pitch"``, ``d_max = "=1.3*height/eps + 2"``, ``thickness = "=200*pitch"``.
    """
    import ast

    if not any(isinstance(v, str) and v.startswith("=") for v in contact.values()):
        return dict(contact)
    from tengsim.run.keys import key_dims
    from tengsim.units import DIMENSIONS, SI_UNIT, parse_quantity, quantity_dim, read_number

    zero = (0, 0, 0, 0)
    qdims = key_dims(contact)  # {} in a dimensionless run
    out = dict(contact)
    done = {}  # key -> (SI value, dimension vector, plain) of its evaluated expression
    busy = set()

    def value(name):
        """(SI value, dimension, plain): plain for a number with no dimension of its own."""
        if name in var:
            return var_number(name, var[name]), zero, True
        if name not in out:
            raise TengsimError(f"expression: unknown name {name!r} (a [contact] key or a [var] variable)")
        v = out[name]
        if name in done:
            return done[name]
        if isinstance(v, str) and v.startswith("="):
            if name in busy:
                raise TengsimError(f"expression: {name!r} depends on itself")
            busy.add(name)
            done[name] = calc(name, v)
            busy.discard(name)
            return done[name]
        if isinstance(v, bool) or isinstance(v, (dict, list)):
            raise TengsimError(f"expression: {name} = {v!r} is not a number")
        x = parse_quantity(v, name=name)
        d = quantity_dim(v)
        if d is not None:
            return x, DIMENSIONS[d], False
        if name not in qdims:
            return x, zero, True
        dim, si = qdims[name]
        if not si:
            own = "X units" if dim == "length" else "units of F (Eq. 10)"
            raise TengsimError(f"expression: {name} = {v!r} is in {own}, not SI: give it with a unit "
                               f"(e.g. '{v}{'um' if dim == 'length' else 'kPa'}') to use it in an expression")
        return x, DIMENSIONS[dim], False

    def calc(key, text):
        src = text[1:].strip()
        if len(src) > MAX_EXPRESSION:
            raise TengsimError(f"{key} = {shown(text)}: an expression is at most {MAX_EXPRESSION} characters")
        try:
            tree = ast.parse(src, mode="eval")
        except (SyntaxError, ValueError, RecursionError, MemoryError):
            raise TengsimError(f"{key} = {shown(text)}: cannot read the expression") from None
        text = shown(text)[1:-1] if len(text) > 60 else text

        def ev(n):
            if isinstance(n, ast.Expression):
                return ev(n.body)
            if isinstance(n, ast.Constant) and isinstance(n.value, (int, float)) and not isinstance(n.value, bool):
                return read_number(n.value, key), zero, True
            if isinstance(n, ast.Name):
                return value(n.id)
            if isinstance(n, ast.UnaryOp) and isinstance(n.op, (ast.USub, ast.UAdd)):
                x, d, p = ev(n.operand)
                return (-x if isinstance(n.op, ast.USub) else x), d, p
            if isinstance(n, ast.BinOp) and isinstance(n.op, (ast.Add, ast.Sub, ast.Mult, ast.Div)):
                (a, da, pa), (b, db, pb) = ev(n.left), ev(n.right)
                if isinstance(n.op, (ast.Add, ast.Sub)):
                    if not pa and not pb and da != db:
                        raise TengsimError(f"{key} = {text!r}: adds {_what(da)} and {_what(db)}")
                    d, p = (db, pb) if pa else (da, pa)
                    return (a + b if isinstance(n.op, ast.Add) else a - b), d, p
                if isinstance(n.op, ast.Mult):
                    return a * b, tuple(x + y for x, y in zip(da, db)), pa and pb
                if b == 0:
                    raise TengsimError(f"{key} = {text!r}: division by zero")
                return a / b, tuple(x - y for x, y in zip(da, db)), pa and pb
            raise TengsimError(f"{key} = {text!r}: only numbers, names, + - * / and parentheses are allowed")

        try:
            x, d, p = ev(tree)
        except RecursionError:
            raise TengsimError(f"{key} = {text!r}: the expression is nested too deeply") from None
        if not math.isfinite(x):
            raise TengsimError(f"{key} = {text!r}: the expression overflows (its value is {x})")
        want = DIMENSIONS[qdims[key][0]] if key in qdims else zero
        if not p and d != want:
            takes = f"{key} takes {_what(want)}" + ("" if key in qdims else " (it is dimensionless here)")
            raise TengsimError(f"{key} = {text!r} is {_what(d)}, but {takes}")
        return float(f"{x:.12g}"), want, False

    for k in list(out):
        v = out[k]
        if isinstance(v, str) and v.startswith("="):
            x = value(k)[0]
            if k in qdims and not qdims[k][1]:  # a bare number here is not SI: give the SI value its unit
                out[k] = f"{x:.12g}{SI_UNIT[qdims[k][0]]}"
            else:
                out[k] = x
    return out


MAX_EXPRESSION = 1000
"""The longest '=' expression (characters): longer ones are refused unread (a parser's recursion)."""


def var_number(name, v) -> float:
    """A [var] variable's value as a number: a string on a 'var.' axis is refused, naming it."""
    from tengsim.units import read_number

    try:
        if isinstance(v, (bool, dict, list)):
            raise ValueError
        return read_number(v, f"var.{name}")
    except TengsimError:
        raise
    except ValueError:
        raise TengsimError(f"var.{name} = {shown(v)} is not a number (a [var] variable is a plain number)") from None


def _what(vec) -> str:
    from tengsim.units import dimension_name

    name = dimension_name(vec)
    return "a plain number" if name == "dimensionless" else f"a {name}"

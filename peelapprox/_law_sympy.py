"""The symbolic form of every peel-force law: the families written once, and any :class:`PeelForce` as sympy.

Each family of :mod:`peelapprox._law_families` is written here once, as a sympy expression in the peel
velocity ``v``, the pull speed ``V`` (both positive symbols, as in :mod:`peelapprox._law_expr`) and its
coefficient symbols (named as in ``FAMILIES[name].defaults``; positive for ``FAMILIES[name].positive``,
real otherwise).  :mod:`peelapprox._law_codegen` renders these into the committed
:mod:`peelapprox._generated_laws` (compiled laws of the ABI and their numpy evaluators), so that a family's
formula has one source:

* ``paper`` — Eq. (fvV) of De, Maybhate & Ananthakrishna (PRE 2004) with its 14 numbers as coefficients,
  ``f = a1 v^p1 + a2 v^p2 + a3 e^(v/v3) - a4 V^q4 - (a5 - a6 V^q6 - a7 V^q7) v^p5``;
* ``cubic`` — ``f = a + b v - c v^2 + d v^3``;
* ``power_branches`` — ``f = A1 v^n1 / (1 + (v/v1)^m) + A2 v^n2``.

:func:`law_expression` gives the sympy form of any law: the paper's fvV (from
:func:`peelapprox._symbolic.peel_force_expr`, exact rationals), a family with its coefficients substituted,
or an expression law rebuilt from its canonical text.  sympy is imported by this module: import it only
where code is derived or generated (``import peelapprox`` does not).
"""

from __future__ import annotations

from typing import Any

import sympy as sp

from ._law_families import FAMILIES

__all__ = ["V", "family_expression", "law_expression", "v"]

#: The law's variables, as :mod:`peelapprox._law_expr` declares them (so expression laws share them).
v = sp.Symbol("v", positive=True)
V = sp.Symbol("V", positive=True)


def _coefficient_symbols(name: str) -> tuple[sp.Symbol, ...]:
    fam = FAMILIES[name]
    return tuple(sp.Symbol(n, positive=True) if n in fam.positive else sp.Symbol(n, real=True) for n in fam.names)


def _paper(c: dict[str, sp.Symbol]) -> sp.Expr:
    """fvV with its 14 numbers as symbols."""
    A = c["a5"] - c["a6"] * V ** c["q6"] - c["a7"] * V ** c["q7"]  # the prefactor of -v^p5
    return (c["a1"] * v ** c["p1"] + c["a2"] * v ** c["p2"] + c["a3"] * sp.exp(v / c["v3"])
            - c["a4"] * V ** c["q4"] - A * v ** c["p5"])


def _cubic(c: dict[str, sp.Symbol]) -> sp.Expr:
    """The N-shaped cubic."""
    return c["a"] + c["b"] * v - c["c"] * v**2 + c["d"] * v**3


def _power_branches(c: dict[str, sp.Symbol]) -> sp.Expr:
    """Two rising power-law branches joined by a falling one."""
    return c["A1"] * v ** c["n1"] / (1 + (v / c["v1"]) ** c["m"]) + c["A2"] * v ** c["n2"]


_FORMS = {"paper": _paper, "cubic": _cubic, "power_branches": _power_branches}


def family_expression(name: str) -> tuple[sp.Expr, tuple[sp.Symbol, ...]]:
    """The family's formula in ``v``, ``V`` and its coefficient symbols (in the family's order).

    Raises
    ------
    ValueError
        ``name`` is not a family (the message lists them).
    """
    if name not in FAMILIES or name not in _FORMS:
        raise ValueError(f"unknown peel-force family {name!r}: the families are {', '.join(FAMILIES)}")
    syms = _coefficient_symbols(name)
    return _FORMS[name]({s.name: s for s in syms}), syms


def law_expression(force: Any) -> sp.Expr:
    """The law ``f(v, V)`` of a :class:`peelapprox.PeelForce` as a sympy expression in :data:`v`, :data:`V`.

    ``"paper"``: fvV of :func:`peelapprox._symbolic.peel_force_expr` (exact rationals); ``"family"``: its
    :func:`family_expression` with the coefficients substituted (as sympy Floats of the stored floats);
    ``"expression"``: rebuilt from the canonical text ``force.source``.

    Raises
    ------
    ValueError
        For a ``"tabulated"`` law (a table has no closed form) or an unknown kind.
    """
    kind = getattr(force, "kind", None)
    if kind == "paper":
        from . import _symbolic as S

        return S.peel_force_expr(v, V)
    if kind == "family":
        expr, syms = family_expression(str(force.name))
        values = dict(force.coefficients)
        return expr.xreplace({s: sp.Float(float(values[s.name])) for s in syms})
    if kind == "expression":
        from ._law_expr import from_text

        return from_text(str(force.source))
    if kind == "tabulated":
        raise ValueError("a tabulated peel-force law has no closed form: law_expression takes a 'paper', "
                         "'family' or 'expression' law")
    raise ValueError(f"force must be a PeelForce of kind 'paper', 'family' or 'expression', got kind {kind!r}")

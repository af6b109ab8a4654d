"""The symbolic form of a peel-force law: the law's variables, a family's formula, any closed-form law as sympy.

``v`` and ``V`` are the positive symbols every law is written in (expression laws share them).
:func:`family_expression` builds a family's formula (:mod:`peelapprox.law._families`) in its coefficient
symbols (positive for ``Family.positive``, real otherwise), what the generator renders;
:func:`law_expression` gives any law with a closed form, from its kind.  sympy is imported by this module:
import it only where code is derived or generated (``import peelapprox`` does not).
"""

from __future__ import annotations

from typing import Any

import sympy as sp

from ._families import FAMILIES

__all__ = ["V", "family_expression", "law_expression", "v"]

#: The law's variables (:mod:`peelapprox.law._expression` declares the same).
v = sp.Symbol("v", positive=True)
V = sp.Symbol("V", positive=True)


def family_expression(name: str) -> tuple[sp.Expr, tuple[sp.Symbol, ...]]:
    """The family's formula in ``v``, ``V`` and its coefficient symbols (in the family's order).

    Raises
    ------
    ValueError
        ``name`` is not a family (the message lists them).
    """
    fam = FAMILIES.get(name)
    if fam is None:
        raise ValueError(f"unknown peel-force family {name!r}: the families are {', '.join(FAMILIES)}")
    syms = tuple(sp.Symbol(n, positive=True) if n in fam.positive else sp.Symbol(n, real=True) for n in fam.names)
    return fam.formula({s.name: s for s in syms}, v, V, sp), syms


def law_expression(force: Any) -> sp.Expr:
    """The law ``f(v, V)`` of a :class:`peelapprox.PeelForce` as a sympy expression in :data:`v`, :data:`V`.

    fvV exactly (rationals, :func:`peelapprox._compiled._symbolic.peel_force_expr`); a family with its coefficients as
    sympy Floats; an expression rebuilt from its canonical text.

    Raises
    ------
    ValueError
        For a tabulated law (a table has no closed form).
    """
    return force.impl.expression(force)

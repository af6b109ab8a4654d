"""Expression peel-force laws: a sympy expression in ``v`` (and ``V``), canonical form, numpy evaluation.

:func:`canonical` turns what the user typed (a string or a sympy expression, with named constants) into
the canonical text of the law — sympy's ``srepr`` of the expression with the constants substituted, in
the symbols ``v`` and ``V`` (both positive) — and checks it; :class:`ExpressionLaw` rebuilds the
expression from that text and evaluates f, f' and f'' (derivatives by sympy) through ``sympy.lambdify``
to numpy.  The canonical text is plain data: it is what a :class:`peelapprox.PeelForce` keeps, pickles
and hashes (its SHA-256 is the law's ``key``, for caches of compiled code).

sympy is imported inside the functions only: ``import peelapprox`` does not import it.

The probe: at construction f, f' and f'' are evaluated on :data:`PROBE_V` (241 points, log-spaced over
:data:`V_DOMAIN` = [1e-6, 1e3] m/s) at each pull speed of :data:`PROBE_PULL` (if the law depends on V); a
non-finite or complex value there is a ValueError naming the point.  An expression law is evaluated on
``V_DOMAIN`` only (outside it, a ValueError), since the probe vouches for nothing else.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

__all__ = ["PROBE_PULL", "PROBE_V", "V_DOMAIN", "ExpressionLaw", "canonical"]

#: The peel velocities [m/s] on which an expression law is probed and may be evaluated.
V_DOMAIN = (1e-6, 1e3)
#: The probe grid of v: 241 points log-spaced over V_DOMAIN (9 decades, neighbours ≈ 9 % apart).
PROBE_V = np.logspace(math.log10(V_DOMAIN[0]), math.log10(V_DOMAIN[1]), 241)
#: Pull speeds [m/s] of the probe when the law depends on V (the paper's range is 0.05-8 m/s).
PROBE_PULL = (0.01, 0.1, 1.0, 10.0)


def _symbols():
    import sympy as sp

    return sp.Symbol("v", positive=True), sp.Symbol("V", positive=True)


def canonical(expr: Any, constants: dict[str, Any]) -> str:
    """The canonical text (``srepr``) of ``expr`` with ``constants`` substituted; checked.

    Raises
    ------
    TypeError
        ``expr`` is neither a string nor a sympy expression, or a constant is not a real number.
    ValueError
        The string does not parse; a constant is named ``v`` or ``V``, is not finite, or does not occur in
        the expression; the expression holds symbols other than ``v``, ``V`` and the constants (named), an
        undefined function, or does not depend on ``v``; or f, f' or f'' is non-finite or complex at a
        point of the probe (named).
    """
    import sympy as sp
    from sympy.core.function import AppliedUndef
    from sympy.parsing.sympy_parser import convert_xor, parse_expr, standard_transformations

    from ._checks import real

    v, V = _symbols()
    for name, value in constants.items():
        if name in ("v", "V"):
            raise ValueError(f"constant {name!r} clashes with the law's variable {name} (v: peel velocity, "
                             "V: pull speed, m/s)")
        x = real(name, value)
        if not math.isfinite(x):
            raise ValueError(f"constant {name} must be finite, got {value!r}")
    names = {name: sp.Symbol(name, real=True) for name in constants}
    if isinstance(expr, str):
        try:
            e = parse_expr(expr, local_dict={"v": v, "V": V, **names},
                           transformations=standard_transformations + (convert_xor,))
        except Exception as exc:  # sympy raises SyntaxError, TokenError, TypeError, ... on bad text
            raise ValueError(f"expression {expr!r} does not parse: {exc}") from None
    elif isinstance(expr, sp.Basic):
        by_name = {"v": v, "V": V, **names}
        e = expr.xreplace({s: by_name[s.name] for s in expr.free_symbols if s.name in by_name})
    else:
        raise TypeError(f"expression must be a string or a sympy expression, got {type(expr).__name__}")
    if not isinstance(e, sp.Expr):
        raise ValueError(f"expression {expr!r} is not a scalar expression (got {type(e).__name__})")
    undef = sorted(str(a.func) for a in e.atoms(AppliedUndef))
    if undef:
        raise ValueError(f"expression {expr!r} calls undefined function(s) {', '.join(undef)}")
    unused = sorted(n for n, s in names.items() if s not in e.free_symbols)
    if unused:
        raise ValueError(f"constant(s) {', '.join(unused)} do not occur in the expression {expr!r}")
    e = e.xreplace({s: sp.Float(float(val)) for s, val in ((names[n], constants[n]) for n in names)})
    # one canonical number: an integral float is the integer (a=150 and a=150.0, "150.0*v" and "150*v" are one law)
    e = e.xreplace({x: sp.Integer(int(x)) for x in e.atoms(sp.Float) if float(x).is_integer()})
    unknown = sorted(s.name for s in e.free_symbols - {v, V})
    if unknown:
        raise ValueError(f"unknown symbol(s) {', '.join(unknown)} in the expression {expr!r}: a law may use v "
                         "(peel velocity, m/s) and V (pull speed, m/s); give constants as keywords, e.g. "
                         f"{unknown[0]}=1.0")
    if v not in e.free_symbols:
        raise ValueError(f"expression {expr!r} does not depend on v: a peel force must vary with the peel velocity")
    text = sp.srepr(e)
    ExpressionLaw(text).probe(str(expr))
    return text


class ExpressionLaw:
    """The evaluator of an expression law, rebuilt from its canonical text."""

    def __init__(self, text: str):
        import sympy as sp

        v, V = _symbols()
        e = sp.sympify(text)
        self.depends_on_V = V in e.free_symbols
        d1 = sp.diff(e, v)
        self.exprs = (e, d1, sp.diff(d1, v))
        self.funcs = [sp.lambdify((v, V), x, modules="numpy") for x in self.exprs]

    def raw(self, v: np.ndarray, V: float, order: int) -> np.ndarray:
        with np.errstate(all="ignore"):
            out = np.asarray(self.funcs[order](v, V))
        if out.dtype.kind in "biu":  # a constant derivative (lambdify returns the number itself)
            out = out.astype(float)
        return np.broadcast_to(out, v.shape).copy() if out.shape != v.shape else out

    def __call__(self, v: np.ndarray, V: float, order: int) -> np.ndarray:
        lo, hi = V_DOMAIN
        if v.size and (v.min() < lo or v.max() > hi):
            bad = v.ravel()[np.flatnonzero(((v < lo) | (v > hi)).ravel())[0]]
            raise ValueError(f"v={float(bad)!r} m/s is outside the domain [{lo:g}, {hi:g}] m/s of an expression "
                             "law (the range its construction probed)")
        return self.raw(v, V, order)

    def probe(self, label: str) -> None:
        """ValueError naming the first point of the probe where f, f' or f'' is complex or not finite."""
        for Vp in (PROBE_PULL if self.depends_on_V else (1.0,)):
            for order, what in enumerate(("f", "f'", "f''")):
                y = self.raw(PROBE_V, Vp, order)
                if np.iscomplexobj(y) and np.any(y.imag != 0):
                    i = int(np.flatnonzero(y.imag != 0)[0])
                    raise ValueError(f"expression {label!r}: {what} is complex at v={PROBE_V[i]:.6g} m/s, "
                                     f"V={Vp:g} m/s ({what} = {complex(y[i])}); a law must be real on v in "
                                     f"[{V_DOMAIN[0]:g}, {V_DOMAIN[1]:g}] m/s")
                y = np.real(y)
                bad = np.flatnonzero(~np.isfinite(y))
                if bad.size:
                    i = int(bad[0])
                    raise ValueError(f"expression {label!r}: {what} is {y[i]} at v={PROBE_V[i]:.6g} m/s, V={Vp:g} "
                                     f"m/s; a law must be finite on v in [{V_DOMAIN[0]:g}, {V_DOMAIN[1]:g}] m/s")

"""The families of peel-force laws: one fixed form each, its coefficients as data (issue 15).

A family is a formula ``f(v, V; c)`` with its coefficients ``c`` passed as numbers, so that changing a
coefficient changes data, not code.  Each family is a :class:`Family` in :data:`FAMILIES`: its coefficient
names and defaults, whether it depends on the pull speed V, and a numpy evaluator of ``f``, ``f'`` and
``f''`` in v.  The formula itself is written once, in sympy, in :mod:`peelapprox._law_sympy`; the evaluator
is the law rendered from it into :mod:`peelapprox._generated_laws` (the same source numba compiles into
the family's law of the ABI, :func:`peelapprox._law_codegen.family_kernel`).
:class:`peelapprox.PeelForce` (``PeelForce.family(name, **c)`` and the
convenience constructors) is the public face; this module knows nothing of it.

* ``paper`` — Eq. (fvV) of De, Maybhate & Ananthakrishna (PRE 2004) with its 14 numbers as coefficients::

      f = a1 v^p1 + a2 v^p2 + a3 e^(v/v3) - a4 V^q4 - (a5 - a6 V^q6 - a7 V^q7) v^p5

  The defaults are the paper's; with them f equals the built-in law to rounding (not bitwise: the built-in
  one is generated in ``w = ln v``).
* ``cubic`` — ``f = a + b v - c v^2 + d v^3``, V-independent: the smooth normal form of the N-shaped
  (rising-falling-rising) peel-force curve that Hong & Yue (Phys. Rev. Lett. 74, 254, 1995) used to model
  peeling; the cubic is the generic smooth N, not Hong & Yue's own piecewise numbers (which could not be
  verified here).  Folds at the roots of ``b - 2 c v + 3 d v^2 = 0``.  Defaults: the issue's example
  ``a=150, b=300, c=300, d=80`` (folds at v = 0.691 and 1.809 m/s).
* ``power_branches`` — ``f = A1 v^n1 / (1 + (v/v1)^m) + A2 v^n2``, V-independent: two rising power-law
  branches, the slow (viscoelastic) and fast (glassy) branches of the strain-energy-release rate G(v) = f/b
  measured on adhesive tapes by Maugis & Barquins (1988) and Barquins & Ciccotti (Int. J. Adhes. Adhes.
  17, 65, 1997), joined by a falling branch where the first term rolls over at ``v ~ v1``.  The defaults are
  a calibration to fvV at V = 1 m/s (folds v_max ≈ 0.506 m/s, f_max ≈ 285.6 N, v_min ≈ 8.59 m/s,
  f_min ≈ 199.4 N, and the paper's f at 0.01-20 m/s to a few per cent), not the measured constants of a
  3M tape, which could not be verified from the primary sources here.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from . import _generated_laws

__all__ = ["FAMILIES", "Family", "packed"]

#: An evaluator: (v array, V float, coefficient tuple in the family's order, order 0|1|2) -> array.
Evaluator = Callable[[np.ndarray, float, tuple, int], np.ndarray]


@dataclass(frozen=True)
class Family:
    """One family: coefficient names and defaults (in order), V-dependence, positivity and its evaluator."""

    name: str
    constructor: str
    defaults: tuple[tuple[str, float], ...]
    depends_on_V: bool
    positive: tuple[str, ...]  # coefficients that must be > 0 (divisors, scales)
    evaluate: Evaluator
    reference: str

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(n for n, _ in self.defaults)


def _generated(name: str) -> Evaluator:
    """The evaluator of the family ``name``: its law rendered from the symbolic form (:mod:`peelapprox._law_sympy`
    by :mod:`peelapprox._law_codegen` into :mod:`peelapprox._generated_laws`), evaluated by numpy on arrays.

    The same source is the compiled law of the ABI, so the formula lives in one place; f and f' come from the
    form ``LAW_FP`` and f'' from ``LAW_FPP`` (x = v).
    """
    law, pack = _generated_laws.LAWS[name]

    def evaluate(v: np.ndarray, V: float, c: tuple, order: int) -> np.ndarray:
        out = np.asarray(law(v, packed(f"the {name!r} family", pack, V, c), 2 if order == 2 else 1)[order],
                         dtype=float)
        return out if out.shape == np.shape(v) else np.broadcast_to(out, np.shape(v)).copy()

    return evaluate


def packed(what: str, pack: Callable[..., Any], V: float, *args: Any) -> np.ndarray:
    """``pack(V, *args)``, the coefficient vector a generated law is evaluated with (:mod:`peelapprox._generated_laws`,
    an expression's kernel), or a ValueError naming ``what`` (the family, ``params.force``) and V.

    The pack is plain Python arithmetic on the user's coefficients: a power ``V**q`` beyond the float range raises
    ``OverflowError``, a quotient by an underflowed square (``a3/v3**2`` with ``v3 = 1e-200``)
    ``ZeroDivisionError``, and a product may overflow to inf silently.  Each of them means that these
    coefficients give no finite law at this V, which is the user's input, not a bug: a ValueError.
    """
    try:
        out = np.asarray(pack(V, *args), dtype=float)
    except (OverflowError, ZeroDivisionError) as exc:
        raise ValueError(f"{what}: its coefficients give no finite law at V={V!r} m/s ({type(exc).__name__}: "
                         f"{exc}); use coefficients of ordinary size (a force in N, velocities in m/s)") from None
    if not np.all(np.isfinite(out)):
        raise ValueError(f"{what}: its coefficients give no finite law at V={V!r} m/s (a term overflows); use "
                         "coefficients of ordinary size (a force in N, velocities in m/s)")
    return out


FAMILIES: dict[str, Family] = {
    f.name: f
    for f in (
        Family("paper", "paper_family",
               (("a1", 400.0), ("p1", 0.35), ("a2", 110.0), ("p2", 0.15), ("a3", 130.0), ("v3", 11.0),
                ("a4", 2.0), ("q4", 1.5), ("a5", 415.0), ("a6", 45.0), ("q6", 0.4), ("a7", 0.35),
                ("q7", 2.15), ("p5", 0.5)),
               True, ("v3",), _generated("paper"),
               "De, Maybhate & Ananthakrishna, Phys. Rev. E (2004), Eq. fvV"),
        Family("cubic", "cubic", (("a", 150.0), ("b", 300.0), ("c", 300.0), ("d", 80.0)),
               False, (), _generated("cubic"),
               "the smooth normal form of the N-shaped law of Hong & Yue, Phys. Rev. Lett. 74, 254 (1995)"),
        Family("power_branches", "power_branches",
               (("A1", 338.5), ("n1", 0.1038), ("v1", 3.244), ("m", 1.074), ("A2", 14.36), ("n2", 0.8502)),
               False, ("A1", "v1", "m"), _generated("power_branches"),
               "Maugis & Barquins (1988); Barquins & Ciccotti, Int. J. Adhes. Adhes. 17, 65 (1997); "
               "defaults calibrated to fvV at V = 1 m/s"),
    )
}


def coefficients(family: Family, given: dict) -> tuple[tuple[str, float], ...]:
    """The family's coefficients in its order: ``given`` over the defaults, each a finite float.

    Raises ValueError naming an unknown coefficient (with the valid names), a non-finite one, or one of
    ``family.positive`` that is not > 0; TypeError (ArgumentTypeError) for a non-number.
    """
    from ._checks import in_range, real, shown

    unknown = sorted(set(given) - set(family.names))
    if unknown:
        raise ValueError(f"unknown coefficient(s) {', '.join(shown(n) for n in unknown)} of the {family.name!r} "
                         f"peel-force family: its coefficients are {', '.join(family.names)}")
    out = []
    for name, default in family.defaults:
        x = given.get(name, default)
        if name in family.positive:
            x = in_range(name, x, 0.0, math.inf, lo_open=True)
        else:
            x = real(name, x)
            if not math.isfinite(x):
                raise ValueError(f"{name} must be a finite number, got {x!r}")
        out.append((name, float(x) + 0.0))  # + 0.0: -0.0 -> 0.0, one canonical zero
    return tuple(out)

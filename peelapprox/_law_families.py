"""The families of peel-force laws: one fixed form each, its coefficients as data (issue 15).

A family is a formula ``f(v, V; c)`` written once here, with its coefficients ``c`` passed as numbers, so
that changing a coefficient changes data, not code.  Each family is a :class:`Family` in :data:`FAMILIES`:
its coefficient names and defaults, whether it depends on the pull speed V, and a numpy evaluator of
``f``, ``f'`` and ``f''`` in v.  :class:`peelapprox.PeelForce` (``PeelForce.family(name, **c)`` and the
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

import numpy as np

__all__ = ["FAMILIES", "Family"]

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


def _paper(v: np.ndarray, V: float, c: tuple, order: int) -> np.ndarray:
    a1, p1, a2, p2, a3, v3, a4, q4, a5, a6, q6, a7, q7, p5 = c
    A = a5 - a6 * V**q6 - a7 * V**q7  # the prefactor of -v^p5
    e = a3 * np.exp(v / v3)
    if order == 0:
        return a1 * v**p1 + a2 * v**p2 + e - a4 * V**q4 - A * v**p5
    if order == 1:
        return a1 * p1 * v ** (p1 - 1) + a2 * p2 * v ** (p2 - 1) + e / v3 - A * p5 * v ** (p5 - 1)
    return (a1 * p1 * (p1 - 1) * v ** (p1 - 2) + a2 * p2 * (p2 - 1) * v ** (p2 - 2) + e / (v3 * v3)
            - A * p5 * (p5 - 1) * v ** (p5 - 2))


def _cubic(v: np.ndarray, V: float, c: tuple, order: int) -> np.ndarray:
    a, b, cc, d = c
    if order == 0:
        return a + v * (b + v * (-cc + v * d))
    if order == 1:
        return b + v * (-2 * cc + 3 * d * v)
    return -2 * cc + 6 * d * v


def _power_branches(v: np.ndarray, V: float, c: tuple, order: int) -> np.ndarray:
    A1, n1, v1, m, A2, n2 = c
    x = (v / v1) ** m
    g = 1.0 + x  # f = A1 v^n1 / g + A2 v^n2
    t = A1 * v**n1 / g
    if order == 0:
        return t + A2 * v**n2
    # with s = m x / g = v g'/g:  v (v^n1/g)' = (n1 - s) v^n1/g,  v² (v^n1/g)'' = [(n1 - s)(n1 - s - 1) - v s'] v^n1/g
    s = m * x / g
    if order == 1:
        return (t * (n1 - s) + A2 * n2 * v**n2) / v
    vs = m * s / g  # v ds/dv = m² x / g² = m s / g
    return (t * ((n1 - s) * (n1 - s - 1) - vs) + A2 * n2 * (n2 - 1) * v**n2) / (v * v)


FAMILIES: dict[str, Family] = {
    f.name: f
    for f in (
        Family("paper", "paper_family",
               (("a1", 400.0), ("p1", 0.35), ("a2", 110.0), ("p2", 0.15), ("a3", 130.0), ("v3", 11.0),
                ("a4", 2.0), ("q4", 1.5), ("a5", 415.0), ("a6", 45.0), ("q6", 0.4), ("a7", 0.35),
                ("q7", 2.15), ("p5", 0.5)),
               True, ("v3",), _paper,
               "De, Maybhate & Ananthakrishna, Phys. Rev. E (2004), Eq. fvV"),
        Family("cubic", "cubic", (("a", 150.0), ("b", 300.0), ("c", 300.0), ("d", 80.0)),
               False, (), _cubic,
               "the smooth normal form of the N-shaped law of Hong & Yue, Phys. Rev. Lett. 74, 254 (1995)"),
        Family("power_branches", "power_branches",
               (("A1", 338.5), ("n1", 0.1038), ("v1", 3.244), ("m", 1.074), ("A2", 14.36), ("n2", 0.8502)),
               False, ("A1", "v1", "m"), _power_branches,
               "Maugis & Barquins (1988); Barquins & Ciccotti, Int. J. Adhes. Adhes. 17, 65 (1997); "
               "defaults calibrated to fvV at V = 1 m/s"),
    )
}


def coefficients(family: Family, given: dict) -> tuple[tuple[str, float], ...]:
    """The family's coefficients in its order: ``given`` over the defaults, each a finite float.

    Raises ValueError naming an unknown coefficient (with the valid names), a non-finite one, or one of
    ``family.positive`` that is not > 0; TypeError (ArgumentTypeError) for a non-number.
    """
    from ._checks import in_range, real

    unknown = sorted(set(given) - set(family.names))
    if unknown:
        raise ValueError(f"unknown coefficient(s) {', '.join(unknown)} of the {family.name!r} peel-force "
                         f"family: its coefficients are {', '.join(family.names)}")
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

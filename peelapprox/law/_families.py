"""The families of peel-force laws: each one fixed formula, written once, next to its coefficients and defaults.

A family is a formula ``f(v, V; c)`` whose coefficients ``c`` are data, so that changing a coefficient changes
data, not code.  Each :class:`Family` of :data:`FAMILIES` holds its coefficient names and defaults, which must
be positive, whether it depends on the pull speed V, and its formula as a function of sympy symbols.  The
generator (``python -m peelapprox.law.codegen``) renders the formulas into :mod:`peelapprox.law._generated`,
the one source both of the compiled law of the ABI (:func:`Family.kernel`) and of the numpy evaluator
(:meth:`Family.evaluate`); both are looked up on first use, so a family added here can be generated from a
clean state.  :class:`peelapprox.PeelForce` (``PeelForce.family(name, **c)``) is the public face.

* ``paper`` — Eq. (fvV) of De, Maybhate & Ananthakrishna (PRE 2004) with its 14 numbers as coefficients; with
  the defaults f equals the built-in law to rounding (not bitwise: that one is generated in ``w = ln v``).
* ``cubic`` — the smooth normal form of the N-shaped (rising-falling-rising) law of Hong & Yue (Phys. Rev.
  Lett. 74, 254, 1995), not their own piecewise numbers; folds at the roots of ``b - 2 c v + 3 d v^2``.
* ``power_branches`` — the slow (viscoelastic) and fast (glassy) branches of G(v) = f/b measured on tapes by
  Maugis & Barquins (1988) and Barquins & Ciccotti (Int. J. Adhes. Adhes. 17, 65, 1997), joined by a falling
  branch where the first term rolls over at ``v ~ v1``; the defaults are a calibration to fvV at V = 1 m/s
  (v_max ≈ 0.506 m/s, f_max ≈ 285.6 N, v_min ≈ 8.59 m/s, f_min ≈ 199.4 N), not a 3M tape's constants.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

__all__ = ["FAMILIES", "Family", "coefficients", "packed"]

#: A formula: ``formula(c, v, V, sp)`` -> the sympy expression of f, given the coefficient symbols ``c`` by name,
#: the symbols v and V and the sympy module (so that this module imports no sympy).
Formula = Callable[[Mapping[str, Any], Any, Any, Any], Any]


@dataclass(frozen=True)
class Family:
    """One family: its formula, coefficient names and defaults (in order), V-dependence, positivity."""

    name: str
    constructor: str
    defaults: tuple[tuple[str, float], ...]
    depends_on_V: bool
    positive: tuple[str, ...]  # coefficients that must be > 0 (divisors, scales)
    formula: Formula
    reference: str

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(n for n, _ in self.defaults)

    def generated(self) -> tuple[Callable, Callable]:
        """``(law, pack)`` of the family in :mod:`peelapprox.law._generated` (plain Python on numpy)."""
        from . import _generated

        hit = _generated.LAWS.get(self.name)
        if hit is None:
            raise RuntimeError(f"the peel-force family {self.name!r} has not been generated: run "
                               "python -m peelapprox.law.codegen")
        return hit

    def evaluate(self, v: np.ndarray, V: float, c: tuple, order: int) -> np.ndarray:
        """f (order 0), f' or f'' at v by numpy, through the generated law (f and f' from ``LAW_FP``, f''
        from ``LAW_FPP``)."""
        law, pack = self.generated()
        out = np.asarray(law(v, packed(f"the {self.name!r} family", pack, V, c), 2 if order == 2 else 1)[order],
                         dtype=float)
        return out if out.shape == np.shape(v) else np.broadcast_to(out, np.shape(v)).copy()


def packed(what: str, pack: Callable[..., Any], V: float, *args: Any) -> np.ndarray:
    """``pack(V, *args)``, the coefficient vector a generated law is evaluated with, or a ValueError naming
    ``what`` (the family, ``params.force``) and V.

    The pack is plain Python arithmetic on the user's coefficients: a power ``V**q`` beyond the float range raises
    ``OverflowError``, a quotient by an underflowed square ``ZeroDivisionError``, and a product may overflow to
    inf silently.  Each means that these coefficients give no finite law at this V: the user's input, a
    ValueError.
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


def _paper(c: Mapping[str, Any], v: Any, V: Any, sp: Any) -> Any:
    """fvV with its 14 numbers as symbols."""
    A = c["a5"] - c["a6"] * V ** c["q6"] - c["a7"] * V ** c["q7"]  # the prefactor of -v^p5
    return (c["a1"] * v ** c["p1"] + c["a2"] * v ** c["p2"] + c["a3"] * sp.exp(v / c["v3"])
            - c["a4"] * V ** c["q4"] - A * v ** c["p5"])


def _cubic(c: Mapping[str, Any], v: Any, V: Any, sp: Any) -> Any:
    """The N-shaped cubic."""
    return c["a"] + c["b"] * v - c["c"] * v**2 + c["d"] * v**3


def _power_branches(c: Mapping[str, Any], v: Any, V: Any, sp: Any) -> Any:
    """Two rising power-law branches joined by a falling one."""
    return c["A1"] * v ** c["n1"] / (1 + (v / c["v1"]) ** c["m"]) + c["A2"] * v ** c["n2"]


FAMILIES: dict[str, Family] = {
    f.name: f
    for f in (
        # f = a1 v^p1 + a2 v^p2 + a3 e^(v/v3) - a4 V^q4 - (a5 - a6 V^q6 - a7 V^q7) v^p5
        Family("paper", "paper_family",
               (("a1", 400.0), ("p1", 0.35), ("a2", 110.0), ("p2", 0.15), ("a3", 130.0), ("v3", 11.0),
                ("a4", 2.0), ("q4", 1.5), ("a5", 415.0), ("a6", 45.0), ("q6", 0.4), ("a7", 0.35),
                ("q7", 2.15), ("p5", 0.5)),
               True, ("v3",), _paper,
               "De, Maybhate & Ananthakrishna, Phys. Rev. E (2004), Eq. fvV"),
        # f = a + b v - c v^2 + d v^3
        Family("cubic", "cubic", (("a", 150.0), ("b", 300.0), ("c", 300.0), ("d", 80.0)),
               False, (), _cubic,
               "the smooth normal form of the N-shaped law of Hong & Yue, Phys. Rev. Lett. 74, 254 (1995)"),
        # f = A1 v^n1 / (1 + (v/v1)^m) + A2 v^n2
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
    from .._checks import in_range, real, shown

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

"""The kinds of event a continued branch reports, in one table: each kind's name (the string stored in
``Bifurcation.kind`` or ``OrbitBranch.stopped``), its test function and its plot marker.

Two families (:mod:`exact.orbits._continuation` describes both):

* the **bifurcations** found between two accepted points by their nontrivial Floquet multipliers ``mu``
  (:data:`BIFURCATIONS`): the test function maps ``mu`` to the signed quantities whose sign change marks the
  kind, for the multipliers of its ``spectrum`` ("real": both real, "complex": a complex pair);
  ``"branch_point"`` is a fold's crossing where the parameter does not turn back, so it has the fold's test;
* the **non-smooth ends** of a branch (:data:`ENDS`), whose test function maps a point's orbit and its crest
  (:class:`exact.Crest`) to a quantity that falls linearly to 0 at the event, so that the last two points
  extrapolate to it.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, NamedTuple

import numpy as np

__all__ = ["BIFURCATIONS", "ENDS", "KINDS", "Kind", "crossing", "gauge", "marker"]


class Kind(NamedTuple):
    """One row of the table."""

    name: str
    test: Callable[..., Any]
    marker: str
    color: str
    spectrum: str = ""


def _real_level(level: float) -> Callable[[np.ndarray], np.ndarray]:
    def test(mu: np.ndarray) -> np.ndarray:
        return mu.real - level
    return test


def _modulus(mu: np.ndarray) -> np.ndarray:
    return np.array([abs(mu[0]) - 1.0])


def _fold_rate(orbit: Any, crest: Any) -> float:
    return float(np.min(np.abs(orbit.fold_rates))) ** 2  # Ġ² is linear in the distance to a grazing


#: The bifurcations, in the order a crossing is looked for: a real multiplier through +1 (fold), through -1
#: (period doubling), a complex pair through the unit circle (Neimark-Sacker), and the fold test's crossing
#: where the parameter does not turn (branch point).
BIFURCATIONS = (
    Kind("fold", _real_level(1.0), "s", "C3", "real"),
    Kind("period_doubling", _real_level(-1.0), "D", "C1", "real"),
    Kind("neimark_sacker", _modulus, "*", "C4", "complex"),
    Kind("branch_point", _real_level(1.0), "o", "k", ""),
)
#: The non-smooth ends, in the order the extrapolated events are reported: an interior crest reaching its fold
#: level (its margin), the lowest level on AB reaching f(0+) (the floor), a fold met tangentially (Ġ²).
ENDS = (
    Kind("crest", lambda orbit, crest: crest.margin, "+", "k"),
    Kind("breakdown", lambda orbit, crest: crest.floor, "1", "k"),
    Kind("grazing", _fold_rate, "x", "k"),
)
KINDS = {k.name: k for k in BIFURCATIONS + ENDS}


def crossing(ma: np.ndarray, mb: np.ndarray) -> str | None:
    """The bifurcation between two orbits of a branch with multipliers ``ma`` and ``mb``, or None: the first kind
    of their common spectrum whose test values (sorted) change sign."""
    real_a, real_b = np.all(np.abs(ma.imag) < 1e-12), np.all(np.abs(mb.imag) < 1e-12)
    if real_a != real_b:
        return None
    spectrum = "real" if real_a else "complex"
    for k in BIFURCATIONS:
        if k.spectrum != spectrum:
            continue
        sa, sb = np.sort(k.test(ma)), np.sort(k.test(mb))
        if spectrum == "complex" and sa[0] * sb[0] < 0 or spectrum == "real" and np.any(np.sign(sa) != np.sign(sb)):
            return k.name
    return None


def gauge(kind: str, mu: np.ndarray) -> float:
    """The test value of ``kind`` nearest 0 at multipliers ``mu``: the quantity a bisection drives to 0."""
    return float(min(KINDS[kind].test(mu), key=abs))


def marker(kind: str) -> tuple[str, str]:
    """The matplotlib marker and colour of ``kind`` (a filled circle for a kind not in the table)."""
    k = KINDS.get(kind)
    return (k.marker, k.color) if k is not None else ("o", "k")

"""What :func:`peelapprox.approximate_attractor` returns, and how sure it is.

:class:`ApproximateAttractor` is a :class:`peelapprox.StickSlipObservables` (every caller of the observables reads
it unchanged) with the map's stability (``multipliers``, ``escape_returns``), its ``confidence`` and the other
attractors the map reached from its other starts (``alternatives``; ``set`` is the primary and those).

The confidence rules (:func:`confidence`), each measured (docs/theory.md, "The approximate attractor"):

* a multiplier of the map's periodic orbit, or of an unstable orbit the map left on its way, within
  :data:`MULTIPLIER_ERROR` of the unit circle: the reduction's multipliers differ from the exact model's
  (:func:`exact.periodic_orbit`) by up to that much, so the orbit's stability, hence which attractor the exact
  run settles on, is not decided by the map;
* the orbit outside the physical range: an angle ``|α|`` at a jump above :data:`ALPHA_LINEAR` (F at the jumps,
  ``f_fold/(1 + sin α)``, then lies outside the law's fold band by more than the exact attractors' oscillations
  explain);
* the exact model breaks down where the chain (one other than the full chain, the default) does not: the full branch
  dynamics linearised in α (genalpha + fullvdot on both branches) run from the solver's start reaches ``F (1 + sin α) =
  f(0+, V)`` on AB (v → 0, CONSTR without a root) within :data:`peelapprox._reduced._approximate.PROBE_RETURNS` returns;
* its regime's calibration (:data:`peelapprox._reduced._validity.VALIDITY`, measured on the atlas's 40 x 40 grid):
  where, of the predictions no other rule flags, fewer than :data:`CALIBRATION_FLOOR` matched an attractor of the
  exact set (only 'high inertia, high V', 93.3 % of 195).
"""

from __future__ import annotations

import dataclasses
import math
import warnings
from dataclasses import dataclass
from typing import Any

from .._observables import StickSlipObservables
from ..io import fmt_number, jsonable
from ._validity import VALIDITY

__all__ = ["ALPHA_LINEAR", "ApproximateAttractor", "ApproximationWarning", "CONFIDENCES",
           "CALIBRATION_FLOOR", "CALIBRATION_POINTS", "MULTIPLIER_ERROR"]

#: The values of :attr:`ApproximateAttractor.confidence`.
CONFIDENCES = ("high", "low")
#: The reduction's multiplier error: the largest |μ| of the default reductions' periodic orbits against
#: :func:`exact.periodic_orbit`'s for the same orbit, at the 16 calibration points where both find it
#: (``python -m comparisons.benchmark.approx_targets --seed 1 --points 100 --multipliers 25``): median 0.0056,
#: 90th percentile 0.043, largest 0.067 (V = 1.48, I = 2.5e-4: 0.862 against 0.929); at three high-inertia points
#: the map's orbit is weakly stable (0.9989-0.9993) where the exact one is weakly unstable (1.00007-1.00022).
MULTIPLIER_ERROR = 0.07
#: The largest ``|α|`` [rad] at a jump inside the physical range.  Measured on the calibration points
#: (``python -m comparisons.benchmark.approx_targets --seed 1``): the rest start's reduced orbits that match the
#: exact attractors at high inertia reach |α| 0.40-0.48 at their jumps (F 187-405 N); those with F in 153-552 N,
#: where the exact attractor stays in 228-356 N (V = 3.1-3.4 m/s, I = 0.04-0.06), reach 0.85-1.0 rad.
ALPHA_LINEAR = 0.6
#: A regime where, of the predictions no other rule flags, fewer than this share matched an attractor of the exact
#: set on the atlas's grid (:data:`peelapprox._reduced._validity.VALIDITY`'s ``unflagged_match``) is low confidence:
#: the issue's calibration target, so that what is left unflagged matches at least as often.  Of the 40 x 40 grid's
#: regimes only 'high inertia, high V' is below it (93.3 % of 195; the others 98.0-100 %).  Read only where at least
#: :data:`CALIBRATION_POINTS` points were measured.
CALIBRATION_FLOOR = 0.95
#: The fewest unflagged points of a regime from which its measured share is read.
CALIBRATION_POINTS = 20


class ApproximationWarning(UserWarning):
    """A prediction of :func:`peelapprox.approximate_attractor` with low confidence (its reason in the text)."""


@dataclass(frozen=True, kw_only=True, repr=False)
class ApproximateAttractor(StickSlipObservables):
    """The attractor the reduced return map predicts (:func:`peelapprox.approximate_attractor`).

    The fields of :class:`peelapprox.StickSlipObservables` and:

    Attributes
    ----------
    multipliers : tuple of complex, or None
        The map's periodic orbit's multipliers (eigenvalues of ``D P^n`` on the section, Newton's finite-difference
        Jacobian); None for an aperiodic or long-period sample and without stick-slip.
    escape_returns : float or None
        For an unstable periodic orbit (the map's orbit being left), or an orbit the map finds weakly stable
        (``|μ|`` in [0.99, 1)) whose full-chain orbit (:attr:`escape_multiplier`) is unstable (the map stays on
        it, the exact run leaves it): the return at which the amplitude law
        ``A_k = A_k0 |μ|^((k - k0)/n)`` reaches :data:`ESCAPE_FRACTION` of its force drop, counted from the start
        (``A`` the envelope of the AB→CD force's deviation from the orbit: the section point's deviation in the
        dominant eigen-coordinates of ``D P^n`` times the force's gradient); None otherwise.  Where the map's leading
        ``|μ|`` is in [0.99, 1.02] the law's rate is :attr:`escape_multiplier`'s (and ``A`` is corrected for the
        returns it grew at the map's rate instead).  Measured against the exact runs where ``|μ|`` - 1 is in
        [1e-4, 1e-2] (docs/theory.md, "Escape returns"): with the default chain at 17 of 17 and 18 of the 19 orbits
        given a return (two seeds).  None for an orbit, stayed on or left, whose deviation at the map's Newton is
        already as large as the orbit (the law has no e-fold to run and would say the map's own return, 40, where
        the exact runs left such orbits at 31-172): its multipliers (or :attr:`escape_multiplier`) still say it is
        unstable.
    escape_multiplier : complex or None
        The multiplier whose ``|μ|`` sets the escape law's rate where it is not the map's own: the leading
        multiplier of the same orbit of the full branch dynamics linearised in α (genalpha + fullvdot, Newton from this
        orbit's section point), used where this orbit's leading ``|μ|`` is in [0.99, 1.02] (there Airy1 + approxvdot's
        ``|μ| - 1`` is 0.6-74 % below the exact orbit's, or of the wrong sign, the full chain's within 0.32 % at the
        orbits the map leaves and 7 % at those it finds weakly stable: docs/theory.md, "Escape returns"); None where
        the rate is ``max |multipliers|`` (the chain is the full one, the default; farther from 1; or that Newton did
        not converge to an unstable orbit).
    confidence : {"high", "low"}
        ``"low"`` where a rule of the module docstring applies; ``confidence_reason`` says which.
    confidence_reason : str
        Why.
    start : str
        The start the map reached this attractor from (``"solver"``, ``"rest"``).
    alternatives : tuple of ApproximateAttractor
        The other attractors reached from the other starts, and the unstable orbits met on the way (each with
        its multipliers and escape return): the set is :attr:`set`.  A start not followed past a weakly unstable
        orbit, because another start's answer ranks first whatever it reaches next, adds only the orbits it left.
    """

    multipliers: tuple[complex, ...] | None = None
    escape_returns: float | None = None
    escape_multiplier: complex | None = None
    confidence: str = "high"
    confidence_reason: str = ""
    start: str = ""
    alternatives: tuple[ApproximateAttractor, ...] = ()

    @property
    def set(self) -> tuple[ApproximateAttractor, ...]:
        """The primary prediction first, then :attr:`alternatives`."""
        return (self, *self.alternatives)

    @property
    def stable(self) -> bool | None:
        """Whether every multiplier lies inside the unit circle (None without multipliers)."""
        return None if self.multipliers is None else max(abs(m) for m in self.multipliers) < 1.0

    def as_dict(self) -> dict[str, Any]:
        """The fields as JSON data: multipliers as ``[re, im]`` pairs, alternatives as their own dicts."""
        d = {f.name: jsonable(getattr(self, f.name)) for f in dataclasses.fields(self)
             if f.name not in ("multipliers", "escape_multiplier", "alternatives")}
        d["multipliers"] = None if self.multipliers is None else [[m.real, m.imag] for m in self.multipliers]
        mu = self.escape_multiplier
        d["escape_multiplier"] = None if mu is None else [mu.real, mu.imag]
        d["alternatives"] = [a.as_dict() for a in self.alternatives]
        return d

    def __repr__(self) -> str:
        base = super().__repr__().replace("StickSlipObservables(", "ApproximateAttractor(", 1)[:-1]
        mu = "" if self.multipliers is None else ", |mu| " + "/".join(fmt_number(abs(m), 6) for m in self.multipliers)
        return f"{base}{mu}, confidence {self.confidence}, {len(self.alternatives)} alternatives)"

    def summary(self) -> str:
        """:meth:`StickSlipObservables.summary` and the stability, confidence and alternatives."""
        lines = [super().summary()]
        if self.multipliers is not None:
            lines.append("  multipliers " + ", ".join(fmt_number(abs(m), 5) for m in self.multipliers) + " (|mu|)"
                         + (f"; escape after ~{fmt_number(self.escape_returns, 3)} returns"
                            if self.escape_returns is not None else ""))
        lines.append(f"  confidence {self.confidence}" + (f": {self.confidence_reason}" if self.confidence_reason
                                                           else ""))
        for a in self.alternatives:
            lines.append(f"  also: {a!r}")
        return "\n".join(lines)


def confidence(o: ApproximateAttractor, label: str, alpha_max: float | None, left: tuple[ApproximateAttractor, ...],
               breakdown: str | None) -> tuple[str, str]:
    """``(confidence, reason)`` of a stick-slip prediction (module docstring's rules, every one that applies).

    ``alpha_max`` is the largest |α| at the sample's jumps, ``left`` the unstable orbits the map left on its way
    there, ``breakdown`` why the full linearised chain breaks down where this one does not (None if it does
    not)."""
    why = []
    for orbit, what in ((o, "its orbit has"), *((x, "the map left an orbit with") for x in left)):
        if orbit.multipliers is not None:
            rho = max(abs(m) for m in orbit.multipliers)
            if abs(rho - 1.0) < MULTIPLIER_ERROR:
                why.append(f"{what} a multiplier |mu| = {_near_one(rho)} within the reduction's multiplier error "
                           f"({MULTIPLIER_ERROR:g}) of 1: which attractor the exact run settles on is not decided by "
                           "the map")
                break
    if alpha_max is not None and alpha_max > ALPHA_LINEAR:
        why.append(f"|alpha| reaches {fmt_number(alpha_max, 3)} rad at a jump, beyond the physical range "
                   f"({ALPHA_LINEAR:g} rad): F at the jumps leaves the fold band by more than the oscillations of the "
                   "exact attractors explain")
    if breakdown is not None:
        why.append(breakdown)
    v = VALIDITY.get(label)
    if v is not None and v.unflagged_points >= CALIBRATION_POINTS and v.unflagged_match < CALIBRATION_FLOOR:
        why.append(f"in its regime {label!r}, predictions no other rule flags matched the exact attractor set on "
                   f"{fmt_number(100 * v.unflagged_match, 3)} % of the {v.unflagged_points} points measured (below "
                   f"{100 * CALIBRATION_FLOOR:.0f} %)")
    return ("low", "; ".join(why)) if why else ("high", "no rule of low confidence applies")


def _near_one(rho: float) -> str:
    """``|μ|`` with the digits that tell it from 1 (``1.000012``, not ``1``), at least five significant ones."""
    digits = 5 if rho == 1.0 else max(5, 2 - int(math.floor(math.log10(abs(rho - 1.0)))))
    return fmt_number(rho, min(digits, 15))


def warn_low(o: ApproximateAttractor) -> None:
    """One :class:`ApproximationWarning` for a low-confidence primary prediction."""
    if o.confidence == "low":
        warnings.warn(f"approximate_attractor at V = {fmt_number(o.V, 4)} m/s, I = {fmt_number(o.I, 4)} kg m^2: "
                      f"low confidence: {o.confidence_reason}", ApproximationWarning, stacklevel=3)

"""Regime estimates without running the DAE (paper Sec. V).

Everything here is closed form or one quadrature of ``f'(v, V)`` of the law ``params.force`` (any
:class:`peelapprox.PeelForce` whose folds can be found: its :func:`peelapprox.branch_structure`,
:func:`peelapprox.fixed_point` and ``force.df``; the paper's fvV by default): the folds,
the fixed point and its Hopf stability, the inertial periods (approxalpha),
the CD damping time (Airy2), branch times and force changes in the
quasi-static limit, the paper's crude estimates, the force bounds
``F = f/(1 + sin α)`` and the slope criterion for the switch from the jumping
mode to a monotonic rise.  :func:`estimate` collects them with a regime label.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field, fields
from typing import Any

import numpy as np

from .._observables import StickSlipObservables
from .._params import PeelParams
from ..law import BranchStructure, FixedPoint, fixed_point
from ..validate import choice, flag, function, in_range, nonnegative, optional, state
from ._alpha import inertial_frequency, law_fprime
from ._regime import INERTIA_RULE, VELOCITY_RULE, _checked, _labels, _law_structure, regime
from ._validity import validity_text

__all__ = [
    "crude_branch_time",
    "quasi_static_branch_time",
    "force_bounds",
    "SlopeCriterion",
    "slope_criterion",
    "RegimeEstimate",
    "estimate",
    "INERTIA_RULE",
    "VELOCITY_RULE",
    "regime",
]

def _folds(params: PeelParams, where: str) -> BranchStructure:
    bs = _law_structure(_checked(params, where))
    if not bs.has_folds:
        raise ValueError(f"V={params.V} is outside the stick-slip window: f(v, V) has no folds "
                         f"(law {params.force!r})")
    return bs


def crude_branch_time(params: PeelParams) -> float:
    """The paper's rough AB time ``(f_max - f_min)/(k V)`` [s] (Sec. V, Case a).

    F rises at ``k V`` (v ≪ V on AB) from ``f_min`` to ``f_max``; α and v are
    ignored.  V=1: 0.0862 s (the paper, reading 284 and 200 off a figure: 0.084).
    """
    bs = _folds(params, "crude_branch_time")
    assert bs.f_max is not None and bs.f_min is not None  # _folds: has_folds
    return (bs.f_max - bs.f_min) / (params.k * params.V)


def quasi_static_branch_time(
    params: PeelParams,
    branch: str = "AB",
    *,
    v_in: float | None = None,
    v_f: float | None = None,
    fprime: Callable[[np.ndarray], np.ndarray] | None = None,
    rate: str = "k(V-v)",
) -> float:
    """Branch time of approxvdot with α̇ = 0: ``Δt = ∫ f'(v) / Ḟ dv`` [s].

    With α̇ = 0, approxvdot reads ``f'(v) v̇ = k(V - v)``, so the time from
    ``v_in`` to ``v_f`` is the quadrature above (:func:`scipy.integrate.quad`,
    relative accuracy ~1e-10).  This is the inertia-free limit and equals
    ``reduced_segment(..., alpha_model="static")``.

    Parameters
    ----------
    branch : {"AB", "CD"}
    v_in, v_f : float, optional
        Default: the landing velocity on the branch and the branch's fold.
    fprime : callable, optional
        Replace ``f'(v, V)`` (e.g. the paper's crude linear form); vectorised
        in v.
    rate : {"k(V-v)", "kV"}
        ``Ḟ``: the approxvdot rate, or ``k V`` (v dropped, the paper's crude
        estimates).

    Returns
    -------
    float
        Δt [s] (positive for a forward passage along the branch).
    """
    bs = _folds(params, "quasi_static_branch_time")
    assert bs.v_max is not None and bs.v_min is not None and bs.v_land_cd is not None  # _folds: has_folds
    branch = choice("branch", branch, ("AB", "CD"))
    rate = choice("rate", rate, ("k(V-v)", "kV"))
    v_in, v_f = optional(state, "v_in", v_in, "v"), optional(state, "v_f", v_f, "v")
    fprime = optional(function, "fprime", fprime)
    if branch == "AB":
        v_in = bs.v_land_ab if v_in is None else v_in
        v_f = bs.v_max if v_f is None else v_f
        if v_in is None:
            raise ValueError(f"no AB landing velocity for V={params.V}; give v_in")
    else:
        v_in = bs.v_land_cd if v_in is None else v_in
        v_f = bs.v_min if v_f is None else v_f
    fpr = (lambda v: law_fprime(params, v)) if fprime is None else fprime
    k, V = params.k, params.V
    if rate == "kV":
        integrand = lambda v: float(fpr(v)) / (k * V)  # noqa: E731
    else:
        if min(v_in, v_f) <= V <= max(v_in, v_f):
            raise ValueError(f"k(V - v) vanishes at v = V = {V} between v_in={v_in} and v_f={v_f}")
        integrand = lambda v: float(fpr(v)) / (k * (V - v))  # noqa: E731
    # the AB integrand is ∝ v^-0.85 near 0: integrate in ln v; a table's f' has a kink at every datum, so its
    # data inside the interval are break points of the quadrature (each piece is smooth)
    lo, hi = sorted((math.log(v_in), math.log(v_f)))
    knots = sorted({math.log(x) for t in params.force.tables for x in t[1] if lo < math.log(x) < hi})
    from scipy import integrate  # on first use: importing this module imports no scipy (docs/performance.md)

    val, _ = integrate.quad(lambda w: integrand(math.exp(w)) * math.exp(w), math.log(v_in), math.log(v_f),
                            epsabs=0.0, epsrel=1e-11, limit=max(200, 4 * len(knots)), points=knots or None)
    return val


def force_bounds(params: PeelParams, alpha_min: float, alpha_max: float, *, linear: bool = False
                 ) -> tuple[float, float]:
    """``F_max ≈ f_max/(1 + sin α_min)`` and ``F_min ≈ f_min/(1 + sin α_max)`` [N].

    From CONSTR, ``F = f(v, V)/(1 + sin α)``: the pull force overshoots the
    folds by the peel-angle factor (paper Sec. V, Case III).  ``linear=True``
    uses the paper's ``1 + α`` (its quoted 438 N and 181 N at V=4, I=1e-2).
    """
    bs = _folds(params, "force_bounds")
    assert bs.f_max is not None and bs.f_min is not None  # _folds: has_folds
    alpha_min, alpha_max = (in_range(name, a, -math.pi / 2, math.pi / 2, lo_open=True, hi_open=True)
                            for name, a in (("alpha_min", alpha_min), ("alpha_max", alpha_max)))
    linear = flag("linear", linear)
    if alpha_min > alpha_max:
        raise ValueError(f"alpha_min must be <= alpha_max, got {alpha_min} > {alpha_max}")
    g = (lambda a: 1.0 + a) if linear else (lambda a: 1.0 + math.sin(a))
    if g(alpha_min) <= 0:
        raise ValueError(f"1 + alpha_min must be > 0 for the linear closure, got alpha_min={alpha_min}")
    return bs.f_max / g(alpha_min), bs.f_min / g(alpha_max)


@dataclass(frozen=True)
class SlopeCriterion:
    """Result of :func:`slope_criterion`.

    ``natural_slope = 2πν α₀`` [rad/s]; ``ratio = α̇_in / natural_slope``;
    ``compatible``: the entry slope can start a sinusoidal sojourn
    (``0 < ratio <= 1 + tol``).
    """

    natural_slope: float
    ratio: float
    compatible: bool
    tol: float


def slope_criterion(params: PeelParams, *, F_in: float, alphadot_in: float, alpha0: float, tol: float = 0.25
                    ) -> SlopeCriterion:
    """The paper's test for leaving the jumping mode on AB (Case II points a vs k).

    A sinusoid ``α₀ sin 2πνt`` has its largest slope ``2πν α₀`` at α ≈ 0,
    with ``2πν = sqrt(F_in R/I)`` (approxalpha).  An AB entry whose α̇ has
    the sign of α₀ (the direction of the sinusoidal stretch: α₀ > 0 for a
    rise, < 0 for a fall) and does not exceed that slope can start the
    monotonic stretch (point a: 9.7 vs 10); a larger or opposite slope cannot,
    and the orbit makes another small loop (point k: 18.3).  ``tol`` absorbs
    the asymmetry from ``v/R`` in FLOW1 that the argument neglects; 0.25 puts
    the paper's two points on either side.
    """
    params = _checked(params, "slope_criterion")  # reads I and R only: any law
    F_in = state("F_in", F_in, "F")
    alphadot_in = state("alphadot_in", alphadot_in, "omega")
    alpha0 = state("alpha0", alpha0, "alpha")
    if alpha0 == 0.0:
        raise ValueError(f"alpha0 must be finite and non-zero (signed amplitude), got {alpha0}")
    tol = nonnegative("tol", tol)
    nat = float(inertial_frequency(params, F_in)) * alpha0
    ratio = alphadot_in / nat
    return SlopeCriterion(nat, ratio, bool(0.0 < ratio <= 1.0 + tol), tol)


@dataclass(frozen=True)
class RegimeEstimate:
    """Everything :func:`estimate` knows about a parameter point without solving the DAE.

    Times in s, forces in N, velocities in m/s.  Fold fields are None outside
    the stick-slip window.
    """

    V: float
    I: float
    k: float
    R: float
    has_folds: bool
    v_max: float | None
    f_max: float | None
    v_min: float | None
    f_min: float | None
    v_land_ab: float | None
    v_land_cd: float | None
    fixed_point_v: float
    fixed_point_F: float
    fixed_point_fprime: float
    fixed_point_stable: bool
    F_mean: float | None
    period_at_f_min: float | None
    period_at_f_max: float | None
    period_at_mean: float | None
    cd_damping_time: float | None
    inertia_ratio: float | None
    t_ab_crude: float | None
    t_ab_quasi_static: float | None
    t_cd_quasi_static: float | None
    dF_ab_quasi_static: float | None
    dF_cd_quasi_static: float | None
    oscillations_per_ab: float | None
    force_gap: float | None
    inertia: str
    velocity: str
    F_max_bound: float | None = None
    F_min_bound: float | None = None
    inertia_rule: str = INERTIA_RULE
    velocity_rule: str = VELOCITY_RULE
    params: PeelParams | None = field(default=None, repr=False, compare=False)
    """The point estimated (what :meth:`attractor` runs); not in :meth:`as_dict`."""

    @property
    def validity(self) -> dict[str, str]:
        """``{"slip_interval": ..., "force_drop": ...}``: how often :meth:`attractor`'s prediction of each was
        within 10 % of the exact attractor's, measured over the stick-slip points of this regime label
        (:mod:`peelapprox._reduced._validity`: the 40 x 40 benchmark of ``comparisons.benchmark.approx_attractor``),
        e.g.
        "within 10 % of the exact attractor on 77 % of the 283 'low inertia, low V' points measured (...)"."""
        return validity_text(self.label)

    def attractor(self, **options: Any) -> StickSlipObservables:
        """The stick-slip attractor predicted from the reduced equations at this point,
        :func:`peelapprox.approximate_attractor` ``(params, **options)`` (milliseconds; no DAE solve): the slip
        interval, force drop, slip and stick times, force extremes and period; :attr:`validity` says how often
        such a prediction was right in this regime.

        Raises
        ------
        ValueError
            The estimate was built without its params (not by :func:`estimate`), or a bad option (named).
        """
        if self.params is None:
            raise ValueError("this RegimeEstimate holds no params (it was not made by estimate()): call "
                             "peelapprox.approximate_attractor(params) instead")
        from ._approximate import approximate_attractor

        return approximate_attractor(self.params, **options)

    @property
    def label(self) -> str:
        """``"<inertia> inertia, <velocity> V"`` or ``"no stick-slip"``."""
        if self.velocity == "stable":
            return "no stick-slip (stable fixed point)"
        return f"{self.inertia} inertia, {self.velocity} V"

    def as_dict(self) -> dict:
        d = {f.name: getattr(self, f.name) for f in fields(self) if f.name != "params"}
        d["label"] = self.label
        return d


def estimate(params: PeelParams, *, alpha_min: float | None = None, alpha_max: float | None = None
             ) -> RegimeEstimate:
    """Regime estimate for one parameter point, without running the DAE.

    Returns the folds, the fixed point and its Hopf stability, the inertial
    periods of approxalpha at ``f_min``, ``f_max`` and ``F_mean = (f_min +
    f_max)/2``, the CD damping time ``R f'(v_land_cd)/F_mean`` (Airy2), the
    crude and quasi-static branch times and force changes, and the regime
    labels (rules in :data:`INERTIA_RULE`, :data:`VELOCITY_RULE`).  Force
    bounds ``f/(1 + sin α)`` are added when both α extremes are given.
    A few milliseconds per call after the first for a given V (the fold
    search is cached).

    Every number is the law ``params.force``'s (its folds and landings from
    :func:`peelapprox.branch_structure`, its fixed point from
    :func:`peelapprox.fixed_point`, f' from ``force.df``).  A law with no
    folds at this V (f' > 0 throughout, so the fixed point is stable) gives
    the no-stick-slip estimate: ``has_folds=False``, the fold, period,
    branch-time and bound fields None, ``inertia="n/a"``,
    ``velocity="stable"``.

    Raises
    ------
    ValueError
        Naming ``params.force``: a law whose folds cannot be found
        (:meth:`PeelForce.folds`), V outside a table's speeds or its fixed
        point outside the law's domain, or a law whose AB→CD jumps cannot
        land within its domain (a table that stops below ``f_max`` on CD).
    """
    params = _checked(params, "estimate")
    angle = dict(lo=-math.pi / 2, hi=math.pi / 2, lo_open=True, hi_open=True)
    alpha_min = optional(in_range, "alpha_min", alpha_min, **angle)
    alpha_max = optional(in_range, "alpha_max", alpha_max, **angle)
    bs = _law_structure(params)
    fp: FixedPoint = fixed_point(params.V, params.R, force=params.force)
    if not bs.has_folds:
        return RegimeEstimate(
            params.V, params.I, params.k, params.R, False, None, None, None, None, None, None, fp.v, fp.F,
            fp.fprime, fp.stable, None, None, None, None, None, None, None, None, None, None, None, None, None,
            "n/a", "stable", params=params)
    assert bs.v_max is not None and bs.f_max is not None and bs.v_min is not None and bs.f_min is not None
    per, tau_cd, ratio, inertia, gap, velocity = _labels(params, bs, fp)
    # quasi-static passages exist only if F keeps moving towards the fold: on AB
    # F rises while v < V, so the fold must lie below V (else the orbit settles
    # at the stable fixed point v = V); on CD F falls while v > V.
    t_ab = t_cd = None
    if bs.v_land_ab is not None and bs.v_max < params.V:
        t_ab = quasi_static_branch_time(params, "AB")
    if bs.v_min > params.V:
        t_cd = quasi_static_branch_time(params, "CD")
    Fmax_b = Fmin_b = None
    if alpha_min is not None or alpha_max is not None:
        if alpha_min is None or alpha_max is None:
            raise ValueError("give both alpha_min and alpha_max for the force bounds")
        Fmax_b, Fmin_b = force_bounds(params, alpha_min, alpha_max)
    return RegimeEstimate(
        V=params.V, I=params.I, k=params.k, R=params.R, has_folds=True, v_max=bs.v_max, f_max=bs.f_max,
        v_min=bs.v_min, f_min=bs.f_min, v_land_ab=bs.v_land_ab, v_land_cd=bs.v_land_cd, fixed_point_v=fp.v,
        fixed_point_F=fp.F, fixed_point_fprime=fp.fprime, fixed_point_stable=fp.stable, F_mean=per.F_mean,
        period_at_f_min=per.at_f_min, period_at_f_max=per.at_f_max, period_at_mean=per.at_mean,
        cd_damping_time=tau_cd, inertia_ratio=ratio, t_ab_crude=crude_branch_time(params),
        t_ab_quasi_static=t_ab, t_cd_quasi_static=t_cd,
        dF_ab_quasi_static=bs.f_max - bs.f_min, dF_cd_quasi_static=bs.f_min - bs.f_max,
        oscillations_per_ab=(t_ab / per.at_mean) if t_ab is not None else None, force_gap=gap,
        inertia=inertia, velocity=velocity, F_max_bound=Fmax_b, F_min_bound=Fmin_b, params=params,
    )

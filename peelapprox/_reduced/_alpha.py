"""Reduced equations for the peel angle α on one branch (paper Sec. V): all from genalpha, ``α̈ = -F R α/I - v̇/R``
(FLOW1 and FLOW2 with ``sin α ≈ α``), by dropping or freezing terms:

=====================  =============================================  =========================
label                  equation                                        here
=====================  =============================================  =========================
approxalpha            ``I α̈ = -F R α``, F constant                   :func:`harmonic_alpha`,
                                                                       :func:`inertial_frequency`
Airy                   ``I α̈ = -(F_in + s t) R α``, ``s = k(V - v)``   :func:`airy_alpha` (exact, Ai/Bi),
                                                                       :func:`alpha_numerical`
(paper's sinusoid)     ``α ≈ A (F_in/F)^¼ sin(∫√(FR/I) dt + φ)``        :func:`sinusoid_alpha`,
                                                                       :func:`wkb_alpha`
Airy1                  ``α̈ = -FRα/I - (Ḟ + F α̇)/(R f'(v))``           :func:`alpha_numerical`
Airy2                  ``α̈ = -FRα/I - F α̇/(R f'(v))``                 :func:`alpha_numerical`
CD limit of Airy2      ``α̇ = -F α/(R f'(v))``, frozen f', F            :func:`cd_decay_alpha`
=====================  =============================================  =========================

The force on the branch is the paper's ``F = F_in + k(V - v) t`` with v frozen (``s = F_rate``, default ``k V``:
the paper drops v on AB); the coupling to the peel velocity (approxvdot, fullvdot) is in
:mod:`peelapprox._reduced._segment`.
Units: t [s], α [rad], α̇ [rad/s], F [N], R [m], I [kg m²], k [N/m], v, V [m/s].

Each formula is written once, below, as a function of scalars that works on numpy arrays and inside numba
(:func:`peelapprox._compiled._jit.jitable`), called by the public functions here and by the compiled segment solver
alike.
Two caveats, measured: numpy's vectorised ``exp`` and the compiled libm ``exp`` differ in the last bit for ~5 %
of arguments (``_decay`` agrees to 1 ulp, not bitwise); and the segment solver multiplies Airy1/Airy2's damping
``(Ḟ + F α̇)/(R f')`` by ``dt/ds = v f'`` with ``f'`` cancelled (it integrates through the fold, ``f' = 0``): the
same equation, not the same floating-point operations.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from .._compiled._jit import jitable
from .._params import PeelParams
from .._ranges import TIME_MAX
from ..errors import SolverFailure
from ..law import branch_structure
from ..validate import choice, in_range, optional, state, states, times
from ..validate import finite as _finite
from ..validate import params as _params

__all__ = [
    "inertial_frequency",
    "inertial_period",
    "InertialPeriods",
    "inertial_periods",
    "harmonic_alpha",
    "airy_alpha",
    "sinusoid_alpha",
    "wkb_amplitude_phase",
    "wkb_alpha",
    "wkb_error_bound",
    "alpha_numerical",
    "cd_damping_time",
    "cd_decay_alpha",
    "ALPHA_FORMS",
]

#: equations accepted by :func:`alpha_numerical`
ALPHA_FORMS = ("airy", "airy1", "airy2")
#: Largest |x| at which :func:`airy_alpha` evaluates Ai(x), Bi(x): scipy returns finite values at x = -1e6
#: and NaN at x = -1e8.
AIRY_X_MAX = 1e6


# ------------------------------------------------------------ the equations, each written once
# (numpy- and numba-compatible: only arithmetic and np ufuncs; kernels call them through jitable)


@jitable
def _omega(F, R, I):
    """Angular frequency ``sqrt(F R/I)`` of approxalpha at force F [rad/s]."""
    return np.sqrt(R * F / I)


@jitable
def _restoring(F, alpha, R, I):
    """The right side ``-F R α/I`` of approxalpha and Airy (FLOW2 with ``sin α ≈ α``) [rad/s²]."""
    return -F * R * alpha / I


def _damping_time(R, fp, F):
    """Damping time ``R f'(v)/F`` of α in Airy2 and its CD limit [s]."""
    return R * fp / F


def _frozen_rate(params: PeelParams, v=0.0):
    """The force rate ``k (V - v)`` of flow3 with v frozen [N/s] (the paper drops v on AB: ``v = 0``)."""
    return params.k * (params.V - v)


@jitable
def _sinusoid(t, A, phi, F_in, s, R, I):
    """(α, α̇) of the WKB sinusoid with amplitude A and phase φ at t = 0."""
    F = F_in + s * t
    sqF = np.sqrt(F)
    sqFin = np.sqrt(F_in)
    # ∫0^t sqrt(R F/I) dt' = (2/(3s)) sqrt(R/I) (F^1.5 - F_in^1.5), written without 1/s
    Phi = (2.0 / 3.0) * np.sqrt(R / I) * t * (F + sqF * sqFin + F_in) / (sqF + sqFin)
    env = A * np.sqrt(np.sqrt(F_in / F))
    sn = np.sin(Phi + phi)
    cs = np.cos(Phi + phi)
    return env * sn, env * (_omega(F, R, I) * cs - s / (4.0 * F) * sn)


@jitable
def _harmonic(t, alpha_in, alphadot_in, F, R, I):
    """(α, α̇) of approxalpha with constant F."""
    Om = _omega(F, R, I)
    c = np.cos(Om * t)
    s = np.sin(Om * t)
    return alpha_in * c + alphadot_in / Om * s, -alpha_in * Om * s + alphadot_in * c


@jitable
def _decay(t, alpha_in, tau):
    """(α, α̇) of ``α̇ = -α/τ``."""
    a = alpha_in * np.exp(-t / tau)
    return a, -a / tau


# ------------------------------------------------------------ validators


def _times(t) -> np.ndarray:
    """Times since the branch entry, any shape, each in [0, TIME_MAX]."""
    return times("t", t, hi=TIME_MAX, increasing=False, ndim=None)


def _force_ramp(params: PeelParams, t: np.ndarray, F_in, F_rate) -> tuple[float, float]:
    """Validate ``F = F_in + F_rate t`` (default rate ``k V``) and keep it positive over t."""
    F_in = state("F_in", F_in, "F")
    s = _frozen_rate(params) if F_rate is None else state("F_rate", F_rate, "F_rate")
    F_end = F_in + s * float(np.max(t))
    if not F_end > 0.0:
        raise ValueError(
            f"F = F_in + F_rate*t must stay in (0, inf) over t; with F_in={F_in} and F_rate={s} it reaches "
            f"{F_end} at t={float(np.max(t))}: valid range is t < {F_in / -s if s < 0 else math.inf}"
        )
    return F_in, s


# ------------------------------------------------------------ approxalpha


def inertial_frequency(params: PeelParams, F):
    """Angular frequency ``2πν = sqrt(F R / I)`` of approxalpha [rad/s].

    Parameters
    ----------
    params : PeelParams
        Uses ``R`` [m] and ``I`` [kg m²].
    F : float or array_like
        Pull force [N] (> 0).

    Returns
    -------
    float or ndarray
        ``sqrt(F R / I)`` [rad/s].  Valid on AB, where ``v/R`` is small in
        FLOW1 so that ``v̇/R`` drops out of genalpha (paper Sec. V, Case I).
    """
    params = _params("params", params, where="inertial_frequency", variants=False)
    Fa = states("F", F, "F")
    out = _omega(Fa, params.R, params.I)
    return float(out) if out.ndim == 0 else out


def inertial_period(params: PeelParams, F):
    """Period ``T = 2π sqrt(I / (F R))`` of approxalpha [s] (``1/ν``)."""
    return 2.0 * np.pi / inertial_frequency(params, F)


def law_fprime(params: PeelParams, v):
    """∂f/∂v of the run's law ``params.force`` at v (fvV through :func:`peelapprox.peel_force_derivative`, bitwise)."""
    return params.force.df(v, params.V)


class InertialPeriods(NamedTuple):
    """Inertial periods of approxalpha at the branch force levels [s]."""

    at_f_min: float
    at_f_max: float
    at_mean: float
    f_min: float
    f_max: float
    F_mean: float


def inertial_periods(params: PeelParams, F_mean: float | None = None) -> InertialPeriods:
    """Periods of approxalpha at ``F = f_min``, ``f_max`` and a mean force.

    The paper (Case I a) estimates the high-frequency α oscillation on AB at
    the lowest force ``F_min ≈ f_min`` and the highest ``F_max ≈ f_max``, and
    for high inertia at a mean ``F`` (default ``(f_min + f_max)/2``).

    Raises
    ------
    ValueError
        If ``f(v, V)`` has no folds (no stick-slip window for this V) and no
        ``F_mean`` is given.
    """
    params = _params("params", params, where="inertial_periods", variants=False)
    bs = branch_structure(params.V, force=params.force)
    F_mean = optional(state, "F_mean", F_mean, "F")
    if not bs.has_folds:
        raise ValueError(f"V={params.V} is outside the stick-slip window (f(v, V) has no folds): f_min/f_max undefined")
    assert bs.f_min is not None and bs.f_max is not None  # has_folds
    Fm = 0.5 * (bs.f_min + bs.f_max) if F_mean is None else F_mean
    return InertialPeriods(
        inertial_period(params, bs.f_min), inertial_period(params, bs.f_max), inertial_period(params, Fm),
        bs.f_min, bs.f_max, Fm,
    )


def harmonic_alpha(params: PeelParams, t, *, F: float, alpha_in: float, alphadot_in: float):
    """Exact solution of approxalpha, ``I α̈ = -F R α`` with constant F.

    Returns ``α(t) = α_in cos Ωt + (α̇_in/Ω) sin Ωt`` and its derivative,
    ``Ω = sqrt(F R/I)``; arrays shaped like ``t`` (time since branch entry, s).
    """
    params = _params("params", params, where="harmonic_alpha", variants=False)
    t = _times(t)
    return _harmonic(t, state("alpha_in", alpha_in, "alpha"), state("alphadot_in", alphadot_in, "omega"),
                     state("F", F, "F"), params.R, params.I)


# ------------------------------------------------------------ Airy


def airy_alpha(params: PeelParams, t, *, F_in: float, alpha_in: float, alphadot_in: float,
               F_rate: float | None = None):
    """Exact solution of the Airy-type equation ``I α̈ = -(F_in + s t) R α`` (Airy).

    The paper says this equation "does not have an exact solution"; it does.
    With ``a = cbrt(R s / I)`` and ``x = -a (t + F_in/s)`` it becomes Airy's
    equation ``d²α/dx² = x α``, so ``α = c1 Ai(x) + c2 Bi(x)``.  Matching
    ``(α_in, α̇_in)`` at t = 0 with the Wronskian ``W(Ai, Bi) = 1/π``::

        c1 =  π (α_in Bi'(x0) + (α̇_in/a) Bi(x0))
        c2 = -π (α_in Ai'(x0) + (α̇_in/a) Ai(x0))

    ``x < 0`` whenever ``F > 0``, so only the oscillatory side of Ai/Bi is
    used (no exponential growth or cancellation).  Evaluated with
    :func:`scipy.special.airy`; ``s = 0`` is approxalpha (:func:`harmonic_alpha`).

    Parameters
    ----------
    params : PeelParams
        ``R``, ``I`` and (for the default rate) ``k``, ``V``.
    t : array_like
        Times since the branch entry [s], ``>= 0``.
    F_in : float
        Pull force at entry [N] (the paper's ``F_min`` on AB).
    alpha_in, alphadot_in : float
        Peel angle [rad] and its rate [rad/s] at entry.
    F_rate : float, optional
        ``s = dF/dt`` [N/s]; default ``k V`` (v dropped on AB, as the paper does).

    Returns
    -------
    alpha, alphadot : ndarray
        Shaped like ``t``.
    """
    params = _params("params", params, where="airy_alpha", variants=False)
    t = _times(t)
    F_in, s = _force_ramp(params, t, F_in, F_rate)
    a_in, ad_in = state("alpha_in", alpha_in, "alpha"), state("alphadot_in", alphadot_in, "omega")
    if s == 0.0:
        return _harmonic(t, a_in, ad_in, F_in, params.R, params.I)
    a = np.cbrt(params.R * s / params.I)
    x0 = -a * F_in / s
    x_far = float(np.max(np.abs(a * (t + F_in / s))))
    if not x_far <= AIRY_X_MAX:
        raise ValueError(
            f"F_rate = {s:g} N/s with t up to {float(np.max(t)):g} s puts the Airy argument "
            f"x = -cbrt(R s/I) (t + F_in/s) at |x| = {x_far:.3g}, beyond {AIRY_X_MAX:g} where scipy's Ai/Bi are "
            f"NaN (|F_rate| too small or t too large): use wkb_alpha there (its error, wkb_error_bound, is "
            f"~|x|^-1.5)")
    from scipy import special  # on first use: importing this module imports no scipy (docs/performance.md)

    ai0, aip0, bi0, bip0 = special.airy(x0)
    c1 = np.pi * (a_in * bip0 + ad_in / a * bi0)
    c2 = -np.pi * (a_in * aip0 + ad_in / a * ai0)
    ai, aip, bi, bip = special.airy(-a * (t + F_in / s))
    return c1 * ai + c2 * bi, -a * (c1 * aip + c2 * bip)


def sinusoid_alpha(params: PeelParams, t, *, F_in: float, amplitude: float, phase: float,
                   F_rate: float | None = None):
    """The paper's slowly varying sinusoid for α on AB, as the WKB form of Airy.

    ``α = A (F_in/F)^(1/4) sin(Φ(t) + φ)``, ``Φ = ∫0^t sqrt(F R/I) dt'``,
    ``F = F_in + s t``.  The paper writes ``α = α_in sin(2πνt + φ)`` with
    ``2πν = sqrt(F R/I)`` and "F treated as a slowly increasing parameter";
    the Liouville–Green (WKB) form makes that precise: the phase is the
    integral of the local frequency and the amplitude follows the adiabatic
    invariant ``∝ F^(-1/4)``.  Its error is bounded by :func:`wkb_error_bound`.

    Parameters
    ----------
    amplitude, phase : float
        ``A`` [rad] (the paper's ``α_in``) and ``φ`` [rad] at t = 0.
    Other parameters as in :func:`airy_alpha`.
    """
    params = _params("params", params, where="sinusoid_alpha", variants=False)
    t = _times(t)
    F_in, s = _force_ramp(params, t, F_in, F_rate)
    return _sinusoid(t, _finite("amplitude", amplitude), _finite("phase", phase), F_in, s, params.R, params.I)


def wkb_amplitude_phase(params: PeelParams, *, F_in: float, alpha_in: float, alphadot_in: float,
                        F_rate: float | None = None) -> tuple[float, float]:
    """``(A, φ)`` of :func:`sinusoid_alpha` matching ``(α_in, α̇_in)`` at t = 0.

    Solves ``A sin φ = α_in`` and ``A (Ω_in cos φ - s/(4 F_in) sin φ) = α̇_in``.
    """
    F_in, s = _force_ramp(_params("params", params, where="wkb_amplitude_phase", variants=False), np.zeros(1), F_in,
                          F_rate)
    a_in, ad_in = state("alpha_in", alpha_in, "alpha"), state("alphadot_in", alphadot_in, "omega")
    return _wkb_match(F_in, s, a_in, ad_in, params.R, params.I)


def _wkb_match(F_in, s, alpha_in, alphadot_in, R, I) -> tuple[float, float]:
    """``(A, φ)`` of the sinusoid through ``(α_in, α̇_in)`` at t = 0 (:func:`wkb_amplitude_phase`, unchecked)."""
    c = (alphadot_in + s * alpha_in / (4.0 * F_in)) / _omega(F_in, R, I)
    return math.hypot(alpha_in, c), math.atan2(alpha_in, c)


def wkb_alpha(params: PeelParams, t, *, F_in: float, alpha_in: float, alphadot_in: float,
              F_rate: float | None = None):
    """:func:`sinusoid_alpha` matched to ``(α_in, α̇_in)`` (see :func:`wkb_amplitude_phase`).

    """
    A, phi = wkb_amplitude_phase(params, F_in=F_in, alpha_in=alpha_in, alphadot_in=alphadot_in, F_rate=F_rate)
    return sinusoid_alpha(params, t, F_in=F_in, amplitude=A, phase=phi, F_rate=F_rate)


def wkb_error_bound(params: PeelParams, t, *, F_in: float, alpha_in: float, alphadot_in: float,
                    F_rate: float | None = None):
    """Rigorous bound on ``|α_Airy(t) - α_WKB(t)|`` [rad].

    Liouville–Green theorem (Olver, *Asymptotics and Special Functions*,
    Ch. 6, Thm 2.2 and §2.4) for ``α̈ = -Q α``, ``Q = R F(t)/I``: the exact
    solutions are ``Q^(-1/4) e^(±iΦ)(1 + ε±)`` with ``ε±`` and ``ε±'``
    vanishing at the reference point t = 0 and ``|ε±| <= exp(𝒱(t)) - 1``,
    where 𝒱 is the variation of the error-control function
    ``∫ Q^(-1/4) d²/dt² Q^(-1/4) dt``.  For ``F = F_in + s t`` this is, in
    closed form::

        𝒱(t) = (5/24) sqrt(I/R) |s| |F_in^(-3/2) - F(t)^(-3/2)|

    Both α and its WKB form are the same combination of the two basis
    solutions (the matching at t = 0 is exact), so
    ``|α - α_WKB| <= A(t) (exp(𝒱) - 1)`` with the WKB envelope
    ``A(t) = A (F_in/F)^(1/4)``.  𝒱 is first order in the adiabatic
    parameter ``s/(F·sqrt(FR/I))``.
    """
    params = _params("params", params, where="wkb_error_bound", variants=False)
    t = _times(t)
    F_in, s = _force_ramp(params, t, F_in, F_rate)
    A, _ = wkb_amplitude_phase(params, F_in=F_in, alpha_in=alpha_in, alphadot_in=alphadot_in, F_rate=F_rate)
    F = F_in + s * t
    var = (5.0 / 24.0) * math.sqrt(params.I / params.R) * abs(s) * np.abs(F_in**-1.5 - F**-1.5)
    return A * (F_in / F) ** 0.25 * np.expm1(var)


# ------------------------------------------------------------ numerical / damped


def alpha_numerical(params: PeelParams, t, *, F_in: float, alpha_in: float, alphadot_in: float,
                    form: str = "airy", F_rate: float | None = None, v: float | None = None,
                    rtol: float = 1e-12, atol: float = 1e-15):
    """Integrate an α equation of Sec. V numerically with v frozen.

    ``form`` selects (``F = F_in + s t``, ``s = F_rate``, ``f' = f'(v, V)`` frozen):

    * ``"airy"``: Airy, ``α̈ = -F R α/I``;
    * ``"airy2"``: Airy2, ``α̈ = -F R α/I - F α̇/(R f')``;
    * ``"airy1"``: Airy1, ``α̈ = -F R α/I - (s + F α̇)/(R f')``.

    Integrated by :func:`scipy.integrate.solve_ivp` (DOP853) with its
    ``rtol``/``atol`` semantics on the state ``(α, α̇)``.  Airy2/Airy1 need
    ``v`` [m/s] on a stable branch (``f'(v, V) > 0``); the damping time is
    ``R f'/F`` (:func:`cd_damping_time`).  The default rate is ``k (V - v)``
    when ``v`` is given, else ``k V``.
    """
    params = _params("params", params, where="alpha_numerical", variants=False)
    form = choice("form", form, ALPHA_FORMS)
    t = _times(t)
    rtol = in_range("rtol", rtol, 1e-14, 1e-2)
    atol = in_range("atol", atol, 1e-100, 1e3)
    a_in, ad_in = state("alpha_in", alpha_in, "alpha"), state("alphadot_in", alphadot_in, "omega")
    if v is not None:
        v = state("v", v, "v")
        if F_rate is None:
            F_rate = _frozen_rate(params, v)
    F_in, s = _force_ramp(params, t, F_in, F_rate)
    R, I = params.R, params.I
    damp = 0.0
    if form != "airy":
        if v is None:
            raise ValueError(f"form={form!r} needs the peel velocity v (f'(v, V) sets the damping)")
        fp = float(law_fprime(params, v))
        if not fp > 0:
            raise ValueError(f"v={v} is not on a stable branch of f(., V={params.V}): f'(v) = {fp} <= 0")
        damp = 1.0 / (R * fp)
    drive = s if form == "airy1" else 0.0

    def rhs(tt, y):
        F = F_in + s * tt
        return [y[1], _restoring(F, y[0], R, I) - damp * (drive + F * y[1])]

    order = np.argsort(t.ravel(), kind="stable")
    tv = t.ravel()[order]
    if tv[-1] == 0.0:  # every time is the entry: nothing to integrate (solve_ivp needs a non-empty span)
        return np.full(t.shape, a_in), np.full(t.shape, ad_in)
    from scipy import integrate  # on first use

    sol = integrate.solve_ivp(rhs, (0.0, float(tv[-1])), [a_in, ad_in], method="DOP853", t_eval=tv,
                              rtol=rtol, atol=atol)
    if sol.status != 0:
        raise SolverFailure(f"solve_ivp failed at t = {sol.t[-1]:.6g} s: {sol.message}", t=float(sol.t[-1]),
                            state={"alpha": float(sol.y[0, -1]), "alphadot": float(sol.y[1, -1])})
    al = np.empty(t.size)
    ad = np.empty(t.size)
    al[order] = sol.y[0]
    ad[order] = sol.y[1]
    return al.reshape(t.shape), ad.reshape(t.shape)


def cd_damping_time(params: PeelParams, F, v):
    """Damping time ``R f'(v, V) / F`` of α on CD [s] (the coefficient in Airy1/Airy2).

    The paper compares it with the inertial period (Sec. V, Case a): when
    ``2π sqrt(I/(FR))`` exceeds it, the damping term of Airy1 controls α on CD
    (high inertia).  ``v`` must be on a stable branch.
    """
    params = _params("params", params, where="cd_damping_time", variants=False)
    Fa = states("F", F, "F")
    fp = np.asarray(law_fprime(params, states("v", v, "v")), dtype=float)
    if np.any(fp <= 0):
        raise ValueError(f"v must be on a stable branch of f(., V={params.V}) (f'(v) > 0)")
    out = _damping_time(params.R, fp, Fa)
    return float(out) if out.ndim == 0 else out


def cd_decay_alpha(params: PeelParams, t, *, F_in: float, alpha_in: float, v_in: float):
    """CD limit of Airy2: ``α̇ = -F α/(R f')`` with f', F frozen at entry (exponential decay).

    Returns ``α = α_in exp(-t/τ)``, ``τ = R f'(v_in)/F_in``.  The paper uses
    it on CD at high inertia, where ``FRα/I`` is small against the damping
    and the stay is short (Case II).  First order: ``α̇_in = -α_in/τ`` is
    implied, not free.
    """
    t = _times(t)
    a_in = state("alpha_in", alpha_in, "alpha")
    tau = cd_damping_time(params, state("F_in", F_in, "F"), state("v_in", v_in, "v"))
    return _decay(t, a_in, tau)

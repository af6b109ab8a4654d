"""The largest Lyapunov exponent of the exact peeling dynamics: one entry point, four methods.

:func:`lyapunov` measures the largest exponent, in bits/s, of the full model FLOW1, FLOW2, flow3 with CONSTR
after a transient, by one of :data:`LYAPUNOV_METHODS`:

* ``"two-trajectory"`` (default) — :func:`~exact.dynamics._benettin.benettin`'s renormalisation of two neighbouring
  hybrid orbits every ``tau`` seconds;
* ``"tangent"`` — the variational equation of the hybrid solver's field with saltation matrices at the
  jumps (:mod:`exact._tangent`; also :func:`lyapunov_tangent`);
* ``"return-map"`` — the tangent map of the AB→CD jump-to-jump map by central differences (also
  :func:`lyapunov_return_map`);
* ``"variational"`` — the variational equations of the ε-regularised system XDAE through diffsol
  (``exact.dynamics._variational``, needs the ``bench`` extra).

Every method returns one :class:`~exact.dynamics._benettin.LyapunovResult`; :func:`check_lyapunov_options` checks a
method's options without running it.  docs/dynamics.md compares the methods.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from peelapprox import (
    BRANCHES,
    LYAPUNOV_TAU,
    T_TRANSIENT,
    PeelParams,
    SolverBudgetExceeded,
    branch_structure,
)
from peelapprox.errors import WallBudget
from peelapprox.validate import (
    duration,
    function,
    optional,
    positive,
    state,
)
from peelapprox.validate import params as _params
from peelapprox.validate import rtol as _rtol

from .._initial import initial_state
from .._model import model_of
from .._shared import DEFAULT_MAX_WALL, natural_scales, paper_model_only
from .._simulate import simulate
from ._attractors import window_run
from ._benettin import (
    STDERR_BATCHES,
    BenettinResult,
    LyapunovResult,
    batch_means,
    benettin,
    variant_two_trajectory,
)
from ._lyapunov_options import D0_RANGE, LYAPUNOV_METHODS, _check, check_lyapunov_options

__all__ = ["LYAPUNOV_METHODS", "D0_RANGE", "check_lyapunov_options", "lyapunov", "lyapunov_tangent",
           "lyapunov_return_map"]

_AB = BRANCHES.index("AB")
def lyapunov(params: PeelParams, method: str = "two-trajectory", *, t_transient: float = T_TRANSIENT,
             alpha0: float = 0.0, rtol: float | None = None, max_wall: float | None = DEFAULT_MAX_WALL,
             **options: Any) -> LyapunovResult:
    """Largest Lyapunov exponent of the exact peeling dynamics, in bits/s, by one of four methods.

    Parameters
    ----------
    params : PeelParams
        With any law ``params.force`` that :func:`exact.simulate` runs (its scales and branches are the law's:
        :func:`peelapprox.branch_structure` with ``force``); ``"variational"``: the paper's law only (ValueError
        naming the method and the law otherwise).  A model without the hybrid method (``exact.MODELS``: a tape
        mass, a constant load) takes ``"two-trajectory"`` only, on its own method (``"smooth"``,
        ``"regularized"``); the other methods are a ValueError naming the model they support.
    method : {"two-trajectory", "tangent", "return-map", "variational"}
        How (module docstring; costs and agreement in docs/usage.md and docs/dynamics.md).
    t_transient : float
        Seconds integrated from the initial state and discarded, in [0, 1e6].
    alpha0 : float
        Initial peel angle; the rest of the initial state is :func:`exact.initial_state`'s.
    rtol : float, optional
        Relative tolerance of the method's solver runs; None: the method's default (1e-12 two-trajectory and
        return-map, 1e-10 tangent, 1e-8 variational).
    max_wall : float or None
        Wall-clock budget [s] of the whole call (``SolverBudgetExceeded`` with ``budget="max_wall"``; None:
        unbounded), checked between solver runs (two-trajectory, return-map), at every jump (tangent) or
        after every renormalisation interval (variational).
    **options
        Keyword-only options of the chosen method, checked before any run (:func:`check_lyapunov_options`); an
        option of another method, or of none, raises :class:`peelapprox.validate.ArgumentTypeError` (a
        ``TypeError`` and ``ValueError``) naming the option and the method.  ``T`` is the measured time [s]
        wherever the method measures a time:

        ================  =========================================================================
        method            options (defaults)
        ================  =========================================================================
        two-trajectory    ``tau`` (0.005 s), ``n`` (10000) or ``T`` (n = max(2, round(T/tau));
                          giving both is an error), ``n_discard`` (200), ``d0`` (1e-7), ``solver``
                          (None; a model variant's scipy solver, docs/tape-mass-dynamics.md)
        tangent           ``T`` (50 s), ``max_steps`` (5e6 per simulated second, at most 1e9)
        return-map        ``n_returns`` (5000), ``h`` (1e-6); no ``T``: the method renormalises once per
                          return and its length is a count of returns, whose times are known only as
                          the orbit runs (``peelapprox dynamics`` converts its measured time with the
                          return rate of its window)
        variational       ``eps`` (1e-7), ``T`` (50 s), ``tau`` (0.5 s), ``progress`` (None)
        ================  =========================================================================

    Returns
    -------
    LyapunovResult
        ``bits_per_s``, ``per_s``, ``stderr_bits`` (batch means of the record's intervals,
        :meth:`BenettinResult.from_logs`; inf with fewer than two, never NaN), the ``benettin`` record (running
        estimate, local rates), ``n_jumps``; ``method`` names the method.

    Raises
    ------
    ValueError
        An unknown method (the message lists :data:`LYAPUNOV_METHODS`), or a bad argument (named, with its range).
    peelapprox.ModelBreakdown, peelapprox.SolverFailure, peelapprox.SolverBudgetExceeded
        As :func:`exact.simulate`, with the time and state.

    Notes
    -----
    With the defaults (``method="two-trajectory"``) this is the two-trajectory renormalisation method
    (Benettin et al. 1980) on the hybrid solver: 50 s measured after 30 s of transient, 3-4 s of wall time.
    Its state is ``(α, ω, F, branch)`` — v follows from CONSTR — and the distance is measured in
    ``(Δα/1 rad, Δω/(V/R), ΔF/f_max)``, continuous across the jumps; renormalisation every ``tau`` seconds is
    postponed in steps of ``tau/8`` while the two orbits are on different branches.  Unless
    ``d0/rtol >= 1e5`` the solver's local errors, fresh every ``tau`` and amplified by the jumps, inflate the
    exponent (9.5-13.5 bits/s at V = 2, I = 1e-4 with d0/rtol = 10-100, 4.06-4.15 for every d0/rtol >= 1e5):
    hence d0 = 1e-7, rtol = 1e-12.  ``d0`` must lie in :data:`D0_RANGE` = [1e-12, 1].
    """
    method = check_lyapunov_options(method, **options)
    if not model_of(_params("params", params)).has_hybrid and method != "two-trajectory":
        paper_model_only(params, f"lyapunov method={method!r}",
                         "a model variant (a tape mass, a constant load) takes method='two-trajectory' only")
    common: dict[str, Any] = dict(t_transient=t_transient, alpha0=alpha0)
    if rtol is not None:
        common["rtol"] = rtol
    return _run_method(params, method, max_wall, common, options)


def _run_method(params: PeelParams, method: str, max_wall: float | None, common: dict[str, Any],
                options: dict[str, Any]) -> LyapunovResult:
    """The exponent by ``method`` with the ``common`` arguments and the method's ``options`` (checked)."""
    if method == "two-trajectory":
        return _two_trajectory(params, max_wall=max_wall, **common, **options)
    if method == "tangent":
        return _tangent(params, max_wall=max_wall, **common, **options)
    if method == "return-map":
        return _return_map(params, max_wall=max_wall, **common, **options)
    from ._variational import lyapunov_variational

    progress = optional(function, "progress", options.pop("progress", None))
    wall = WallBudget(optional(positive, "max_wall", max_wall))
    if wall.limit is not None:
        progress = _watch_wall(wall, progress)
    return lyapunov_variational(params, progress=progress, **common, **options)


def _watch_wall(wall: WallBudget, progress: Callable | None) -> Callable:
    """A ``progress(t_done, t_total)`` callback that raises once ``wall`` is spent, then calls ``progress``
    (the variational method reports after every renormalisation interval)."""

    def watch(t_done, t_total):
        wall.left(t_done, {"t": t_done}, t_total)
        if progress is not None:
            progress(t_done, t_total)

    return watch


def _two_trajectory(params: PeelParams, *, t_transient: float = T_TRANSIENT, tau: float = LYAPUNOV_TAU,
                    n: int | None = None, T: float | None = None, n_discard: int = 200, d0: float = 1e-7,
                    alpha0: float = 0.0, rtol: float = 1e-12, max_wall: float | None = DEFAULT_MAX_WALL,
                    solver: str | None = None) -> LyapunovResult:
    """Method ``"two-trajectory"`` of :func:`lyapunov` (its Notes): :func:`benettin` on the hybrid solver, or for
    a model without the hybrid method (``Model.has_hybrid``) on its method with ``solver``
    (:func:`exact.dynamics._benettin.variant_two_trajectory`).

    ``n`` renormalisation intervals are measured (10000 by default), or ``max(2, round(T/tau))`` of them when
    ``T`` is given (:func:`lyapunov` refuses both).  The two orbits' state is ``(α, ω, F, branch)``; ``run``
    advances one by a hybrid run, ``rescale`` puts the perturbation back to ``d0`` along its direction
    (halving the step while the moved state would leave its branch's level range), ``advance`` postpones the
    renormalisation while the orbits are on different branches.
    """
    params = _params("params", params)
    wall = WallBudget(optional(positive, "max_wall", max_wall))
    tau = _check("tau", tau)
    d0 = _check("d0", d0)
    t_transient = duration("t_transient", t_transient, zero=True)
    if T is not None:
        n = max(2, round(_check("T", T) / tau))
    n, n_discard = _check("n", 10000 if n is None else n), _check("n_discard", n_discard)
    alpha0 = state("alpha0", alpha0, "alpha")
    rtol = _rtol("rtol", rtol)
    if not model_of(params).has_hybrid:
        return variant_two_trajectory(params, t_transient=t_transient, tau=tau, n=n, n_discard=n_discard, d0=d0,
                                      alpha0=alpha0, rtol=rtol, solver=solver, max_wall=wall.limit)
    if solver is not None:
        raise ValueError(f"lyapunov: solver applies to a model variant's method (a model without the hybrid "
                         f"method: a tape mass, a constant load), not to the hybrid method of the paper's model; got "
                         f"solver={solver!r}")
    pair = _TwoOrbits(params, rtol, tau, d0, wall, t_transient + (n + n_discard) * tau)
    s0 = initial_state(params, alpha0=alpha0)
    ref = (s0.alpha, s0.omega, s0.F, s0.branch)
    if t_transient > 0:
        ref, _ = pair.run(ref, t_transient)
    # the perturbation: along F (the variable the constraint and the jumps act on), size d0
    pert = pair.rescale(ref, (ref[0], ref[1], ref[2] + d0 * pair.scale[2], ref[3]), 1.0)
    res = benettin(pair.advance, ref, pert, pair.distance, pair.rescale, n, n_discard=n_discard)
    ln2 = math.log(2.0)
    return LyapunovResult(res.exponent, res.exponent / ln2, res.stderr / ln2, res, params, tau, pair.jumps)


class _TwoOrbits:
    """The two orbits of :func:`_two_trajectory` on the hybrid solver, states ``(α, ω, F, branch)``: ``run``
    advances one by a hybrid run (within the call's ``wall``, ``t_total`` the simulated time of the call),
    ``distance`` measures in the natural scales, ``rescale`` puts the perturbation back along its direction,
    ``advance`` moves both by ``tau`` and postpones the renormalisation while they are on different branches;
    ``jumps`` counts the reference's jumps."""

    MAX_POSTPONES = 64

    def __init__(self, params: PeelParams, rtol: float, tau: float, d0: float, wall: WallBudget, t_total: float):
        self.params, self.rtol, self.tau, self.d0, self.wall, self.t_total = params, rtol, tau, d0, wall, t_total
        self.bs = branch_structure(params.V, force=params.force)
        self.scale = natural_scales(params)
        self.jumps = 0

    def run(self, state, dt):
        params, (a, w, F, br) = self.params, state
        try:
            tr = simulate(params, dt, alpha0=a, omega0=w, F0=F, branch0=br, rtol=self.rtol, save="jumps",
                          max_wall=self.wall.left(0.0, lambda: initial_state(params, alpha0=a, omega0=w, F0=F,
                                                                             branch0=br).__dict__, self.t_total))
        except SolverBudgetExceeded as exc:
            raise self.wall.reraise(exc) from None
        s = tr.final_state
        return (s.alpha, s.omega, s.F, s.branch), len(tr.jumps)

    def vec(self, s):
        return np.array(s[:3]) / self.scale

    def distance(self, a, b):
        return float(np.linalg.norm(self.vec(a) - self.vec(b)))

    def rescale(self, ref, pert, factor):
        # a state near a fold may leave its branch's level range when moved: halve the step until it does not
        for _ in range(60):
            x = (self.vec(ref) + factor * (self.vec(pert) - self.vec(ref))) * self.scale
            G = x[2] * (1.0 + float(self.params.closure(x[0])[0]))
            if self.bs.has_root(G, ref[3]):
                return (float(x[0]), float(x[1]), float(x[2]), ref[3])
            factor *= 0.5
        return ref  # unreachable in practice: the reference itself lies on its branch

    def advance(self, ref, pert):
        tau = self.tau
        ref, nj = self.run(ref, tau)
        pert, _ = self.run(pert, tau)
        dt = tau
        for _ in range(self.MAX_POSTPONES):
            if ref[3] == pert[3]:
                break
            ref, nj2 = self.run(ref, tau / 8)
            pert, _ = self.run(pert, tau / 8)
            dt += tau / 8
            nj += nj2
        else:
            raise RuntimeError(f"lyapunov: the two orbits stayed on different branches for {self.MAX_POSTPONES} "
                               f"postponements of tau/8 = {tau / 8:g} s: d0 = {self.d0:g} is too large for this orbit")
        self.jumps += nj
        return ref, pert, dt


def lyapunov_tangent(
    params: PeelParams,
    *,
    t_transient: float = T_TRANSIENT,
    T: float = 50.0,
    rtol: float = 1e-10,
    alpha0: float = 0.0,
    max_steps: int | None = None,
) -> LyapunovResult:
    """Largest Lyapunov exponent from the tangent (variational) dynamics with saltation matrices, in bits/s.

    The variational equation of the hybrid solver's desingularised field is integrated with the state by
    the package's DOP853; the tangent crosses each jump through the saltation matrix of the fold event and
    the reset to the landing root (:mod:`exact._tangent`).  Its equal-time (α, ω, F) size is measured and
    renormalised after every jump.  Slower than the two-trajectory :func:`lyapunov` (hundreds of steps per
    branch stay: the difference-quotient tangent is stiff near the folds), ~1 s of wall time per simulated
    second at V = 2, I = 1e-4.  The same as ``lyapunov(params, "tangent", ..., max_wall=None)``.

    Parameters
    ----------
    params : PeelParams
    t_transient : float
        Seconds integrated from the initial state and discarded, in [0, 1e6].
    T : float
        Seconds measured, in (0, 1e6].
    rtol : float
        Relative tolerance of the DOP853 run, in :data:`peelapprox.RTOL_RANGE`.
    alpha0 : float
        Initial peel angle; the rest of the initial state is :func:`exact.initial_state`'s.
    max_steps : int, optional
        Bound on the accepted steps; None: 5e6 per simulated second (~1.2e6 are used at V = 2, I = 1e-4).

    Returns
    -------
    LyapunovResult
        ``bits_per_s`` and ``per_s``, ``stderr_bits`` (batch means: the record's intervals between
        renormalisations at the jumps grouped into :data:`TANGENT_BATCHES` runs of about equal time), ``tau``
        the mean time of those batches, ``n_jumps``;
        ``notes`` reports the steps taken.

    Raises
    ------
    ValueError
        A bad argument (named, with its range).
    peelapprox.ModelBreakdown, peelapprox.SolverFailure
        As :func:`exact.simulate`, with the time and state (also when ``max_steps`` is spent).
    """
    return _tangent(params, t_transient=t_transient, T=T, rtol=rtol, alpha0=alpha0, max_steps=max_steps)


#: Batches of the tangent method's record (its standard error is that of the batch means, as every method's).
TANGENT_BATCHES = STDERR_BATCHES


def _tangent(params: PeelParams, *, t_transient: float = T_TRANSIENT, T: float = 50.0, rtol: float = 1e-10,
             alpha0: float = 0.0, max_steps: int | None = None, max_wall: float | None = None) -> LyapunovResult:
    """Method ``"tangent"`` of :func:`lyapunov` (:func:`lyapunov_tangent`, and a wall budget ``max_wall``)."""
    from .._tangent import lyapunov_saltation  # its kernels compile on first use: not at ``import exact``

    params = _params("params", params)
    paper_model_only(params, "lyapunov method 'tangent' (saltation matrices at the hybrid jumps)",
                     "use method='two-trajectory'")
    T = _check("T", T)
    t_transient = duration("t_transient", t_transient, zero=True)
    rtol = _rtol("rtol", rtol)
    alpha0 = state("alpha0", alpha0, "alpha")
    max_steps = _check("max_steps", max_steps)
    max_wall = optional(positive, "max_wall", max_wall)
    t0 = time.perf_counter()
    lam, n_jumps, t, steps, (logs, dts) = lyapunov_saltation(params, t_transient=t_transient, T=T, rtol=rtol,
                                                             alpha0=alpha0, max_steps=max_steps, max_wall=max_wall)
    # the record of the renormalisations (the tangent's unit size is d0 = 1) in batches of consecutive intervals
    # (batch means: the growth between two jumps alternates with the branch, so single intervals are strongly
    # correlated); the exponent is the sum of the logs in the order they came, as lyapunov_saltation formed it
    logs, dts = batch_means(logs, dts, TANGENT_BATCHES)
    b = dataclasses.replace(BenettinResult.from_logs(logs, dts, 1.0, time.perf_counter() - t0), exponent=lam)
    ln2 = math.log(2.0)
    return LyapunovResult(lam, lam / ln2, b.stderr / ln2, b, params, b.time / b.n, n_jumps,
                          method="tangent dynamics with saltation matrices", notes=[f"steps={steps}"])


def lyapunov_return_map(
    params: PeelParams,
    *,
    t_transient: float = T_TRANSIENT,
    n_returns: int = 5000,
    h: float = 1e-6,
    rtol: float = 1e-12,
    alpha0: float = 0.0,
    max_wall: float | None = DEFAULT_MAX_WALL,
) -> LyapunovResult:
    """Largest Lyapunov exponent from the tangent map of the jump-to-jump (Poincaré) map, in bits/s.

    The section is the AB→CD jump; the return map P takes the state (α, ω, F) just after one such jump to
    the state at the next.  A tangent vector w is pushed through P's Jacobian by central differences,
    ``DP w ≈ [P(x + h w) − P(x − h w)] / 2h`` in the scaled variables (α, ω/(V/R), F/f_max) — the jumps'
    saltation is inside P, so nothing is linearised across them — and renormalised every return.  The
    flow's exponent is ``Σ log|DP_k w_k| / Σ T_k`` over the return times T_k.  Unlike the two-trajectory
    :func:`lyapunov` there is no finite perturbation left to grow and no renormalisation noise; the result is
    independent of h over 1e-8 … 1e-5 (docs/dynamics.md).  On a periodic orbit it gives the (negative)
    transverse exponent, not the flow's 0.  A cross-check of :func:`lyapunov`, not a replacement: it needs a
    return map with at least two returns per second of the run.  The same as
    ``lyapunov(params, "return-map", ...)``.

    Parameters
    ----------
    params : PeelParams
    t_transient : float
        Seconds integrated from the initial state before the first section crossing, in [0, 1e6]; the map
        starts at the transient's last AB→CD jump, so it must hold one.
    n_returns : int
        Returns measured, >= 2 (a count of returns, not a time: the table of :func:`lyapunov`).
    h : float
        Central-difference step in the scaled variables, in (0, 1].
    rtol : float
        Relative tolerance of every hybrid run, in :data:`peelapprox.RTOL_RANGE`.
    alpha0 : float
        Initial peel angle of the transient's run; the rest of the initial state is
        :func:`exact.initial_state`'s.
    max_wall : float or None
        Wall-clock budget [s] of the whole computation (``SolverBudgetExceeded``, ``budget="max_wall"``; None:
        unbounded).

    Returns
    -------
    LyapunovResult
        ``bits_per_s``, ``per_s``, ``stderr_bits`` (batch means of the per-return logs), the ``benettin`` record,
        ``n_jumps``; ``method`` names the method.

    Raises
    ------
    ValueError
        A bad argument (named, with its range); no AB→CD jump within ``t_transient``; the orbit stops
        returning to the section; a perturbed orbit does not return (``h`` too large).
    peelapprox.ModelBreakdown, peelapprox.SolverFailure, peelapprox.SolverBudgetExceeded
        As :func:`exact.simulate`, with the time and state.
    """
    return _return_map(params, t_transient=t_transient, n_returns=n_returns, h=h, rtol=rtol, alpha0=alpha0,
                       max_wall=max_wall)


def _return_map(params: PeelParams, *, t_transient: float = T_TRANSIENT, n_returns: int = 5000, h: float = 1e-6,
                rtol: float = 1e-12, alpha0: float = 0.0, max_wall: float | None = DEFAULT_MAX_WALL) -> LyapunovResult:
    """Method ``"return-map"`` of :func:`lyapunov` (:func:`lyapunov_return_map`)."""
    params = _params("params", params)
    paper_model_only(params, "lyapunov method 'return-map' (the hybrid AB->CD section map)",
                     "use method='two-trajectory'")
    h = _check("h", h)
    rtol = _rtol("rtol", rtol)
    t_transient = duration("t_transient", t_transient, zero=True)
    n_returns = _check("n_returns", n_returns)
    alpha0 = state("alpha0", alpha0, "alpha")
    wall = WallBudget(optional(positive, "max_wall", max_wall))
    scale = natural_scales(params)

    def ret(x, horizon):
        try:
            J = simulate(params, horizon, alpha0=x[0], omega0=x[1], F0=x[2], branch0="CD", rtol=rtol, save="jumps",
                         max_wall=wall.left(0.0, lambda: initial_state(params, alpha0=x[0], omega0=x[1], F0=x[2],
                                                                           branch0="CD").__dict__, horizon)).jumps
        except SolverBudgetExceeded as exc:
            raise wall.reraise(exc) from None
        ab = np.flatnonzero(np.asarray(J.from_branch) == _AB)
        if ab.size == 0:
            return None, None
        i = ab[0]
        return np.array([J.alpha[i], J.omega[i], J.F[i]]), float(J.t[i])

    try:
        J0 = window_run(params, t_transient=0.0, window=max(float(t_transient), 1e-3), rtol=rtol, alpha0=alpha0,
                        max_wall=wall.limit).jumps
    except SolverBudgetExceeded as exc:
        raise wall.reraise(exc) from None
    ab = np.flatnonzero(np.asarray(J0.from_branch) == _AB)
    if ab.size == 0:
        raise ValueError(f"no AB→CD jump within t_transient = {t_transient} s: no return map to linearise")
    k = int(ab[-1])  # start on the section, at the transient's last AB→CD jump
    x = np.array([J0.alpha[k], J0.omega[k], J0.F[k]])
    w = np.array([0.3, 0.3, 1.0]) / math.sqrt(1.18)
    wall0 = time.perf_counter()
    logs: list[float] = []
    dts: list[float] = []
    horizon, jumps = 1.0, 0
    while len(logs) < int(n_returns):
        y, dt = ret(x, horizon)
        if y is None:
            if horizon > 1e3:
                raise ValueError("the orbit stopped returning to the AB→CD section (no stick-slip)")
            horizon *= 2.0
            continue
        horizon = 3.0 * dt
        yp, _ = ret(x + h * w * scale, horizon)
        ym, _ = ret(x - h * w * scale, horizon)
        if yp is None or ym is None:
            raise ValueError("a perturbed orbit did not return within 3 return times: h is too large")
        Dw = (yp - ym) / (2.0 * h) / scale
        d = float(np.linalg.norm(Dw))
        logs.append(math.log(d))
        dts.append(dt)
        w, x = Dw / d, y
        jumps += 2
    b = BenettinResult.from_logs(logs, dts, h, time.perf_counter() - wall0)
    ln2 = math.log(2.0)
    return LyapunovResult(b.exponent, b.exponent / ln2, b.stderr / ln2, b, params, b.time / b.n, jumps,
                          method="tangent map of the AB→CD return map (central differences)")

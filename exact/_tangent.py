"""Tangent (variational) dynamics of the hybrid solution with saltation matrices at the jumps.

On a branch the hybrid solver integrates the desingularised field ``y' = g(y)``, ``y = (t, α, ω, u = ln v)``,
in the parameter s (``exact._hybrid``); g is smooth through the folds.  A tangent vector δy obeys
``δy' = Dg(y) δy``, integrated here together with y by the same compiled DOP853 (state + tangent, 8
components); ``Dg`` is the analytic Jacobian of the field (:mod:`exact._jacobian`: the chain rule through
CONSTR, with f'' of the law and the closure's second derivative).

At the fold (the event ``h(y) = u − ln v_fold = 0``) the reset sets v to the landing root and keeps
(t, α, ω).  The saltation matrix maps the tangent across it,

    δy⁺ = S δy⁻,    S = R + (g⁺ − R g⁻) ∇hᵀ / (∇hᵀ g⁻),    R = diag(1, 1, 1, 0),

i.e. ``δy⁺ = R δy⁻ + (g⁺ − R g⁻) δu⁻ / g_u⁻``: a perturbation that reaches the fold earlier by
``δu⁻/g_u⁻`` in s has spent that long on the new branch.  (S maps the flow direction onto the flow
direction, ``S g⁻ = g⁺``: tested.)  At the fold ``g⁻ = (0, 0, 0, Ġ)`` (dt/ds, dα/ds and dω/ds vanish
with f'), so ``R g⁻ = 0``.  Perturbations
are compared at equal t at the measurement points: the (α, ω) part of ``δy − ẏ δt`` with
``ẏ = (dy/ds)/(dt/ds)``, and the F part from CONSTR, ``δF = (∂F/∂α) δα + (∂F/∂u) δu``.

This module owns only its small driver (integrate to the fold, no output); the step is the package's one
DOP853 (:mod:`peelapprox._compiled._dop853`).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numba import types as _t

from peelapprox import BREAKDOWN_LEVEL, T_TRANSIENT
from peelapprox.errors import SolverBudgetExceeded, WallBudget
from peelapprox.kernels import (
    LAW_TYPE,
    STEP_FAILED,
    compile_only,
    crossing,
    interp,
    interp1,
    kernel,
    make_dop853,
    pack_inlined,
    pack_law,
    rebind,
    solve_theta,
    workspace,
)
from peelapprox.kernels import N_STAGES as _NS
from peelapprox.kernels import status as _st
from peelapprox.validate import duration, integer, optional, positive

from . import _hybrid as H
from . import _hybrid_driver as HD
from ._jacobian import jacobian_law, jacobian_paper

DONE, FOLD, MAX_STEPS, NO_LANDING, NO_ROOT, STEP_FAIL, V_CEILING = (
    _st.DONE, _st.FOLD, _st.MAX_STEPS, _st.NO_LANDING, _st.NO_ROOT, _st.STEP_FAIL, _st.V_CEILING)
status_error = _st.status_error


#: Bound per copy of the driver (:func:`to_fold`): the field ``_FIELD(y, P, out)`` (the hybrid solver's, the
#: law inlined or as an argument), its Jacobian ``_JAC(y, P, J)``, ``P = _PACK(p, law, coef)``, the tangent
#: field ``_RHS_T`` and ``_dop_t``, its DOP853 pieces.  Never compiled with these placeholders.
_FIELD: Any = None
_JAC: Any = None
_PACK: Any = None
_RHS_T: Any = None
_dop_t: Any = None


def _rhs_tangent(y, P, out):
    """d(y, δy)/ds: the hybrid field and its Jacobian (:mod:`exact._jacobian`) applied to δy."""
    g = np.empty(4)
    _FIELD(y[:4], P, g)
    J = np.empty((4, 4))
    _JAC(y[:4], P, J)
    for i in range(4):
        out[i] = g[i]
        acc = 0.0
        for j in range(4):
            acc += J[i, j] * y[4 + j]
        out[4 + i] = acc


def _to_fold(y, p, law, coef, br, rtol, atol, t_max, max_steps):
    """Integrate (y, δy) from ``y`` on branch ``br`` to its fold or to t = t_max (whichever first).

    Returns (status, steps) with a code of :mod:`peelapprox._status`; y holds the state there: FOLD (v
    exactly at the fold), DONE (t = t_max), STEP_FAIL, MAX_STEPS, NO_ROOT (u <= ln v_breakdown on AB, the
    model's criterion, or the start of the law's domain).
    """
    P = _PACK(p, law, coef)
    K, y_new, f0, tmp, sc, work, Fc, ye = workspace(8)
    _RHS_T(y, P, f0)
    h = _dop_t.initial_step(y, f0, P, rtol, atol, work)
    uf = p[H.P_UEV_AB] if br == 0 else p[H.P_UEV_CD]
    for n in range(max_steps):
        status, h, h_next, n_rej, n_rhs = _dop_t.step(y, f0, h, P, rtol, atol, K, y_new, tmp, sc)
        if status == STEP_FAILED:
            return STEP_FAIL, n
        if br == 0 and y_new[3] <= p[H.P_UFLOOR]:
            for i in range(8):
                y[i] = y_new[i]
            return NO_ROOT, n + 1
        crossed = (y_new[3] >= uf) if br == 0 else (y_new[3] <= uf)
        x_fold = 2.0
        if crossed:
            _dop_t.dense(y, y_new, K, h, P, Fc, tmp)
            x_fold = solve_theta(y, Fc, 3, uf, y[3] - uf, 1.0, y_new[3] - uf)
        # t_max inside the step (tau increases up to the fold): stop exactly there, as simulate does at t_end
        x_b = min(x_fold, 1.0)
        tau_b = interp1(y, Fc, x_b, 0) if crossed else y_new[0]
        if tau_b >= t_max:
            if not crossed:
                _dop_t.dense(y, y_new, K, h, P, Fc, tmp)
            interp(y, Fc, crossing(y, Fc, 0, t_max, x_b, tau_b), ye)
            for i in range(8):
                y[i] = ye[i]
            y[0] = t_max
            return DONE, n + 1
        if crossed:
            interp(y, Fc, x_fold, ye)
            for i in range(8):
                y[i] = ye[i]
            y[3] = np.log(p[H.P_VMAX] if br == 0 else p[H.P_VMIN])
            return FOLD, n + 1
        if br == 1 and y_new[3] > p[H.P_UCEIL]:  # above the law's domain (a table's end) or a runaway
            for i in range(8):
                y[i] = y_new[i]
            return V_CEILING, n + 1
        for i in range(8):
            y[i] = y_new[i]
            f0[i] = K[_NS, i]
        h = h_next
    return MAX_STEPS, max_steps


_A1 = _t.float64[::1]
#: The one signature of both copies of :func:`_to_fold`: ``(y, p, law, coef, br, rtol, atol, t_max, max_steps)
#: -> (status, steps)``.
TO_FOLD_SIG = _t.UniTuple(_t.int64, 2)(_A1, _A1, LAW_TYPE, _A1, _t.int64, _t.float64, _A1, _t.float64, _t.int64)


def _make_to_fold(field, jac, pack, tag: str):
    rhs_t = kernel(rebind(_rhs_tangent, _FIELD=field, _JAC=jac), name=f"rhs_tangent_{tag}", inner=True)
    return kernel(rebind(_to_fold, _PACK=pack, _RHS_T=rhs_t, _dop_t=make_dop853(rhs_t)), name=f"to_fold_{tag}")


_TO_FOLD = {False: _make_to_fold(H._rhs, jacobian_paper, pack_inlined, "inlined"),
            True: _make_to_fold(HD._rhs_law, jacobian_law, pack_law, "law")}


def to_fold(law_argument: bool) -> Any:
    """The tangent driver :func:`_to_fold` with the paper's law inlined (False, the default path) or with the
    law as an argument (True), compiled for :data:`TO_FOLD_SIG` on first use (loaded from numba's cache)."""
    return compile_only(_TO_FOLD[bool(law_argument)], TO_FOLD_SIG)


@dataclass(frozen=True)
class TangentSystem:
    """What the tangent integration of one run needs (:func:`tangent_system`).

    Attributes
    ----------
    law : CompiledLaw
        The run's law (``peelapprox.kernels.compiled_law``).
    p : ndarray
        The hybrid driver's parameter vector (folds, landings, floors of the law).
    run : numba dispatcher
        :func:`to_fold` for the law (inlined fvV or the law as an argument).
    field : callable
        ``field(y, out)``: the hybrid field d(t, α, ω, u)/ds at ``y[:4]``.
    pull : callable
        ``pull(alpha, v)``: CONSTR's pull force.
    """

    law: Any
    p: np.ndarray
    run: Any
    field: Callable[[np.ndarray, np.ndarray], None]
    pull: Callable[[float, float], float]

    def landing(self, br: int) -> float:
        """Where a jump from the fold of branch ``br`` (0: AB, 1: CD) lands [m/s]; <= 0 if it cannot."""
        return float(self.p[H.P_VLCD] if br == 0 else self.p[H.P_VLAB])

    def jump(self, y: np.ndarray, br: int) -> float | None:
        """The jump from the fold of branch ``br`` in place: ``y = (state, tangent)`` at the fold becomes the
        state at the landing (τ reset to 0) and the tangent mapped by the saltation matrix (:func:`saltation`).
        Returns ``Ġ`` on arrival at the fold (the field's u-component there), or None, ``y`` untouched, if the
        jump cannot land."""
        v_land = self.landing(br)
        if not v_land > 0.0:
            return None
        gm, gp = np.empty(4), np.empty(4)
        self.field(y[:4], gm)
        y[0], y[3] = 0.0, math.log(v_land)
        self.field(y[:4], gp)
        y[4:] = saltation(y[4:], gm, gp)
        return float(gm[3])


def tangent_system(params) -> TangentSystem:
    """The :class:`TangentSystem` of ``params`` (its law's compiled driver, field and pull force)."""
    from ._shared import paper_model_only

    paper_model_only(params, "the hybrid tangent dynamics (section returns, periodic_orbit, solve_orbit, "
                     "continue_orbit, lyapunov methods 'tangent' and 'return-map')",
                     "use exact.orbit_diagram, exact.attractors or lyapunov(method='two-trajectory')")
    cl = HD.law_for(params)  # the paper's law (default): the driver with fvV inlined
    law, coef, bs = cl.arg, cl.coef, cl.structure
    p = HD.param_vector(params) if cl.inlined else HD.param_vector(params, None, bs, cl.domain)
    if cl.inlined:
        def field(y, out):
            H._rhs(y, p, out)

        def pull(a, v):
            return H.pull_force(a, v, p)
    else:
        rhs_law = HD.field_law()

        def field(y, out):
            rhs_law(y, p, law, coef, out)

        def pull(a, v):
            return HD.pull_force_law(a, v, p, law, coef)
    return TangentSystem(cl, p, to_fold(not cl.inlined), field, pull)


def saltation(dy, g_minus, g_plus) -> np.ndarray:
    """The tangent after a jump: ``S δy⁻`` with the fold event ``u = ln v_fold`` and the reset v := v_land
    (module docstring); ``g_minus``, ``g_plus`` are the desingularised field before and after."""
    R_dy = np.array([dy[0], dy[1], dy[2], 0.0])
    R_g = np.array([g_minus[0], g_minus[1], g_minus[2], 0.0])
    return R_dy + (np.asarray(g_plus) - R_g) * (dy[3] / g_minus[3])


def _equal_time_vector(y, field, pull, scale):
    """(δα, δω, δF) at equal t (module docstring), scaled by (1, V/R, f_max); ``field(y, out)`` and
    ``pull(alpha, v)`` are the hybrid field and CONSTR's pull force of the run's law."""
    g = np.empty(4)
    field(y[:4], g)
    dt = y[4]
    if g[0] != 0.0:
        da = y[5] - g[1] / g[0] * dt
        dw = y[6] - g[2] / g[0] * dt
        du = y[7] - g[3] / g[0] * dt
    else:  # exactly at a fold dα/dt and dω/dt stay finite but the quotient is 0/0: use δ at equal s
        da, dw, du = y[5], y[6], y[7]
    eps = 1e-7
    v = math.exp(y[3])
    Fa = (pull(y[1] + eps, v) - pull(y[1] - eps, v)) / (2 * eps)
    Fu = (pull(y[1], math.exp(y[3] + eps)) - pull(y[1], math.exp(y[3] - eps))) / (2 * eps)
    return np.array([da, dw, Fa * da + Fu * du]) / scale


#: Default step budget of :func:`lyapunov_saltation` per simulated second (measured: ~1.2e6 steps/s at
#: V = 2, I = 1e-4, rtol 1e-10).
STEPS_PER_SECOND = 5_000_000
#: Cap of that default: 1e9 steps, ~35 min of work at ~2 us per (state + tangent) step, so that a default call
#: is bounded in wall time whatever T (the driver is one compiled loop and cannot watch a clock).
MAX_DEFAULT_STEPS = 1_000_000_000


def lyapunov_saltation(params, *, t_transient: float = T_TRANSIENT, T: float = 50.0, rtol: float = 1e-10,
                       alpha0: float = 0.0, max_steps: int | None = None, max_wall: float | None = None):
    """Largest Lyapunov exponent [1/s] from the tangent dynamics with saltation matrices (module docstring).

    Starts from the state at ``t_transient`` (exact.simulate from ``alpha0``), integrates the tangent for ``T``
    seconds, renormalising it after every jump, where its equal-time (α, ω, F) size is measured. Returns
    ``(exponent_per_s, n_jumps, time, steps, (logs, dts))``: the last two are the log growth of the tangent
    between consecutive renormalisations (at the jumps and at the end) and their durations.  ``T`` must lie in
    (0, 1e6] s and ``t_transient`` in [0, 1e6] s.  ``max_steps`` (an integer in [1, 1e15]; default
    ``STEPS_PER_SECOND * (T + 1)``, at most ``MAX_DEFAULT_STEPS`` = 1e9, ~35 min) bounds the accepted steps;
    exceeding it raises :class:`peelapprox.SolverBudgetExceeded`, a step-size failure
    :class:`peelapprox.SolverFailure` and a fold with no landing root :class:`peelapprox.ModelBreakdown`, each
    with the time and state. ``max_wall`` [s] (None: unbounded) bounds the wall time, checked by the transient's
    run and after every jump (the compiled loop between two jumps is bounded by ``max_steps``); exceeding it
    raises :class:`peelapprox.SolverBudgetExceeded` with ``budget="max_wall"``.
    """
    from ._methods import ATOL_SCALE
    from ._shared import natural_scales

    T = duration("T", T)
    t_transient = duration("t_transient", t_transient, zero=True)
    max_steps = optional(integer, "max_steps", max_steps)
    wall = WallBudget(optional(positive, "max_wall", max_wall))
    s = _transient_state(params, t_transient, alpha0, rtol, wall)
    ts = tangent_system(params)
    # the tangent's own accuracy need is modest (growth rates to ~1e-6) and its difference quotient carries
    # ~1e-9 relative noise: an absolute 1e-7 on the (unit-size) tangent keeps the steps those of the state
    atol = np.concatenate([rtol * np.asarray(ATOL_SCALE["hybrid"]), np.full(4, 1e-7)])
    if max_steps is None:
        max_steps = min(int(STEPS_PER_SECOND * (T + 1.0)), MAX_DEFAULT_STEPS)
    walk = _TangentWalk(params, ts, natural_scales(params), t_transient, s)
    while walk.t < T:
        status, n = ts.run(walk.y, ts.p, ts.law.arg, ts.law.coef, walk.br, rtol, atol, T - walk.t,
                           max_steps - walk.steps)
        walk.steps += n
        if status == DONE:
            walk.t += walk.y[0]
            walk.renormalise(at_jump=False)
            break
        if status != FOLD:
            raise walk.stop_error(status, max_steps)
        walk.t += walk.y[0]
        walk.jump()
        wall.left(t_transient + walk.t, lambda t=walk.t: walk.where(t), t_transient + T)
    return walk.logs / walk.t, walk.n_jumps, walk.t, walk.steps, (np.array(walk.seg_logs), np.array(walk.seg_dts))


def _transient_state(params, t_transient: float, alpha0: float, rtol: float, wall: WallBudget):
    """The state at ``t_transient`` of ``exact.simulate`` from ``alpha0`` (at 0: the initial state itself, as
    simulate needs t_end > 0); the wall budget's error if the transient used it up."""
    from ._initial import initial_state
    from ._simulate import simulate

    try:
        return (simulate(params, t_transient, alpha0=alpha0, rtol=rtol, save="jumps", max_wall=wall.limit).final_state
                if t_transient > 0 else initial_state(params, alpha0=alpha0))
    except SolverBudgetExceeded as exc:
        raise wall.reraise(exc) from None


class _TangentWalk:
    """The state and tangent ``y`` of :func:`lyapunov_saltation` on branch ``br``, the time ``t`` since the
    transient, and the log growth recorded at each renormalisation (jumps at one instant make one interval)."""

    def __init__(self, params, ts: TangentSystem, scale: np.ndarray, t_transient: float, s) -> None:
        self.params, self.ts, self.scale, self.t_transient = params, ts, scale, t_transient
        self.br = 0 if s.branch == "AB" else 1
        self.y = np.array([0.0, s.alpha, s.omega, math.log(s.v), 0.0, 0.0, 0.0, 1.0])
        self.y[4:] /= np.linalg.norm(self.size())
        self.t, self.logs, self.n_jumps, self.steps = 0.0, 0.0, 0, 0
        self.seg_logs: list[float] = []  # per renormalisation: the log growth and the time since the last one
        self.seg_dts: list[float] = []
        self.t_last, self.pending = 0.0, 0.0  # growth not yet recorded

    def size(self) -> np.ndarray:
        """The tangent's scaled (δα, δω, δF) at equal t."""
        return _equal_time_vector(self.y, self.ts.field, self.ts.pull, self.scale)

    def where(self, t_now: float) -> dict:
        y = self.y
        v = math.exp(y[3])
        return dict(t=self.t_transient + t_now, alpha=float(y[1]), omega=float(y[2]), F=float(self.ts.pull(y[1], v)),
                    v=v, branch="AB" if self.br == 0 else "CD")

    def record(self, g: float) -> None:
        self.pending += g
        if self.t > self.t_last:
            self.seg_logs.append(self.pending)
            self.seg_dts.append(self.t - self.t_last)
            self.t_last, self.pending = self.t, 0.0

    def renormalise(self, at_jump: bool) -> None:
        """Record the tangent's log growth; after a jump, rescale it to size 1 (at the end, leave it)."""
        if not at_jump:
            g = math.log(np.linalg.norm(self.size()))
            self.logs += g
            self.record(g)
            return
        d = float(np.linalg.norm(self.size()))
        self.logs += math.log(d)
        self.record(math.log(d))
        self.y[4:] /= d

    def jump(self) -> None:
        """Jump from the fold reached at ``t`` (its saltation), or raise the stop of a jump that cannot land."""
        cl, bs, t, params = self.ts.law, self.ts.law.structure, self.t, self.params
        if self.ts.jump(self.y, self.br) is None:
            code, what = HD.domain_status(NO_LANDING, cl, math.exp(self.y[3]), math.inf)
            raise status_error(code, t=self.t_transient + t, state=self.where(t), prefix="tangent integration: ",
                               where=f"at t = {self.t_transient + t:.6g} s", f_min=bs.f_min, f_zero=bs.f_zero,
                               what=what, lo=cl.domain[0], hi=cl.domain[1], law=repr(params.force))
        self.br = 1 - self.br
        self.n_jumps += 1
        self.renormalise(at_jump=True)

    def stop_error(self, status: int, max_steps: int) -> Exception:
        """The documented exception of the compiled loop's stop ``status`` (neither DONE nor FOLD)."""
        cl, bs, y, t, p = self.ts.law, self.ts.law.structure, self.y, self.t, self.ts.p
        lo, hi = cl.domain
        status, what = HD.domain_status(status, cl, math.exp(y[3]), math.inf)
        return status_error(status, t=self.t_transient + t + y[0], state=self.where(t + y[0]),
                            prefix="tangent integration: ", where=f"at t = {self.t_transient + t + y[0]:.6g} s",
                            limit=int(max_steps), f_zero=bs.f_zero, level=BREAKDOWN_LEVEL, v=math.exp(y[3]), lo=lo,
                            hi=hi, law=repr(self.params.force), v_ceiling=math.exp(p[H.P_UCEIL]), what=what)

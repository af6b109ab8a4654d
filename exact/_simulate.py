"""``exact.simulate``: argument checking, the default initial state, dispatch."""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable, Sequence
from typing import Any, cast

import numpy as np

from peelapprox import (
    BRANCHES,
    BREAKDOWN_LEVEL,
    STATE_RANGES,
    TIME_MAX,
    BranchStructure,
    PeelParams,
    branch_inverse,
    branch_structure,
    peel_force,
)
from peelapprox.errors import SolverBudgetExceeded, budget_exceeded
from peelapprox.io import ProgressLine
from peelapprox.kernels import ALL_LAWS, BuildExpired, caller_budget, model_block
from peelapprox.kernels import status as S
from peelapprox.validate import choice, duration, in_range, interval, optional, shown, state
from peelapprox.validate import params as _params

from . import _hybrid as H
from . import _hybrid_law as HL
from ._options import (
    ATOL_SCALE,
    STEP_BUDGET,
    Budget,
    Hybrid,
    Regularized,
    SaveAt,
    Smooth,
    default_max_steps,
    method_option,
    output_options,
)
from ._options import _atol_vector as _atol_vector  # also read by exact._variational (exact.simulate's atol rule)
from ._trajectory import Jumps, SolverStats, State, Trajectory

__all__ = ["simulate", "initial_state", "compile_kernels", "ATOL_SCALE", "STEP_BUDGET", "default_max_steps"]

_COMPILE_TIME: dict[str, float | None] = {"hybrid": None}


def initial_state(
    params: PeelParams,
    *,
    alpha0: float = 0.0,
    omega0: float | None = None,
    F0: float | None = None,
    branch0: str | None = None,
    t0: float = 0.0,
) -> State:
    """The consistent initial state used by :func:`simulate`.

    Defaults (documented behaviour): ``α = 0``, ``ω = V/R``,
    ``F = 1.01 f(V, V)`` and v the lowest-velocity stable root of CONSTR,
    ``f(v, V) = F (1 - cos θ)``: on AB if the level lies in AB's range
    ``(f(0+), f_max]``, otherwise on CD.  f is the law ``params.force`` (the paper's fvV, or a cubic, whose
    folds are :func:`peelapprox.kernels.cubic_v_structure`'s and whose root is found in ln v by Brent's method).

    Parameters
    ----------
    params : PeelParams
        The model's parameters (V, I, k, R, l, geometry).
    alpha0 : float
        Peel angle α [rad], in ``STATE_RANGES["alpha"]``.
    omega0 : float, optional
        Roller angular velocity ω [rad/s]; None: ``V/R`` (the roller turning with the pull).
    F0 : float, optional
        Pull force F [N]; None: ``1.01 f(V, V)``, just above steady sliding.
    branch0 : {"AB", "CD"}, optional
        The branch v is taken on; None: AB when the level has a root there, else CD.
    t0 : float
        Initial time [s], in ``[0, TIME_MAX]``.

    Returns
    -------
    State
        ``t, alpha, omega, F, v, branch`` with v solving CONSTR on the branch (consistent: the DAE starts on
        its constraint manifold).

    Raises
    ------
    ValueError
        Naming the argument and its valid range, if the level
        ``F0 (1 - cos θ(α0))`` has no root on the requested branch (or on
        any branch), or if ``1 - cos θ(α0) <= 0``; or, when F0 is not given,
        if the default ``1.01 f(V, V)`` is outside ``STATE_RANGES["F"]`` (a
        law in other units than newtons, or with coefficients like 1e300).
        A message about a value the caller did not pass says that the
        default was used.
    """
    _params("params", params)
    a0 = state("alpha0", alpha0, "alpha")
    w0 = params.V / params.R if omega0 is None else state("omega0", omega0, "omega")
    law = None if params.force.kind == "paper" else HL.law_for(params)  # another law: its compiled form
    if law is None:
        fVV = float(peel_force(params.V, params.V))
    elif F0 is None and not law.domain[0] <= params.V <= law.domain[1]:
        raise ValueError(f"F0 was not given, and its default 1.01 f(V, V) needs f at v=V={params.V!r} m/s, outside "
                         f"the domain {law.domain} m/s of params.force={shown(params.force)}: give F0")
    else:
        fVV = law.f(params.V)
    if F0 is None:
        F = 1.01 * fVV
        f_lo, f_hi = STATE_RANGES["F"]
        if not (math.isfinite(F) and f_lo <= F <= f_hi):
            raise ValueError(f"F0 was not given, so its default 1.01 f(V, V) = {F:.6g} N was used (f of params.force="
                             f"{shown(params.force)} at V={params.V!r} m/s), outside STATE_RANGES['F'] = "
                             f"{interval(f_lo, f_hi)} N, the pull forces the solvers are built for: give F0 in that "
                             "range, or a law in newtons whose f(V, V) lies in it")
        f0 = f"F0 (not given: the default 1.01 f(V, V) = {F!r} N)"
    else:
        F = state("F0", F0, "F")
        f0 = f"F0={F!r}"
    t0 = in_range("t0", t0, 0.0, TIME_MAX)
    branch0 = optional(choice, "branch0", branch0, BRANCHES)
    at = f"alpha0={a0!r}" + (" (the default)" if a0 == 0.0 else "")
    c = float(params.closure(a0)[0])
    if not (1.0 + c > 0.0):
        raise ValueError(f"alpha0={a0!r} makes 1 - cos(theta) = {1 + c} <= 0: alpha0 must keep 1 + sin(alpha0) > 0")
    G = F * (1.0 + c)
    bs = branch_structure(params.V) if law is None else law.structure
    if branch0 is None:
        for cand in ("AB", "CD") if bs.has_folds else ("AB",):
            if bs.has_root(G, cand):
                branch0 = cand
                break
        else:
            raise ValueError(
                f"{f0} gives F0*(1 - cos theta)={G}, below f(0+, V)={bs.f_zero}: no stable root of CONSTR; "
                f"F0 must exceed {bs.f_zero / (1 + c)} at {at}"
            )
    if branch0 not in BRANCHES:
        raise ValueError(f"branch0 must be 'AB' or 'CD' (or None for the lowest root), got {branch0!r}")
    lo, hi = bs.level_range(branch0)  # raises for CD without folds
    if not bs.has_root(G, branch0):
        raise ValueError(
            f"{f0} at {at} gives the level F0*(1 - cos theta)={G}, which has no root on branch0={branch0!r}; "
            f"valid F0 range on {branch0}: ({lo / (1 + c)}, {hi / (1 + c)})"
        )
    v = branch_inverse(G, params.V, branch0) if law is None else law.branch_root(G, branch0)
    return State(float(t0), a0, w0, F, float(v), branch0)


def compile_kernels() -> float:
    """Compile (or load from numba's on-disk cache) the hybrid kernel (the driver with the paper's law inlined).

    Returns the seconds spent in this process the first time; 0 afterwards.
    """
    if _COMPILE_TIME["hybrid"] is not None:
        return 0.0
    t0 = time.perf_counter()
    p = PeelParams(V=1.0, I=1e-5)
    st = initial_state(p)
    _run_hybrid(p, 1e-4, st, Hybrid(rtol=1e-6), SaveAt(steps=True),
                Budget(max_points=10**4, max_steps=10**3, max_jumps=10**4), None)
    dt = time.perf_counter() - t0
    _COMPILE_TIME["hybrid"] = dt
    return dt


def _progress_printer(label: str) -> Callable[[float, float], None]:
    """``progress=True``: :class:`peelapprox.io.ProgressLine` in per mille of ``t_end`` (a line per 5 %)."""
    line: list[ProgressLine] = []

    def report(t: float, t_end: float) -> None:
        if not line:
            line.append(ProgressLine(label, 1000, count=False))
        line[0].update(min(1000, max(0, int(1000 * t / t_end))), f"t = {t:.6g} / {t_end:.6g} s")

    return report


def simulate(
    params: PeelParams,
    t_end: float,
    *,
    alpha0: float = 0.0,
    omega0: float | None = None,
    F0: float | None = None,
    branch0: str | None = None,
    Vp0: float | None = None,
    method: str | Hybrid | Regularized | Smooth | None = None,
    solver: str | None = None,
    rtol: float = 1e-8,
    atol: None | float | Sequence[float] = None,
    eps: float | None = None,
    t_transient: float = 0.0,
    t_eval: Sequence[float] | None = None,
    save: str = "steps",
    max_points: int = 5_000_000,
    max_steps: int | None = None,
    max_jumps: int = 20_000_000,
    max_wall: float | None = None,
    v_floor: float | None = None,
    progress: None | bool | Callable[[float, float], None] = None,
    saveat: SaveAt | None = None,
    budget: Budget | None = None,
) -> Trajectory:
    """Integrate the peeling model (FLOW1, FLOW2, flow3, CONSTR) from t = 0 to t_end.

    Parameters
    ----------
    params : PeelParams
        Physical parameters, the ``cos θ`` closure (``geometry``) and the law ``force``: the paper's fvV, or
        ``PeelForce.cubic(...)`` with ``method="hybrid"`` (the law driver); other laws: ValueError.
    t_end : float
        Final time [s], in (0, TIME_MAX] = (0, 1e6].
    alpha0, omega0, F0, branch0 : optional
        Initial state; defaults ``α = 0``, ``ω = V/R``, ``F = 1.01 f(V, V)``,
        ``branch0=None`` meaning the lowest-velocity stable root of CONSTR
        (see :func:`initial_state`).  v is always the root of CONSTR on
        ``branch0``, so the start is consistent.
    Vp0 : float, optional
        Initial pull speed [m/s] under a load (``params.loading == "load"``), in
        [0, 1e3]; default ``params.V``.  A ValueError under velocity control.
    method : {"hybrid", "regularized", "smooth"} or Hybrid or Regularized or Smooth, optional
        ``"hybrid"`` (the default for the paper's model): the ε → 0 limit,
        event-driven, compiled DOP853 on the desingularised branch dynamics
        with exact fold jumps (see :mod:`exact._hybrid`).  ``"regularized"``:
        the paper's scheme, mass matrix ``diag(1, 1, 1, ε)``, integrated by
        scipy's stiff ``solver`` (the default for a massless tape under a load,
        ``params.loading == "load"``).  ``"smooth"`` (the default, and the only
        method, for the tape-mass model ``params.tape_mass``): its ODE on a
        scipy ``solver`` (docs/tape-mass.md).  None: the model's default.
        A method the model cannot use is a ValueError saying which it can.
        A method object (:class:`Hybrid`, :class:`Regularized`, :class:`Smooth`) holds
        ``solver``, ``eps``, ``rtol``, ``atol`` and ``v_floor`` itself: those
        keywords must then stay at their defaults (ValueError naming both).
    solver : {"Radau", "BDF", "LSODA"}, optional
        scipy solver for ``method="regularized"`` (analytic Jacobian);
        default "Radau".  ``method="smooth"`` also takes "DOP853" and "RK45";
        its default is "LSODA", the fastest at every tape mass measured
        (docs/tape-mass.md, "Which integrator").
        Passing it with the hybrid method is an error.
    rtol, atol : float, float or 4 floats
        Local error control per step: RMS over components of
        ``err_i / (atol_i + rtol |y_i|) <= 1``.  Hybrid components are
        ``(τ, α, ω, ln v)`` (τ = time since the last jump), regularised ones are
        ``(α, ω, F, v)``.  ``rtol`` in ``RTOL_RANGE`` = [1e-14, 1e-2];
        ``atol`` (each component) in ``ATOL_RANGE`` = [1e-100, 1];
        ``atol=None`` uses ``rtol * ATOL_SCALE[method]``.
    eps : float, optional
        Regularisation ε (``method="regularized"`` only; an error with the
        hybrid method), in ``EPS_RANGE`` = [1e-15, 1e-2], default 1e-7 as in
        the paper.
    t_transient : float
        Integrate from 0 but store nothing (points or jumps) before this time.
    t_eval : array_like, optional
        Store the state exactly at these times (sorted, within
        ``[t_transient, t_end]``) instead of at every step.
    save : {"steps", "jumps"}
        Without ``t_eval``: ``"steps"`` stores every accepted step plus the
        states just before and after each jump; ``"jumps"`` stores only jumps
        (memory proportional to the number of jumps, not of steps).
    max_points, max_steps, max_jumps : int
        Budgets: stored points, accepted steps (all, from t = 0) and stored
        jumps (those at t >= t_transient: a memory budget, like max_points).
        Needing more than one raises :class:`SolverBudgetExceeded` (with the
        partial trajectory); nothing is truncated silently.  ``max_steps=None``
        scales the step budget with the horizon (:func:`default_max_steps`:
        1e6 steps per simulated second within [1e6, 2e7] for the hybrid
        method, ~35 s of work at most; 1e5/s within [1e5, 5e5] for the
        regularised one, ~80 s; 1e6/s within [1e5, 5e6] for the tape-mass
        model, ~60 s of its default LSODA).
    max_wall : float, optional
        Wall-clock budget [s] of the integration (checked between hybrid
        kernel calls, at most 250,000 steps (~0.4 s) apart, and at every step
        of the regularised scheme);
        exceeding it raises :class:`SolverBudgetExceeded` with
        ``budget="max_wall"``.  None (default): bounded by ``max_steps`` only.
    v_floor : float, optional
        None (default): the model's criterion.  On AB the level
        ``G = F(1 - cos θ)`` falling to ``f(0+, V)`` leaves CONSTR without a
        root (the peel front would have to stop): :class:`ModelBreakdown`
        with ``reason="no_root"`` once ``G - f(0+) <= 1e-10 max(|f(0+)|, 1 N)``,
        i.e. v below ``BranchStructure.v_breakdown`` (~1e-67 m/s; the hybrid
        method integrates ln v, so it follows v that far).  A number [m/s]:
        stop earlier, at that velocity, with ``reason="v_floor"`` (a
        threshold of the user's, not of the model).
    progress : bool or callable, optional
        ``True`` prints progress to stderr; a callable receives ``(t, t_end)``
        between chunks of work.
    saveat : SaveAt, optional
        ``save``, ``t_eval`` and ``t_transient`` as one object; those
        keywords must then stay at their defaults (a keyword at its default
        value counts as not given; otherwise ValueError naming both).
    budget : Budget, optional
        ``max_points``, ``max_steps``, ``max_jumps`` and ``max_wall`` as one
        object, on the same rule.

    Returns
    -------
    Trajectory
        Stored points, jumps, counters (``stats``), settings and the final
        state.

    Raises
    ------
    ValueError
        Bad arguments, naming the argument and its valid range.
    ModelBreakdown
        The model breaks down along the orbit (see the exception).
    SolverBudgetExceeded, SolverFailure
        Budget used up / the integrator cannot proceed.
    """
    _params("params", params)
    opts = method_option(method, solver=solver, eps=eps, rtol=rtol, atol=atol, v_floor=v_floor, params=params)
    t_end = duration("t_end", t_end)
    out, lim = output_options(opts.name, t_end, saveat, budget, save=save, t_eval=t_eval, t_transient=t_transient,
                              max_points=max_points, max_steps=max_steps, max_jumps=max_jumps, max_wall=max_wall)
    if progress is True:
        progress = _progress_printer(f"simulate V={params.V} I={params.I}")
    elif progress is False:
        progress = None
    elif progress is not None and not callable(progress):
        raise TypeError(f"progress must be None, a bool or a callable (t, t_end), got {type(progress).__name__}")

    st0 = None
    try:
        with caller_budget(lim.max_wall):  # an expression law compiled for this run is bounded by max_wall too
            st0 = initial_state(params, alpha0=alpha0, omega0=omega0, F0=F0, branch0=branch0)
            if Vp0 is not None:
                if params.loading != "load":
                    raise ValueError(f"Vp0 (the initial pull speed) applies only under loading='load'; got Vp0={Vp0!r} "
                                     "with loading='velocity' (the pull speed is params.V)")
                st0 = dataclasses.replace(st0, Vp=in_range("Vp0", Vp0, 0.0, VP0_MAX))
            if isinstance(opts, Hybrid):
                ct = compile_kernels()
                traj = _run_hybrid(params, t_end, st0, opts, out, lim, progress)
                if ct:
                    traj.stats = SolverStats(**{**traj.stats.__dict__, "compile_time": ct})
                return traj
            from ._regularized import run_regularized

            return run_regularized(params, t_end, st0, opts, out, lim, progress)  # the ε-scheme, the variants' ODEs
    except BuildExpired:
        raise SolverBudgetExceeded(f"more than {lim.max_wall:g} s of wall time (max_wall) compiling the peel-force "
                                   f"law {params.force!r} before the run started; pass a larger max_wall, or None "
                                   "(a law is compiled once per machine, then loaded from the cache)",
                                   budget="max_wall", limit=float(lim.max_wall or 0.0), t=0.0 if st0 is None else st0.t,
                                   state={"t": 0.0} if st0 is None else dataclasses.asdict(st0)) from None


#: Largest initial pull speed ``Vp0`` [m/s] under a load: the model's velocities stay below 1e3 m/s (STATE_RANGES).
VP0_MAX = 1e3

#: On CD, v above this [m/s] is a runaway of the pull force (ModelBreakdown "v_ceiling").
V_CEILING = 1e3


def _param_vector(params: PeelParams, v_floor: float | None = None, bs: BranchStructure | None = None,
                  domain: tuple[float, float] = (0.0, math.inf)) -> np.ndarray:
    """The kernel's parameter vector (``exact._hybrid`` layout); ``v_floor=None``: the model's breakdown
    criterion, ``BranchStructure.v_breakdown``; ``bs``: the law's branch structure (default: the paper's law's,
    :func:`peelapprox.branch_structure`, and only the paper's law is accepted: the inlined driver's vector)."""
    laws = ("paper",) if bs is None else ALL_LAWS  # another law: b, A unused (0.0), the law driver's
    if bs is None:
        bs = branch_structure(params.V)
    p = model_block(params, H.N_P, laws)  # the model block (peelapprox.kernels), then the hybrid driver's fields
    p[H.P_FOLDS] = 1.0 if bs.has_folds else 0.0
    p[H.P_VMAX] = bs.v_max if bs.has_folds else math.inf
    p[H.P_VMIN] = bs.v_min if bs.has_folds else 0.0
    p[H.P_VLCD] = bs.v_land_cd if bs.has_folds else 0.0
    p[H.P_VLAB] = bs.v_land_ab if (bs.has_folds and bs.v_land_ab is not None) else -1.0
    p[H.P_UFLOOR] = math.log(bs.v_breakdown if v_floor is None else max(v_floor, bs.v_breakdown))
    p[H.P_UCEIL] = math.log(min(V_CEILING, domain[1]))
    # the fold fields are floats when has_folds (peelapprox.BranchStructure)
    p[H.P_UEV_AB] = math.log(cast(float, bs.v_max) * (1.0 - H.FOLD_REL)) if bs.has_folds else math.inf
    p[H.P_UEV_CD] = math.log(cast(float, bs.v_min) * (1.0 + H.FOLD_REL)) if bs.has_folds else -math.inf
    return p


_PAUSE_STEPS = 250_000  # steps per kernel call between progress/budget checks (~0.3 s)


def _run_hybrid(params: PeelParams, t_end: float, s0: State, method: Hybrid, saveat: SaveAt, budget: Budget,
                progress: Callable[[float, float], None] | None) -> Trajectory:
    """Driver for ``simulate(method="hybrid")``: the options validated, the budget resolved."""
    rtol, atol, v_floor = method.rtol, method.atol_vector(), method.v_floor
    t_store, max_wall = saveat.t_transient, budget.max_wall
    max_points, max_jumps, max_steps = budget.max_points, budget.max_jumps, int(cast(int, budget.max_steps))
    cl = HL.law_for(params)  # the paper's law (default): the driver with fvV inlined
    law, coef, bs, law_argument = cl.arg, cl.coef, cl.structure, not cl.inlined
    p = _param_vector(params, v_floor, bs, cl.domain)
    run = HL.driver(law_argument)
    st = np.array([s0.t, 0.0, s0.alpha, s0.omega, math.log(s0.v), 0.0, BRANCHES.index(s0.branch)], dtype=float)
    cnt = np.zeros(H.N_C, dtype=np.int64)
    if saveat.ts is not None:
        mode, cap = H.SAVE_TEVAL, saveat.ts.size
        t_eval = saveat.ts.copy()  # writeable, as the compiled kernel is typed for
    else:
        mode = H.SAVE_STEPS if saveat.steps else H.SAVE_NONE
        # two rows of slack: a step may store two (at a jump), and the budget raises only when *more*
        # than max_points rows are needed (the kernel returns OUT_FULL before a step without room for two)
        cap = min(max_points + 2, 1 << 16) if mode == H.SAVE_STEPS else 1
        t_eval = np.zeros(0)
    out = np.empty((cap, H.N_O))
    out_br = np.empty(cap, dtype=np.int8)
    jcap = min(max_jumps + 1, 1 << 14)  # one slot of slack: JUMPS_FULL in the last view means > max_jumps
    jbuf = np.empty((jcap, H.N_J))
    chunks: list[np.ndarray] = []
    bchunks: list[np.ndarray] = []
    jchunks: list[np.ndarray] = []
    n_stored = 0
    if mode == H.SAVE_STEPS and s0.t >= t_store:
        out[0] = (s0.t, s0.alpha, s0.omega, s0.F, s0.v)
        out_br[0] = st[H.S_BR]
        cnt[H.C_NOUT] = 1

    def state_dict():
        a, v = st[H.S_AL], math.exp(st[H.S_U])
        # the kernel keeps the state in the domain (v = e^u > 0)
        F = float(HL.pull_force_law(a, v, p, law, coef) if law_argument else H.pull_force(a, v, p))
        return dict(t=float(st[H.S_T0] + st[H.S_TAU]), alpha=float(a), omega=float(st[H.S_OM]), F=F, v=float(v),
                    branch=BRANCHES[int(st[H.S_BR])])

    wall0 = time.perf_counter()

    def build(final: bool = True) -> Trajectory:
        data = np.concatenate(chunks + [out[: cnt[H.C_NOUT]]]) if chunks else out[: cnt[H.C_NOUT]].copy()
        brs = np.concatenate(bchunks + [out_br[: cnt[H.C_NOUT]]]) if bchunks else out_br[: cnt[H.C_NOUT]].copy()
        jd = np.concatenate(jchunks + [jbuf[: cnt[H.C_NJOUT]]]) if jchunks else jbuf[: cnt[H.C_NJOUT]].copy()
        sd = state_dict()
        stats = SolverStats(
            n_steps=int(cnt[H.C_STEPS]),
            n_rejected=int(cnt[H.C_REJ]),
            n_rhs=int(cnt[H.C_RHS]),
            n_jumps=int(cnt[H.C_JUMPS]),
            wall_time=time.perf_counter() - wall0,
        )
        return Trajectory(
            t=data[:, H.O_T], alpha=data[:, H.O_AL], omega=data[:, H.O_OM], F=data[:, H.O_F], v=data[:, H.O_V],
            branch=brs, jumps=Jumps.from_buffer(jd), stats=stats, params=params, method="hybrid", solver="DOP853",
            rtol=rtol, atol=atol, eps=None, initial_state=s0, final_state=State(**sd), t_end=t_end,
            t_transient=t_store, status=0 if final else 1,
            message="reached t_end" if final else "stopped early",
        )

    def over_budget(name: str, limit: float) -> SolverBudgetExceeded:
        return budget_exceeded(name, limit, t_end, state_dict(), build(False))

    n_jstored = 0
    next_pause = _PAUSE_STEPS  # step count of the next PAUSE, counted over calls (buffer returns interleave)

    def checkpoint() -> None:
        """Between kernel calls: the wall budget and progress (every return, whatever stopped the call)."""
        if max_wall is not None and time.perf_counter() - wall0 > max_wall:
            raise over_budget("max_wall", max_wall)
        if progress:
            progress(float(st[H.S_T0] + st[H.S_TAU]), t_end)

    while True:
        quota = max(1, min(next_pause, max_steps) - int(cnt[H.C_STEPS]))
        # buffer views never reach past the budgets (+ slack), so a full buffer that ends at the budget
        # means the run needs more than the budget
        nv = cap if mode != H.SAVE_STEPS else min(cap, max_points + 2 - n_stored)
        jv = min(jcap, max_jumps + 1 - n_jstored)
        status = run(st, p, law, coef, rtol, atol, t_end, t_store, mode, t_eval, out[:nv], out_br[:nv], jbuf[:jv],
                       cnt, quota)
        if status == S.DONE:
            if n_stored + int(cnt[H.C_NOUT]) > max_points:
                raise over_budget("max_points", max_points)
            if n_jstored + int(cnt[H.C_NJOUT]) > max_jumps:
                raise over_budget("max_jumps", max_jumps)
            if progress:
                progress(t_end, t_end)
            return build()
        if status == S.OUT_FULL:
            if n_stored + int(cnt[H.C_NOUT]) > max_points:
                raise over_budget("max_points", max_points)
            n = int(cnt[H.C_NOUT])
            n_stored += n
            chunks.append(out[:n].copy())
            bchunks.append(out_br[:n].copy())
            cnt[H.C_NOUT] = 0
            checkpoint()
            continue
        if status == S.JUMPS_FULL:
            if n_jstored + int(cnt[H.C_NJOUT]) > max_jumps:
                raise over_budget("max_jumps", max_jumps)
            n_jstored += int(cnt[H.C_NJOUT])
            jchunks.append(jbuf[: cnt[H.C_NJOUT]].copy())
            cnt[H.C_NJOUT] = 0
            checkpoint()
            continue
        if status == S.PAUSE:
            if int(cnt[H.C_STEPS]) >= max_steps:
                raise over_budget("max_steps", max_steps)
            next_pause = int(cnt[H.C_STEPS]) + _PAUSE_STEPS
            checkpoint()
            continue
        sd = state_dict()
        if status == S.NO_ROOT and v_floor is not None and v_floor > bs.v_breakdown:
            status, why = S.V_FLOOR, f"the caller's v_floor; F(1 - cos theta) -> f(0+, V)={bs.f_zero:.6g} N"
        else:
            why = ""
        lo, hi = cl.domain
        status, what = HL.domain_status(status, cl, sd["v"], V_CEILING)
        raise S.status_error(
            status, t=sd["t"], state=sd, partial=build(False),
            prefix=f"hybrid solver at t={sd['t']:.9g} on {sd['branch']}: ",
            f_zero=bs.f_zero, f_min=bs.f_min, level=BREAKDOWN_LEVEL, v=sd["v"], v_ceiling=V_CEILING,
            v_floor=v_floor, why=why, lo=lo, hi=hi, law=repr(params.force), what=what,
        )


def hybrid_field(params: PeelParams, v_floor: float | None = None, *,
                 law_argument: bool | None = None) -> tuple[Callable, Any]:
    """The hybrid solver's compiled field ``rhs(y, p, out)`` and its parameter vector ``p`` for ``params``
    (``v_floor`` as in :func:`simulate`), e.g. to time one field evaluation in a compiled loop.

    ``law_argument=False``: the field with the paper's law fvV inlined and ``p`` the parameter vector (the
    paper's law only: ValueError for another ``params.force``).
    ``law_argument=True``: the field of the driver that takes the law as a function argument (the one
    :func:`simulate` runs for a ``params.force`` other than the paper's; also for the paper's law, which the
    default driver inlines) and ``(p, law, coef)``; the field is called as ``rhs(y, (p, law, coef), out)`` from a
    loop compiled with ``law`` of type :data:`peelapprox.kernels.LAW_TYPE`.
    ``law_argument=None`` (default): the field :func:`simulate` runs for ``params.force`` -- inlined for the
    paper's law, the law as an argument for any other.
    """
    if law_argument is None:
        law_argument = params.force.kind != "paper" if isinstance(params, PeelParams) else False
    if not law_argument:
        return H._rhs, _param_vector(params, v_floor)
    cl = HL.law_for(params)
    return HL._rhs_law, (_param_vector(params, v_floor, cl.structure, cl.domain), cl.fn, cl.coef)

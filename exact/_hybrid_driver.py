"""The hybrid solver's driver: the peel-force law bound to the compiled loop, the parameter vector, and the
Python loop that runs it (buffers, budgets, errors).

The compiled loop, :func:`exact._hybrid._run`, calls its field, pull force and DOP853 pieces through module
globals, bound here twice (:func:`driver`):

* ``driver(False)``: the paper's law fvV **inlined** (the field :func:`exact._hybrid._rhs`, ``p`` carrying
  ``b, A``), the default path;
* ``driver(True)``: the law as an **argument** ``law`` (:data:`peelapprox.kernels.LAW_TYPE`) with its
  coefficients ``coef``, travelling with ``p`` as ``P = (p, law, coef)`` to :func:`_rhs_law`: compiled once
  for :data:`RUN_SIG`, it runs every compiled law without compiling again.

Why two: through the argument the law is an indirect call LLVM cannot inline (+5-10 % per step; ``python -m
comparisons.benchmark.law_cost``).  The kernels that call a law are compiled without numba's reference-counting
runtime (``kernel(nrt=False)``): it would wrap every indirect call in atomic updates (62 instead of 29 ns per
field evaluation).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from typing import TYPE_CHECKING, Any, cast

import numpy as np
from numba import types as _t

from peelapprox import BRANCHES, BREAKDOWN_LEVEL, BranchStructure, PeelParams, branch_structure
from peelapprox.errors import SolverBudgetExceeded, budget_exceeded
from peelapprox.kernels import (
    ALL_LAWS,
    LAW_FP,
    LAW_LNV,
    LAW_TYPE,
    CompiledLaw,
    compile_only,
    kernel,
    make_dop853,
    model_block,
    pack_inlined,
    pack_law,
    rebind,
)
from peelapprox.kernels import status as S

from . import _hybrid as H
from ._initial import law_for
from ._trajectory import Jumps, SolverStats, State, Trajectory

if TYPE_CHECKING:
    from ._method_contract import Method
    from ._options import Budget, SaveAt

__all__ = ["RUN_SIG", "V_RUNAWAY", "load_hybrid", "domain_status", "driver", "field_law", "hybrid_field",
           "law_for", "param_vector", "pull_force_law", "run_hybrid"]

#: On CD, v above this [m/s] is a runaway of the pull force (status ``V_CEILING``, ModelBreakdown "v_ceiling").
V_RUNAWAY = 1e3

_A1 = _t.float64[::1]


@kernel(nrt=False)  # no reference counting around the law call (module docstring)
def _pull_force_P(alpha, v, P):
    """F = f(v) / (1 + c(α))  (CONSTR solved for F), f the law of ``P = (p, law, coef)``: ``law(v, coef, LAW_FP)``."""
    p, law, coef = P
    f, _, _ = law(v, coef, LAW_FP)
    c, _ = H._closure(alpha, p)
    return f / (1.0 + c)


@kernel(signature=_t.float64(_t.float64, _t.float64, _A1, LAW_TYPE, _A1), nrt=False, lazy=True)
def pull_force_law(alpha, v, p, law, coef):
    """:func:`exact._hybrid.pull_force` for the law ``law`` with the coefficients ``coef``."""
    return _pull_force_P(alpha, v, (p, law, coef))


@kernel(nrt=False)  # no reference counting around the law call (module docstring)
def _rhs_law(y, P, out):
    """The field of :func:`exact._hybrid._rhs` for the law of ``P = (p, law, coef)``: ``law(u, coef, LAW_LNV)``
    gives ``(v, f, v f')``."""
    p, law, coef = P
    v, f, g = law(y[3], coef, LAW_LNV)
    H._field(y, p, v, f, g, out)


@kernel(nrt=False)
def _field_law(y, p, law, coef, out):
    """:func:`_rhs_law` with the law and its coefficients as separate arguments (the form Python calls)."""
    _rhs_law(y, (p, law, coef), out)


def field_law() -> Any:
    """``field(y, p, law, coef, out)``: the hybrid field d(τ, α, ω, u)/ds of the law ``law``, compiled for that one
    signature on first use: the saltation tangent's field outside its compiled driver."""
    return compile_only(_field_law, _t.void(_A1, _A1, LAW_TYPE, _A1, _A1))


#: The one signature of both drivers: ``(st, p, law, coef, rtol, atol, t_end, t_store, save_mode, t_eval, out,
#: out_br, jbuf, cnt, max_call_steps) -> status``.
RUN_SIG = _t.int64(
    _A1, _A1, LAW_TYPE, _A1, _t.float64, _A1, _t.float64, _t.float64, _t.int64, _A1, _t.float64[:, ::1], _t.int8[::1],
    _t.float64[:, ::1], _t.int64[::1], _t.int64,
)


def _driver_copy(field: Callable, pull: Callable, pack: Callable, tag: str) -> Callable:
    """:func:`exact._hybrid._run` reading ``field``, ``pull``, ``pack`` and the DOP853 pieces of ``field`` as its
    globals ``_FIELD``, ``_PULL``, ``_PACK``, ``_dop`` (:func:`peelapprox.kernels.rebind`), and the step's pieces
    that call them (``exact._hybrid.BOUND_HELPERS``) bound likewise, as inner kernels named after ``tag``."""
    pieces = dict(_FIELD=field, _PULL=pull, _PACK=pack, _dop=make_dop853(field))
    helpers = {name: kernel(rebind(getattr(H, name), **pieces), inner=True, name=f"{name.lstrip('_')}_{tag}")
               for name in H.BOUND_HELPERS}
    return rebind(H._run, **pieces, **helpers)


_DRIVERS = {
    False: kernel(_driver_copy(H._rhs, H.pull_force, pack_inlined, "inlined"), name="run_inlined"),
    True: kernel(_driver_copy(_rhs_law, _pull_force_P, pack_law, "law"), name="run_law"),
}


def driver(law_argument: bool) -> Any:
    """The compiled hybrid loop (:func:`exact._hybrid._run`), compiled for :data:`RUN_SIG` on first use (loaded
    from numba's cache when it is there): ``law_argument=False`` with fvV inlined (``law``, ``coef`` unused),
    True with the law ``law`` and its coefficients ``coef``."""
    return compile_only(_DRIVERS[bool(law_argument)], RUN_SIG)


def domain_status(status: int, cl: CompiledLaw, v: float, ceiling: float) -> tuple[int, str]:
    """``(status, what)``: a driver's breakdown status re-read as ``LAW_DOMAIN`` where the law's domain, not the
    model, stopped the run -- the floor on AB (NO_ROOT) or a CD→AB landing (NO_LANDING) at a domain starting above
    0, the CD ceiling below ``ceiling`` -- with ``what`` happened (the message's first words)."""
    lo, hi = cl.domain
    bs = cl.structure
    if status == S.NO_ROOT and lo > 0:
        return S.LAW_DOMAIN, f"on AB the level F(1 - cos theta) fell to f = {bs.f_zero:.6g} N at the start of the law"
    if status == S.NO_LANDING and lo > 0:
        return S.LAW_DOMAIN, (f"the CD->AB jump from f_min = {bs.f_min:.6g} N would land below the start of the law "
                              f"(f = {bs.f_zero:.6g} N there)")
    if status == S.V_CEILING and hi < ceiling:
        return S.LAW_DOMAIN, f"v = {v:.6g} m/s rose above the end of the law on CD"
    return status, ""


def param_vector(params: PeelParams, v_floor: float | None = None, bs: BranchStructure | None = None,
                 domain: tuple[float, float] = (0.0, math.inf)) -> np.ndarray:
    """The compiled loop's parameter vector (the layout of :mod:`exact._hybrid`).

    ``v_floor=None``: the model's breakdown criterion, ``BranchStructure.v_breakdown``; ``bs``: the law's branch
    structure (default: the paper's law's, and only the paper's law is accepted: the inlined driver's vector);
    ``domain``: the law's, whose top caps the CD runaway speed :data:`V_RUNAWAY`.
    """
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
    p[H.P_UCEIL] = math.log(min(V_RUNAWAY, domain[1]))
    # the fold fields are floats when has_folds (peelapprox.BranchStructure)
    p[H.P_UEV_AB] = math.log(cast(float, bs.v_max) * (1.0 - H.FOLD_REL)) if bs.has_folds else math.inf
    p[H.P_UEV_CD] = math.log(cast(float, bs.v_min) * (1.0 + H.FOLD_REL)) if bs.has_folds else -math.inf
    return p


def hybrid_field(params: PeelParams, v_floor: float | None = None, *,
                 law_argument: bool | None = None) -> tuple[Callable, Any]:
    """The hybrid solver's compiled field ``rhs(y, p, out)`` and its parameter vector ``p`` for ``params``
    (``v_floor`` as in :func:`exact.simulate`), e.g. to time one field evaluation in a compiled loop.

    ``law_argument=False``: the field with the paper's law fvV inlined (ValueError for another
    ``params.force``).  True: the field that takes the law as an argument, called as ``rhs(y, (p, law, coef),
    out)`` from a loop compiled with ``law`` of type :data:`peelapprox.kernels.LAW_TYPE`, and ``(p, law,
    coef)``.  None (default): the one :func:`exact.simulate` runs, inlined for the paper's law only.
    """
    if law_argument is None:
        law_argument = params.force.kind != "paper" if isinstance(params, PeelParams) else False
    if not law_argument:
        return H._rhs, param_vector(params, v_floor)
    cl = law_for(params)
    return _rhs_law, (param_vector(params, v_floor, cl.structure, cl.domain), cl.fn, cl.coef)


_COMPILE_TIME: dict[str, float | None] = {"hybrid": None}


def load_hybrid() -> float:
    """Compile (or load from numba's on-disk cache) the hybrid kernel (the driver with the paper's law inlined);
    ``exact.compile_kernels`` warms every kernel of a user's first calls.

    Returns the seconds spent in this process the first time; 0 afterwards.
    """
    if _COMPILE_TIME["hybrid"] is not None:
        return 0.0
    t0 = time.perf_counter()
    driver(False)
    H.pull_force(0.0, 1.0, param_vector(PeelParams(V=1.0, I=1e-5)))
    dt = time.perf_counter() - t0
    _COMPILE_TIME["hybrid"] = dt
    return dt


_PAUSE_STEPS = 250_000  # steps per kernel call between progress/budget checks (~0.3 s)
#: The storage budgets checked when the loop returns with a status: all at the end, the full one's otherwise.
_CHECKED = {S.DONE: ("max_points", "max_jumps"), S.OUT_FULL: ("max_points",), S.JUMPS_FULL: ("max_jumps",)}


class _Buffers:
    """The loop's output buffers (points, their branches, jumps) and what was emptied from them.

    Their views never reach past the budgets plus slack, so a full buffer that ends at a budget means the run
    needs more than the budget: points get two rows of slack (a step may store two, at a jump; the kernel returns
    OUT_FULL before a step without room for two), jumps one (JUMPS_FULL in the last view means > max_jumps).
    """

    def __init__(self, saveat: SaveAt, budget: Budget):
        self.max_points, self.max_jumps = budget.max_points, budget.max_jumps
        if saveat.ts is not None:
            self.mode, cap = H.SAVE_TEVAL, saveat.ts.size
            self.t_eval = saveat.ts.copy()  # writeable, as the compiled kernel is typed for
        else:
            self.mode = H.SAVE_STEPS if saveat.steps else H.SAVE_NONE
            cap = min(self.max_points + 2, 1 << 16) if self.mode == H.SAVE_STEPS else 1
            self.t_eval = np.zeros(0)
        self.out = np.empty((cap, H.N_O))
        self.out_br = np.empty(cap, dtype=np.int8)
        self.jbuf = np.empty((min(self.max_jumps + 1, 1 << 14), H.N_J))
        self.chunks: list[np.ndarray] = []
        self.bchunks: list[np.ndarray] = []
        self.jchunks: list[np.ndarray] = []
        self.n_stored = 0
        self.n_jstored = 0

    def views(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The parts of the buffers the next kernel call may fill."""
        cap = self.out.shape[0]
        nv = cap if self.mode != H.SAVE_STEPS else min(cap, self.max_points + 2 - self.n_stored)
        jv = min(self.jbuf.shape[0], self.max_jumps + 1 - self.n_jstored)
        return self.out[:nv], self.out_br[:nv], self.jbuf[:jv]

    def over(self, cnt: np.ndarray, budgets: tuple[str, ...]) -> str | None:
        """The first of ``budgets`` (``"max_points"``, ``"max_jumps"``) that the stored rows exceed, if any."""
        needs = {"max_points": self.n_stored + int(cnt[H.C_NOUT]), "max_jumps": self.n_jstored + int(cnt[H.C_NJOUT])}
        return next((name for name in budgets if needs[name] > getattr(self, name)), None)

    def empty_points(self, cnt: np.ndarray) -> None:
        n = int(cnt[H.C_NOUT])
        self.n_stored += n
        self.chunks.append(self.out[:n].copy())
        self.bchunks.append(self.out_br[:n].copy())
        cnt[H.C_NOUT] = 0

    def empty_jumps(self, cnt: np.ndarray) -> None:
        self.n_jstored += int(cnt[H.C_NJOUT])
        self.jchunks.append(self.jbuf[: cnt[H.C_NJOUT]].copy())
        cnt[H.C_NJOUT] = 0

    def stored(self, cnt: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Every stored point, its branch and every stored jump (new arrays)."""
        n, nj = cnt[H.C_NOUT], cnt[H.C_NJOUT]
        data = np.concatenate(self.chunks + [self.out[:n]]) if self.chunks else self.out[:n].copy()
        brs = np.concatenate(self.bchunks + [self.out_br[:n]]) if self.bchunks else self.out_br[:n].copy()
        jd = np.concatenate(self.jchunks + [self.jbuf[:nj]]) if self.jchunks else self.jbuf[:nj].copy()
        return data, brs, jd


def run_hybrid(params: PeelParams, t_end: float, s0: State, method: Method, saveat: SaveAt, budget: Budget,
               progress: Callable[[float, float], None] | None) -> Trajectory:
    """``simulate(method="hybrid")`` from the consistent state ``s0``, the options validated and the budget
    resolved: the compiled loop called until t_end, emptying its buffers and checking the wall budget between
    calls; a stop of the model or the integrator raises its documented exception with the partial trajectory.
    The first run of a process records the seconds spent compiling in ``stats.compile_time``."""
    ct = load_hybrid()
    traj = _drive(params, t_end, s0, method, saveat, budget, progress)
    if ct:
        traj.stats = SolverStats(**{**traj.stats.__dict__, "compile_time": ct})
    return traj


def _drive(params: PeelParams, t_end: float, s0: State, method: Method, saveat: SaveAt, budget: Budget,
           progress: Callable[[float, float], None] | None) -> Trajectory:
    """:func:`run_hybrid` without the compile bookkeeping: the law bound, the buffers set, the loop called."""
    rtol, atol, v_floor = method.rtol, method.atol_vector(), method.v_floor
    t_store, max_wall, max_steps = saveat.t_transient, budget.max_wall, int(cast(int, budget.max_steps))
    cl = law_for(params)  # the paper's law (default): the driver with fvV inlined
    law, coef, bs, law_argument = cl.arg, cl.coef, cl.structure, not cl.inlined
    p = param_vector(params, v_floor, bs, cl.domain)
    run = driver(law_argument)
    st = np.array([s0.t, 0.0, s0.alpha, s0.omega, math.log(s0.v), 0.0, BRANCHES.index(s0.branch)], dtype=float)
    cnt = np.zeros(H.N_C, dtype=np.int64)
    buf = _Buffers(saveat, budget)
    if buf.mode == H.SAVE_STEPS and s0.t >= t_store:
        buf.out[0] = (s0.t, s0.alpha, s0.omega, s0.F, s0.v)
        buf.out_br[0] = st[H.S_BR]
        cnt[H.C_NOUT] = 1
    wall0 = time.perf_counter()

    def state_dict():
        a, v = st[H.S_AL], math.exp(st[H.S_U])
        # the kernel keeps the state in the domain (v = e^u > 0)
        F = float(pull_force_law(a, v, p, law, coef) if law_argument else H.pull_force(a, v, p))
        return dict(t=float(st[H.S_T0] + st[H.S_TAU]), alpha=float(a), omega=float(st[H.S_OM]), F=F, v=float(v),
                    branch=BRANCHES[int(st[H.S_BR])])

    def build(final: bool = True) -> Trajectory:
        data, brs, jd = buf.stored(cnt)
        stats = SolverStats(n_steps=int(cnt[H.C_STEPS]), n_rejected=int(cnt[H.C_REJ]), n_rhs=int(cnt[H.C_RHS]),
                            n_jumps=int(cnt[H.C_JUMPS]), wall_time=time.perf_counter() - wall0)
        return Trajectory(
            t=data[:, H.O_T], alpha=data[:, H.O_AL], omega=data[:, H.O_OM], F=data[:, H.O_F], v=data[:, H.O_V],
            branch=brs, jumps=Jumps.from_buffer(jd), stats=stats, params=params, method="hybrid", solver="DOP853",
            rtol=rtol, atol=atol, eps=None, initial_state=s0, final_state=State(**state_dict()), t_end=t_end,
            t_transient=t_store, status=0 if final else 1, message="reached t_end" if final else "stopped early",
        )

    def over_budget(name: str, limit: float) -> SolverBudgetExceeded:
        return budget_exceeded(name, limit, t_end, state_dict(), build(False))

    next_pause = _PAUSE_STEPS  # step count of the next PAUSE, counted over calls (buffer returns interleave)
    while True:
        quota = max(1, min(next_pause, max_steps) - int(cnt[H.C_STEPS]))
        out, out_br, jbuf = buf.views()
        status = run(st, p, law, coef, rtol, atol, t_end, t_store, buf.mode, buf.t_eval, out, out_br, jbuf, cnt,
                     quota)
        over = buf.over(cnt, _CHECKED.get(status, ()))
        if over is not None:
            raise over_budget(over, getattr(buf, over))
        if status == S.DONE:
            if progress:
                progress(t_end, t_end)
            return build()
        if status == S.OUT_FULL:
            buf.empty_points(cnt)
        elif status == S.JUMPS_FULL:
            buf.empty_jumps(cnt)
        elif status == S.PAUSE:
            if int(cnt[H.C_STEPS]) >= max_steps:
                raise over_budget("max_steps", max_steps)
            next_pause = int(cnt[H.C_STEPS]) + _PAUSE_STEPS
        else:
            raise _stop_error(status, params, cl, v_floor, state_dict(), build(False))
        # between kernel calls: the wall budget and progress (every return, whatever stopped the call)
        if max_wall is not None and time.perf_counter() - wall0 > max_wall:
            raise over_budget("max_wall", max_wall)
        if progress:
            progress(float(st[H.S_T0] + st[H.S_TAU]), t_end)


def _stop_error(status: int, params: PeelParams, cl: CompiledLaw, v_floor: float | None, sd: dict,
                partial: Trajectory) -> Exception:
    """The documented exception of a loop that stopped with the breakdown or failure ``status`` in state ``sd``."""
    bs = cl.structure
    if status == S.NO_ROOT and v_floor is not None and v_floor > bs.v_breakdown:
        status, why = S.V_FLOOR, f"the caller's v_floor; F(1 - cos theta) -> f(0+, V)={bs.f_zero:.6g} N"
    else:
        why = ""
    lo, hi = cl.domain
    status, what = domain_status(status, cl, sd["v"], V_RUNAWAY)
    return S.status_error(
        status, t=sd["t"], state=sd, partial=partial, prefix=f"hybrid solver at t={sd['t']:.9g} on {sd['branch']}: ",
        f_zero=bs.f_zero, f_min=bs.f_min, level=BREAKDOWN_LEVEL, v=sd["v"], v_ceiling=V_RUNAWAY,
        v_floor=v_floor, why=why, lo=lo, hi=hi, law=repr(params.force), what=what,
    )

"""Work-precision benchmark of the exact solvers, the ε study and the speed targets, timed in one run.

``peelapprox benchmark [--quick] [--out DIR]`` (or :func:`run_benchmark`) measures, on this machine and
in one process:

1. **Work precision** on three scenes (:data:`BENCH_SCENES`: V=1, I=1e-5; V=1, I=1e-2; V=4, I=1e-2) over
   a fixed horizon: CPU (wall) time against the error of the jump sequence, for

   * the hybrid ε → 0 solver (``exact.simulate``, ``method="hybrid"``) at rtol 1e-4 … 1e-12;
   * the paper's ε-regularised scheme on scipy's Radau, BDF and LSODA at ε = 1e-7 (the paper's) and 1e-10;
   * the external compiled peers on the same regularised system (SUNDIALS IDA and CVODE through
     scikit-sundae, Rust diffsol through pydiffsol; :mod:`comparisons._peers`), when the optional
     ``peelapprox[bench]`` extra is installed.

   **Error metric** (:func:`jump_errors`): over the first N jumps of the reference (all the jumps in the
   horizon), ``max_j |t_j - t_j^ref| / T̄`` with T̄ the reference's mean interval between jumps, and
   ``max_j |F_j - F_j^ref| / F_j^ref``; the reported error is the larger of the two.  A run with a different
   number of jumps in the horizon has error ``inf`` (it is on another orbit) and is shown as such.  The
   regularised runs record a jump where v crosses the inflection velocity of f, the hybrid one at the fold:
   their difference is the ε-bias of the paper's scheme (fold-passage delay + transit), which is part of
   their error by design — it is what a user of that scheme gets.
   **Reference**: the hybrid solver at rtol 1e-13, cross-checked by a second, independent method
   (:func:`branchwise_reference`: scipy's DOP853 on (α, ω, F) with v from the branch inverse of CONSTR and
   the folds as events — no desingularisation, no shared integrator code); their agreement is reported.
   **Timing** as the SciML work-precision benchmarks: one untimed warm-up per configuration, then the
   minimum over repeats.  The multi-second scipy Radau/BDF runs are warmed up on the horizon up to the
   reference's second jump (which exercises every code path) and timed once.

2. **ε study** (:func:`eps_study`): the regularised scheme's jump-time bias vs ε from 1e-4 to 1e-12 (Radau,
   rtol 1e-10), a least-squares power law ``bias = C ε^p`` (the fold-passage theory gives p = 2/3), and
   what happens at ε = 1e-15 in double precision.

3. **Targets** (:func:`speed_targets`): µs per accepted step on every scene, V=4, I=1e-2 for 200 s, the
   speed-up over Radau at matched error, and where the time goes (field evaluations vs. the rest, per jump).

Outputs: ``work_precision.csv`` / ``.json``, ``eps_study.csv``, ``work_precision.png``, ``eps_study.png`` and
``benchmark.md`` (pasted into ``docs/performance.md``).
"""

from __future__ import annotations

import contextlib
import functools
import math
import os
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, field
from typing import Any, cast

import numpy as np
from scipy.integrate import solve_ivp

from exact import ModelBreakdown, SolverBudgetExceeded, SolverFailure, compile_kernels, initial_state, simulate
from peelapprox import PeelParams, branch_structure
from peelapprox import _generated as _g
from peelapprox._peelforce import _invert, peel_force_coefficients

__all__ = [
    "BenchScene",
    "BENCH_SCENES",
    "WPRow",
    "EpsRow",
    "BenchmarkReport",
    "branchwise_reference",
    "jump_errors",
    "work_precision",
    "matched_ratios",
    "ratio_summary",
    "eps_study",
    "small_eps_check",
    "fit_power_law",
    "speed_targets",
    "run_benchmark",
    "markdown",
    "plot_work_precision",
    "plot_eps_study",
]


@dataclass(frozen=True)
class BenchScene:
    """One work-precision scene: parameters, start and horizon (all jumps in the horizon are compared)."""

    name: str
    V: float
    I: float
    horizon: float
    alpha0: float = 0.0

    @property
    def params(self) -> PeelParams:
        return PeelParams(V=self.V, I=self.I)


#: The three scenes of issue 5 (the paper's Cases I-III).  Horizons hold 8, 35 and 47 jumps: every part of
#: a solver is exercised (folds, both branches, landings, the rapid-jump cascades of Cases II-III), while
#: scipy's Radau at ε = 1e-10 and rtol 1e-9 still finishes each in ~10 s.
BENCH_SCENES = (
    BenchScene("V1-I1e-5", 1.0, 1e-5, 0.3),
    BenchScene("V1-I1e-2", 1.0, 1e-2, 0.5),
    BenchScene("V4-I1e-2", 4.0, 1e-2, 0.05, alpha0=0.3),
)


# ---------------------------------------------------------------------------------------------- reference
def branchwise_reference(params: PeelParams, t_end: float, *, alpha0: float = 0.0, rtol: float = 1e-13):
    """The jump sequence by a second, independent method (the reference's cross-check).

    Formulation: on a stable branch the DAE (FLOW1, FLOW2, flow3, CONSTR) is an ODE in ``(α, ω, F)`` with
    ``v = v_branch(F (1 + c(α)))``, the branch inverse of fvV (solved by brentq at every field evaluation;
    the level is clipped at the fold value so that trial stages past the fold stay defined).  scipy's DOP853
    integrates it in t; the fold is the terminal event ``G = f_max`` (AB) or ``G = f_min`` (CD), located by
    scipy's event finder on the dense output, and the orbit restarts on the other branch with (α, ω, F)
    continuous.  Nothing is shared with the hybrid solver except the generated model functions: no
    desingularisation, no compiled kernel, no v state.  Near a fold ``v(G)`` has a square-root singularity,
    so this is slow and loses a few digits; it is a check, not a solver.

    Parameters
    ----------
    params : PeelParams
    t_end : float
        Horizon [s].
    alpha0 : float
        Initial peel angle (the rest of the initial state as :func:`exact.initial_state`).
    rtol : float
        scipy's rtol (atol = rtol times the state scale).

    Returns
    -------
    (t, F) : tuple of ndarray
        Jump times and F at the jumps.
    """
    s0 = initial_state(params, alpha0=alpha0)
    bs = branch_structure(params.V)
    b, A = peel_force_coefficients(params.V)
    V, I, k, R, L = params.V, params.I, params.k, params.R, params.l
    if params.geometry != "paper":
        raise ValueError("branchwise_reference supports geometry='paper' only")

    def v_of(y, branch):
        c, _ = _g.closure_paper(y[0], R, L)
        G = y[2] * (1.0 + c)
        if branch == "AB":
            return _invert(min(G, bs.f_max), bs, "AB", b, A), c
        return _invert(max(G, bs.f_min), bs, "CD", b, A), c

    def make(branch):
        def rhs(t, y):
            v, c = v_of(y, branch)
            return list(_g.slow_rates(y[0], y[1], y[2], v, c, V, I, k, R))

        level = bs.f_max if branch == "AB" else bs.f_min

        def fold(t, y):
            c, _ = _g.closure_paper(y[0], R, L)
            return y[2] * (1.0 + c) - level

        fold.terminal = True
        fold.direction = 1.0 if branch == "AB" else -1.0
        return rhs, fold

    t, y, br = s0.t, np.array([s0.alpha, s0.omega, s0.F]), s0.branch
    # the benchmark scenes are stick-slip orbits: the folds exist and f_max is a float (BranchStructure)
    scale = np.array([1.0, params.V / params.R, float(cast(float, bs.f_max))])
    jt, jF = [], []
    while t < t_end:
        rhs, fold = make(br)
        sol = solve_ivp(rhs, (t, t_end), y, method="DOP853", rtol=rtol, atol=rtol * scale, events=fold)
        if sol.status < 0:
            raise SolverFailure(f"branchwise reference failed at t={sol.t[-1]}: {sol.message}", t=float(sol.t[-1]),
                                state=dict(alpha=sol.y[0, -1], omega=sol.y[1, -1], F=sol.y[2, -1]))
        if sol.status == 1:
            t, y = float(sol.t_events[0][0]), sol.y_events[0][0]
            jt.append(t)
            jF.append(y[2])
            br = "CD" if br == "AB" else "AB"
        else:
            break
    return np.array(jt), np.array(jF)


def jump_errors(t: np.ndarray, F: np.ndarray, t_ref: np.ndarray, F_ref: np.ndarray) -> tuple[float, float]:
    """The benchmark's error metric (module docstring): ``(max |Δt_j| / T̄_ref, max |ΔF_j| / F_j^ref)``
    over the reference's jumps; ``(inf, inf)`` if the run has a different number of jumps."""
    if len(t_ref) < 2:
        raise ValueError(f"the reference needs at least 2 jumps in the horizon, got {len(t_ref)}")
    if len(t) != len(t_ref):
        return math.inf, math.inf
    T = (t_ref[-1] - t_ref[0]) / (len(t_ref) - 1)
    return float(np.max(np.abs(t - t_ref)) / T), float(np.max(np.abs(F - F_ref) / np.abs(F_ref)))


# ---------------------------------------------------------------------------------------------- methods
@dataclass
class WPRow:
    """One work-precision point.  ``error = max(err_t, err_F)``; ``time`` is the minimum wall time over the
    timed repeats after one untimed warm-up; ``status`` is ``ok`` or the failure's message."""

    scene: str
    method: str
    solver: str
    eps: float
    rtol: float
    err_t: float
    err_F: float
    error: float
    time: float
    steps: int
    n_rhs: int
    jumps: int
    status: str = "ok"


def _timed(fn: Callable, repeats: int, warm: Callable | None = None):
    (warm or fn)()  # warm-up, untimed (``warm``: a shorter run, for the multi-second scipy stiff runs)
    best, out = math.inf, None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def _row(scene, method, solver, eps, rtol, ref, t, F, wall, steps, n_rhs, status="ok"):
    et, eF = jump_errors(t, F, *ref) if status == "ok" else (math.nan, math.nan)
    return WPRow(scene.name, method, solver, eps, rtol, et, eF, max(et, eF), wall, int(steps), int(n_rhs), len(t),
                 status)


def _simulate_row(scene, ref, repeats, method, solver, eps, rtol):
    kw = dict(alpha0=scene.alpha0, rtol=rtol, save="jumps")
    warm = None
    if method == "regularized":
        kw.update(method="regularized", solver=solver, eps=eps)
        if solver != "LSODA":  # its first jumps exercise every code path; the timed run is seconds long
            warm = lambda: simulate(scene.params, ref[0][1], **kw)  # noqa: E731
    try:
        wall, tr = _timed(lambda: simulate(scene.params, scene.horizon, **kw), repeats, warm)
    except (SolverFailure, ModelBreakdown, SolverBudgetExceeded) as exc:
        msg = str(exc).split(":")[0] if len(str(exc)) > 120 else str(exc)
        return _row(scene, method, solver, eps, rtol, ref, np.array([]), np.array([]), math.nan, 0, 0,
                    status=f"failed at t={getattr(exc, 't', math.nan):.4g} s: {msg[:100]}")
    return _row(scene, method, solver, eps, rtol, ref, tr.jumps.t, tr.jumps.F, wall, tr.stats.n_steps,
                tr.stats.n_rhs, )


@contextlib.contextmanager
def _c_stdout_to_stderr():
    """SUNDIALS prints its failure messages on the C-level stdout; route them to stderr so that the
    benchmark's stdout stays a clean table (``--format json`` must parse)."""
    sys.stdout.flush()
    saved = os.dup(1)
    try:
        os.dup2(2, 1)
        yield
    finally:
        sys.stdout.flush()
        os.dup2(saved, 1)
        os.close(saved)


def _peer_row(scene, ref, repeats, peer, eps, rtol):
    from ._peers import run_peer

    res = None
    best = math.inf
    for i in range(repeats + 1):  # the first (warm-up) call is untimed
        with _c_stdout_to_stderr():
            res = run_peer(peer, scene.params, scene.horizon, eps=eps, rtol=rtol, alpha0=scene.alpha0)
        if res.status != "ok":
            break
        if i:
            best = min(best, res.wall_time)
    if res.status != "ok":
        return _row(scene, "peer", peer, eps, rtol, ref, np.array([]), np.array([]), math.nan, 0, 0,
                    status=res.status[:120])
    return _row(scene, "peer", peer, eps, rtol, ref, res.jump_t, res.jump_F, best, res.n_steps, res.n_rhs)


def work_precision(
    scene: BenchScene,
    *,
    hybrid_rtols: Sequence[float] = (1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12),
    scipy_solvers: Sequence[str] = ("Radau", "BDF", "LSODA"),
    peers: Sequence[str] = (),
    eps_values: Sequence[float] = (1e-7, 1e-10),
    reg_rtols: Sequence[float] = (1e-5, 1e-7, 1e-9),
    repeats: int = 5,
    slow_repeats: int = 1,
    progress: Callable[[str], None] | None = None,
) -> tuple[list[WPRow], dict]:
    """Work-precision rows for one scene (module docstring for the methodology).

    Returns
    -------
    rows : list of WPRow
    reference : dict
        ``t``, ``F`` (the rtol-1e-13 hybrid jump sequence), ``check_t``/``check_F`` (its agreement with
        :func:`branchwise_reference`, in the error metric) and ``n_jumps``.
    """
    say = progress or (lambda msg: None)
    say(f"{scene.name}: reference (hybrid rtol 1e-13) and its branch-wise cross-check")
    ref_tr = simulate(scene.params, scene.horizon, alpha0=scene.alpha0, rtol=1e-13, save="jumps")
    ref = (ref_tr.jumps.t, ref_tr.jumps.F)
    bt, bF = branchwise_reference(scene.params, scene.horizon, alpha0=scene.alpha0)
    ct, cF = jump_errors(bt, bF, *ref)
    reference = dict(scene=scene.name, n_jumps=len(ref[0]), check_t=ct, check_F=cF, t=ref[0], F=ref[1],
                     horizon=scene.horizon)
    rows: list[WPRow] = []
    for rt in hybrid_rtols:
        say(f"{scene.name}: hybrid rtol {rt:.0e}")
        rows.append(_simulate_row(scene, ref, repeats, "hybrid", "DOP853 (compiled)", 0.0, rt))
    for eps in eps_values:
        for solver in scipy_solvers:
            for rt in reg_rtols:
                say(f"{scene.name}: regularized scipy {solver} eps {eps:.0e} rtol {rt:.0e}")
                rep = repeats if solver == "LSODA" else slow_repeats
                rows.append(_simulate_row(scene, ref, rep, "regularized", solver, eps, rt))
        for peer in peers:
            for rt in reg_rtols:
                say(f"{scene.name}: regularized {peer} eps {eps:.0e} rtol {rt:.0e}")
                rows.append(_peer_row(scene, ref, repeats, peer, eps, rt))
    return rows, reference


def matched_ratios(rows: Sequence[WPRow]) -> list[dict]:
    """For each non-hybrid run of a scene with a finite error: the fastest hybrid run of that scene whose
    error is at most the run's error, and the time ratio (their time / hybrid time)."""
    out = []
    for r in rows:
        if r.method == "hybrid" or not math.isfinite(r.error) or not math.isfinite(r.time):
            continue
        ok = [h for h in rows if h.scene == r.scene and h.method == "hybrid" and h.error <= r.error]
        if ok:
            h = min(ok, key=lambda x: x.time)
            out.append(dict(scene=r.scene, method=r.method, solver=r.solver, eps=r.eps, rtol=r.rtol, error=r.error,
                            time=r.time, hybrid_rtol=h.rtol, hybrid_error=h.error, hybrid_time=h.time,
                            ratio=r.time / h.time))
    return out


def ratio_summary(ratios: Sequence[dict]) -> dict:
    """``{solver: {scene: smallest ratio}}`` over :func:`matched_ratios` (each peer's best showing)."""
    out: dict = {}
    for m in ratios:
        per = out.setdefault(m["solver"], {})
        per[m["scene"]] = min(per.get(m["scene"], math.inf), m["ratio"])
    return out


# ---------------------------------------------------------------------------------------------- ε study
@dataclass
class EpsRow:
    """The regularised scheme's fold-passage delays at one ε: ``delay_ab`` = t_reg − t_hybrid at the first
    AB→CD jump, ``delay_cd`` at the first CD→AB jump [s] (the regularised jump is the inflection crossing,
    so this is the delay past the fold plus the transit to the inflection); ``err_F`` = max |ΔF|/F there."""

    eps: float
    solver: str
    rtol: float
    delay_ab: float
    delay_cd: float
    err_F: float
    time: float
    steps: int
    status: str = "ok"


@functools.lru_cache(maxsize=4)
def _eps_reference(scene: BenchScene):
    """The ε → 0 jumps (hybrid, rtol 1e-13) of a scene and the ε studies' horizon (halfway between the
    second and third jump): one AB-fold and one CD-fold passage, in that order."""
    full = simulate(scene.params, scene.horizon, alpha0=scene.alpha0, rtol=1e-13, save="jumps").jumps
    if len(full) < 3:
        raise ValueError(f"the ε study needs a scene with at least 3 jumps in its horizon, {scene.name} has "
                         f"{len(full)}")
    if full.from_branch[0] != 0:
        raise ValueError(f"the ε study needs the scene's first jump to be AB→CD ({scene.name}'s is CD→AB)")
    return full, 0.5 * (full.t[1] + full.t[2])


def eps_study(
    scene: BenchScene,
    eps_values: Sequence[float] = (1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12, 1e-15),
    *,
    solver: str = "Radau",
    rtol: float = 1e-10,
    max_steps: int = 60_000,
    progress: Callable[[str], None] | None = None,
) -> list[EpsRow]:
    """Fold-passage delay of the regularised scheme vs ε, against the ε → 0 (hybrid, rtol 1e-13) jumps.

    The horizon ends halfway between the reference's second and third jump, so one passage of each fold
    is measured from the same initial state (over longer horizons the delays accumulate and, at V=1,
    I=1e-5, the orbit eventually changes).  Every ε is run once; a failure (e.g. at ε = 1e-15) or a run
    over ``max_steps`` (Radau at ε <= 1e-12 grinds at the CD fold: 70-90 s at 1e-12, 540 s at 1e-13 before
    failing; ε = 1e-11 needs 35 000 steps) is a row with its status, not an exception.
    """
    say = progress or (lambda msg: None)
    full, horizon = _eps_reference(scene)
    ref = full[0], full[1]
    rows = []
    for eps in eps_values:
        say(f"eps study {scene.name}: {solver} eps {eps:.0e}")
        t0 = time.perf_counter()
        try:
            tr = simulate(scene.params, horizon, alpha0=scene.alpha0, method="regularized", solver=solver,
                          eps=eps, rtol=rtol, save="jumps", max_steps=max_steps)
        except (SolverFailure, ModelBreakdown, SolverBudgetExceeded) as exc:
            rows.append(EpsRow(eps, solver, rtol, math.nan, math.nan, math.nan, time.perf_counter() - t0, 0,
                               status=f"{type(exc).__name__} at t={getattr(exc, 't', math.nan):.4g} s"))
            continue
        wall = time.perf_counter() - t0
        if len(tr.jumps) != 2:
            rows.append(EpsRow(eps, solver, rtol, math.nan, math.nan, math.nan, wall, tr.stats.n_steps,
                               status=f"{len(tr.jumps)} jumps instead of 2 (another orbit)"))
            continue
        rows.append(EpsRow(eps, solver, rtol, tr.jumps.t[0] - ref[0].t, tr.jumps.t[1] - ref[1].t,
                           max(abs(tr.jumps.F[i] - ref[i].F) / ref[i].F for i in (0, 1)), wall, tr.stats.n_steps))
    return rows


def small_eps_check(
    scene: BenchScene,
    eps_values: Sequence[float] = (1e-12, 1e-15),
    *,
    rtol: float = 1e-8,
    peers: Sequence[str] = (),
    progress: Callable[[str], None] | None = None,
) -> list[EpsRow]:
    """Which solvers of the regularised system get through both folds at tiny ε in double precision (the
    paper: results do not depend on ε for 1e-7 … 1e-15).  The horizon and delays are as in :func:`eps_study`;
    scipy Radau in the ODE form ``v̇ = φ_v/ε`` and every installed peer (IDA integrates the DAE residual
    ``M Ẋ − φ``, as MATLAB's ode15s does with a mass matrix)."""
    from ._peers import run_peer

    say = progress or (lambda msg: None)
    full, horizon = _eps_reference(scene)
    rows = []
    for eps in eps_values:
        say(f"small eps {eps:.0e}: Radau")
        rows += eps_study(scene, (eps,), rtol=rtol, max_steps=50_000)
        for peer in peers:
            say(f"small eps {eps:.0e}: {peer}")
            with _c_stdout_to_stderr():
                r = run_peer(peer, scene.params, horizon, eps=eps, rtol=rtol, alpha0=scene.alpha0)
            if r.status != "ok" or len(r.jump_t) != 2:
                status = r.status if r.status != "ok" else f"{len(r.jump_t)} jumps instead of 2"
                rows.append(EpsRow(eps, peer, rtol, math.nan, math.nan, math.nan, r.wall_time, r.n_steps,
                                   status=status[:100]))
                continue
            rows.append(EpsRow(eps, peer, rtol, r.jump_t[0] - full.t[0], r.jump_t[1] - full.t[1],
                               max(abs(r.jump_F[i] - full.F[i]) / full.F[i] for i in (0, 1)), r.wall_time,
                               r.n_steps))
    return rows


def fit_power_law(eps: np.ndarray, bias: np.ndarray) -> tuple[float, float, float]:
    """Least-squares fit of ``log bias = log C + p log ε``; returns ``(C, p, max relative residual)``."""
    eps, bias = np.asarray(eps, float), np.asarray(bias, float)
    ok = np.isfinite(bias) & (bias > 0)
    if ok.sum() < 3:
        raise ValueError(f"fit_power_law needs at least 3 finite positive biases, got {int(ok.sum())}")
    p, logC = np.polyfit(np.log(eps[ok]), np.log(bias[ok]), 1)
    resid = np.exp(np.log(bias[ok]) - (logC + p * np.log(eps[ok]))) - 1.0
    return float(np.exp(logC)), float(p), float(np.max(np.abs(resid)))


# ---------------------------------------------------------------------------------------------- targets
def _rhs_cost_ns(n: int = 200_000) -> float:
    """Wall time of one hybrid field evaluation [ns], measured in a compiled loop."""
    from numba import njit

    from exact import _hybrid as H
    from exact._simulate import _param_vector

    @njit
    def loop(y, p, out, n):
        acc = 0.0
        for i in range(n):
            y[3] = -1.2 + 1e-9 * i  # u = ln v, v ~ 0.3 m/s
            H._rhs(y, p, out)
            acc += out[3]
        return acc

    p = _param_vector(PeelParams(V=1.0, I=1e-5), 1e-9)
    y, out = np.array([0.0, 0.01, 10.0, -1.2]), np.empty(4)
    loop(y, p, out, 10)
    best = math.inf
    for _ in range(5):
        t0 = time.perf_counter()
        loop(y, p, out, n)
        best = min(best, time.perf_counter() - t0)
    return 1e9 * best / n


def speed_targets(*, repeats: int = 5, long_run: float = 200.0,
                  progress: Callable[[str], None] | None = None) -> list[dict]:
    """The exact-model issue's speed targets, measured: per-step cost on each scene (rtol 1e-8, 1 s, or the
    long run), the long V=4 run, and the share of the time spent in field evaluations."""
    say = progress or (lambda msg: None)
    rhs_ns = _rhs_cost_ns()
    out = []
    for sc, t_end in ((BENCH_SCENES[0], 1.0), (BENCH_SCENES[1], 5.0), (BENCH_SCENES[2], long_run)):
        say(f"targets: {sc.name}, {t_end:g} s at rtol 1e-8")
        rep = 1 if t_end > 20 else repeats
        wall, tr = _timed(lambda: simulate(sc.params, t_end, alpha0=sc.alpha0, rtol=1e-8, save="jumps"), rep)
        s = tr.stats
        out.append(dict(scene=sc.name, t_end=t_end, wall=wall, steps=s.n_steps, rejected=s.n_rejected, rhs=s.n_rhs,
                        jumps=s.n_jumps, us_per_step=1e6 * wall / s.n_steps, rhs_per_step=s.n_rhs / s.n_steps,
                        rhs_ns=rhs_ns, rhs_share=s.n_rhs * rhs_ns * 1e-9 / wall,
                        steps_per_jump=s.n_steps / max(s.n_jumps, 1)))
    return out


def compile_costs() -> tuple[float, float]:
    """Cold compilation (empty numba cache) and cached load of the hybrid kernels, each in a fresh process [s]."""
    import subprocess
    import tempfile

    code = "import time; t=time.perf_counter(); import exact; exact.compile_kernels(); print(time.perf_counter()-t)"
    with tempfile.TemporaryDirectory() as d:
        env = dict(os.environ, NUMBA_CACHE_DIR=d)
        cold = float(subprocess.check_output([sys.executable, "-c", code], env=env).decode().split()[-1])
        warm = float(subprocess.check_output([sys.executable, "-c", code], env=env).decode().split()[-1])
    return cold, warm


# ---------------------------------------------------------------------------------------------- report
@dataclass
class BenchmarkReport:
    """Everything one ``peelapprox benchmark`` run measured."""

    rows: list[WPRow]
    references: list[dict]
    ratios: list[dict]
    eps_rows: list[EpsRow]
    eps_fit: dict
    small_eps: list[EpsRow]
    targets: list[dict]
    peers: tuple
    quick: bool
    wall_time: float
    machine: str = field(default="")
    compile: tuple = (math.nan, math.nan)


def run_benchmark(*, quick: bool = False, peers: Sequence[str] | None = None,
                  progress: Callable[[str], None] | None = None) -> BenchmarkReport:
    """Run the whole benchmark (module docstring).  ``quick`` thins the tolerance grids, uses 3 repeats,
    only ε = 1e-7 for the scipy sweep and a 20 s long run; it is meant to finish in well under 5 minutes.
    ``peers=None`` uses every installed peer (:func:`comparisons._peers.available_peers`)."""
    import platform

    t_start = time.perf_counter()
    compile_kernels()
    if peers is None:
        try:
            from ._peers import available_peers

            peers = available_peers()
        except ImportError:
            peers = ()
    peers = tuple(peers)
    kw: dict[str, Any]
    if quick:
        kw = dict(hybrid_rtols=(1e-4, 1e-6, 1e-8, 1e-10, 1e-12), eps_values=(1e-7,), reg_rtols=(1e-5, 1e-8),
                  repeats=3)
    else:
        kw = dict()
    rows, refs = [], []
    for sc in BENCH_SCENES:
        r, ref = work_precision(sc, peers=peers, progress=progress, **kw)
        rows += r
        refs.append(ref)
    eps_values = (1e-4, 1e-6, 1e-8, 1e-10, 1e-15) if quick else \
        (1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12, 1e-15)
    eps_rows = eps_study(BENCH_SCENES[0], eps_values, max_steps=60_000, progress=progress)
    small_eps = small_eps_check(BENCH_SCENES[0], peers=peers, progress=progress)
    eps_fit = {}
    for key in ("delay_ab", "delay_cd"):
        ok = [e for e in eps_rows if e.status == "ok" and 1e-12 <= e.eps <= 1e-5]
        try:
            eps_fit[key] = fit_power_law(np.array([e.eps for e in ok]), np.array([getattr(e, key) for e in ok]))
        except ValueError:
            pass
    targets = speed_targets(repeats=3 if quick else 5, long_run=20.0 if quick else 200.0, progress=progress)
    if progress:
        progress("compile costs (fresh processes, cold and cached)")
    compile_ = compile_costs()
    machine = (f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
               f"Python {platform.python_version()}")
    return BenchmarkReport(rows, refs, matched_ratios(rows), eps_rows, eps_fit, small_eps, targets, peers, quick,
                           time.perf_counter() - t_start, machine, compile_)


def _g3(x):
    return "–" if x is None or (isinstance(x, float) and math.isnan(x)) else ("inf" if x == math.inf else f"{x:.3g}")


def markdown(rep: BenchmarkReport) -> str:
    """The report as markdown (the tables of docs/performance.md)."""
    L = [f"Measured in one run ({'--quick' if rep.quick else 'full'}), {rep.wall_time:.0f} s in all, on {rep.machine}.",
         f"Peers installed: {', '.join(rep.peers) or 'none'}.", ""]
    L += ["### References", "",
          "| scene | horizon [s] | jumps | branch-wise check: Δt/T̄ | ΔF/F |", "|---|---|---|---|---|"]
    for ref in rep.references:
        L.append(f"| {ref['scene']} | {ref['horizon']:g} | {ref['n_jumps']} | {_g3(ref['check_t'])} | "
                 f"{_g3(ref['check_F'])} |")
    L += ["", "### Work precision", "",
          "| scene | method | solver | ε | rtol | error (max of the two) | Δt/T̄ | ΔF/F | time [s] | steps | RHS "
          "| status |",
          "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rep.rows:
        eps = "0" if r.method == "hybrid" else f"{r.eps:.0e}"
        L.append(f"| {r.scene} | {r.method} | {r.solver} | {eps} | {r.rtol:.0e} | {_g3(r.error)} | {_g3(r.err_t)} | "
                 f"{_g3(r.err_F)} | {_g3(r.time)} | {r.steps} | {r.n_rhs} | {r.status} |")
    L += ["", "### Speed-up at matched error: summary", "",
          "The smallest ratio over each solver's runs (its best showing) per scene; details below.", "",
          "| solver | " + " | ".join(s.name for s in BENCH_SCENES) + " |",
          "|---|" + "---|" * len(BENCH_SCENES)]
    for solver, per in ratio_summary(rep.ratios).items():
        L.append(f"| {solver} | " + " | ".join(f"{per[s.name]:.0f}×" if s.name in per else "–"
                                                for s in BENCH_SCENES) + " |")
    L += ["", "### Speed-up at matched error", "",
          "Each regularised run against the fastest hybrid run with an error at most as large.", "",
          "| scene | run | its error | its time [s] | hybrid rtol | hybrid error | hybrid time [s] | ratio |",
          "|---|---|---|---|---|---|---|---|"]
    for m in rep.ratios:
        L.append(f"| {m['scene']} | {m['solver']} ε={m['eps']:.0e} rtol {m['rtol']:.0e} | {_g3(m['error'])} | "
                 f"{_g3(m['time'])} | {m['hybrid_rtol']:.0e} | {_g3(m['hybrid_error'])} | {_g3(m['hybrid_time'])} | "
                 f"{m['ratio']:.0f}× |")
    L += ["", "### ε study (V=1, I=1e-5: the first passage of each fold; Radau rtol 1e-10)", "",
          "| ε | delay at the AB fold [s] | delay at the CD fold [s] | max ΔF/F | time [s] | steps | status |",
          "|---|---|---|---|---|---|---|"]
    for e in rep.eps_rows:
        L.append(f"| {e.eps:.0e} | {_g3(e.delay_ab)} | {_g3(e.delay_cd)} | {_g3(e.err_F)} | {_g3(e.time)} | {e.steps} |"
                 f" {e.status} |")
    for key, (C, p, res) in rep.eps_fit.items():
        L += ["", f"Fit of the {key.replace('delay_', '').upper()} delay over ε ∈ [1e-12, 1e-5]: "
                  f"{C:.3g} · ε^{p:.4f} s (max relative residual {res:.1e})."]
    L += ["", "### Tiny ε in double precision (same horizon, rtol 1e-8)", "",
          "| ε | solver | delay at the AB fold [s] | delay at the CD fold [s] | time [s] | status |",
          "|---|---|---|---|---|---|"]
    for e in rep.small_eps:
        L.append(f"| {e.eps:.0e} | {e.solver} | {_g3(e.delay_ab)} | {_g3(e.delay_cd)} | {_g3(e.time)} | {e.status} |")
    L += ["", "### Speed targets", "",
          "| scene | simulated [s] | wall [s] | steps | jumps | µs/step | RHS/step | ns/RHS | RHS share of time "
          "| steps/jump |",
          "|---|---|---|---|---|---|---|---|---|---|"]
    for t in rep.targets:
        L.append(f"| {t['scene']} | {t['t_end']:g} | {t['wall']:.3g} | {t['steps']} | {t['jumps']} | "
                 f"{t['us_per_step']:.2f} | {t['rhs_per_step']:.1f} | {t['rhs_ns']:.0f} | "
                 f"{100 * t['rhs_share']:.0f} % | "
                 f"{t['steps_per_jump']:.1f} |")
    L += ["", f"Kernel compilation in a fresh process with an empty numba cache: {rep.compile[0]:.1f} s; loading "
              f"the on-disk cache in a fresh process: {rep.compile[1]:.2f} s (never included in the times above)."]
    return "\n".join(L) + "\n"


def plot_work_precision(rep: BenchmarkReport, path) -> None:
    """Time vs error, one panel per scene, one line per method family (log-log)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    scenes = [s.name for s in BENCH_SCENES]
    fig, axes = plt.subplots(1, len(scenes), figsize=(5 * len(scenes), 4.2), squeeze=False)
    for ax, sc in zip(axes[0], scenes):
        rows = [r for r in rep.rows if r.scene == sc and math.isfinite(r.error) and math.isfinite(r.time)]
        keys = sorted({(r.method, r.solver, r.eps) for r in rows}, key=lambda k: (k[0] != "hybrid", k))
        for key in keys:
            rr = sorted([r for r in rows if (r.method, r.solver, r.eps) == key], key=lambda r: r.rtol)
            label = "hybrid (ε→0)" if key[0] == "hybrid" else f"{key[1]} ε={key[2]:.0e}"
            ax.loglog([r.error for r in rr], [r.time for r in rr], "o-" if key[0] == "hybrid" else ".--",
                      lw=2 if key[0] == "hybrid" else 1, label=label)
        ax.set_title(sc)
        ax.set_xlabel("error: max(|Δt|/T̄, |ΔF|/F) over the jumps")
        ax.set_ylabel("wall time [s]")
        ax.grid(True, which="both", alpha=0.3)
    axes[0][0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_eps_study(rep: BenchmarkReport, path) -> None:
    """Fold-passage delay vs ε (log-log) with the fitted power laws."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(5.5, 4.2))
    for key, mk in (("delay_ab", "o"), ("delay_cd", "s")):
        ok = [e for e in rep.eps_rows if e.status == "ok" and getattr(e, key) > 0]
        name = key.replace("delay_", "").upper()
        line, = ax.loglog([e.eps for e in ok], [getattr(e, key) for e in ok], mk, label=f"{name} fold")
        if key in rep.eps_fit:
            C, p, _ = rep.eps_fit[key]
            x = np.logspace(-12, -5, 50)
            ax.loglog(x, C * x**p, "-", color=line.get_color(), label=f"{C:.3g} ε^{p:.3f}")
    ax.set_xlabel("ε")
    ax.set_ylabel("jump delay t_reg − t_hybrid [s]")
    ax.set_title("ε-regularised scheme (Radau, rtol 1e-10)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def rows_as_dicts(rep: BenchmarkReport) -> tuple[list[dict], list[dict]]:
    """(work-precision rows, ε rows including the tiny-ε check) as plain dicts for CSV/JSON."""
    return [asdict(r) for r in rep.rows], [asdict(e) for e in rep.eps_rows + rep.small_eps]

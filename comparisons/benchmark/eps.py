"""The ε study: the regularised scheme's fold-passage delay against ε, its power law, and which solvers get
through the folds at tiny ε in double precision (methodology: :mod:`comparisons.benchmark`)."""

from __future__ import annotations

import functools
import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from exact import ModelBreakdown, SolverBudgetExceeded, SolverFailure, simulate

from .peers import run_peer
from .scenes import BenchScene
from .timing import c_stdout_to_stderr

__all__ = ["EpsRow", "eps_study", "small_eps_check", "fit_power_law"]


@dataclass
class EpsRow:
    """The regularised scheme's fold-passage delays at one ε: ``delay_ab`` = t_reg − t_hybrid at the first
    AB→CD jump, ``delay_cd`` at the first CD→AB jump [s] (the regularised jump is the inflection crossing,
    so this is the delay past the fold plus the transit to the inflection); ``err_F`` = max ``|ΔF|/F`` there."""

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
    say = progress or (lambda msg: None)
    full, horizon = _eps_reference(scene)
    rows = []
    for eps in eps_values:
        say(f"small eps {eps:.0e}: Radau")
        rows += eps_study(scene, (eps,), rtol=rtol, max_steps=50_000)
        for peer in peers:
            say(f"small eps {eps:.0e}: {peer}")
            with c_stdout_to_stderr():
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

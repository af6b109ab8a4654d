"""Work precision on one scene: wall time against the error of the jump sequence for the hybrid solver, the
paper's ε-regularised scheme on scipy and the external peers (methodology: :mod:`comparisons.benchmark`)."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from exact import ModelBreakdown, SolverBudgetExceeded, SolverFailure, simulate

from .peers import run_peer
from .reference import branchwise_reference
from .scenes import BenchScene, jump_errors
from .timing import c_stdout_to_stderr, timed

__all__ = ["WPRow", "work_precision", "matched_ratios", "ratio_summary"]


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
        wall, tr = timed(lambda: simulate(scene.params, scene.horizon, **kw), repeats, warm)
    except (SolverFailure, ModelBreakdown, SolverBudgetExceeded) as exc:
        text = " ".join(str(exc).split())  # the whole message, its reason included, on one line
        msg = text if len(text) <= 200 else text[:199] + "…"
        return _row(scene, method, solver, eps, rtol, ref, np.array([]), np.array([]), math.nan, 0, 0,
                    status=f"failed at t={getattr(exc, 't', math.nan):.4g} s: {msg}")
    return _row(scene, method, solver, eps, rtol, ref, tr.jumps.t, tr.jumps.F, wall, tr.stats.n_steps,
                tr.stats.n_rhs, )


def _peer_row(scene, ref, repeats, peer, eps, rtol):
    res = None
    best = math.inf
    for i in range(repeats + 1):  # the first (warm-up) call is untimed
        with c_stdout_to_stderr():
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

"""What an atlas will cost: each part's wall time per point, measured at sample points of the grid in this
process, and the projected time of the whole grid (:func:`atlas_cost`, ``peelapprox atlas --cost N``).

The parts are the measures' own pieces: the exact window run with its observables (``exact``), the reductions
on the same window's stays (``segments``; the run is cached, so this is the reduced solves alone), each
approximation (``approx:<name>``) and the regime label (``regime``).  The sample is a regular sub-grid (a point
in the middle of each block of the grid), so it spans the grid's regimes; the projection is the sample's mean
per point times the grid's points, divided by the workers (perfect parallelism: the points are independent).
"""

from __future__ import annotations

import math
import sys
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from peelapprox import PARAM_RANGES, PeelParams, estimate
from peelapprox.errors import SolverBudgetExceeded
from peelapprox.io import fmt_number, write_rows
from peelapprox.validate import integer, optional, positive

from ..sweep.store import check_axis
from .approximations import predict
from .engine import atlas_options
from .measures import measure_exact, measure_segments

__all__ = ["AtlasCost", "atlas_cost", "sample_grid"]


def sample_grid(I_values: Sequence[float], V_values: Sequence[float], n: int) -> list[tuple[float, float]]:
    """About ``n`` points (I, V) of the grid on a regular sub-grid: along each axis ``m = ceil(sqrt(n))`` indices,
    the middles of ``m`` equal blocks of it (all of it when it is shorter), and every pair of them: a stratified
    sample, one point per block of the grid."""
    m = max(1, math.ceil(math.sqrt(n)))
    pick = [np.unique(((np.arange(min(m, len(a))) + 0.5) * len(a) / min(m, len(a))).astype(int))
            for a in (I_values, V_values)]
    return [(float(I_values[i]), float(V_values[j])) for i in pick[0] for j in pick[1]]


@dataclass(frozen=True)
class AtlasCost:
    """Measured per-point costs of an atlas's parts and the projected time of its grid.

    Attributes
    ----------
    points : list of (float, float)
        The sample (I, V).
    times : dict
        Part -> the wall time [s] at each sample point (``exact``, ``segments``, ``regime``,
        ``approx:<name>``).
    warmup : float
        Wall time of the first call (kernels compiled or loaded from their cache) [s], not in ``times``.
    total_points, workers : int
        The grid's size and the workers the projection assumes.
    """

    points: list[tuple[float, float]]
    times: dict[str, list[float]]
    warmup: float
    total_points: int
    workers: int
    statuses: list[str] = field(default_factory=list)

    def per_point(self) -> float:
        """Mean wall time of one point, every part [s]."""
        return float(sum(np.mean(t) for t in self.times.values()))

    def projected(self) -> float:
        """Projected wall time of the whole grid on ``workers`` processes [s] (mean per point x points /
        workers; start-up and compilation not included)."""
        return self.per_point() * self.total_points / self.workers

    def rows(self) -> list[dict]:
        """One row per part: sample points, median, mean and worst seconds per point, the projected core-seconds
        for the grid; then a ``total`` row with the projected wall time on ``workers``."""
        out = [{"part": part, "points": len(t), "median_s": float(np.median(t)), "mean_s": float(np.mean(t)),
                "max_s": float(np.max(t)), "grid_core_s": float(np.mean(t)) * self.total_points}
               for part, t in self.times.items()]
        out.append({"part": "total", "points": len(self.points), "median_s": None, "mean_s": self.per_point(),
                    "max_s": None, "grid_core_s": self.per_point() * self.total_points,
                    "workers": self.workers, "grid_wall_s": self.projected()})
        return out

    def write(self, path) -> str:
        """:meth:`rows` to ``path`` (``.csv`` or ``.json``)."""
        return write_rows(path, self.rows())

    def __str__(self) -> str:
        lines = [f"{'part':<24} {'median':>9} {'mean':>9} {'max':>9}  per point [s], {len(self.points)} sample "
                 "points"]
        for r in self.rows()[:-1]:
            lines.append(f"{r['part']:<24} {fmt_number(r['median_s'], 3):>9} {fmt_number(r['mean_s'], 3):>9} "
                         f"{fmt_number(r['max_s'], 3):>9}")
        lines.append(f"one point {fmt_number(self.per_point(), 3)} s; {self.total_points} points on "
                     f"{self.workers} workers: {fmt_number(self.projected() / 60, 3)} min projected "
                     f"(warm-up {fmt_number(self.warmup, 3)} s, start-up not included)")
        return "\n".join(lines)


#: The most sample points :func:`atlas_cost` times (each is one exact run and the approximations, seconds to a
#: minute): a projection's error falls as 1/sqrt(sample), 1/20 at 400; more is a slow atlas, not a cost.
MAX_SAMPLE = 400


def _budget(max_wall: float | None, t0: float, total: int) -> Any:
    """``left(done)``: ``{"max_wall": seconds left}`` for the next run (``{}`` when unbounded), or
    SolverBudgetExceeded once the budget is spent, saying that ``done`` of ``total`` points were timed."""

    def left(done: int) -> dict[str, float]:
        if max_wall is None:
            return {}
        rest = max_wall - (time.perf_counter() - t0)
        if rest <= 0.0:
            raise SolverBudgetExceeded(f"atlas_cost: more than {max_wall:g} s of wall time (max_wall) with {done} of "
                                       f"{total} sample points timed; pass a larger max_wall, or None (or a "
                                       "smaller sample)",
                                       budget="max_wall", limit=max_wall, t=0.0, state={}, partial=None)
        return {"max_wall": rest}

    return left


def _time_point(p: PeelParams, opts: Mapping[str, Any], times: dict[str, list[float]], statuses: list[str],
                left: Any) -> None:
    """Time each part of the atlas at ``p`` into ``times`` (``left()``: the budget left, or its exception)."""
    t = time.perf_counter()
    statuses.append(measure_exact(p, {**opts, **left()})["status"])
    times["exact"].append(time.perf_counter() - t)
    left()
    t = time.perf_counter()
    measure_segments(p, opts)
    times["segments"].append(time.perf_counter() - t)
    t = time.perf_counter()
    try:
        estimate(p)
    except ValueError:
        pass
    times["regime"].append(time.perf_counter() - t)
    for name, ref in opts["approximations"].items():
        left()
        t = time.perf_counter()
        try:
            predict(name, p, ref)
        except Exception:  # timed all the same: a failing prediction is part of the atlas's cost
            pass
        times[f"approx:{name}"].append(time.perf_counter() - t)


def atlas_cost(I_values: Sequence[float] | np.ndarray, V_values: Sequence[float] | np.ndarray, *, sample: int = 16,
               workers: int = 2, approximations: Sequence[str] | None = None, k: float | None = None,
               R: float | None = None, options: Mapping[str, Any] | None = None, progress: bool = False,
               max_wall: float | None = 600.0) -> AtlasCost:
    """Time each part of an atlas at about ``sample`` points of the grid, in this process, and project the
    grid's wall time on ``workers`` processes.

    Parameters
    ----------
    I_values, V_values : sequence of float
        The grid whose cost is projected (checked as :func:`~comparisons.atlas.atlas` checks it).
    sample : int
        About this many points are timed (a regular sub-grid: :func:`sample_grid`), 1 to :data:`MAX_SAMPLE`.
    workers : int
        The processes the projection assumes, >= 1.
    approximations, k, R, options
        As :func:`~comparisons.atlas.atlas` (the paper's law).
    progress : bool
        A line on stderr per point.
    max_wall : float or None
        The wall-clock budget [s] of the whole call (default 600; None: unbounded): each exact run gets what is
        left of it, and no point starts once it is spent.  A numba compilation (the first call of a cold cache)
        is one native call that no budget interrupts.

    Returns
    -------
    AtlasCost

    Raises
    ------
    SolverBudgetExceeded
        ``budget="max_wall"``: the budget was spent before every sample point was timed (a cost projected from
        fewer points would be an answer to another question); the message says how many were.
    """
    I_vals = check_axis("I_values", I_values, *PARAM_RANGES["I"])
    V_vals = check_axis("V_values", V_values, *PARAM_RANGES["V"])
    sample, workers = integer("sample", sample, lo=1, hi=MAX_SAMPLE), integer("workers", workers, lo=1)
    max_wall = optional(positive, "max_wall", max_wall)
    opts = atlas_options(approximations=approximations, k=k, R=R, **dict(options or {}))
    model = {n: opts[n] for n in ("k", "R") if n in opts}
    t0 = time.perf_counter()
    points = sample_grid(I_vals, V_vals, sample)
    left = _budget(max_wall, t0, len(points))
    times: dict[str, list[float]] = {"exact": [], "segments": [], "regime": []}
    times.update({f"approx:{name}": [] for name in opts["approximations"]})
    statuses: list[str] = []
    try:
        measure_exact(PeelParams(V=1.0, I=1e-5, **model), {**opts, "t_transient": 0.0, "t_window": 0.05,
                                                            **left(0)})
        warmup = time.perf_counter() - t0
        for n, (I, V) in enumerate(points, start=1):
            _time_point(PeelParams(V=V, I=I, **model), opts, times, statuses, lambda done=n - 1: left(done))
            if progress:
                print(f"atlas cost: {n}/{len(points)} I={I:.4g} V={V:.4g} exact {times['exact'][-1]:.3f} s, "
                      f"segments {times['segments'][-1]:.3f} s ({statuses[-1]})", file=sys.stderr, flush=True)
    except SolverBudgetExceeded as exc:  # an exact run stopped by what was left of the budget: the call's own
        if exc.budget == "max_wall" and max_wall is not None:
            left(len(times["regime"]))
        raise
    return AtlasCost(points, times, warmup, len(I_vals) * len(V_vals), workers, statuses)

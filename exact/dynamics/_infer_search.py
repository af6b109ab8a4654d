"""The search of :func:`exact.infer`: the fitted coordinates, the grid and its extension, the model's residuals at a
trial point, the replicate spread of aperiodic series and the attractor lines of the verdict.

The records: :class:`Problem` (what is fitted, fixed for a call), :class:`SeriesFit` (one series, its pull speed
and its statistics) and :class:`Point` (one evaluated trial point).  The search loop is in
``exact/dynamics/_infer.py``, the result's assembly in ``exact/dynamics/_infer_result.py``.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np

from peelapprox import ForceSeries, PeelParams
from peelapprox.io import fmt_number

from ._attractor_set_runs import default_starts
from ._infer_stats import (
    NOISE_REPLICATES,
    PERIOD_MARGIN,
    REPEATABILITY,
    STATISTICS,
    SeriesData,
    SetReading,
    data_period,
    model_period,
    noise_spread,
    period_disagreements,
    replicate_mean,
    replicate_spread,
    set_statistics,
)

__all__ = ["CHECK_STARTS", "GRID_RUNS", "JITTER", "LOG", "PENALTY", "Point", "Problem", "ReplicateCheck", "SeriesFit",
           "apply", "attractor_lines", "edge_sides", "extend", "free_names", "grid", "grid_point", "nodes",
           "period_check", "refine", "replicate_check", "replicated", "residuals", "shares", "spans", "values_of"]

#: The most grid points of the search per series (an odd number per axis, params0 at the centre: 9 x 9 for two
#: parameters).
GRID_RUNS = 81
#: The parameters fitted in ln θ (positive, spanning decades); the others, a law's coefficients, in θ.
LOG = ("I", "k", "R")
#: A residual for a model run that does not stick-slip or breaks down: far outside any σ.
PENALTY = 1e3
_F_CYCLE = STATISTICS.index("f_cycle")


@dataclass(frozen=True)
class SeriesFit:
    """One series of a fit: the trace, its pull speed, its statistics (:class:`SeriesData`) and whether the trace
    is aperiodic (its return map has no period: chaotic or quasi-periodic)."""

    series: ForceSeries
    V: float
    data: SeriesData
    aperiodic: bool = False


@dataclass(frozen=True)
class Problem:
    """What one :func:`exact.infer` call fits, fixed for the call (picklable: a pool's task carries it).

    Attributes
    ----------
    params0 : PeelParams
        The model and the centre of the search.
    names : tuple of str
        The free parameters (:func:`free_names`).
    sel : ndarray of int
        The indices into :data:`STATISTICS` of the ``statistics`` asked for.
    t_transient, rtol : float
        Of every model run.
    attractors : int
        Starts of the attractor set's design tried at each trial point (:func:`set_statistics`).
    replicates : int
        For an aperiodic series, the model's statistics at a trial point are the mean over this many replicates
        (:func:`replicate_mean`) where more than 1; 1: one reading (:func:`set_statistics`).
    """

    params0: PeelParams
    names: tuple[str, ...]
    sel: np.ndarray
    t_transient: float
    rtol: float
    attractors: int
    replicates: int = 1


@dataclass(frozen=True)
class Point:
    """One evaluated trial point: its fitted coordinates, χ², the model's statistics per series (None: no
    stick-slip) and their readings (the attractor each was read from)."""

    x: np.ndarray
    chi2: float
    models: list[np.ndarray | None]
    readings: list[SetReading]


def best(evaluated: Sequence[Point]) -> Point:
    """The evaluated point of the smallest χ² (the first of ties)."""
    return min(evaluated, key=lambda e: e.chi2)


def free_names(params0: PeelParams, free: Sequence[str]) -> list[str]:
    """The free parameters, checked: I, k, R, or ``force.<coefficient>`` of a family law."""
    if isinstance(free, str) or not isinstance(free, Sequence) or not free:
        raise TypeError(f"free must be a non-empty sequence of parameter names, got {free!r}")
    coefs = dict(params0.force.coefficients) if params0.force.kind == "family" else {}
    out = []
    for name in free:
        if not isinstance(name, str):
            raise TypeError(f"free: each name must be a string, got {name!r}")
        if name.startswith("force."):
            if name[6:] not in coefs:
                have = ", ".join(f"force.{c}" for c in coefs) or "none (params0.force is not a family law)"
                raise ValueError(f"free: {name!r} is not a coefficient of params0.force; its coefficients: {have}")
        elif name not in LOG:
            raise ValueError(f"free: {name!r} is not a fitted parameter; choose from I, k, R, force.<coefficient>")
        if name in out:
            raise ValueError(f"free: {name!r} is given twice")
        out.append(name)
    return out


def apply(params0: PeelParams, names: Sequence[str], x: np.ndarray, V: float) -> PeelParams:
    """``params0`` at pull speed V with the free parameters at ``x`` (ln θ for I, k, R)."""
    changes: dict[str, Any] = {"V": V}
    coefs = dict(params0.force.coefficients) if params0.force.kind == "family" else {}
    for name, xi in zip(names, x):
        if name in LOG:
            changes[name] = math.exp(float(xi))
        else:
            coefs[name[6:]] = float(xi)
    if any(n.startswith("force.") for n in names):
        changes["force"] = type(params0.force).family(str(params0.force.name), **coefs)
    return params0.replace(**changes)


def values_of(names: Sequence[str], x: np.ndarray) -> list[float]:
    """The parameters' values at fitted coordinates ``x``."""
    return [math.exp(float(xi)) if n in LOG else float(xi) for n, xi in zip(names, x)]


def grid(names: Sequence[str], x0: np.ndarray, lo: np.ndarray, hi: np.ndarray, search: float, n_series: int
         ) -> tuple[list[np.ndarray], np.ndarray, np.ndarray]:
    """The search grid's nodes per axis (``exact/dynamics/_infer.py``'s docstring) and its box ``(low, high)``
    per parameter, in fitted coordinates."""
    half = np.array([math.log(search) if n in LOG else 0.3 * max(abs(x), 1e-12) for n, x in zip(names, x0)])
    box_lo, box_hi = np.maximum(x0 - half, lo), np.minimum(x0 + half, hi)
    per = max(3, int(math.floor((GRID_RUNS / max(n_series, 1)) ** (1.0 / len(names)) + 1e-9)))
    per = min(per - (per % 2 == 0), 9)  # odd: params0 is a node
    return [np.linspace(a, b, per) for a, b in zip(box_lo, box_hi)], box_lo, box_hi


def nodes(axes: list[np.ndarray]) -> np.ndarray:
    """Every point of the grid whose nodes per axis are ``axes``."""
    return np.array(np.meshgrid(*axes, indexing="ij")).reshape(len(axes), -1).T


def spans(names: Sequence[str], evaluated: Sequence[Point], jac: np.ndarray | None, n_obs: int,
          chi2_noise: float = 0.0, coarse: np.ndarray | None = None
          ) -> tuple[np.ndarray, float, float, np.ndarray, np.ndarray, np.ndarray | None]:
    """The best evaluated point, its χ², the scale s, the 95 % interval ``(low, high)`` per parameter in fitted
    coordinates (the union of the profile and the Jacobian's) and the covariance (or None).  ``chi2_noise``: the
    standard deviation of χ² over the best point's neighbours (:func:`replicate_check`; 0 without an aperiodic
    series), twice which widens the profile's threshold: a point whose χ² is a draw is as good as the best where
    it lies within the draws' scatter.  ``coarse``: a second Jacobian at the best point, the valley walk's at the
    search's resolution (``exact/dynamics/_infer_valley.py``), whose ±1.96 standard errors join the union too; the
    covariance returned then has on its diagonal the larger of the two variances (the standard errors quoted)."""
    dof = n_obs - len(names)
    top = best(evaluated)
    x, chi2 = top.x, top.chi2
    s = max(1.0, chi2 / dof) if dof > 0 else 1.0
    accept = np.array([e.x for e in evaluated if e.chi2 <= chi2 + 3.84 * s + 2.0 * chi2_noise])
    lo_, hi_ = accept.min(axis=0), accept.max(axis=0)
    cov = None if jac is None else np.linalg.pinv(jac.T @ jac) * s
    wide = None if coarse is None else np.linalg.pinv(coarse.T @ coarse) * s
    for c in (cov, wide):
        if c is None:
            continue
        for i in range(len(names)):
            if math.isfinite(float(c[i, i])) and c[i, i] > 0:
                se = math.sqrt(float(c[i, i]))
                lo_[i], hi_[i] = min(lo_[i], x[i] - 1.96 * se), max(hi_[i], x[i] + 1.96 * se)
    if wide is not None:  # each variance the larger of the two (the standard errors quoted)
        cov = wide.copy() if cov is None else cov.copy()
        np.fill_diagonal(cov, np.fmax(np.diag(cov), np.diag(wide)))
    return np.asarray(x), float(chi2), s, lo_, hi_, cov


def edge_sides(names: Sequence[str], evaluated: Sequence[Point], jac: np.ndarray | None, n_obs: int, box: tuple,
               limits: tuple) -> list[tuple[int, int]]:
    """The box's sides ``(parameter index, -1 low / +1 high)`` that the 95 % interval reaches and that can still
    move outwards within :data:`peelapprox.PARAM_RANGES`."""
    _, _, _, lo_, hi_, _ = spans(names, evaluated, jac, n_obs)
    out = []
    for i in range(len(names)):
        if lo_[i] <= box[0][i] + 1e-12 and box[0][i] > limits[0][i] + 1e-12:
            out.append((i, -1))
        if hi_[i] >= box[1][i] - 1e-12 and box[1][i] < limits[1][i] - 1e-12:
            out.append((i, 1))
    return out


def extend(names: Sequence[str], axes: list[np.ndarray], box_lo: np.ndarray, box_hi: np.ndarray,
           sides: list[tuple[int, int]], limits: tuple, search: float
           ) -> tuple[list[np.ndarray], np.ndarray, np.ndarray]:
    """The grid with each side in ``sides`` moved outwards by the initial half-width (a factor ``search`` for
    I, k, R; 30 % of the value for a coefficient), within the limits, at the axis' node spacing: the new nodes
    with the other axes' nodes are the points evaluated next."""
    axes, box_lo, box_hi = [a.copy() for a in axes], box_lo.copy(), box_hi.copy()
    for i, side in sides:
        a = axes[i]
        step = float(a[1] - a[0]) if a.size > 1 else 0.1
        width = math.log(search) if names[i] in LOG else 0.3 * max(abs(float(a[a.size // 2])), 1e-12)
        n = max(1, int(math.ceil(width / step - 1e-9)))
        if side < 0:
            new = np.maximum(a[0] - step * np.arange(n, 0, -1), limits[0][i])
            axes[i] = np.unique(np.concatenate([new, a]))
            box_lo[i] = axes[i][0]
        else:
            new = np.minimum(a[-1] + step * np.arange(1, n + 1), limits[1][i])
            axes[i] = np.unique(np.concatenate([a, new]))
            box_hi[i] = axes[i][-1]
    return axes, box_lo, box_hi


def residuals(problem: Problem, fits: Sequence[SeriesFit], x: np.ndarray, left: float
              ) -> tuple[np.ndarray, list[np.ndarray | None], list[SetReading]]:
    """The weighted residuals of the model at ``x`` against every series' statistics, the model's statistics
    per series (None: no stick-slip) and their readings (:func:`set_statistics`: the attractor closest to the
    data among the first ``problem.attractors`` starts), each run bounded by ``left`` seconds (at least 1)."""
    out: list[np.ndarray] = []
    models: list[np.ndarray | None] = []
    readings: list[SetReading] = []
    for f in fits:
        d = f.data
        p = apply(problem.params0, problem.names, x, f.V)
        if f.aperiodic and problem.replicates > 1:
            r = replicate_mean(p, f.series, d.threshold, d.noise, problem.t_transient, problem.rtol, max(1.0, left),
                               d.target(problem.sel), problem.replicates)
        else:
            r = set_statistics(p, f.series, d.threshold, d.noise, problem.t_transient, problem.rtol, max(1.0, left),
                               d.target(problem.sel), problem.attractors)
        out.append(d.residuals(r.values, problem.sel, PENALTY))
        models.append(r.values)
        readings.append(r)
    return np.concatenate(out), models, readings


def grid_point(problem: Problem, fits: Sequence[SeriesFit], x: np.ndarray, deadline: float
               ) -> tuple[np.ndarray, list[np.ndarray | None], list[SetReading]] | None:
    """:func:`residuals` at a grid point as a pool's task; None when the call's ``deadline`` (a ``time.time()``)
    passed before it began."""
    left = deadline - time.time()
    if left <= 0:
        return None
    return residuals(problem, fits, x, left)


def refine(axes: list[np.ndarray], evaluated: Sequence[Point], box: tuple[np.ndarray, np.ndarray], top: int
           ) -> list[np.ndarray]:
    """The points of a finer grid around each of the ``top`` best evaluated points: per axis offsets
    ``{-2, -1, 0, 1, 2}`` quarters of the grid's node spacing (``{-1, 0, 1}`` halves with three parameters or
    more), so that each best node's cell is covered at a quarter of its spacing; inside ``box``, each point once,
    in a fixed order (the best node's first), the evaluated ones left out by the caller."""
    steps = np.array([float(a[1] - a[0]) if a.size > 1 else 0.0 for a in axes])
    frac = np.array([-0.5, -0.25, 0.0, 0.25, 0.5]) if len(axes) <= 2 else np.array([-0.5, 0.0, 0.5])
    offsets = nodes([frac * st for st in steps])
    out: list[np.ndarray] = []
    seen: set[tuple[float, ...]] = set()
    for e in sorted(evaluated, key=lambda e: e.chi2)[:top]:
        for off in offsets:
            x = e.x + off
            key = tuple(np.round(x, 9).tolist())
            if key in seen or np.any(x < box[0] - 1e-12) or np.any(x > box[1] + 1e-12):
                continue
            seen.add(key)
            out.append(x)
    return out


def n_fitted(problem: Problem, fits: Sequence[SeriesFit]) -> int:
    """The number of statistics fitted over all series."""
    return sum(int(np.count_nonzero(f.data.used[problem.sel])) for f in fits)


def replicated(problem: Problem, evaluated: list[Point], fits: list[SeriesFit], left: float
               ) -> tuple[list[SeriesFit], int, tuple[str, ...]]:
    """For each aperiodic series, the model's replicate spread at the best grid point (:func:`replicate_spread`,
    the replicates on the data's attractor) added in quadrature to the statistics' σ (a diagonal synthetic
    likelihood, Wood 2010; divided by √m where the model's statistics are a mean over m = ``problem.replicates``
    replicates), and √2 times the detector's spread under noise there (:func:`noise_spread`, from the start of
    the replicate closest to the data: the data and the model each carry one noise draw); the cycle line's σ
    starts there from half a periodogram bin instead of :data:`REPEATABILITY`'s 3 % (the torus' modulation
    moves smoothly with I, as I^-1/2: at the quasi-periodic V = 3.923 m/s, I = 0.01045 a fit 12 % high in I was
    called identified with the 3 %, its line 5.3 % low, under 2 σ); and the cycle line
    dropped where it is not stable across the replicates; the χ² of every point evaluated so far (``evaluated``,
    updated in place) recomputed with the new σ.  Returns the series, the number of fitted statistics and the
    notes."""
    x = best(evaluated).x
    out, notes, t0 = [], [], time.perf_counter()
    for f in fits:
        d = f.data
        if not f.aperiodic or left - (time.perf_counter() - t0) <= 1.0:
            out.append(f)
            continue
        p = apply(problem.params0, problem.names, x, f.V)
        sd, stable, n, start = replicate_spread(p, f.series, d.threshold, d.noise, problem.t_transient, problem.rtol,
                                                left - (time.perf_counter() - t0), target=d.target(problem.sel))
        nsd = None if start is None or left - (time.perf_counter() - t0) <= 1.0 else noise_spread(
            p, f.series, d.threshold, d.noise, problem.t_transient, problem.rtol, left - (time.perf_counter() - t0),
            start)
        if sd is None and nsd is None:
            out.append(f)
            continue
        sig, used = d.sigma.copy(), d.used.copy()
        # an aperiodic trace's cycle line is not a period-n cycle on a comb of windows: its σ is half a periodogram
        # bin (data_statistics' floor), not REPEATABILITY's 3 %, joined by its spreads below (docstring)
        sig[_F_CYCLE] = 0.5 / f.series.duration
        if nsd is not None:  # the data's noise draw and the model's: twice the variance
            sig = np.hypot(sig, math.sqrt(2.0) * nsd)
            notes.append(f"V = {fmt_number(f.V, 4)} m/s: an aperiodic trace; the detector's spread over "
                         f"{NOISE_REPLICATES} noise draws (times sqrt 2) added to each statistic's sigma")
        if sd is not None:
            sig = np.hypot(sig, sd / math.sqrt(problem.replicates))
            notes.append(f"V = {fmt_number(f.V, 4)} m/s: an aperiodic trace; the model's spread over {n} replicates "
                         "on its attractor added to each statistic's sigma")
        if used[_F_CYCLE] and sd is not None and not stable:
            used[_F_CYCLE] = False
            notes.append(f"f_cycle is not fitted at V = {fmt_number(f.V, 4)} m/s: the model's cycle line is not "
                         f"stable across its replicates (absent in one, or spread over "
                         f"{fmt_number(100 * REPEATABILITY['f_cycle'], 2)} %)")
        out.append(dataclasses.replace(f, data=dataclasses.replace(d, sigma=sig, used=used)))
    n_obs = n_fitted(problem, out)
    if n_obs < len(problem.names):  # dropping the line would leave too few statistics: keep the former reading
        return fits, n_fitted(problem, fits), ()
    for i, e in enumerate(evaluated):
        res = np.concatenate([f.data.residuals(m, problem.sel, PENALTY) for m, f in zip(e.models, out)])
        evaluated[i] = dataclasses.replace(e, chi2=float(res @ res))
    return out, n_obs, tuple(notes)


#: The relative step (in ln θ for I, k, R; of the value for a coefficient) of the neighbours at which
#: :func:`replicate_check` re-reads an aperiodic fit's best point: far below the statistics' resolution (their
#: σ of 2 % moves by ~0.3 σ), far above what separates two windows of a chaotic run.
JITTER = 3e-3
#: The starts of the attractor set's design from which :func:`replicate_check` reads each neighbour (the attractor
#: closest to the data among them, :func:`set_statistics`): in a chaotic band the solver's start at a neighbour
#: often falls into a periodic window while another start still reaches the data's attractor.  At the truth of
#: V = 0.6854 m/s, I = 2.459e-5, k = 1317 (``infer_targets`` seed 3, chaotic) the solver's start at I +0.3 % reaches
#: a period-6 orbit (χ² 149 on 6) and the start α0 = -0.3 the chaotic attractor (χ² 2.1); at the island
#: V = 2.249 m/s, I = 1.95e-4 (39 % below the truth) all 4 starts at I +0.3 % give χ² 60-93: an island stays one.
CHECK_STARTS = 4


class ReplicateCheck(NamedTuple):
    """What :func:`replicate_check` found at an aperiodic fit's best point."""

    chi2: float                 #: the neighbours' χ² (with the new σ), summed
    n_stat: int                 #: its degrees of freedom (neighbours x fitted statistics)
    n_runs: int                 #: the model runs made for the neighbours
    chi2_sd: float              #: the standard deviation of χ² from neighbour to neighbour
    fits: list[SeriesFit]       #: the series with their new σ


def _chi2(models: Sequence[np.ndarray | None], fits: Sequence[SeriesFit], sel: np.ndarray) -> tuple[float, int]:
    """χ² of the model statistics ``models`` (one per series) against ``fits``, and the number of residuals."""
    res = np.concatenate([f.data.residuals(m, sel, PENALTY) for m, f in zip(models, fits)])
    return float(res @ res), res.size


def replicate_check(problem: Problem, evaluated: list[Point], fits: Sequence[SeriesFit], left: float
                    ) -> ReplicateCheck | None:
    """The neighbours of the best point, for a fit with an aperiodic series: σ re-estimated there, and their χ².

    The model's statistics at the best point moved by ±:data:`JITTER` along each parameter (all series; each
    neighbour read from the attractor closest to the data among the first :data:`CHECK_STARTS` starts): for each
    aperiodic series the variance of each statistic over those neighbours and the best point (draws the
    statistics cannot tell apart) joins σ² (a diagonal synthetic likelihood's covariance at the best point, Wood
    2010); the χ² of every evaluated point is recomputed with it (``evaluated`` updated in place).  Each trial
    point of an aperiodic series is read from one window of its attractor, a draw, and the best of many draws is
    biased low; where the best is an island (a lucky window, a narrow periodic window in the chaotic band) its
    neighbours do not fit.  At V = 2.249 m/s, I = 3.2e-4 (chaotic) a fit with I 39 % low had χ² 2.55 on 4 dof,
    its neighbours 0.1-0.7 % away 8-43, while 4 later windows of its own run fitted (21 on 24).  None without an
    aperiodic series or where the budget is spent."""
    if not evaluated or not any(f.aperiodic for f in fits):
        return None
    top = best(evaluated)
    x = top.x
    wide = dataclasses.replace(problem, attractors=max(problem.attractors, CHECK_STARTS))
    t0, draws = time.perf_counter(), []
    for i in range(len(problem.names)):
        step = JITTER if problem.names[i] in LOG else JITTER * max(abs(float(x[i])), 1e-12)
        for sign in (-1.0, 1.0):
            left_now = left - (time.perf_counter() - t0)
            if left_now <= 1.0:
                return None
            xn = x.copy()
            xn[i] += sign * step
            _, models, readings = residuals(wide, fits, xn, left_now)
            draws.append((models, sum(r.n_runs for r in readings)))
    new_fits = []
    for j, f in enumerate(fits):
        reads = [m[j] for m, _ in draws] + [top.models[j]]
        if not f.aperiodic or any(m is None for m in reads):
            new_fits.append(f)
            continue
        sd = np.array(reads).std(axis=0, ddof=1)
        new_fits.append(dataclasses.replace(f, data=dataclasses.replace(f.data, sigma=np.hypot(f.data.sigma, sd))))
    for i, e in enumerate(evaluated):
        evaluated[i] = dataclasses.replace(e, chi2=_chi2(e.models, new_fits, problem.sel)[0])
    c, sizes = zip(*(_chi2(models, new_fits, problem.sel) for models, _ in draws))
    chi2 = np.array(c)
    return ReplicateCheck(float(chi2.sum()), sum(sizes), sum(v[1] for v in draws),
                          float(chi2.std(ddof=1)) if chi2.size > 1 else 0.0, new_fits)


def shares(problem: Problem, evaluated: Sequence[Point], fits: Sequence[SeriesFit], left: float
           ) -> list[SetReading | None]:
    """At the best point, per series, the whole design of starts (:func:`set_statistics` with ``share``); None
    where the budget is spent."""
    if not evaluated:
        return []
    x = best(evaluated).x
    t0, out = time.perf_counter(), list[SetReading | None]()
    for f in fits:
        d = f.data
        spent = time.perf_counter() - t0
        if left - spent <= 1.0:
            out.append(None)
            continue
        out.append(set_statistics(apply(problem.params0, problem.names, x, f.V), f.series, d.threshold, d.noise,
                                  problem.t_transient, problem.rtol, left - spent, d.target(problem.sel), 8,
                                  share=True))
    return out


def attractor_lines(evaluated: Sequence[Point], full: Sequence[SetReading | None], Vs: Sequence[float]
                    ) -> tuple[str, ...]:
    """Per series, the attractor the best point's statistics are read from, the start reaching it and its
    share of the set's starts."""
    if not evaluated:
        return ()
    top = best(evaluated).readings
    out = []
    padded: list[SetReading | None] = [*full, *([None] * (len(top) - len(full)))]
    for V, r, whole in zip(Vs, top, padded):
        share = ("its share of the set's starts not measured (max_wall spent)" if whole is None or whole.share is None
                 else f"share {fmt_number(100 * whole.share, 3)} % of the set's {whole.n_runs} starts")
        out.append(f"at V = {fmt_number(V, 4)} m/s on the {r.label} attractor (from the start {r.start!r}; {share})")
    return tuple(out)


def period_check(problem: Problem, evaluated: Sequence[Point], fits: Sequence[SeriesFit], left: float
                 ) -> tuple[tuple[str, ...], int]:
    """Whether the best point's attractor has the data's period, per series (:func:`period_disagreements` in
    ``exact/dynamics/_infer_stats.py``): the sentences of the clear disagreements and the model runs spent.  Where
    the data read periodic and the best point's reading (the knee detector's) another period or none, its trace is
    run again from the same start and read as the data are (:func:`model_period`: at its noise's tolerance and at
    :data:`PERIOD_MARGIN` times the data's); once ``left`` seconds are spent it is not, and a periodic reading of
    another period counts, its margin unmeasured."""
    if not evaluated:
        return (), 0
    top = best(evaluated)
    t0, n_runs = time.perf_counter(), 0
    data, model, wide, Vs = [], [], [], []
    for f, r in zip(fits, top.readings):
        p, tol = data_period(f.series)
        q: int | None = None
        w: int | None | bool = None
        if p is not None and r.values is not None and r.period != p:
            spent = time.perf_counter() - t0
            params = apply(problem.params0, problem.names, top.x, f.V)
            start = next((st.kwargs() for st in default_starts(params) if st.name == r.start), None)
            if left - spent <= 1.0 or start is None:
                q, w = r.period, False
            else:
                q, w = model_period(params, f.series, f.data.threshold, f.data.noise, problem.t_transient,
                                    problem.rtol, left - spent, start, PERIOD_MARGIN * tol)
                n_runs += 1
        data.append(p)
        model.append(q)
        wide.append(w)
        Vs.append(f.V)
    return period_disagreements(data, model, wide, Vs), n_runs

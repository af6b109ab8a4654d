"""Parameters from data: the model's parameters whose force trace reads like the measured one.

:func:`infer` adjusts the free parameters of a :class:`peelapprox.PeelParams` (I, k, R, a family law's
coefficients) until the exact model's force trace, sampled like the measured :class:`peelapprox.ForceSeries`
and read by the same slip detector with the same threshold, gives the same statistics, at one pull speed or
several (one series per V).

* **Statistics and residuals** (``exact/dynamics/_infer_stats.py``): seven statistics of the trace, the model's
  read off an exact run sampled, noised and detected as the data were; residuals ``(model - data) / σ``.  The
  search's pieces (the grid, its extension, the residuals at a trial point, the replicate spread) are in
  ``exact/dynamics/_infer_search.py``, the result and its verdicts in ``exact/dynamics/_infer_result.py``; they
  pass named records (a series' ``SeriesData``, ``SeriesFit``, ``Problem``, an evaluated ``Point``, ``Outcome``).
* **The attractor set.**  At each trial point the statistics are those of the attractor closest to the data
  among those reached from the first ``attractors`` starts of :func:`exact.attractor_set`'s design
  (:func:`set_statistics`); at the best point the whole design runs once to name that attractor and its share
  (:attr:`Inference.attractors`).  For an aperiodic series the model's spread over replicates at the best grid
  point (those on the data's attractor) joins each σ and the cycle line is kept only where it is stable across
  them (:func:`replicate_spread`);
  with ``replicates`` > 1 the model's statistics at every trial point are the mean over that many replicates
  (:func:`replicate_mean`: a synthetic likelihood's mean, Wood 2010) and the spread's share of σ shrinks by
  √replicates.
* **Search, then fit.**  An attractor's statistics are not smooth in the parameters (periodic windows,
  coexisting attractors), so a local fit alone finds a nearby minimum with an overconfident interval.  First
  a grid over ``params0 / search`` to ``params0 · search`` (ln θ for I, k, R; ±30 % for coefficients; at most
  :data:`GRID_RUNS` points per series), a finer grid around its :data:`REFINE_TOP` best nodes (each node's cell at
  a quarter of the spacing), then :func:`scipy.optimize.least_squares` (to :data:`XTOL`) from the best point,
  and from the next best ones (:data:`N_STARTS` in all) while the fit's χ² is improbable (:data:`GOOD_FIT`).
  Where the 95 % interval (below) reaches a side of the box, that side moves out by the initial half-width (at
  the grid's node spacing, within :data:`peelapprox.PARAM_RANGES`), the new nodes are evaluated and the fit
  repeated, at most :data:`MAX_EXTEND` times: a verdict "the edge of the search" then means the data, not the
  box.
* **Intervals.**  95 %, the union of two: the profile of every evaluated point (the parameter's range among the
  points with χ² ≤ χ²_min + 3.84 · s, s = max(1, χ²_min/dof)) and the Jacobian's at the optimum (±1.96 standard
  errors of ``s (JᵀJ)⁻¹``); for an aperiodic series at least ± a quarter of the first grid's node spacing, the
  search's finest (below it such a χ² is a comb of windows).  Where a parameter would be identified, the χ² is first
  walked along its least-curved direction from the best point at that spacing (``exact/dynamics/_infer_valley.py``:
  a long narrow valley oblique to the grid, or a comb of windows along one, widens the interval; the probes'
  Jacobian at that spacing joins it).  A parameter is *not identified* when that interval spans more than a factor 2
  (log-fitted) or its value (coefficients), or reaches the edge of the search: the data do not determine it, and the
  report says so instead of quoting a number.  None is identified when the best fit is poor (χ² improbable at
  :data:`POOR_FIT`, at :data:`GOOD_FIT` where a series is aperiodic): the model describes the data nowhere in the
  search.  With an aperiodic series the best point's neighbours (±``JITTER`` along each parameter; each from the
  attractor closest to the data among the set's first ``CHECK_STARTS`` starts) are read too: each trial point's
  statistics are one window's, a draw, and the best of many draws is biased low.  Each statistic's σ is joined by
  its spread over the best point and its neighbours (every χ² recomputed with it); where the neighbours' χ² (summed)
  is still improbable at :data:`GOOD_FIT` nothing is identified, and their χ² spread widens the profile's threshold
  (``replicate_check`` in ``exact/dynamics/_infer_search.py``).
* **The period check.**  Where the data's return map is periodic and the best point's attractor clearly periodic
  of another period (read by :meth:`peelapprox.ForceSeries.observables` at the tolerance of the series' noise, the
  model's trace noised like the data; still so at ``PERIOD_MARGIN`` times that tolerance), nothing is identified
  and the verdicts say why (``period_check`` in ``exact/dynamics/_infer_search.py``): the statistics are means over
  a cycle, and the one that carries the period, the cycle frequency, is not fitted where the data's periodogram
  holds no line, so χ² cannot see it (docs/your-data.md, seed 8 trace 2).  It judges after the valley walk and
  steers nothing.
* **A second pass.**  Where those verdicts identify nothing because the best fit is poor (its χ², or an aperiodic
  fit's neighbours', improbable at ``poor_fit``) or the period check disagrees, the comb was not resolved: a window
  narrower than the grid's spacing holds the truth and no node (docs/your-data.md, seed 8 traces 2 and 3).  The
  cells of a few coarse nodes (the start, the nodes on the data's period, the best ones) are evaluated at a quarter
  of the spacing and a least-squares fit runs from the best new point; where it is better than the first pass's
  best, the replicate check, the valley walk and the period check run again on it (``exact/dynamics/_infer_fine.py``).
  A fit identifying anything never runs it.
"""

from __future__ import annotations

import dataclasses
import math
import sys
import time
from collections.abc import Callable, Sequence
from concurrent.futures import Executor
from typing import Any

import numpy as np

from peelapprox import PARAM_RANGES, ForceSeries, PeelParams
from peelapprox.io import fmt_number
from peelapprox.parallel import AUTO, POOL_KINDS, map_points
from peelapprox.validate import choice, integer, optional, positive

from ._infer_fine import second_pass
from ._infer_result import POOR_FIT, Inference, Outcome, assemble
from ._infer_search import (
    GRID_RUNS,
    JITTER,
    LOG,
    PENALTY,
    Point,
    Problem,
    ReplicateCheck,
    SeriesFit,
    attractor_lines,
    best,
    edge_sides,
    extend,
    free_names,
    grid,
    grid_point,
    n_fitted,
    nodes,
    period_check,
    refine,
    replicate_check,
    replicated,
    residuals,
    shares,
    values_of,
)
from ._infer_stats import STATISTICS, data_statistics
from ._infer_valley import VALLEY_STEPS, valley_walk

__all__ = ["DIFF_STEP", "GOOD_FIT", "GRID_RUNS", "Inference", "MAX_EXTEND", "POOR_FIT", "N_STARTS", "REFINE_TOP",
           "XTOL", "infer"]

#: Relative step of the forward-difference Jacobian.
DIFF_STEP = 1e-3
#: The least-squares fit starts from the best grid point, then from the next best ones (at most this many starts
#: in all) while its χ² is improbable at :data:`GOOD_FIT`: on a comb of periodic windows a local fit from the
#: best node can end in a neighbouring window (V = 1, I = 1e-2: χ² = 18.8 on 5 dof at I -3 %, k -2 %, where the
#: truth gives 0.01).
N_STARTS = 3
#: The most times the search box is extended (each side the 95 % interval reaches moved out by the initial
#: half-width, within :data:`peelapprox.PARAM_RANGES`) before a verdict: a start a factor 3 off puts the truth
#: on the initial box's edge, and "not identified: the edge of the search" would then describe the box, not the
#: data.
MAX_EXTEND = 3
#: The χ² probability from which a fit needs no further start (:data:`N_STARTS`), and below which a fit to an
#: aperiodic series identifies nothing (:data:`POOR_FIT`).
GOOD_FIT = 0.05
#: The least-squares fit's ``xtol`` (scipy's default 1e-8): it stops when a step moves the fitted coordinates
#: (ln θ for I, k, R) by less than this fraction of their norm (~10 for I and k: a step under ~0.1 % of the
#: parameters), where the statistics' σ of 2 % (:data:`REPEATABILITY`) makes a finer optimum meaningless.  At
#: V = 1.477 m/s, I = 4.73e-5 the default spent its last 25 of 45 runs moving I and k by under 1e-4.
XTOL = 1e-4
#: After the first grid (and, for an aperiodic series, its replicate spread), a finer grid around this many of
#: its best nodes (:func:`refine`: each node's cell at a quarter of the node spacing, 24 points a node for two
#: parameters) before the least-squares fit: at a chaotic point (V = 2.249 m/s, I = 3.2e-4, k = 702) χ² within 10 %
#: of the truth ranges over 1.6-54 from point to point (a comb of windows), so the grid's nodes, 31 % apart,
#: missed the truth's valley and the fit settled at 2.6 times the truth (χ² 26 on 4 dof).  0: no refinement.
REFINE_TOP = 2
_F_CYCLE = STATISTICS.index("f_cycle")


def infer(series: ForceSeries, params0: PeelParams, free: Sequence[str] = ("I", "k"), *,
          more: Sequence[ForceSeries] = (), statistics: Sequence[str] = STATISTICS, search: float = 3.0,
          t_transient: float = 30.0, rtol: float = 1e-8, max_wall: float = 600.0, attractors: int = 1,
          replicates: int = 1,
          progress: Callable[[str], None] | bool | None = True, executor: str | Executor | None = None,
          max_workers: int | None = None) -> Inference:
    """The model's parameters whose force traces read like the measured ones (module docstring).

    Parameters
    ----------
    series : ForceSeries
        A trace with its pull speed ``V`` set.
    params0 : PeelParams
        The model and the centre of the search; parameters not in ``free`` keep their values.
    free : sequence of str
        The fitted parameters: ``"I"``, ``"k"``, ``"R"``, ``"force.<coefficient>"`` of a family law (("I", "k")).
    more : sequence of ForceSeries
        Traces at other pull speeds, fitted together with ``series``.
    statistics : sequence of str
        The statistics fitted, a subset of :data:`STATISTICS` (all).  Where coexisting attractors make the
        period, and with it the cycle frequency and the means over a cycle, jump between neighbouring parameter
        values (low inertia), the per-stick statistics ``("rise", "F_start", "force_drop")`` vary smoothly.
    search : float
        The grid spans ``params0 / search`` to ``params0 · search`` for I, k and R (±30 % for coefficients),
        within :data:`peelapprox.PARAM_RANGES`; in (1, 100] (3).
    t_transient : float
        Seconds of each model run before its sampled window, in (0, 1e4] (30).
    rtol : float
        Of every model run (1e-8, :func:`exact.simulate`'s default): at 12 seeded points of
        ``comparisons.benchmark.infer_targets`` the statistics lie within 0.01 σ of those at 1e-10 (28 % less
        CPU) except where chaotic, where a change of rtol moves the window along the attractor (1-2.3 σ).
    max_wall : float
        Wall-clock budget [s] (600): at its end the best point so far is returned with status ``"budget"``.  It
        is checked before each model run and each run gets what is left of it, so a call ends within about one
        run past it (measured: 622 s at 600, status ``"converged"``, ``infer_targets`` seed 7 trace 1 on 2
        cores at ``nice -n 19`` beside other jobs; 322 s for the same trace at a lower load).
    attractors : int
        At each trial point, the statistics are those of the attractor closest to the data among those reached
        from the first ``attractors`` starts of :func:`exact.attractor_set`'s design (the solver's start first;
        the further starts run only while none fits within 3 σ), in [1, 8]; 1 (the default): the solver's start
        alone; 3: the opt-in for multistable traces (docs/your-data.md: it measured no better under a budget).
        At the best point every start of the design runs once, to name the attractor and its share.
    replicates : int
        For an aperiodic (chaotic or quasi-periodic) series, the model's statistics at each trial point are the
        mean over the aperiodic traces of the first ``replicates`` starts of the design (a synthetic likelihood's
        mean, Wood 2010; the replicate spread's share of σ shrinks by √replicates), in [1, 8]; 1 (the default):
        one reading, as for a periodic series.  Costs ``replicates`` runs per trial point and aperiodic series.
    progress : callable, bool or None
        Called with a line of text after each model run; True (default): those lines on stderr (a fit takes
        tens of seconds to minutes); False or None: silent.
    executor : {"auto", "threads", "processes", "serial"} or concurrent.futures.Executor, optional
        Where the search grid's runs go: a local pool of :mod:`peelapprox.parallel` (None: ``"auto"``,
        processes on more than two CPUs, threads on one or two), or any executor, used as is; the least-squares
        fits after it run here.  The result does not depend on it (the runs are recorded in grid order).
    max_workers : int, optional
        Of a local pool (default: the CPUs; 0: in this process).

    Returns
    -------
    Inference

    Raises
    ------
    ValueError, TypeError
        A series without V or without stick-slip, an unknown or repeated free parameter, an option out of
        range; each names the argument.
    """
    t_wall = time.perf_counter()
    say = _progress(progress)
    problem, fits, notes, n_obs, x0, limits = _prepare(
        series, params0, free, more, statistics, search=search, t_transient=t_transient, rtol=rtol,
        max_wall=max_wall, attractors=attractors, replicates=replicates, executor=executor, max_workers=max_workers)
    run = _Search(problem, fits, t_wall, positive("max_wall", max_wall), say, executor,
                  optional(integer, "max_workers", max_workers, 0))
    first = run.run(x0, limits, float(search), n_obs, notes)
    base = run.fits
    check, outcome = _replicated(problem, run, first)
    outcome = _walked(problem, run, outcome)
    outcome, n_period = _period_checked(problem, run, outcome)
    found, outcome = second_pass(problem, run, outcome, first, x0, _Spent, {"diff_step": DIFF_STEP, "xtol": XTOL})
    n_fine = 0
    if found is not None:  # a better point: the verdict machinery again, on it
        check, outcome, n_fine = _verdicts_again(problem, run, found, check, base)
    full = shares(problem, run.evaluated, run.fits, run.left())
    res = assemble(problem, run.fits, dataclasses.replace(outcome, wall=time.perf_counter() - t_wall))
    n_runs = (sum(r.n_runs for e in run.evaluated for r in e.readings) + sum(r.n_runs for r in full if r is not None)
              + (check.n_runs if check is not None else 0) + n_period + n_fine)
    lines = attractor_lines(run.evaluated, full, [f.V for f in run.fits])
    return dataclasses.replace(res, n_evaluations=n_runs, attractors=lines,
                               verdicts={k: f"{v}; {'; '.join(lines)}" for k, v in res.verdicts.items()})


def _verdicts_again(problem: Problem, run: _Search, found: Outcome, former: ReplicateCheck | None,
                    base: list) -> tuple[ReplicateCheck | None, Outcome, int]:
    """The neighbours' check (from the first pass's σ, ``base``), the valley walk and the period check on the
    second pass's better point ``found``: the check kept, the outcome and the runs to count beyond the evaluated
    points' (the period check's, and the former check's where a new one replaced it)."""
    run.fits = base
    check, outcome = _replicated(problem, run, found)
    if check is None and former is not None:  # the budget spent before the check: the former σ kept
        check, run.fits = former, former.fits
        outcome = dataclasses.replace(outcome, replicate=(former.chi2, former.n_stat), chi2_noise=former.chi2_sd)
    outcome = _walked(problem, run, outcome)
    outcome, n_more = _period_checked(problem, run, outcome)
    return check, outcome, n_more + (former.n_runs if former is not None and former is not check else 0)


def _replicated(problem: Problem, run: _Search, outcome: Outcome) -> tuple[ReplicateCheck | None, Outcome]:
    """The neighbours' check of an aperiodic fit (:func:`replicate_check`): the fits' σ joined by the spread (set
    on ``run``) and the outcome with its χ², its noise and a note; ``(None, outcome)`` for a periodic fit."""
    check = replicate_check(problem, run.evaluated, run.fits, run.left())
    if check is None:
        return None, outcome
    run.fits = check.fits
    note = (f"an aperiodic fit: each statistic's sigma joined by its spread over the best point and its "
            f"{2 * len(problem.names)} neighbours; chi2 at those neighbours {fmt_number(100 * JITTER, 2)} % away "
            f"= {fmt_number(check.chi2, 4)} on {check.n_stat} statistics, from neighbour to neighbour "
            f"± {fmt_number(check.chi2_sd, 3)} (the profile's threshold widened by twice that)")
    return check, dataclasses.replace(outcome, replicate=(check.chi2, check.n_stat), chi2_noise=check.chi2_sd,
                                      notes=outcome.notes + (note,))


def _walked(problem: Problem, run: _Search, outcome: Outcome) -> Outcome:
    """The valley walk (``exact/dynamics/_infer_valley.py``) where the search would call a parameter identified:
    its points join ``run.evaluated`` (the outcome's list) and a note says what it found.  A fit identifying
    nothing is left as it is (the walk could only widen its intervals)."""
    if outcome.spacing is None or not any(assemble(problem, run.fits, outcome).identified.values()):
        return outcome
    dof = outcome.n_obs - len(problem.names)

    def threshold() -> float:
        low = min(e.chi2 for e in run.evaluated)
        return low + 3.84 * (max(1.0, low / dof) if dof > 0 else 1.0) + 2.0 * outcome.chi2_noise

    def evaluate(x: np.ndarray) -> np.ndarray | None:
        try:
            return run.residuals(x)
        except _Spent:
            return None

    def residual_of(e: Point) -> np.ndarray:
        return np.concatenate([f.data.residuals(m, problem.sel, PENALTY) for m, f in zip(e.models, run.fits)])

    before = best(run.evaluated)
    walk = valley_walk(problem.names, run.evaluated, evaluate, residual_of, outcome.spacing, outcome.box, threshold)
    after = best(run.evaluated)
    names = problem.names
    # both Jacobians are at the former best where the walk moved it (a few steps along the valley): both kept, the
    # union of their intervals counts (a local curvature of the same valley; dropping one could only narrow it)
    jac, coarse, n_runs = outcome.jac, walk.jac, walk.n_runs
    note = (f"the valley walk before a verdict: {n_runs} runs (the residuals at a quarter of the grid's "
            f"spacing along each parameter, then up to {VALLEY_STEPS} such steps each way along the least-curved "
            f"direction of chi2, {walk.reach[0]} and {walk.reach[1]} taken; the Jacobian of those residuals joins "
            "the 95 % intervals)")
    if walk.moved:
        note += (": it found a better point, " + ", ".join(f"{n} = {fmt_number(v, 5)}" for n, v in
                                                         zip(names, values_of(names, after.x)))
                 + f" (chi2 {fmt_number(after.chi2, 4)} against {fmt_number(before.chi2, 4)}); both Jacobians are "
                 "the former best's")
    status, message = outcome.status, outcome.message
    if n_runs and run.left() <= 0:
        status, message = "budget", f"max_wall = {fmt_number(run.max_wall, 3)} s spent; the best point so far"
    return dataclasses.replace(outcome, notes=outcome.notes + (note,), status=status, message=message,
                               walk=n_runs, jac=jac, coarse=coarse)


def _period_checked(problem: Problem, run: _Search, outcome: Outcome) -> tuple[Outcome, int]:
    """The period check at the best point (``period_check``): where the fit's attractor and the data are both
    periodic of clearly different periods, the outcome says so (nothing is then identified) with a note; and the
    runs it spent."""
    periods, n_runs = period_check(problem, run.evaluated, run.fits, run.left())
    if not periods:
        return outcome, n_runs
    note = (f"the period check: {'; '.join(periods)}; each period read by ForceSeries.observables at the tolerance "
            "of the series' noise (the model's trace noised like the data): nothing identified")
    return dataclasses.replace(outcome, periods=periods, notes=outcome.notes + (note,)), n_runs


def _progress(progress: Callable[[str], None] | bool | None) -> Callable[[str], None] | None:
    """``infer``'s ``progress`` as a callable or None (True: lines on stderr)."""
    if progress is True:
        def say(line: str) -> None:
            print(line, file=sys.stderr, flush=True)
        return say
    if progress is False or progress is None:
        return None
    if not callable(progress):
        raise TypeError(f"progress must be a callable, True, False or None, got {type(progress).__name__}")
    return progress


def _prepare(series: ForceSeries, params0: PeelParams, free: Sequence[str], more: Sequence[ForceSeries],
             statistics: Sequence[str], *, search: float, t_transient: float, rtol: float, max_wall: float,
             attractors: int, replicates: int, executor: Any, max_workers: int | None
             ) -> tuple[Problem, list[SeriesFit], tuple[str, ...], int, np.ndarray, tuple[np.ndarray, np.ndarray]]:
    """``infer``'s arguments checked (each error names its argument) and the data read: the problem, the
    series with their statistics, the notes, the number of fitted statistics, the start in fitted coordinates
    and the limits of :data:`peelapprox.PARAM_RANGES` in them."""
    if not isinstance(params0, PeelParams):
        raise TypeError(f"params0 must be a PeelParams, got {type(params0).__name__}")
    all_series = [series, *more]
    for s in all_series:
        if not isinstance(s, ForceSeries):
            raise TypeError(f"series and more must be ForceSeries, got {type(s).__name__}")
    names = free_names(params0, free)
    if isinstance(statistics, str) or not isinstance(statistics, Sequence) or not statistics:
        raise TypeError(f"statistics must be a non-empty sequence of names from {STATISTICS}, got {statistics!r}")
    sel = np.array([STATISTICS.index(choice("statistics", n, STATISTICS)) for n in statistics])
    if len(set(sel.tolist())) != sel.size:
        raise ValueError(f"statistics: a name is given twice in {tuple(statistics)!r}")
    positive("max_wall", max_wall)
    search = positive("search", search, hi=100.0)
    if search <= 1.0:
        raise ValueError(f"search must be in (1, 100], got {search!r}")
    t_transient = positive("t_transient", t_transient, hi=1e4)
    optional(integer, "max_workers", max_workers, 0)
    if not (executor is None or executor in POOL_KINDS or callable(getattr(executor, "submit", None))):
        raise ValueError(f"executor must be None, one of {POOL_KINDS} or a concurrent.futures.Executor, got "
                         f"{executor!r}")
    if isinstance(attractors, bool) or not isinstance(attractors, (int, np.integer)) or not 1 <= attractors <= 8:
        raise ValueError(f"attractors must be an integer in [1, 8], got {attractors!r}")
    if isinstance(replicates, bool) or not isinstance(replicates, (int, np.integer)) or not 1 <= replicates <= 8:
        raise ValueError(f"replicates must be an integer in [1, 8], got {replicates!r}")
    data = [data_statistics(s) for s in all_series]
    notes = tuple(f"f_cycle is not fitted at V = {fmt_number(float(s.V), 4)} m/s: no line of a period-n cycle "
                  "stands out of its periodogram (a period-1 trace)"
                  for s, d in zip(all_series, data) if s.V is not None and not d.used[_F_CYCLE] and _F_CYCLE in sel)
    problem = Problem(params0, tuple(names), sel, t_transient, rtol, int(attractors), int(replicates))
    fits = [SeriesFit(s, float(s.V), d, s.observables().period is None)  # all have V (data_statistics)
            for s, d in zip(all_series, data) if s.V is not None]
    n_obs = n_fitted(problem, fits)
    if n_obs < len(names):
        raise ValueError(f"statistics: {n_obs} fitted statistic(s) for {len(names)} free parameter(s) "
                         f"{tuple(names)}: give more statistics or more series"
                         + (f" ({notes[0]})" if notes else ""))
    coefs = dict(params0.force.coefficients) if params0.force.kind == "family" else {}
    x0 = np.array([math.log(getattr(params0, n)) if n in LOG else coefs[n[6:]] for n in names])
    lo = np.array([math.log(PARAM_RANGES[n][0]) if n in LOG else -np.inf for n in names])
    hi = np.array([math.log(PARAM_RANGES[n][1]) if n in LOG else np.inf for n in names])
    return problem, fits, notes, n_obs, np.clip(x0, lo, hi), (lo, hi)


class _Spent(Exception):
    """``max_wall`` is spent."""


class _Search:
    """One call's search: the points evaluated (:class:`Point`, in the order evaluated), the series' current
    statistics (an aperiodic series' σ grows by the replicate spread after the first grid) and the budget."""

    def __init__(self, problem: Problem, fits: list[SeriesFit], t_wall: float, max_wall: float,
                 progress: Callable[[str], None] | None, executor: str | Executor | None, max_workers: int | None):
        self.problem, self.fits = problem, fits
        self.t_wall, self.max_wall = t_wall, max_wall
        self.progress, self.executor, self.max_workers = progress, executor, max_workers
        self.evaluated: list[Point] = []

    def left(self) -> float:
        """Seconds of ``max_wall`` left."""
        return self.max_wall - (time.perf_counter() - self.t_wall)

    def record(self, x: np.ndarray, res: np.ndarray, models: list, readings: list) -> np.ndarray:
        """Keep a point evaluated (and say so); returns its residuals."""
        self.evaluated.append(Point(np.array(x), float(res @ res), models, readings))
        if self.progress is not None:
            names = self.problem.names
            self.progress(f"infer: run {len(self.evaluated)}, chi2 = {fmt_number(self.evaluated[-1].chi2, 4)} at "
                          + ", ".join(f"{n} = {fmt_number(v, 5)}" for n, v in zip(names, values_of(names, x))))
        return res

    def residuals(self, x: np.ndarray) -> np.ndarray:
        """The residuals at ``x``, run here (the least-squares fit's function); :class:`_Spent` past the budget."""
        left = self.left()
        if left <= 0:
            raise _Spent
        return self.record(x, *residuals(self.problem, self.fits, x, left))

    def run_nodes(self, points: list[np.ndarray]) -> None:
        """The nodes' runs, independent: on the pool, then recorded in node order (the fit's starts, its ties
        included, are those of a serial grid)."""
        deadline = time.time() + self.left()
        found: dict[int, tuple | None] = {}
        map_points(grid_point, [(k, (self.problem, self.fits, x, deadline)) for k, x in enumerate(points)],
                   found.__setitem__, pool=AUTO if self.executor is None else self.executor,
                   max_workers=self.max_workers, deadline=deadline)
        for k, x in enumerate(points):
            value = found.get(k)
            if value is not None:
                self.record(x, *value)
            else:  # not begun by the budget's end (_Spent here), or lost: run here, raising what a serial run would
                self.residuals(x)

    def fit(self, box_lo: np.ndarray, box_hi: np.ndarray, n_obs: int) -> Any:
        """The least-squares fit from the best evaluated points (at most :data:`N_STARTS`) in the box: the best."""
        from scipy.optimize import least_squares
        from scipy.stats import chi2 as chi2_dist

        top = None
        for e in sorted(self.evaluated, key=lambda e: e.chi2)[:N_STARTS]:
            sol = least_squares(self.residuals, np.clip(e.x, box_lo, box_hi), bounds=(box_lo, box_hi),
                                diff_step=DIFF_STEP, xtol=XTOL, max_nfev=100)
            if top is None or sol.cost < top.cost:
                top = sol
            if chi2_dist.sf(2.0 * top.cost, max(n_obs - len(self.problem.names), 1)) >= GOOD_FIT:
                break
        assert top is not None  # the grid has at least 3 points
        return top

    def run(self, x0: np.ndarray, limits: tuple[np.ndarray, np.ndarray], search: float, n_obs: int,
            notes: tuple[str, ...]) -> Outcome:
        """Grid, fit, and the box extended while the 95 % interval reaches its edge (module docstring)."""
        names = self.problem.names
        axes, box_lo, box_hi = grid(names, x0, limits[0], limits[1], search, len(self.fits))
        first = axes
        status, message, jac, n_extended = "converged", "", None, 0
        aperiodic = [f.aperiodic for f in self.fits]
        try:
            while True:
                self.run_nodes([x for x in nodes(axes)
                                if not any(np.allclose(x, e.x, rtol=0.0, atol=1e-9) for e in self.evaluated)])
                if n_extended == 0 and any(aperiodic):
                    self.fits, n_obs, extra = replicated(self.problem, self.evaluated, self.fits, self.left())
                    notes += extra
                if n_extended == 0 and REFINE_TOP:
                    self.run_nodes([x for x in refine(axes, self.evaluated, (box_lo, box_hi), REFINE_TOP)
                                    if not any(np.allclose(x, e.x, rtol=0.0, atol=1e-9) for e in self.evaluated)])
                top = self.fit(box_lo, box_hi, n_obs)
                jac, status, message = top.jac, "converged" if top.success else "failed", str(top.message)
                if n_extended >= MAX_EXTEND:
                    break
                sides = edge_sides(names, self.evaluated, jac, n_obs, (box_lo, box_hi), limits)
                if not sides:
                    break
                axes, box_lo, box_hi = extend(names, axes, box_lo, box_hi, sides, limits, search)
                n_extended += 1
                if self.progress is not None:
                    self.progress("infer: points as good as the best reach the edge of the search; the box extended "
                                  "to " + ", ".join(f"{n} in [{fmt_number(a, 4)}, {fmt_number(b, 4)}]" for n, a, b in
                                                    zip(names, values_of(names, box_lo), values_of(names, box_hi))))
        except _Spent:
            status, message = "budget", f"max_wall = {fmt_number(self.max_wall, 3)} s spent; the best point so far"
        if n_extended:
            message += f" (the search box extended {n_extended} time(s): the best points reached its edge)"
        resolution = None
        if any(aperiodic):  # the search's finest spacing: refine's quarter of the first grid's (Outcome.resolution)
            resolution = 0.25 * np.array([float(a[1] - a[0]) if a.size > 1 else 0.0 for a in first])
            notes += ("an aperiodic fit: each 95 % interval at least the search's finest spacing (a quarter of the "
                      "grid's), below which an aperiodic trace's chi2 is a comb of windows",)
        spacing = np.array([float(a[1] - a[0]) if a.size > 1 else 0.0 for a in first])
        return Outcome(self.evaluated, jac, (box_lo, box_hi), n_obs, status, message,
                       time.perf_counter() - self.t_wall, notes, GOOD_FIT if any(aperiodic) else POOR_FIT,
                       resolution=resolution, spacing=spacing)

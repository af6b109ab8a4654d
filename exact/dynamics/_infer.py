"""Parameters from data: the model's parameters whose force trace reads like the measured one.

:func:`infer` adjusts the free parameters of a :class:`peelapprox.PeelParams` (I, k, R, a family law's
coefficients) until the exact model's force trace, sampled like the measured :class:`peelapprox.ForceSeries`
and read by the same slip detector with the same threshold, gives the same statistics, at one pull speed or
several (one series per V).

* **Statistics and residuals** (``exact/dynamics/_infer_stats.py``): seven statistics of the trace, the model's
  read off an exact run sampled, noised and detected as the data were; residuals ``(model - data) / σ``.
* **The attractor set.**  At each trial point the statistics are those of the attractor closest to the data
  among those reached from the first ``attractors`` starts of :func:`exact.attractor_set`'s design
  (:func:`set_statistics`); at the best point the whole design runs once to name that attractor and its share
  (:attr:`Inference.attractors`).  For an aperiodic series the model's spread over replicates at the best grid
  point joins each σ and the cycle line is kept only where it is stable across them (:func:`replicate_spread`).
* **Search, then fit.**  An attractor's statistics are not smooth in the parameters (periodic windows,
  coexisting attractors), so a local fit alone finds a nearby minimum with an overconfident interval.  First
  a grid over ``params0 / search`` to ``params0 · search`` (ln θ for I, k, R; ±30 % for coefficients; at most
  :data:`GRID_RUNS` points per series), then :func:`scipy.optimize.least_squares` from the grid's best point,
  and from the next best ones (:data:`STARTS` in all) while the fit's χ² is improbable (:data:`GOOD_FIT`).
  Where the 95 % interval (below) reaches a side of the box, that side moves out by the initial half-width (at
  the grid's node spacing, within :data:`peelapprox.PARAM_RANGES`), the new nodes are evaluated and the fit
  repeated, at most :data:`MAX_EXTEND` times: a verdict "the edge of the search" then means the data, not the
  box.
* **Intervals.**  95 %, the union of two: the profile of every evaluated point (the parameter's range among the
  points with χ² ≤ χ²_min + 3.84 · s, s = max(1, χ²_min/dof)) and the Jacobian's at the optimum (±1.96
  standard errors of ``s (JᵀJ)⁻¹``).  A parameter is *not identified* when that interval spans more than a
  factor 2 (log-fitted) or its value (coefficients), or reaches the edge of the search: the data do not
  determine it, and the report says so instead of quoting a number.  None is identified when the best fit is
  poor (χ² improbable at :data:`POOR_FIT`, at :data:`GOOD_FIT` where a series is aperiodic): the model describes
  the data nowhere in the search.
"""

from __future__ import annotations

import dataclasses
import math
import sys
import time
from collections.abc import Callable, Sequence
from concurrent.futures import Executor
from dataclasses import dataclass
from typing import Any

import numpy as np

from peelapprox import PARAM_RANGES, ForceSeries, PeelParams
from peelapprox.io import fmt_number, jsonable
from peelapprox.parallel import AUTO, POOL_KINDS, map_points
from peelapprox.validate import choice, integer, optional, positive

from ._infer_stats import OBSERVABLES, REPEATABILITY, SetReading, data_statistics, replicate_spread, set_statistics

__all__ = ["DIFF_STEP", "GOOD_FIT", "GRID_RUNS", "Inference", "MAX_EXTEND", "POOR_FIT", "STARTS", "infer"]

#: The most grid points of the search per series (an odd number per axis, params0 at the centre: 9 x 9 for two
#: parameters).
GRID_RUNS = 81
#: Below this probability of χ² (given its degrees of freedom) the model does not describe the data at any
#: point evaluated, and no parameter is called identified.
#: ... and below :data:`GOOD_FIT` where a series is aperiodic: its σ rests on a few model replicates
#: (``replicate_spread``), and at V = 1.82 m/s, I = 2.37e-4 (chaotic) a fit with probability 0.023 sat at I
#: 2.9 times the truth, its interval excluding it.
POOR_FIT = 1e-3
#: Relative step of the forward-difference Jacobian.
DIFF_STEP = 1e-3
#: The least-squares fit starts from the best grid point, then from the next best ones (at most this many starts
#: in all) while its χ² is improbable at :data:`GOOD_FIT`: on a comb of periodic windows a local fit from the
#: best node can end in a neighbouring window (V = 1, I = 1e-2: χ² = 18.8 on 5 dof at I -3 %, k -2 %, where the
#: truth gives 0.01).
STARTS = 3
#: The most times the search box is extended (each side the 95 % interval reaches moved out by the initial
#: half-width, within :data:`peelapprox.PARAM_RANGES`) before a verdict: a start a factor 3 off puts the truth
#: on the initial box's edge, and "not identified: the edge of the search" would then describe the box, not the
#: data.
MAX_EXTEND = 3
#: The χ² probability from which a fit needs no further start (:data:`STARTS`).
GOOD_FIT = 0.05
#: The parameters fitted in ln θ (positive, spanning decades); the others, a law's coefficients, in θ.
_LOG = ("I", "k", "R")
#: A residual for a model run that does not stick-slip or breaks down: far outside any σ.
_PENALTY = 1e3
_F_CYCLE = OBSERVABLES.index("f_cycle")


@dataclass(frozen=True)
class Inference:
    """What :func:`infer` found.

    Attributes
    ----------
    params : PeelParams
        ``params0`` with the fitted values (its V that of the first series).
    values, stderr : dict
        Fitted value and standard error of each free parameter: **for I, k and R the standard error of ln θ**
        (a relative error: 0.0257 is 2.6 %); :attr:`stderr_abs` gives every one in its parameter's units.
    intervals : dict
        95 % interval ``(low, high)`` of each free parameter.
    identified : dict
        Whether the data determine each free parameter (module docstring), and ``verdicts`` the sentence why.
    residuals : list of dict
        Per series and observable: V, observable, data, sigma, model, normalised residual.
    chi2, dof : float, int
        Σ residual² at the optimum and observables minus free parameters.
    status, message : str
        ``"converged"``, ``"budget"`` (``max_wall`` spent: the best point so far) or ``"failed"``; why.
    n_evaluations : int
        Exact attractor runs.
    wall_time : float
        Seconds.
    notes : tuple of str
        What was left out and why (a statistic a series does not carry).
    attractors : tuple of str
        Per series, the attractor of the best point's set the fit is on: its label, the start that reaches it
        and its share of the set's starts (:func:`exact.attractor_set`'s design).
    """

    params: PeelParams
    values: dict[str, float]
    stderr: dict[str, float | None]
    intervals: dict[str, tuple[float, float] | None]
    identified: dict[str, bool]
    verdicts: dict[str, str]
    residuals: list[dict[str, Any]]
    chi2: float
    dof: int
    status: str
    message: str
    n_evaluations: int
    wall_time: float
    notes: tuple[str, ...] = ()
    attractors: tuple[str, ...] = ()

    @property
    def stderr_abs(self) -> dict[str, float | None]:
        """The standard error of each free parameter in its own units (I, k, R: value times the error of ln θ,
        to first order; a coefficient's as it is)."""
        out: dict[str, float | None] = {}
        for name, se in self.stderr.items():
            out[name] = None if se is None else (abs(self.values[name]) * se if name in _LOG else se)
        return out

    def __repr__(self) -> str:
        vals = ", ".join(f"{n}={fmt_number(v, 5)}" for n, v in self.values.items())
        se = ", ".join(f"{n}: {'None' if x is None else fmt_number(x, 3)}" for n, x in self.stderr.items())
        return (f"Inference({self.status}: {vals}; stderr of ln I, k, R (relative) / of a coefficient {{{se}}}; "
                f"chi2 {fmt_number(self.chi2, 4)} on {self.dof} dof, {self.n_evaluations} runs)")

    def report(self) -> str:
        """A plain-text report: each parameter with its interval or why it is not identified, the fit's χ²
        and the residual table."""
        lines = [f"infer: {self.status} ({self.message}); {self.n_evaluations} exact runs, "
                 f"{fmt_number(self.wall_time, 3)} s; chi2 = {fmt_number(self.chi2, 4)} on {self.dof} dof"]
        for name, value in self.values.items():
            iv = self.intervals[name]
            span = "" if iv is None else f", 95 % in [{fmt_number(iv[0], 4)}, {fmt_number(iv[1], 4)}]"
            sa = self.stderr_abs[name]
            se = "" if sa is None else f" ± {fmt_number(sa, 3)} (standard error)"
            lines.append(f"  {name} = {fmt_number(value, 5)}{se}{span}: {self.verdicts[name]}")
        lines += [f"  attractor: {a}" for a in self.attractors]
        lines += [f"  note: {n}" for n in self.notes]
        for r in self.residuals:
            lines.append(f"  V = {fmt_number(r['V'], 4)} m/s {r['observable']}: data {fmt_number(r['data'], 5)} "
                         f"± {fmt_number(r['sigma'], 2)}, model {fmt_number(r['model'], 5)}, "
                         f"residual {fmt_number(r['residual'], 3)}")
        return "\n".join(lines)

    def as_dict(self) -> dict[str, Any]:
        """The result as plain JSON data (``params`` as its fields)."""
        import dataclasses

        d = {f.name: getattr(self, f.name) for f in dataclasses.fields(self) if f.name != "params"}
        return jsonable({**d, "params": dataclasses.asdict(self.params)})

    def plot(self, ax: Any = None) -> Any:
        """Model against data: each observable's data (with its σ) and the fitted model, per series, as
        model/data - 1 [%]; returns the axes."""
        from peelapprox.plotting import pyplot

        plt = pyplot()
        if ax is None:
            _, ax = plt.subplots(figsize=(6, 3.5))
        xs = np.arange(len(self.residuals))
        rel = [100 * (r["model"] / r["data"] - 1) if r["data"] else 0.0 for r in self.residuals]
        err = [100 * r["sigma"] / abs(r["data"]) if r["data"] else 0.0 for r in self.residuals]
        ax.axhline(0.0, color="0.6", lw=0.8)
        ax.errorbar(xs, np.zeros_like(xs, dtype=float), yerr=err, fmt="none", ecolor="0.4", capsize=3,
                    label="data ± σ")
        ax.plot(xs, rel, "o", color="C3", label="fitted model")
        ax.set_xticks(xs, [f"{r['observable']}\nV={fmt_number(r['V'], 3)}" for r in self.residuals], fontsize=7)
        ax.set_ylabel("model / data − 1 [%]")
        fitted = ", ".join(f"{k} = {fmt_number(v, 4)}" for k, v in self.values.items())
        ax.set_title(f"infer: {fitted} (χ² = {fmt_number(self.chi2, 3)}, {self.dof} dof)", fontsize=9)
        ax.legend(fontsize=8)
        return ax


def _free_names(params0: PeelParams, free: Sequence[str]) -> list[str]:
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
        elif name not in _LOG:
            raise ValueError(f"free: {name!r} is not a fitted parameter; choose from I, k, R, force.<coefficient>")
        if name in out:
            raise ValueError(f"free: {name!r} is given twice")
        out.append(name)
    return out


def _apply(params0: PeelParams, names: list[str], x: np.ndarray, V: float) -> PeelParams:
    """``params0`` at pull speed V with the free parameters at ``x`` (ln θ for I, k, R)."""
    changes: dict[str, Any] = {"V": V}
    coefs = dict(params0.force.coefficients) if params0.force.kind == "family" else {}
    for name, xi in zip(names, x):
        if name in _LOG:
            changes[name] = math.exp(float(xi))
        else:
            coefs[name[6:]] = float(xi)
    if any(n.startswith("force.") for n in names):
        changes["force"] = type(params0.force).family(str(params0.force.name), **coefs)
    return params0.replace(**changes)


def _grid(names: list[str], x0: np.ndarray, lo: np.ndarray, hi: np.ndarray, search: float, n_series: int
          ) -> tuple[list[np.ndarray], np.ndarray, np.ndarray]:
    """The search grid's nodes per axis (module docstring) and its box ``(low, high)`` per parameter, in fitted
    coordinates."""
    half = np.array([math.log(search) if n in _LOG else 0.3 * max(abs(x), 1e-12) for n, x in zip(names, x0)])
    box_lo, box_hi = np.maximum(x0 - half, lo), np.minimum(x0 + half, hi)
    per = max(3, int(math.floor((GRID_RUNS / max(n_series, 1)) ** (1.0 / len(names)) + 1e-9)))
    per = min(per - (per % 2 == 0), 9)  # odd: params0 is a node
    return [np.linspace(a, b, per) for a, b in zip(box_lo, box_hi)], box_lo, box_hi


def _nodes(axes: list[np.ndarray]) -> np.ndarray:
    """Every point of the grid whose nodes per axis are ``axes``."""
    return np.array(np.meshgrid(*axes, indexing="ij")).reshape(len(axes), -1).T


def _spans(names: list[str], evaluated: list, jac: np.ndarray | None, n_obs: int
           ) -> tuple[np.ndarray, float, float, np.ndarray, np.ndarray, np.ndarray | None]:
    """The best evaluated point, its χ², the scale s, the 95 % interval ``(low, high)`` per parameter in fitted
    coordinates (module docstring: the union of the profile and the Jacobian's) and the covariance (or None)."""
    dof = n_obs - len(names)
    x, chi2 = min(evaluated, key=lambda e: e[1])[:2]
    s = max(1.0, chi2 / dof) if dof > 0 else 1.0
    accept = np.array([e[0] for e in evaluated if e[1] <= chi2 + 3.84 * s])
    lo_, hi_ = accept.min(axis=0), accept.max(axis=0)
    cov = None if jac is None else np.linalg.pinv(jac.T @ jac) * s
    if cov is not None:
        for i in range(len(names)):
            if math.isfinite(float(cov[i, i])) and cov[i, i] > 0:
                se = math.sqrt(float(cov[i, i]))
                lo_[i], hi_[i] = min(lo_[i], x[i] - 1.96 * se), max(hi_[i], x[i] + 1.96 * se)
    return np.asarray(x), float(chi2), s, lo_, hi_, cov


def _edge_sides(names: list[str], evaluated: list, jac: np.ndarray | None, n_obs: int, box: tuple,
                limits: tuple) -> list[tuple[int, int]]:
    """The box's sides ``(parameter index, -1 low / +1 high)`` that the 95 % interval reaches and that can still
    move outwards within :data:`peelapprox.PARAM_RANGES`."""
    _, _, _, lo_, hi_, _ = _spans(names, evaluated, jac, n_obs)
    out = []
    for i in range(len(names)):
        if lo_[i] <= box[0][i] + 1e-12 and box[0][i] > limits[0][i] + 1e-12:
            out.append((i, -1))
        if hi_[i] >= box[1][i] - 1e-12 and box[1][i] < limits[1][i] - 1e-12:
            out.append((i, 1))
    return out


def _extend(names: list[str], axes: list[np.ndarray], box_lo: np.ndarray, box_hi: np.ndarray,
            sides: list[tuple[int, int]], limits: tuple, search: float
            ) -> tuple[list[np.ndarray], np.ndarray, np.ndarray]:
    """The grid with each side in ``sides`` moved outwards by the initial half-width (a factor ``search`` for
    I, k, R; 30 % of the value for a coefficient), within the limits, at the axis' node spacing: the new nodes
    with the other axes' nodes are the points evaluated next."""
    axes, box_lo, box_hi = [a.copy() for a in axes], box_lo.copy(), box_hi.copy()
    for i, side in sides:
        a = axes[i]
        step = float(a[1] - a[0]) if a.size > 1 else 0.1
        width = math.log(search) if names[i] in _LOG else 0.3 * max(abs(float(a[a.size // 2])), 1e-12)
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


def infer(series: ForceSeries, params0: PeelParams, free: Sequence[str] = ("I", "k"), *,
          more: Sequence[ForceSeries] = (), statistics: Sequence[str] = OBSERVABLES, search: float = 3.0,
          t_transient: float = 30.0, rtol: float = 1e-10, max_wall: float = 600.0, attractors: int = 1,
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
        The statistics fitted, a subset of :data:`OBSERVABLES` (all).  Where coexisting attractors make the
        period, and with it the cycle frequency and the means over a cycle, jump between neighbouring parameter
        values (low inertia), the per-stick statistics ``("rise", "F_start", "force_drop")`` vary smoothly.
    search : float
        The grid spans ``params0 / search`` to ``params0 · search`` for I, k and R (±30 % for coefficients),
        within :data:`peelapprox.PARAM_RANGES`; in (1, 100] (3).
    t_transient : float
        Seconds of each model run before its sampled window, in (0, 1e4] (30).
    rtol : float
        Of every model run (1e-10).
    max_wall : float
        Wall-clock budget [s] (600): at its end the best point so far is returned with status ``"budget"``.
    attractors : int
        At each trial point, the statistics are those of the attractor closest to the data among those reached
        from the first ``attractors`` starts of :func:`exact.attractor_set`'s design (the solver's start first;
        the further starts run only while none fits within 3 σ), in [1, 8]; 1 (the default): the solver's start
        alone; 3 is the opt-in for multistable traces (docs/your-data.md; measured not yet to rescue the needle
        basin at V = 1, I = 1e-5).
        At the best point every start of the design runs once, to name the attractor and its share.
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
    from scipy.optimize import least_squares
    from scipy.stats import chi2 as chi2_dist

    t_wall = time.perf_counter()
    if progress is True:
        def progress(line: str) -> None:
            print(line, file=sys.stderr, flush=True)
    elif progress is False:
        progress = None
    elif progress is not None and not callable(progress):
        raise TypeError(f"progress must be a callable, True, False or None, got {type(progress).__name__}")
    if not isinstance(params0, PeelParams):
        raise TypeError(f"params0 must be a PeelParams, got {type(params0).__name__}")
    all_series = [series, *more]
    for s in all_series:
        if not isinstance(s, ForceSeries):
            raise TypeError(f"series and more must be ForceSeries, got {type(s).__name__}")
    names = _free_names(params0, free)
    if isinstance(statistics, str) or not isinstance(statistics, Sequence) or not statistics:
        raise TypeError(f"statistics must be a non-empty sequence of names from {OBSERVABLES}, got {statistics!r}")
    sel = np.array([OBSERVABLES.index(choice("statistics", n, OBSERVABLES)) for n in statistics])
    if len(set(sel.tolist())) != sel.size:
        raise ValueError(f"statistics: a name is given twice in {tuple(statistics)!r}")
    max_wall = positive("max_wall", max_wall)
    search = positive("search", search, hi=100.0)
    if search <= 1.0:
        raise ValueError(f"search must be in (1, 100], got {search!r}")
    t_transient = positive("t_transient", t_transient, hi=1e4)
    max_workers = optional(integer, "max_workers", max_workers, 0)
    if not (executor is None or executor in POOL_KINDS or callable(getattr(executor, "submit", None))):
        raise ValueError(f"executor must be None, one of {POOL_KINDS} or a concurrent.futures.Executor, got "
                         f"{executor!r}")
    if isinstance(attractors, bool) or not isinstance(attractors, (int, np.integer)) or not 1 <= attractors <= 8:
        raise ValueError(f"attractors must be an integer in [1, 8], got {attractors!r}")
    data = [data_statistics(s) for s in all_series]
    notes = tuple(f"f_cycle is not fitted at V = {fmt_number(float(s.V), 4)} m/s: no line of a period-n cycle "
                  "stands out of its periodogram (a period-1 trace)"
                  for s, d in zip(all_series, data) if s.V is not None and not d[4][_F_CYCLE] and _F_CYCLE in sel)
    n_obs = sum(int(np.count_nonzero(d[4][sel])) for d in data)
    if n_obs < len(names):
        raise ValueError(f"statistics: {n_obs} fitted statistic(s) for {len(names)} free parameter(s) "
                         f"{tuple(names)}: give more statistics or more series"
                         + (f" ({notes[0]})" if notes else ""))
    Vs = [float(s.V) for s in all_series if s.V is not None]  # _data refused a series without V
    coefs = dict(params0.force.coefficients) if params0.force.kind == "family" else {}
    x0 = np.array([math.log(getattr(params0, n)) if n in _LOG else coefs[n[6:]] for n in names])
    lo = np.array([math.log(PARAM_RANGES[n][0]) if n in _LOG else -np.inf for n in names])
    hi = np.array([math.log(PARAM_RANGES[n][1]) if n in _LOG else np.inf for n in names])
    x0 = np.clip(x0, lo, hi)
    evaluated: list[tuple[np.ndarray, float, list, list]] = []

    class _Spent(Exception):
        pass

    def record(x: np.ndarray, res: np.ndarray, models: list, readings: list) -> np.ndarray:
        evaluated.append((np.array(x), float(res @ res), models, readings))
        if progress is not None:
            progress(f"infer: run {len(evaluated)}, chi2 = {fmt_number(evaluated[-1][1], 4)} at "
                     + ", ".join(f"{n} = {fmt_number(v, 5)}" for n, v in zip(names, _values(names, x))))
        return res

    def residuals(x: np.ndarray) -> np.ndarray:
        left = max_wall - (time.perf_counter() - t_wall)
        if left <= 0:
            raise _Spent
        return record(x, *_residuals(params0, names, x, all_series, Vs, data, sel, t_transient, rtol, left,
                                    int(attractors)))

    def run_nodes(nodes: list[np.ndarray]) -> None:
        """The nodes' runs, independent: on the pool, then recorded in node order (the fit's starts, its ties
        included, are those of a serial grid)."""
        deadline = time.time() + max_wall - (time.perf_counter() - t_wall)
        found: dict[int, tuple | None] = {}
        map_points(_grid_point, [(k, (params0, names, x, all_series, Vs, data, sel, t_transient, rtol, deadline,
                                      int(attractors))) for k, x in enumerate(nodes)], found.__setitem__,
                   pool=AUTO if executor is None else executor, max_workers=max_workers, deadline=deadline)
        for k, x in enumerate(nodes):
            value = found.get(k)
            if value is not None:
                record(x, *value)
            else:  # not begun by the budget's end (_Spent here), or lost: run here, raising what a serial run would
                residuals(x)

    axes, box_lo, box_hi = _grid(names, x0, lo, hi, search, len(all_series))
    status, message, jac, n_extended = "converged", "", None, 0
    aperiodic = [s.observables().period is None for s in all_series]
    try:
        while True:
            run_nodes([x for x in _nodes(axes)
                       if not any(np.allclose(x, e[0], rtol=0.0, atol=1e-9) for e in evaluated)])
            if n_extended == 0 and any(aperiodic):
                data, n_obs, extra = _replicated(evaluated, all_series, data, aperiodic, sel, Vs, params0, names,
                                                 t_transient, rtol, max_wall - (time.perf_counter() - t_wall),
                                                 len(names))
                notes += extra
            best = None
            for start, *_ in sorted(evaluated, key=lambda e: e[1])[:STARTS]:
                sol = least_squares(residuals, np.clip(start, box_lo, box_hi), bounds=(box_lo, box_hi),
                                    diff_step=DIFF_STEP, max_nfev=100)
                if best is None or sol.cost < best.cost:
                    best = sol
                if chi2_dist.sf(2.0 * best.cost, max(n_obs - len(names), 1)) >= GOOD_FIT:
                    break
            assert best is not None  # the grid has at least 3 points
            jac = best.jac
            status = "converged" if best.success else "failed"
            message = str(best.message)
            if n_extended >= MAX_EXTEND:
                break
            sides = _edge_sides(names, evaluated, jac, n_obs, (box_lo, box_hi), (lo, hi))
            if not sides:
                break
            axes, box_lo, box_hi = _extend(names, axes, box_lo, box_hi, sides, (lo, hi), search)
            n_extended += 1
            if progress is not None:
                progress("infer: points as good as the best reach the edge of the search; the box extended to "
                         + ", ".join(f"{n} in [{fmt_number(a, 4)}, {fmt_number(b, 4)}]" for n, a, b in
                                     zip(names, _values(names, box_lo), _values(names, box_hi))))
    except _Spent:
        status, message = "budget", f"max_wall = {fmt_number(max_wall, 3)} s spent; the best point so far"
    if n_extended:
        message += (f" (the search box extended {n_extended} time(s): the best points reached its edge)")
    shares = _shares(evaluated, all_series, data, sel, Vs, params0, names, t_transient, rtol,
                     max_wall - (time.perf_counter() - t_wall))
    res = _result(params0, names, sel, jac, evaluated, (box_lo, box_hi), data, Vs, status, message,
                  time.perf_counter() - t_wall, n_obs, notes, GOOD_FIT if any(aperiodic) else POOR_FIT)
    runs = sum(r.n_runs for e in evaluated for r in e[3]) + sum(r.n_runs for r in shares if r is not None)
    names_ = _attractor_lines(evaluated, shares, Vs)
    return dataclasses.replace(res, n_evaluations=runs, attractors=names_,
                               verdicts={k: f"{v}; {'; '.join(names_)}" for k, v in res.verdicts.items()})


def _replicated(evaluated: list, all_series: list, data: list, aperiodic: list[bool], sel: np.ndarray,
                Vs: list[float], params0: PeelParams, names: list[str], t_transient: float, rtol: float, left: float,
                n_free: int) -> tuple[list, int, tuple[str, ...]]:
    """For each aperiodic series, the model's replicate spread at the best grid point (:func:`replicate_spread`)
    added in quadrature to the statistics' σ (a diagonal synthetic likelihood, Wood 2010), and the cycle line
    dropped where it is not stable across the replicates; the χ² of every point evaluated so far recomputed with
    the new σ.  Returns the data, the number of fitted statistics and the notes."""
    x = min(evaluated, key=lambda e: e[1])[0]
    out, notes, t0 = [], [], time.perf_counter()
    for k, (s, V, d) in enumerate(zip(all_series, Vs, data)):
        vals, sig, threshold, noise, used = d
        if not aperiodic[k] or left - (time.perf_counter() - t0) <= 1.0:
            out.append(d)
            continue
        sd, stable, n = replicate_spread(_apply(params0, names, x, V), s, threshold, noise, t_transient, rtol,
                                         left - (time.perf_counter() - t0))
        if sd is None:
            out.append(d)
            continue
        sig, used = np.hypot(sig, sd), used.copy()
        notes.append(f"V = {fmt_number(V, 4)} m/s: an aperiodic trace; the model's spread over {n} replicates "
                     "added to each statistic's sigma")
        if used[_F_CYCLE] and not stable:
            used[_F_CYCLE] = False
            notes.append(f"f_cycle is not fitted at V = {fmt_number(V, 4)} m/s: the model's cycle line is not "
                         f"stable across its replicates (absent in one, or spread over "
                         f"{fmt_number(100 * REPEATABILITY['f_cycle'], 2)} %)")
        out.append((vals, sig, threshold, noise, used))
    n_obs = sum(int(np.count_nonzero(d[4][sel])) for d in out)
    if n_obs < n_free:  # dropping the line would leave too few statistics: keep the former reading
        return data, sum(int(np.count_nonzero(d[4][sel])) for d in data), ()
    for i, e in enumerate(evaluated):
        res = np.concatenate([np.full(int(np.count_nonzero(used[sel])), _PENALTY) if m is None
                              else ((m - vals) / sig)[sel[used[sel]]]
                              for m, (vals, sig, _, _, used) in zip(e[2], out)])
        evaluated[i] = (e[0], float(res @ res), e[2], e[3])
    return out, n_obs, tuple(notes)


def _shares(evaluated: list, all_series: list, data: list, sel: np.ndarray, Vs: list[float], params0: PeelParams,
            names: list[str],
            t_transient: float, rtol: float, left: float) -> list[SetReading | None]:
    """At the best point, per series, the whole design of starts (:func:`set_statistics` with ``share``); None
    where the budget is spent."""
    if not evaluated:
        return []
    x = min(evaluated, key=lambda e: e[1])[0]
    t0, out = time.perf_counter(), list[SetReading | None]()
    for s, V, (vals, sig, threshold, noise, used) in zip(all_series, Vs, data):
        spent = time.perf_counter() - t0
        if left - spent <= 1.0:
            out.append(None)
            continue
        use_mask = np.zeros(len(OBSERVABLES), dtype=bool)
        use_mask[sel[used[sel]]] = True
        out.append(set_statistics(_apply(params0, names, x, V), s, threshold, noise, t_transient, rtol,
                                  left - spent, (vals, sig, use_mask), 8, share=True))
    return out


def _attractor_lines(evaluated: list, shares: list[SetReading | None], Vs: list[float]) -> tuple[str, ...]:
    """Per series, the attractor the best point's statistics are read from, the start reaching it and its
    share of the set's starts."""
    if not evaluated:
        return ()
    best = min(evaluated, key=lambda e: e[1])[3]
    out = []
    padded: list[SetReading | None] = [*shares, *([None] * (len(best) - len(shares)))]
    for V, r, full in zip(Vs, best, padded):
        share = ("its share of the set's starts not measured (max_wall spent)" if full is None or full.share is None
                 else f"share {fmt_number(100 * full.share, 3)} % of the set's {full.n_runs} starts")
        out.append(f"at V = {fmt_number(V, 4)} m/s on the {r.label} attractor (from the start {r.start!r}; {share})")
    return tuple(out)


def _residuals(params0: PeelParams, names: list[str], x: np.ndarray, all_series: list, Vs: list[float],
               data: list, sel: np.ndarray, t_transient: float, rtol: float, left: float, attractors: int
               ) -> tuple[np.ndarray, list[np.ndarray | None], list[SetReading]]:
    """The weighted residuals of the model at ``x`` against every series' statistics, the model's statistics
    per series (None: no stick-slip) and their readings (:func:`set_statistics`: the attractor closest to the
    data among the first ``attractors`` starts), each run bounded by ``left`` seconds (at least 1)."""
    out: list[np.ndarray] = []
    models: list[np.ndarray | None] = []
    readings: list[SetReading] = []
    for s, V, (vals, sig, threshold, noise, used) in zip(all_series, Vs, data):
        use_mask = np.zeros(len(OBSERVABLES), dtype=bool)
        use_mask[sel[used[sel]]] = True
        r = set_statistics(_apply(params0, names, x, V), s, threshold, noise, t_transient, rtol, max(1.0, left),
                           (vals, sig, use_mask), attractors)
        m = r.values
        use = sel[used[sel]]
        out.append(np.full(use.size, _PENALTY) if m is None else ((m - vals) / sig)[use])
        models.append(m)
        readings.append(r)
    return np.concatenate(out), models, readings


def _grid_point(params0: PeelParams, names: list[str], x: np.ndarray, all_series: list, Vs: list[float],
                data: list, sel: np.ndarray, t_transient: float, rtol: float, deadline: float, attractors: int
                ) -> tuple[np.ndarray, list[np.ndarray | None], list[SetReading]] | None:
    """:func:`_residuals` at a grid point as a pool's task; None when the call's ``deadline`` (a
    ``time.time()``) passed before it began."""
    left = deadline - time.time()
    if left <= 0:
        return None
    return _residuals(params0, names, x, all_series, Vs, data, sel, t_transient, rtol, left, attractors)


def _values(names: list[str], x: np.ndarray) -> list[float]:
    return [math.exp(float(xi)) if n in _LOG else float(xi) for n, xi in zip(names, x)]


def _result(params0: PeelParams, names: list[str], sel: np.ndarray, jac: np.ndarray | None, evaluated: list,
            box: tuple,
            data: list, Vs: list[float], status: str, message: str, wall: float, n_obs: int,
            notes: tuple[str, ...], poor_fit: float = POOR_FIT) -> Inference:
    """The :class:`Inference` at the best evaluated point: intervals and verdicts (module docstring)."""
    from scipy.stats import chi2 as chi2_dist

    dof = n_obs - len(names)
    if not evaluated:
        raise ValueError("max_wall was spent before the first model run: give a larger max_wall")
    x, chi2, s, lo_all, hi_all, cov = _spans(names, evaluated, jac, n_obs)
    model = min(evaluated, key=lambda e: e[1])[2]
    # as many statistics as parameters (dof 0) should fit exactly: judge its χ² as on one degree of freedom
    p_fit = float(chi2_dist.sf(chi2, max(dof, 1)))
    poor = p_fit < poor_fit
    values = dict(zip(names, _values(names, x)))
    stderr: dict[str, float | None] = dict.fromkeys(names)
    intervals: dict[str, tuple[float, float] | None] = {}
    identified = dict.fromkeys(names, False)
    verdicts: dict[str, str] = {}
    for i, name in enumerate(names):
        lo_i, hi_i = float(lo_all[i]), float(hi_all[i])
        if cov is not None and math.isfinite(float(cov[i, i])) and cov[i, i] > 0:
            stderr[name] = math.sqrt(float(cov[i, i]))
        edge = lo_i <= box[0][i] + 1e-12 or hi_i >= box[1][i] - 1e-12
        log = name in _LOG
        intervals[name] = (math.exp(lo_i), math.exp(hi_i)) if log else (float(lo_i), float(hi_i))
        narrow = (hi_i - lo_i <= math.log(2.0)) if log else (hi_i - lo_i <= abs(float(x[i])))
        identified[name] = narrow and not edge and not poor
        if poor:
            verdicts[name] = (f"not identified: the best point evaluated fits poorly (chi2 = {fmt_number(chi2, 4)} on "
                              f"{dof} dof, probability {fmt_number(p_fit, 2)}): the model at no point searched "
                              "describes the data")
        elif identified[name]:
            reach = max(x[i] - lo_i, hi_i - x[i])
            verdicts[name] = ((f"identified: 95 % within a factor {fmt_number(math.exp(reach), 3)}" if log
                               else f"identified: 95 % within ± {fmt_number(reach, 3)}")
                              + f" (chi2 = {fmt_number(chi2, 4)} on {dof} dof, probability {fmt_number(p_fit, 2)})")
        elif edge:
            verdicts[name] = ("not identified: points as good as the best reach the edge of the search "
                              f"[{fmt_number(_values([name], np.array([box[0][i]]))[0], 4)}, "
                              f"{fmt_number(_values([name], np.array([box[1][i]]))[0], 4)}]")
        else:
            verdicts[name] = (f"not identified: its 95 % interval spans more than "
                              f"{'a factor 2' if log else 'its value'}")
    residuals = []
    for V, (vals, sig, _, _, used), m in zip(Vs, data, model or [None] * len(data)):
        for j in sel[used[sel]].tolist():
            obs = OBSERVABLES[j]
            mv = None if m is None else float(m[j])
            residuals.append({"V": V, "observable": obs, "data": float(vals[j]), "sigma": float(sig[j]),
                              "model": mv, "residual": None if mv is None else (mv - float(vals[j])) / float(sig[j])})
    return Inference(params=_apply(params0, names, x, Vs[0]), values=values, stderr=stderr, intervals=intervals,
                     identified=identified, verdicts=verdicts, residuals=residuals, chi2=chi2, dof=dof,
                     status=status, message=message, n_evaluations=len(evaluated) * len(data), wall_time=wall,
                     notes=notes)

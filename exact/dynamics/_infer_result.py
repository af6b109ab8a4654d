"""The result of :func:`exact.infer`: :class:`Inference`, and its assembly at the best evaluated point
(:func:`assemble`: intervals and verdicts, ``exact/dynamics/_infer.py``'s docstring)."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from peelapprox import PeelParams
from peelapprox.io import fmt_number, jsonable

from ._infer_search import LOG, Point, Problem, SeriesFit, apply, best, spans, values_of
from ._infer_stats import STATISTICS

__all__ = ["POOR_FIT", "Inference", "Outcome", "assemble"]

#: Below this probability of χ² (given its degrees of freedom) the model does not describe the data at any
#: point evaluated, and no parameter is called identified.
#: ... and below :data:`GOOD_FIT` where a series is aperiodic: its σ rests on a few model replicates
#: (``replicate_spread``), and at V = 1.82 m/s, I = 2.37e-4 (chaotic) a fit with probability 0.023 sat at I
#: 2.9 times the truth, its interval excluding it.
POOR_FIT = 1e-3


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
            out[name] = None if se is None else (abs(self.values[name]) * se if name in LOG else se)
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



@dataclass(frozen=True)
class Outcome:
    """How a search ended, what :func:`assemble` reads.

    Attributes
    ----------
    evaluated : sequence of Point
        Every trial point evaluated.
    jac : ndarray or None
        The last least-squares fit's Jacobian (None: no fit ran).
    box : tuple of ndarray
        The search box ``(low, high)`` in fitted coordinates.
    n_obs : int
        The statistics fitted.
    status, message : str
        As :class:`Inference`'s.
    wall : float
        Seconds.
    notes : tuple of str
        What was left out and why.
    poor_fit : float
        The χ² probability below which no parameter is identified (:data:`POOR_FIT`, or ``GOOD_FIT`` where a
        series is aperiodic).
    replicate : tuple of (float, int) or None
        For a fit with an aperiodic series, the χ² summed over the best point's neighbours and its degrees of
        freedom (``replicate_check`` in ``exact/dynamics/_infer_search.py``): improbable at ``poor_fit``, no
        parameter is identified (the best point was a lucky draw).
    chi2_noise : float
        The standard deviation of χ² over those neighbours (0: periodic series): twice it widens the profile's
        threshold (``spans``).
    resolution : ndarray or None
        For a fit with an aperiodic series, the least half-width of each 95 % interval in fitted coordinates: the
        search's finest spacing (a quarter of the first grid's node spacing, ``refine``).  Between its points an
        aperiodic trace's χ² is a comb of windows, so neither the profile nor the Jacobian resolves finer: at
        V = 0.6854 m/s, I = 2.459e-5 (chaotic) the fit at I -2.7 % had a profile interval of ±1 %.  None: the
        interval as found.
    spacing : ndarray or None
        The first grid's node spacing per axis in fitted coordinates (the valley walk's step is a quarter of it,
        ``exact/dynamics/_infer_valley.py``); None: no walk.
    walk : int
        The valley walk's runs (0: no walk; they are among ``evaluated``).
    coarse : ndarray or None
        The residuals' Jacobian at the best point by central differences at a quarter of the first grid's node
        spacing (the valley walk's probes, at the best point before the walk): its ±1.96 standard errors join the
        95 % interval (``spans``), centred, like ``jac``'s, on the best point after the walk.
    periods : tuple of str
        Where the best point's attractor and the data are both periodic of clearly different periods, the
        sentences saying so (``period_check`` in ``exact/dynamics/_infer_search.py``): no parameter is then
        identified.  ``()``: none.
    """

    evaluated: Sequence[Point]
    jac: np.ndarray | None
    box: tuple[np.ndarray, np.ndarray]
    n_obs: int
    status: str
    message: str
    wall: float
    notes: tuple[str, ...] = ()
    poor_fit: float = POOR_FIT
    replicate: tuple[float, int] | None = None
    chi2_noise: float = 0.0
    resolution: np.ndarray | None = None
    spacing: np.ndarray | None = None
    walk: int = 0
    coarse: np.ndarray | None = None
    periods: tuple[str, ...] = ()


def _verdict(name: str, i: int, x: np.ndarray, lo_i: float, hi_i: float, box: tuple, fit: tuple[float, int, float],
             poor: bool, identified: bool) -> str:
    """The sentence why parameter ``name`` is identified or not; ``fit`` is (χ², dof, its probability)."""
    chi2, dof, p_fit = fit
    log = name in LOG
    if poor:
        return (f"not identified: the best point evaluated fits poorly (chi2 = {fmt_number(chi2, 4)} on "
                f"{dof} dof, probability {fmt_number(p_fit, 2)}): the model at no point searched "
                "describes the data")
    if identified:
        reach = max(x[i] - lo_i, hi_i - x[i])
        return ((f"identified: 95 % within a factor {fmt_number(math.exp(reach), 3)}" if log
                 else f"identified: 95 % within ± {fmt_number(reach, 3)}")
                + f" (chi2 = {fmt_number(chi2, 4)} on {dof} dof, probability {fmt_number(p_fit, 2)})")
    if lo_i <= box[0][i] + 1e-12 or hi_i >= box[1][i] - 1e-12:
        return ("not identified: points as good as the best reach the edge of the search "
                f"[{fmt_number(values_of([name], np.array([box[0][i]]))[0], 4)}, "
                f"{fmt_number(values_of([name], np.array([box[1][i]]))[0], 4)}]")
    return f"not identified: its 95 % interval spans more than {'a factor 2' if log else 'its value'}"


def _residual_rows(problem: Problem, fits: Sequence[SeriesFit], model: list | None) -> list[dict[str, Any]]:
    """Per series and fitted statistic: V, observable, data, sigma, model, normalised residual."""
    rows = []
    for f, m in zip(fits, model or [None] * len(fits)):
        d = f.data
        for j in d.fitted(problem.sel).tolist():
            mv = None if m is None else float(m[j])
            rows.append({"V": f.V, "observable": STATISTICS[j], "data": float(d.values[j]),
                         "sigma": float(d.sigma[j]), "model": mv,
                         "residual": None if mv is None else (mv - float(d.values[j])) / float(d.sigma[j])})
    return rows


def assemble(problem: Problem, fits: Sequence[SeriesFit], outcome: Outcome) -> Inference:
    """The :class:`Inference` at the best evaluated point: intervals and verdicts (``exact/dynamics/_infer.py``'s
    docstring)."""
    from scipy.stats import chi2 as chi2_dist

    names, box = problem.names, outcome.box
    dof = outcome.n_obs - len(names)
    if not outcome.evaluated:
        raise ValueError("max_wall was spent before the first model run: give a larger max_wall")
    x, chi2, s, lo_all, hi_all, cov = spans(names, outcome.evaluated, outcome.jac, outcome.n_obs, outcome.chi2_noise,
                                            outcome.coarse)
    # as many statistics as parameters (dof 0) should fit exactly: judge its χ² as on one degree of freedom
    p_fit = float(chi2_dist.sf(chi2, max(dof, 1)))
    poor = p_fit < outcome.poor_fit
    if outcome.replicate is not None and not poor:
        p_rep = float(chi2_dist.sf(outcome.replicate[0], max(outcome.replicate[1], 1)))
        if p_rep < outcome.poor_fit:
            poor, chi2_rep = True, outcome.replicate
    stderr: dict[str, float | None] = dict.fromkeys(names)
    intervals: dict[str, tuple[float, float] | None] = {}
    identified = dict.fromkeys(names, False)
    verdicts: dict[str, str] = {}
    for i, name in enumerate(names):
        lo_i, hi_i = float(lo_all[i]), float(hi_all[i])
        if cov is not None and math.isfinite(float(cov[i, i])) and cov[i, i] > 0:
            stderr[name] = math.sqrt(float(cov[i, i]))
        edge = lo_i <= box[0][i] + 1e-12 or hi_i >= box[1][i] - 1e-12
        if outcome.resolution is not None:  # no finer than the search's spacing (Outcome.resolution)
            lo_i, hi_i = min(lo_i, float(x[i] - outcome.resolution[i])), max(hi_i, float(x[i] + outcome.resolution[i]))
        log = name in LOG
        intervals[name] = (math.exp(lo_i), math.exp(hi_i)) if log else (float(lo_i), float(hi_i))
        narrow = (hi_i - lo_i <= math.log(2.0)) if log else (hi_i - lo_i <= abs(float(x[i])))
        identified[name] = narrow and not edge and not poor
        verdicts[name] = _verdict(name, i, x, lo_i, hi_i, box, (chi2, dof, p_fit), poor, identified[name])
        if poor and outcome.replicate is not None and p_fit >= outcome.poor_fit:
            verdicts[name] = (f"not identified: the best point fits (chi2 = {fmt_number(chi2, 4)} on {dof} dof) "
                              f"but its neighbours do not (chi2 = {fmt_number(chi2_rep[0], 4)} on {chi2_rep[1]}, "
                              f"probability {fmt_number(p_rep, 2)}): the best of many windows was a lucky draw")
    if outcome.periods:  # the statistics' chi2 does not see a period the data show (docs/your-data.md)
        identified = dict.fromkeys(names, False)
        verdicts = {n: f"not identified: {'; '.join(outcome.periods)}; chi2 = {fmt_number(chi2, 4)} on {dof} dof "
                    "does not see it (the statistics are means over a cycle, and the cycle frequency is not fitted "
                    "where the data's periodogram holds no line)" for n in names}
    return Inference(params=apply(problem.params0, names, x, fits[0].V), values=dict(zip(names, values_of(names, x))),
                     stderr=stderr, intervals=intervals, identified=identified, verdicts=verdicts,
                     residuals=_residual_rows(problem, fits, best(outcome.evaluated).models), chi2=chi2, dof=dof,
                     status=outcome.status, message=outcome.message,
                     n_evaluations=len(outcome.evaluated) * len(fits), wall_time=outcome.wall, notes=outcome.notes)

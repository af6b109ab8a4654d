"""``run_compare``: all scenes, the per-regime error statistics, timings, and their markdown/CSV/JSON.

This is what ``peelapprox compare`` runs.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

from peelapprox.io import fmt_number, html_table, optional_import

from ._compare import RowTable, compare
from ._runs import RUNS, RunSpec, exact_run
from ._scenes import SCENES, Row

__all__ = ["StatRow", "CompareReport", "statistics", "run_compare", "markdown", "STAT_RUNS"]

#: the runs whose every segment enters the statistics (one per regime)
STAT_RUNS = ("V1-I1e-5", "V1-I1e-3", "V1-I1e-2", "V4-I1e-2")


@dataclass(frozen=True)
class StatRow:
    """Distribution of one reduction's ``|relative error|`` in one quantity over all segments of one run.

    ``n`` segments were tried, ``n_failed`` of them broke down or did not exit (those are not in the
    percentiles); ``n_defined`` had the quantity (a period needs ≥ 2 crossings or extrema).
    """

    run: str
    regime: str
    branch: str
    method: str
    quantity: str
    n: int
    n_failed: int
    n_defined: int
    median: float | None
    p90: float | None
    max: float | None

    #: Units of the columns (``RowTable.to_dataframe``): the percentiles are |relative errors| (fractions).
    UNITS = {"median": "", "p90": "", "max": ""}

    def as_dict(self) -> dict:
        return asdict(self)


def statistics(runs: Sequence[str | RunSpec] = STAT_RUNS, models=None) -> RowTable:
    """Median, 90th percentile and max of ``|relative error|`` of Δt, ΔF and the α period, per run, branch and
    reduction, over every complete segment of each run's window (seeded from the exact entries).

    ``runs`` are names of :data:`RUNS` or :class:`RunSpec` s (a run of any peel-force law: its reductions use
    that law); ``models`` as in :func:`compare` (default :data:`DEFAULT_MODELS`).  Returns a
    :class:`RowTable` of :class:`StatRow` (a list; ``.to_dataframe()`` gives a pandas DataFrame).
    """
    out = RowTable()
    for spec in runs:
        run = exact_run(spec)
        name = run.spec.name
        rows = compare(run.trajectory, models, segs=run.segments)
        keys = []
        for r in rows:
            k = (r.branch, f"{r.alpha_model} + {r.v_equation}")
            if k not in keys:
                keys.append(k)
        for branch, method in keys:
            sel = [r for r in rows if (r.branch, f"{r.alpha_model} + {r.v_equation}") == (branch, method)]
            failed = sum(r.status != "ok" for r in sel)
            for q in ("dt", "dF", "period"):
                e = np.abs([v for v in (getattr(r, f"{q}_rel_error") for r in sel if r.status == "ok")
                            if v is not None])
                stats = (float(np.median(e)), float(np.percentile(e, 90)), float(e.max())) if len(e) else (None,) * 3
                out.append(StatRow(name, run.spec.regime, branch, method, q, len(sel), failed, len(e), *stats))
    return out


@dataclass
class CompareReport:
    """Rows of every scene, the statistics, the transient checks and the timings [s]."""

    rows: list[Row]
    stats: list[StatRow]
    transients: dict[str, str]
    timings: dict[str, float]
    figures: list[str] = field(default_factory=list)

    def row_dicts(self) -> list[dict]:
        return [r.as_dict() for r in self.rows]

    def stat_dicts(self) -> list[dict]:
        return [s.as_dict() for s in self.stats]

    def to_dataframe(self, table: str = "rows") -> Any:
        """A table of the report as a :class:`pandas.DataFrame`: ``"rows"`` (every scene's :class:`Row`, with
        its ``verdict``), ``"stats"`` (:class:`StatRow`) or ``"timings"`` (``step, wall_time`` [s]).

        Raises
        ------
        ValueError
            If ``table`` is none of these.
        ImportError
            If pandas is not installed (``pip install 'peelapprox[data]'``).
        """
        if table == "rows":
            return RowTable(self.rows).to_dataframe(Row)
        if table == "stats":
            return RowTable(self.stats).to_dataframe(StatRow)
        if table == "timings":
            pd = optional_import("pandas", "CompareReport.to_dataframe")
            df = pd.DataFrame({"step": list(self.timings), "wall_time": list(self.timings.values())})
            df.attrs["units"] = {"wall_time": "s"}
            return df
        raise ValueError(f"table must be one of 'rows', 'stats', 'timings', got {table!r}")

    def _summary(self) -> dict:
        verdicts = [r.verdict for r in self.rows]
        return {"rows": len(self.rows), "within": verdicts.count("within"), "outside": verdicts.count("outside"),
                "failed": sum(v.startswith("failed") for v in verdicts), "statistics rows": len(self.stats),
                "runs": ", ".join(self.transients) or "none", "total time [s]": self.timings.get("total")}

    def __repr__(self) -> str:
        d = self._summary()
        return (f"CompareReport({d['rows']} rows: {d['within']} within, {d['outside']} outside, {d['failed']} failed "
                f"the claim; {d['statistics rows']} statistics rows; runs: {d['runs']}; "
                f"total {fmt_number(d['total time [s]'], 3)} s)")

    def _repr_html_(self) -> str:
        return html_table("CompareReport", self._summary())


def run_compare(scenes: Sequence[str] | None = None, *, statistics_runs: Sequence[str] | None = STAT_RUNS,
                figures_dir: str | None = None,
                progress: Callable[[str], None] | None = None) -> CompareReport:
    """Run the scenes (default: all of :data:`SCENES`, in order), then the statistics.

    Parameters
    ----------
    scenes : sequence of str, optional
        Scene names; unknown names raise ``ValueError`` listing the valid ones.
    statistics_runs : sequence of str or None
        Runs for :func:`statistics`; None or empty skips them.
    figures_dir : str, optional
        Where the scenes' figures (Figs. 8 and 9) are drawn; None draws none.
    progress : callable, optional
        Receives one line of text per finished step.

    Returns
    -------
    CompareReport
        ``timings`` holds one entry per exact run (simulation + transient check + segmentation),
        per scene (its rows and figures, the run excluded) and ``"statistics"``, ``"total"``.
    """
    names = list(SCENES) if not scenes else list(scenes)
    for n in names:
        if n not in SCENES:
            raise ValueError(f"scene must be one of {list(SCENES)}, got {n!r}")
    for n in statistics_runs or ():
        if n not in RUNS:
            raise ValueError(f"statistics run must be one of {list(RUNS)}, got {n!r}")
    say = progress or (lambda msg: None)
    t_all = time.perf_counter()
    timings: dict[str, float] = {}
    transients: dict[str, str] = {}

    def ensure_run(name):
        if name not in transients:
            r = exact_run(name)
            timings[f"run {name}"] = r.wall_time
            transients[name] = r.transient.describe()
            say(f"exact run {name}: {r.wall_time:.2f} s, {len(r.segments)} segments; {transients[name]}")
        return exact_run(name)

    rows: list[Row] = []
    figures: list[str] = []
    for i, n in enumerate(names, 1):
        sc = SCENES[n]
        run = ensure_run(sc.run)
        t0 = time.perf_counter()
        rows.extend(sc.rows(run))
        if figures_dir is not None and sc.figures is not None:
            figures.extend(sc.figures(run, figures_dir))
        timings[f"scene {n}"] = time.perf_counter() - t0
        say(f"[{i}/{len(names)}] {n}: {timings[f'scene {n}']:.2f} s")
    stats: list[StatRow] = []
    if statistics_runs:
        for n in statistics_runs:
            ensure_run(n)
        t0 = time.perf_counter()
        stats = statistics(statistics_runs)
        timings["statistics"] = time.perf_counter() - t0
        say(f"statistics over {', '.join(statistics_runs)}: {timings['statistics']:.2f} s")
    timings["total"] = time.perf_counter() - t_all
    return CompareReport(rows, stats, transients, timings, figures)


# --------------------------------------------------------------------------------------------
# rendering

def _fmt(x) -> str:
    """A number of the error tables: 4 significant digits, scientific notation outside [1e-3, 1e4)."""
    return fmt_number(x, 4, nan="nan", plain=(1e-3, 1e4))


def _pct(x, signed: bool = True) -> str:
    if x is None:
        return "–"
    digits = ".1f" if abs(x) >= 1e-3 or x == 0 else ".1e"
    return f"{100 * x:{'+' if signed else ''}{digits}} %"


def markdown(report: CompareReport, *, figures_rel: str | None = None) -> str:
    """The report as markdown: one table per scene, then the statistics, transients and timings."""
    out = []
    by_scene: dict[str, list[Row]] = {}
    for r in report.rows:
        by_scene.setdefault(r.scene, []).append(r)
    for name, rows in by_scene.items():
        sc = SCENES[name]
        out += [f"## {sc.title}", "", f"Scene `{name}`, run `{sc.run}` ({RUNS[sc.run].regime}). "
                f"Segment: {sc.selector}.", "",
                "| quantity | seed | method | paper approx | paper exact | ours approx | ours exact | rel. error "
                "| claim | verdict | note |", "|---|---|---|---|---|---|---|---|---|---|---|"]
        for r in rows:
            claim = "–" if r.claim is None else f"≤ {100 * r.claim:.0f} %"
            out.append(f"| {r.quantity} | {r.seed} | {r.method} | {_fmt(r.paper_approx)} | {_fmt(r.paper_exact)} | "
                       f"{_fmt(r.ours_approx)} | {_fmt(r.ours_exact)} | {_pct(r.rel_error)} | {claim} | "
                       f"{r.verdict or '–'} | {r.note} |")
        out.append("")
        if figures_rel is not None and sc.figures is not None:
            for f in report.figures:
                stem = f.rsplit("/", 1)[-1]
                if (name == "case-I-times" and stem.startswith("fig8")) or (name == "case-II-point-a"
                                                                           and stem.startswith("fig9")):
                    out += [f"![{stem}]({figures_rel}/{stem})", ""]
    if report.stats:
        out += ["## Error statistics over all segments of each run", "",
                "|Relative error| of each reduction seeded from every exact segment of the run's window "
                "(failed reductions are counted, not averaged).", "",
                "| run | regime | branch | method | quantity | n | failed | defined | median | p90 | max |",
                "|---|---|---|---|---|---|---|---|---|---|---|"]
        for s in report.stats:
            out.append(f"| {s.run} | {s.regime} | {s.branch} | {s.method} | {s.quantity} | {s.n} | {s.n_failed} | "
                       f"{s.n_defined} | {_pct(s.median, False)} | {_pct(s.p90, False)} | {_pct(s.max, False)} |")
        out.append("")
    out += ["## Exact runs: past the transient?", "", "| run | V | I | α0 | transient [s] | window [s] | check |",
            "|---|---|---|---|---|---|---|"]
    for n, d in report.transients.items():
        sp = RUNS[n]
        out.append(f"| {n} | {sp.V:g} | {sp.I:g} | {sp.alpha0:g} | {sp.t_transient:g} | {sp.window:g} | {d} |")
    out += ["", "## Timings (this run)", "", "| step | wall time [s] |", "|---|---|"]
    out += [f"| {k} | {v:.3f} |" for k, v in report.timings.items()]
    return "\n".join(out) + "\n"

"""Seed the reduced equations from exact segments and measure their errors.

``compare(trajectory, models)`` runs every reduction on every complete segment
of an exact trajectory, seeded with the segment's entry state (F, α, α̇, v) and
integrated to the segment's exit velocity (the fold), and reports Δt, ΔF and
the local α period (:meth:`Segment.local_period`) from both, with absolute and relative errors.  A
reduction that breaks down (for example v → 0 on AB) or does not reach the
fold is reported as a failed row with its reason, never silently dropped.

The trajectory may be of any peel-force law (``trajectory.params.force``): every reduction is then integrated
with that law (its folds, f' and domain: :func:`peelapprox.reduced_segment`), seeded from that law's exact
segments; a reduction that leaves the law's domain (a table's range) is the row ``"breakdown: law_domain"``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass, fields
from typing import Any

from peelapprox import ModelBreakdown, SolverBudgetExceeded, reduced_segment
from peelapprox.io import fmt_number, html_table, optional_import
from peelapprox.validate import params as _params

from ._segments import Segment, _crossings, _extrema, local_period, segments

__all__ = ["DEFAULT_MODELS", "ComparisonRow", "RowTable", "compare", "run_reduction"]

#: reductions tried on each branch by default: (alpha_model, v_equation)
DEFAULT_MODELS: dict[str, tuple[tuple[str, str], ...]] = {
    "AB": (("approxalpha", "approxvdot"), ("sinusoid", "approxvdot"), ("genalpha", "approxvdot"),
           ("genalpha", "fullvdot")),
    "CD": (("airy2", "approxvdot"), ("airy2_frozen", "approxvdot"), ("exponential", "approxvdot"),
           ("genalpha", "approxvdot"), ("genalpha", "fullvdot")),
}


@dataclass(frozen=True)
class ComparisonRow:
    """One reduction on one exact segment.  Errors are ``approx - exact`` and ``(approx - exact)/|exact|``;
    None where a quantity is undefined (no α period in the segment, or the reduction failed)."""

    segment: int
    branch: str
    alpha_model: str
    v_equation: str
    status: str
    dt_exact: float
    dt_approx: float | None
    dt_abs_error: float | None
    dt_rel_error: float | None
    dF_exact: float
    dF_approx: float | None
    dF_abs_error: float | None
    dF_rel_error: float | None
    period_exact: float | None
    period_approx: float | None
    period_rel_error: float | None

    #: Units of the columns (``RowTable.to_dataframe``): dt in seconds, dF in newtons, errors relative
    #: (``*_rel_error``: a fraction) or in the quantity's unit.
    UNITS = {"dt_exact": "s", "dt_approx": "s", "dt_abs_error": "s", "dt_rel_error": "", "dF_exact": "N",
             "dF_approx": "N", "dF_abs_error": "N", "dF_rel_error": "", "period_exact": "s", "period_approx": "s",
             "period_rel_error": ""}

    def as_dict(self) -> dict:
        return asdict(self)


class RowTable(list):
    """A list of table rows (:class:`ComparisonRow`, :class:`StatRow`, :class:`Row`: dataclasses with
    ``as_dict``), as :func:`compare` and :func:`statistics` return them, that also turns into a DataFrame."""

    def to_dataframe(self, row_type: type | None = None) -> Any:
        """One DataFrame row per row (``as_dict()``: the fields, and ``verdict`` for a scene's :class:`Row`),
        None as NaN in number columns; ``df.attrs["units"]`` where the row type states them (``UNITS``).
        ``row_type`` gives the columns of an empty table (default: the first row's type).

        Raises
        ------
        ImportError
            If pandas is not installed (``pip install 'peelapprox[data]'``).
        """
        pd = optional_import("pandas", "comparisons' to_dataframe")
        kind = row_type or (type(self[0]) if self else None)
        cols = None if self or kind is None else [f.name for f in fields(kind)]
        df = pd.DataFrame([r.as_dict() for r in self], columns=cols)
        df.attrs["units"] = dict(getattr(kind, "UNITS", {}))
        return df

    def _summary(self) -> dict[str, Any]:
        """Counts and medians a person reads first: the row type, the statuses, the reductions and the median
        relative errors where the rows have them."""
        if not self:
            return {"rows": 0}
        out: dict[str, Any] = {"rows": f"{len(self)} {type(self[0]).__name__}"}
        for name in ("status", "verdict"):
            if hasattr(self[0], name):
                counts: dict[str, int] = {}
                for r in self:
                    key = str(getattr(r, name)).split(":")[0]
                    counts[key] = counts.get(key, 0) + 1
                out[name] = ", ".join(f"{k} {v}" for k, v in sorted(counts.items(), key=lambda kv: -kv[1])[:4])
        if hasattr(self[0], "alpha_model"):
            models = sorted({f"{r.branch} {r.alpha_model}/{r.v_equation}" for r in self})
            out["reductions"] = f"{len(models)}: " + ", ".join(models[:6]) + (" ..." if len(models) > 6 else "")
        for col in ("dt_rel_error", "dF_rel_error"):
            vals = [abs(getattr(r, col)) for r in self if getattr(r, col, None) is not None]
            if vals:
                out[f"median |{col}|"] = f"{fmt_number(100 * sorted(vals)[len(vals) // 2], 3)} %"
        return out

    def __repr__(self) -> str:
        """A short summary (the rows themselves: ``list(table)``, ``table.to_dataframe()``)."""
        parts = "; ".join(f"{k} {v}" if k != "rows" else str(v) for k, v in self._summary().items())
        return f"RowTable({parts}; .to_dataframe() or list(...) for the rows)"

    def _repr_html_(self) -> str:
        return html_table("RowTable", self._summary())


def run_reduction(params, branch: str, alpha_model: str, v_equation: str, **seed):
    """One reduced solve that reports a physical breakdown as a status instead of raising.

    ``seed`` goes to :func:`peelapprox.reduced_segment`.  ``status`` is ``"ok"``,
    ``"breakdown: <reason>"`` (:class:`~peelapprox.ModelBreakdown`) or
    ``"no exit: <budget>"`` (:class:`~peelapprox.SolverBudgetExceeded`); the
    result is None unless the status is ``"ok"``.  Bad arguments still raise
    ``ValueError``.
    """
    try:
        return reduced_segment(params, branch, alpha_model=alpha_model, v_equation=v_equation, **seed), "ok"
    except ModelBreakdown as exc:
        return None, f"breakdown: {exc.reason}"
    except SolverBudgetExceeded as exc:
        return None, f"no exit: {exc.budget}"


def _err(a: float | None, e: float | None):
    if a is None or e is None:
        return None, None
    return a - e, (a - e) / abs(e) if e != 0 else None


def compare(trajectory, models: Mapping[str, Sequence[tuple[str, str]]] | None = None, *,
            segs: list[Segment] | None = None, rtol: float = 1e-10, periods: bool = True) -> RowTable:
    """Every reduction on every segment of an exact trajectory, seeded from exact entry states.

    Parameters
    ----------
    trajectory : exact.Trajectory
        Of any peel-force law (its ``params.force`` is the reductions' law).  Stored points are needed for the
        period columns (else they are None).
    models : dict, optional
        ``{"AB": [(alpha_model, v_equation), ...], "CD": [...]}``; default
        :data:`DEFAULT_MODELS`.
    segs : list of Segment, optional
        A subset of ``segments(trajectory)`` to compare (default: all).
    rtol : float
        Tolerance of the reduced solves.
    periods : bool
        False: leave ``period_approx`` and ``period_rel_error`` None and let the reduced solves store no steps
        (``save="none"``; Δt and ΔF are the same numbers, the steps taken being the same): for a caller that
        compares Δt and ΔF only (an atlas), whose Python per row it saves.

    Returns
    -------
    RowTable of ComparisonRow
        A list (``.to_dataframe()`` gives it as a pandas DataFrame).  Status ``"ok"`` or
        ``"breakdown: <reason>"`` / ``"no exit: <budget>"``.

    Raises
    ------
    ValueError
        A trajectory of a model variant (``trajectory.params.tape_mass`` / ``.loading``): the reduced
        equations are derived for the massless model under velocity control
        (:func:`peelapprox.validate.paper_model`).
    """
    models = DEFAULT_MODELS if models is None else models
    # the reductions are the paper's massless constant-V equations: a variant's trajectory is refused here
    params = _params("trajectory.params", trajectory.params, where="compare", variants=False)
    if not isinstance(periods, bool):
        raise TypeError(f"periods must be True or False, got {periods!r}")
    save = "steps" if periods else "none"
    rows = RowTable()
    for s in (segments(trajectory) if segs is None else segs):
        p_ex = s.local_period()
        for am, ve in models.get(s.branch, ()):
            dt_a = dF_a = p_a = None
            r, status = run_reduction(params, s.branch, am, ve, rtol=rtol, save=save, **s.entry())
            if r is not None:
                dt_a, dF_a = r.dt, r.dF
                if periods:
                    p_a = local_period(_crossings(r.t, r.alpha, r.alphadot), _extrema(r.t, r.alpha, r.alphadot))
            dt_abs, dt_rel = _err(dt_a, s.dt)
            dF_abs, dF_rel = _err(dF_a, s.dF)
            _, p_rel = _err(p_a, p_ex)
            rows.append(ComparisonRow(s.index, s.branch, am, ve, status, s.dt, dt_a, dt_abs, dt_rel, s.dF, dF_a,
                                      dF_abs, dF_rel, p_ex, p_a, p_rel))
    return rows

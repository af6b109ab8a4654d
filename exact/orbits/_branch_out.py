"""Data out and notebook display of a continued branch (:meth:`exact.OrbitBranch.to_dataframe`, its ``__repr__``
and ``_repr_html_``), kept apart so that :mod:`exact.orbits._continuation` stays the computation."""

from __future__ import annotations

from typing import Any

from peelapprox.io import fmt_number, html_table, optional_import, param_attrs

__all__ = ["branch_dataframe", "branch_summary"]

#: Units of the continuation parameters (a family coefficient's: none).
_PARAMETER_UNITS = {"V": "m/s", "I": "kg m²", "k": "N/m"}


def branch_dataframe(br: Any) -> Any:
    """:meth:`exact.OrbitBranch.to_dataframe` (its docstring): columns the parameter, ``n, period, stable,
    residual``, the multipliers ``mu<i>_abs/_re/_im`` and the return-map values ``F<i>``."""
    pd = optional_import("pandas", "OrbitBranch.to_dataframe")
    df = pd.DataFrame(br.rows())
    unit = _PARAMETER_UNITS.get(br.parameter, "")
    df.attrs.update({
        "units": {c: unit if c == br.parameter else "s" if c == "period" else
                  "N" if c[:1] == "F" and c[1:].isdigit() else "" for c in df.columns},
        "parameter": br.parameter, "stopped": br.stopped, "end_value": br.end_value, "message": br.message,
        "bifurcations": [{"kind": b.kind, "value": b.value} for b in br.bifurcations],
        "params": param_attrs(br.points[0].orbit.params) if br.points else {}})
    return df


def branch_summary(br: Any, *, short: bool) -> str:
    """An :class:`exact.OrbitBranch` as one line (``short``, its ``__repr__``) or a small HTML table."""
    vals = [p.value for p in br.points]
    d = {"parameter": br.parameter, "points": len(br.points),
         "range": f"{fmt_number(min(vals), 6)} … {fmt_number(max(vals), 6)}" if vals else "–",
         "n": br.points[0].orbit.n if br.points else "–",
         "stable points": sum(bool(p.orbit.stable) for p in br.points),
         "bifurcations": ", ".join(f"{b.kind} at {fmt_number(b.value, 6)}" for b in br.bifurcations) or "none",
         "stopped": f"{br.stopped} at {fmt_number(br.end_value, 6)}", "wall time [s]": br.wall_time}
    if not short:
        return html_table("OrbitBranch", d)
    return (f"OrbitBranch({d['parameter']} in [{d['range']}], period-{d['n']}, {d['points']} points "
            f"({d['stable points']} stable), bifurcations: {d['bifurcations']}, stopped: {d['stopped']})")

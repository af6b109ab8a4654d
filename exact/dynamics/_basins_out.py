"""Data out and notebook display of the basins (:meth:`exact.BasinResult.to_xarray`, its ``__repr__`` and
``_repr_html_``), kept apart so that :mod:`exact.dynamics._basins` stays the computation."""

from __future__ import annotations

import json
from typing import Any

import numpy as np

from peelapprox.io import fmt_number, html_table, optional_import, param_attrs

__all__ = ["basins_summary", "basins_xarray"]

#: Units and descriptions of the second axis of a basin grid.
_AXES = {"F0": ("N", "initial pull force"), "omega0": ("rad/s", "initial roller angular velocity")}


def basins_xarray(res: Any, code_text: dict[int, str]) -> Any:
    """:meth:`exact.BasinResult.to_xarray` (its docstring); ``code_text`` the text of each outcome code < 0."""
    xr = optional_import("xarray", "BasinResult.to_xarray")
    dims = ("alpha0", res.axis)
    codes = {**{a.id: f"A{a.id}_{a.label}" for a in res.attractors}, **{c: t.replace(" ", "_")
                                                                      for c, t in code_text.items()}}
    n = np.array([res.attractors[c].n if c >= 0 else 0 for c in res.labels.ravel()], dtype=np.int64)
    n = n.reshape(res.labels.shape)
    unit, what = _AXES[res.axis]
    return xr.Dataset(
        {"label": (dims, np.asarray(res.labels), {
            "description": "attractor id (>= 0, BasinResult.attractors) or outcome code (< 0)",
            "flag_values": np.array(sorted(codes), dtype=np.int64),
            "flag_meanings": " ".join(codes[c] for c in sorted(codes))}),
         "outcome": (dims, np.asarray(res.texts, dtype=str), {"description": "outcome of the start"}),
         "n": (dims, n, {"description": "period n of the attractor reached (AB->CD jumps per period; 0: none)"}),
         "n_returns": (dims, np.asarray(res.n_returns), {"description": "AB->CD jumps in the start's window"})},
        coords={"alpha0": ("alpha0", np.asarray(res.alpha0), {"units": "rad", "description": "initial peel angle"}),
                res.axis: (res.axis, np.asarray(res.values), {"units": unit, "description": what})},
        attrs={**{f"params_{k}": v for k, v in param_attrs(res.params).items()},
               "t_transient": res.t_transient, "window": res.window, "rtol": res.rtol, "max_period": res.max_period,
               "wall_time": res.wall_time, "attractors": json.dumps(
                   [{"id": a.id, "n": a.n, "cycle": list(a.cycle), "count": a.count, "start": list(a.start)}
                    for a in res.attractors])})


def basins_summary(res: Any, *, short: bool) -> str:
    """A :class:`exact.BasinResult` as one line of key numbers (``short``, its ``__repr__``) or a small HTML
    table (its ``_repr_html_``)."""
    p = res.params
    grid = f"{res.alpha0.size} alpha0 x {res.values.size} {res.axis}"
    counts = list(res.counts().items())
    outcomes = ", ".join(f"{k}: {v}" for k, v in counts[:6]) + (" …" if len(counts) > 6 else "")
    if short:
        return (f"BasinResult({grid}, V={p.V:g}, I={p.I:g}; {outcomes}; "
                f"wall_time={fmt_number(res.wall_time, 3)} s)")
    atts = "; ".join(a.describe() for a in res.attractors[:4]) + (" …" if len(res.attractors) > 4 else "")
    return html_table("BasinResult", {"grid": grid, "V [m/s]": p.V, "I [kg m²]": p.I, "force": repr(p.force),
                                      "outcomes": outcomes, "attractors": atts or "none",
                                      "wall time [s]": res.wall_time})

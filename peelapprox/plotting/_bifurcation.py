"""The orbit diagram over one parameter with continued branches of periodic orbits (:func:`plot_bifurcation`)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from ._figure import _canvas, _save, axis_label, params_label

__all__ = ["MAX_BRANCHES", "plot_bifurcation"]

#: The branches :func:`plot_bifurcation` draws by default (the first ones): 30 overlapping branches are a tangle.
MAX_BRANCHES = 12

#: The legend's names of the bifurcation kinds (exact.orbits' table); another kind: its name, spaced.
_KIND_NAMES = {"fold": "fold", "period_doubling": "period doubling", "neimark_sacker": "Neimark–Sacker",
               "branch_point": "branch point"}

#: Families (branches continued from one orbit) named one by one in the legend up to this many.
_NAMED_FAMILIES = 6


def _chosen(branches: list, select: Sequence[int] | None, max_branches: int | None) -> list:
    """The branches to draw: those numbered ``select`` (from 1, as the CLI's table and ``--out`` rows name
    them) or all, the first ``max_branches`` of them."""
    from ..validate import integer

    numbered = list(enumerate(branches, start=1))
    if select is not None:
        if isinstance(select, (str, bytes)) or not isinstance(select, Sequence):
            raise TypeError(f"select must be a sequence of branch numbers (from 1), got {select!r}")
        if not select or not branches:
            raise ValueError(f"select must name at least one of the {len(branches)} branches (numbered from 1), "
                             f"got {list(select)!r}")
        wanted = [integer("select", k, lo=1, hi=len(branches)) for k in select]
        numbered = [numbered[k - 1] for k in dict.fromkeys(wanted)]
    if max_branches is not None:
        numbered = numbered[:integer("max_branches", max_branches, lo=1)]
    return [b for _, b in numbered]


def plot_bifurcation(diagram: Any = None, branches: Any = (), path: str | None = None, *, params: Any = None,
                     select: Sequence[int] | None = None, max_branches: int | None = MAX_BRANCHES,
                     title: str | None = None, ax: Any = None, fig: Any = None):
    """The brute-force orbit diagram with continued branches of periodic orbits drawn over it.

    Parameters
    ----------
    diagram : exact.OrbitDiagram, optional
        Grey dots: F at the AB→CD jumps after the transient, at each value of the parameter.
    branches : sequence of exact.OrbitBranch
        Each branch's return-map values (F at its n jumps) against the parameter, thin lines (one colour per
        starting orbit): solid where the orbit is stable, dashed where it is unstable; each bifurcation marked
        once, on the branch's highest return-map line (square: fold, diamond: period doubling, star:
        Neimark–Sacker), and its non-smooth end (``end_value``: x grazing, + crest event, tri breakdown).
    path : str, optional
        Also write the figure there (:func:`save_figure`: the format from the extension, reproducible bytes).
    params : PeelParams, optional
        The run's parameters, for the title (the swept one left out).  Default: those of the first branch's
        orbit, if any.
    select : sequence of int, optional
        Draw only these branches, numbered from 1 in the order of ``branches`` (as ``peelapprox bifurcation``
        numbers them).
    max_branches : int or None
        Draw at most this many of the (selected) branches, the first ones (default :data:`MAX_BRANCHES`); the
        title says how many of how many are shown.  None: all.
    title : str, optional
        Default: the swept parameter, the other parameters and the branches shown.
    ax : matplotlib axes, optional
        Draw there (the legend beside it).
    fig : matplotlib.figure.Figure, optional
        Draw into this (empty) figure.  Neither: a new :func:`new_figure`.

    Returns
    -------
    matplotlib.figure.Figure
        The figure drawn into (that of ``ax`` when given).
    """
    fig, axs = _canvas(ax, fig, (1, 1), (10, 5.5))
    ax = axs[0, 0]
    name = getattr(diagram, "parameter", None)
    branches = list(branches)
    if params is None and branches:
        params = branches[0].points[0].orbit.params
    handles: dict[str, Any] = {}  # the legend: the dots, the starting orbits, the line styles, the markers
    markers: dict[str, Any] = {}
    if diagram is not None:
        _draw_diagram(ax, diagram, handles)
    shown = _chosen(branches, select, max_branches)
    families = list(dict.fromkeys(id(b.points[0].orbit) for b in branches))  # one colour per starting orbit
    name_families = len({id(b.points[0].orbit) for b in shown}) <= _NAMED_FAMILIES
    styles: set[str] = set()
    for br in shown:
        name = br.parameter
        color = f"C{families.index(id(br.points[0].orbit)) % 10}"
        _draw_branch(ax, br, color, handles if name_families else None, markers, styles)
    _legend(ax, handles, markers, styles)
    swept = str(name) if name else "parameter"
    ax.set(xlabel=axis_label(swept) if name else swept, ylabel="F at the AB→CD jumps [N]")
    if diagram is not None and len(diagram.values):
        lo, hi = float(np.min(diagram.values)), float(np.max(diagram.values))
        if hi > lo:
            ax.set_xlim(lo - 0.02 * (hi - lo), hi + 0.02 * (hi - lo))
    which = "" if not branches else (f", {len(shown)} of {len(branches)} branches" if len(shown) < len(branches)
                                     else f", {len(branches)} branch{'es' if len(branches) > 1 else ''}")
    fixed = params_label(params, skip=swept)
    ax.set_title(title or f"orbit diagram over {swept}" + (f" at {fixed}" if fixed else "") + which)
    _save(fig, path, dpi=130)
    return fig


def _draw_diagram(ax: Any, diagram: Any, handles: dict[str, Any]) -> None:
    """The diagram's grey dots, and their legend entry."""
    from matplotlib.lines import Line2D

    xs_d = [np.full(F.size, x) for x, F in zip(diagram.values, diagram.returns)]
    if xs_d:
        ax.plot(np.concatenate(xs_d), np.concatenate(list(diagram.returns)), ".", color="0.45", ms=2.5,
                alpha=0.8, zorder=1)
    handles["brute-force runs: F at each AB→CD jump"] = Line2D([], [], ls="", marker=".", color="0.45", ms=6)


def _draw_branch(ax: Any, br: Any, color: str, handles: dict[str, Any] | None, markers: dict[str, Any],
                 styles: set[str]) -> None:
    """One branch's lines (solid where stable), bifurcations and end; its family's legend entry in ``handles``
    (None: families not named), its markers' in ``markers``, its line styles added to ``styles``."""
    from matplotlib.lines import Line2D

    xs = np.array([p.value for p in br.points])
    stable = np.array([p.orbit.stable for p in br.points])
    # (points, n), each point's values sorted: the set of F at its jumps, as the diagram shows them (the
    # cyclic order of an orbit's jumps is not kept from point to point)
    Fs = np.sort(np.array([p.orbit.return_map_values for p in br.points]), axis=1)
    for i in range(len(xs) - 1):  # each piece solid if both its ends are stable, else dashed
        style = "-" if stable[i] and stable[i + 1] else "--"
        styles.add(style)
        ax.plot(xs[i:i + 2], Fs[i:i + 2], style, color=color, lw=0.9, zorder=2)
    if handles is not None:
        o = br.points[0].orbit
        handles.setdefault(f"period-{o.n} orbit from {br.parameter} = {br.points[0].value:.4g}",
                           Line2D([], [], color=color, lw=1.5))
    for b in br.bifurcations:  # once per bifurcation: on the branch's highest line there
        marker, c = b.marker  # from the kinds' table of exact.orbits
        ax.plot([b.value], [float(np.max(b.orbit.return_map_values))], marker, color=c, ms=8, mec="k", zorder=3)
        markers.setdefault(_KIND_NAMES.get(b.kind, b.kind.replace("_", " ")),
                           Line2D([], [], ls="", marker=marker, color=c, ms=8, mec="k"))
    if br.end_marker is not None:  # the non-smooth end, at its (extrapolated) parameter value
        ax.plot([br.end_value], [float(Fs[-1].max())], br.end_marker, color="k", ms=7, zorder=3)
        markers.setdefault(f"end: {br.stopped}", Line2D([], [], ls="", marker=br.end_marker, color="k", ms=7))


def _legend(ax: Any, handles: dict[str, Any], markers: dict[str, Any], styles: set[str]) -> None:
    """The legend beside the axes: the dots, the families, the line styles drawn, the markers."""
    from matplotlib.lines import Line2D

    for style, what in (("-", "stable orbit"), ("--", "unstable orbit")):
        if style in styles:
            handles[what] = Line2D([], [], ls=style, color="0.2", lw=1.2)
    handles.update(markers)
    if handles:
        ax.legend(handles.values(), handles.keys(), loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)

"""The atlas's maps over the (V, I) plane (V linear, I logarithmic, one cell per grid point).

* :func:`plot_error_map` — one approximation's relative error of one observable, on a logarithmic colour
  scale diverging about 10 % (blue within, red beyond), the cells within 10 % outlined (the 10 % contour, drawn
  on the cells' edges: the grid's own resolution, no interpolation); the cells where it is undefined are
  coloured by why (no exact stick-slip, no stick-slip predicted).
* :func:`plot_dynamics_map` — the exact dynamics' class (period n, aperiodic, steady, breakdown, ...) with
  :func:`peelapprox.estimate`'s regime labels drawn over it (their boundaries, and each label once).
* :func:`plot_segment_maps` — every reduction's per-point median (or worst) per-segment error, one panel each.
* :func:`plot_multistability_map`, :func:`plot_confidence_map` — with sets (``atlas(..., sets=True)``): the
  number of exact attractors at each point, and the confidence of the primary prediction, the cells where it
  matches no attractor of the set outlined.
* :func:`write_maps` — all of them as PNG files.

Figures come from :func:`peelapprox.plotting.new_figure` (matplotlib imported on first use only).
"""

from __future__ import annotations

import os
from collections.abc import Callable
from typing import Any

import numpy as np

from peelapprox.plotting import cell_edges, new_figure, save_figure

from .approximations import OBSERVABLES, TOLERANCE, key_of

__all__ = ["plot_error_map", "plot_dynamics_map", "plot_segment_maps", "plot_multistability_map",
           "plot_confidence_map", "write_maps", "class_group", "CLASS_GROUPS"]

#: The groups the dynamics map colours (a period-n class falls into its period's group), in legend order.
CLASS_GROUPS = ("period-1", "period-2", "period-3", "period 4-8", "period 9-32", "aperiodic", "too short",
                "steady", "transient", "too few slips", "breakdown", "budget", "failed", "not computed")
_GROUP_COLOURS = ("#1f77b4", "#2ca02c", "#17becf", "#bcbd22", "#9467bd", "#d62728", "#ff9896", "#c7c7c7",
                  "#dbdb8d", "#f7b6d2", "#000000", "#8c564b", "#7f7f7f", "#ffffff")
#: Why an error is undefined -> (legend text, colour) of its cells on an error map.
_UNDEFINED = (("exact:", "no exact stick-slip", "#d9d9d9"), ("predicted:", "no stick-slip predicted / failed",
                                                              "#f4a582"),
              ("failed:", "point failed", "#7f7f7f"), ("no exact value", "no exact value", "#bdbdbd"),
              ("not predicted", "not predicted", "#fddbc7"), ("exact value 0", "exact value 0", "#bdbdbd"))


def class_group(cls: str) -> str:
    """The :data:`CLASS_GROUPS` entry of an exact class (``"period-5"`` -> ``"period 4-8"``)."""
    if cls.startswith("period-"):
        n = int(cls.split("-", 1)[1])
        return f"period-{n}" if n <= 3 else ("period 4-8" if n <= 8 else "period 9-32")
    return cls if cls in CLASS_GROUPS else "failed"


def _sorted(result: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``(V, I, oi, ov)``: the axes in increasing order and the index arrays that sort a map."""
    oi, ov = np.argsort(result.I_values), np.argsort(result.V_values)
    return result.V_values[ov], result.I_values[oi], oi, ov


def _axes(ax: Any, fig: Any, figsize: tuple[float, float]) -> tuple[Any, Any]:
    if ax is not None and fig is not None:
        raise ValueError("ax and fig: give one of them (the figure of ax is where it is drawn)")
    if ax is not None:
        return ax.figure, ax
    fig = fig if fig is not None else new_figure(figsize=figsize)
    return fig, fig.add_subplot(1, 1, 1)


def _frame(ax: Any, VE: np.ndarray, IE: np.ndarray) -> None:
    ax.set_yscale("log")
    ax.set(xlabel="V [m/s]", ylabel="I [kg m²]", xlim=(VE[0], VE[-1]), ylim=(IE[0], IE[-1]))


def _outline(ax: Any, VE: np.ndarray, IE: np.ndarray, inside: np.ndarray, **style: Any) -> None:
    """Draw the cell edges between neighbouring cells whose values in ``inside`` differ (a boolean array: the
    outline of a region; labels: the borders between them)."""
    from matplotlib.collections import LineCollection

    segs = [[(VE[j + 1], IE[i]), (VE[j + 1], IE[i + 1])] for i in range(inside.shape[0])
            for j in range(inside.shape[1] - 1) if inside[i, j] != inside[i, j + 1]]
    segs += [[(VE[j], IE[i + 1]), (VE[j + 1], IE[i + 1])] for i in range(inside.shape[0] - 1)
             for j in range(inside.shape[1]) if inside[i, j] != inside[i + 1, j]]
    if segs:
        ax.add_collection(LineCollection(segs, **style))


def _error_layer(ax: Any, VE: np.ndarray, IE: np.ndarray, err: np.ma.MaskedArray, tol: float, vmin: float,
                 vmax: float) -> Any:
    """The error cells and the outline of the cells within ``tol``; returns the mesh.  The colours are
    logarithmic and diverging about ``tol`` when it is the geometric middle of [vmin, vmax] (the default
    [1e-3, 10] about 10 %): blue within, red beyond; errors outside the range take its end colours."""
    from matplotlib import colormaps
    from matplotlib.colors import LogNorm

    shown = np.ma.MaskedArray(np.clip(err.data, vmin, vmax), mask=err.mask)
    mesh = ax.pcolormesh(VE, IE, shown, cmap=colormaps["RdBu_r"], norm=LogNorm(vmin, vmax), edgecolors="face")
    inside = (~err.mask) & (err.data <= tol)
    _outline(ax, VE, IE, inside, colors="white", linewidths=3.0)
    _outline(ax, VE, IE, inside, colors="black", linewidths=1.2)
    return mesh


def plot_error_map(result: Any, name: str, observable: str, path: str | None = None, *,
                   tol: float = TOLERANCE, vmin: float = 1e-3, vmax: float = 10.0, ax: Any = None,
                   fig: Any = None) -> Any:
    """The relative error ``|predicted - exact| / |exact|`` of approximation ``name``'s ``observable`` over
    the (V, I) plane, with the outline of the cells within ``tol`` (10 %).

    Parameters
    ----------
    result : AtlasResult
    name : str
        An approximation of the atlas (``result.approximations``).
    observable : str
        One of :data:`~comparisons.atlas.approximations.OBSERVABLES`.
    path : str, optional
        Also write the figure there (format from the extension).
    tol : float
        The outlined error (0.10).
    vmin, vmax : float
        The colour scale's range (logarithmic; errors outside it take its end colours).
    ax, fig : optional
        Draw into these matplotlib axes, or this empty figure (neither: a new figure).

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.colors import ListedColormap
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    err = result.relative_error(name, observable)
    why = result.undefined(name, observable)
    V, I, oi, ov = _sorted(result)
    err, why = err[np.ix_(oi, ov)], why[np.ix_(oi, ov)]
    fig, ax = _axes(ax, fig, (7.5, 5.0))
    VE, IE = cell_edges(V, False), cell_edges(I, True)
    codes = np.ma.masked_all(why.shape)
    legend: list[Any] = []
    for n, (prefix, text, colour) in enumerate(_UNDEFINED):
        hit = np.array([str(w).startswith(prefix) for w in why.ravel()]).reshape(why.shape)
        if hit.any():
            codes[hit] = n
            legend.append(Patch(facecolor=colour, edgecolor="0.5", label=text))
    if codes.count():
        ax.pcolormesh(VE, IE, codes, cmap=ListedColormap([c for _, _, c in _UNDEFINED]), vmin=-0.5,
                      vmax=len(_UNDEFINED) - 0.5, edgecolors="face")
    mesh = _error_layer(ax, VE, IE, err, tol, vmin, vmax)
    bar = fig.colorbar(mesh, ax=ax, label=f"|relative error| of {observable}")
    bar.ax.axhline(tol, color="black", linewidth=1.5)
    legend.append(Line2D([], [], color="black", linewidth=1.2, label=f"outline: within {tol:.0%}"))
    _frame(ax, VE, IE)
    w = result.within(name, observable, tol)
    share = "–" if w["fraction"] is None else f"{w['within']}/{w['stick_slip']}"
    ax.set_title(f"{name}: {observable}, within {tol:.0%} at {share} stick-slip points", fontsize=10)
    if legend:
        ax.legend(handles=legend, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=len(legend), fontsize=8,
                  frameon=False)
    if path:
        save_figure(fig, path, dpi=120)
    return fig


def _short(label: str) -> str:
    return "stable fixed point" if label.startswith("no stick-slip") else label.replace(" inertia", " I")


def plot_dynamics_map(result: Any, path: str | None = None, *, regimes: bool = True, ax: Any = None,
                      fig: Any = None) -> Any:
    """The exact dynamics' class at each point (:data:`CLASS_GROUPS`), with :func:`peelapprox.estimate`'s
    regime labels drawn over it: black lines between cells of different labels, each label written once in
    its region (``regimes=False``: the classes alone).  ``path``, ``ax``, ``fig`` as :func:`plot_error_map`.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch

    V, I, oi, ov = _sorted(result)
    classes = result.exact_class()[np.ix_(oi, ov)]
    groups = np.array([CLASS_GROUPS.index(class_group(str(c))) for c in classes.ravel()]).reshape(classes.shape)
    fig, ax = _axes(ax, fig, (8.5, 5.5))
    VE, IE = cell_edges(V, False), cell_edges(I, True)
    ax.pcolormesh(VE, IE, groups, cmap=ListedColormap(_GROUP_COLOURS), vmin=-0.5, vmax=len(CLASS_GROUPS) - 0.5,
                  edgecolors="face")
    present = sorted(set(groups.ravel().tolist()))
    handles = [Patch(facecolor=_GROUP_COLOURS[g], edgecolor="0.5", label=CLASS_GROUPS[g]) for g in present]
    if regimes:
        from scipy import ndimage

        labels = result.regime()[np.ix_(oi, ov)]
        _outline(ax, VE, IE, labels, colors="black", linewidths=2.0)
        logI = np.log10(I)
        scale_i, scale_v = max(float(np.ptp(logI)), 1e-9), max(float(np.ptp(V)), 1e-9)
        for lab in dict.fromkeys(labels.ravel()):
            parts, n = ndimage.label(labels == lab)
            for part in range(1, n + 1):  # each connected region once, if it holds >= 1 % of the cells
                ii, jj = np.nonzero(parts == part)
                if ii.size < max(1, round(0.01 * labels.size)):
                    continue
                ci, cj = np.mean(logI[ii]), np.mean(V[jj])  # its centre; written at its cell nearest to it
                k = int(np.argmin(((logI[ii] - ci) / scale_i) ** 2 + ((V[jj] - cj) / scale_v) ** 2))
                ax.text(V[jj[k]], I[ii[k]], _short(str(lab)), ha="center", va="center", fontsize=8,
                        bbox=dict(boxstyle="round,pad=0.2", facecolor="white", alpha=0.85, edgecolor="black"))
        handles.append(Patch(facecolor="none", edgecolor="black", linewidth=2, label="estimate's regimes"))
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8, title="exact dynamics",
              title_fontsize=8)
    _frame(ax, VE, IE)
    n_ss = int(result.stick_slip().sum())
    ax.set_title(f"exact dynamics ({n_ss}/{classes.size} points stick-slip) and estimate's regimes", fontsize=10)
    if path:
        save_figure(fig, path, dpi=120)
    return fig


def plot_segment_maps(result: Any, stat: str = "dt_median", path: str | None = None, *,
                      tol: float = TOLERANCE, vmin: float = 1e-3, vmax: float = 10.0, fig: Any = None) -> Any:
    """Every reduction's per-point ``stat`` (``dt_median``, ``dt_worst``, ``dF_median``, ``dF_worst``) of its
    per-segment relative errors, one panel each (AB reductions in the first row, CD in the second), with the
    outline of the cells within ``tol``; cells without a value blank.  ``path``, ``fig`` as :func:`plot_error_map`.

    Returns
    -------
    matplotlib.figure.Figure
    """
    if stat not in ("dt_median", "dt_worst", "dF_median", "dF_worst"):
        raise ValueError(f"stat must be dt_median, dt_worst, dF_median or dF_worst, got {stat!r}")
    rows = [[r for r in result.reductions if r.startswith(b)] for b in ("AB", "CD")]
    rows = [r for r in rows if r]
    ncol = max((len(r) for r in rows), default=1)
    fig = fig if fig is not None else new_figure(figsize=(3.3 * ncol + 1.2, 3.0 * max(len(rows), 1) + 0.6))
    V, I, oi, ov = _sorted(result)
    VE, IE = cell_edges(V, False), cell_edges(I, True)
    mesh = None
    axes = []
    for r, reds in enumerate(rows):
        for c, red in enumerate(reds):
            ax = fig.add_subplot(len(rows), ncol, r * ncol + c + 1)
            axes.append(ax)
            err = result.segment_error(red, stat)[np.ix_(oi, ov)]
            mesh = _error_layer(ax, VE, IE, err, tol, vmin, vmax)
            _frame(ax, VE, IE)
            branch, rest = red.split("_", 1)
            am, ve = rest.rsplit("_", 1)  # the v equations have no "_", some alpha models do
            ax.set_title(f"{branch}: {am} + {ve}", fontsize=9)
            ax.tick_params(labelsize=7)
            ax.xaxis.label.set_size(8)
            ax.yaxis.label.set_size(8)
    if mesh is not None:
        label = f"{stat} of |relative error|"
        if len(rows[0]) < ncol:  # in the first row's empty slot, leaving the panels' grid as it is
            slot = fig.add_subplot(len(rows), ncol, ncol)
            slot.set_axis_off()
            bar = fig.colorbar(mesh, cax=slot.inset_axes((0.05, 0.0, 0.08, 1.0)), label=label)
        else:
            bar = fig.colorbar(mesh, ax=axes, label=label)
        bar.ax.axhline(tol, color="black", linewidth=1.5)
    fig.suptitle(f"reductions seeded from exact branch entries: {stat.replace('_', ' ')} over each point's "
                 f"stays (outlined: within {tol:.0%})", fontsize=10)
    if path:
        save_figure(fig, path, dpi=110)
    return fig


def _categories(ax: Any, fig: Any, result: Any, codes: np.ndarray, names: list[str], colours: list[str],
                title: str, path: str | None, missed: np.ndarray | None = None) -> Any:
    """Cells coloured by category (``codes[i, j]`` an index into ``names``; -1 blank), a legend, the outline of
    the ``missed`` cells (no attractor of the set matched) and the frame; written to ``path`` if given."""
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch

    V, I, oi, ov = _sorted(result)
    codes = codes[np.ix_(oi, ov)]
    fig, ax = _axes(ax, fig, (8.0, 5.0))
    VE, IE = cell_edges(V, False), cell_edges(I, True)
    ax.pcolormesh(VE, IE, np.ma.masked_less(codes, 0), cmap=ListedColormap(colours), vmin=-0.5,
                  vmax=len(names) - 0.5, edgecolors="face")
    present = sorted({int(c) for c in codes.ravel() if c >= 0})
    handles: list[Any] = [Patch(facecolor=colours[c], edgecolor="0.5", label=names[c]) for c in present]
    if missed is not None:
        from matplotlib.lines import Line2D

        inside = missed[np.ix_(oi, ov)]
        _outline(ax, VE, IE, inside, colors="white", linewidths=3.0)
        _outline(ax, VE, IE, inside, colors="black", linewidths=1.2)
        handles.append(Line2D([], [], color="black", linewidth=1.2, label="outline: matches no attractor"))
    ax.legend(handles=handles, loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    _frame(ax, VE, IE)
    ax.set_title(title, fontsize=10)
    if path:
        save_figure(fig, path, dpi=120)
    return fig


def _missed(result: Any) -> np.ndarray:
    """Boolean map: the primary prediction matches no stick-slip attractor of the set (``set_match`` False)."""
    rows = {(r["I"], r["V"]): r for r in result.set_rows()}
    return np.array([[rows.get((I, V), {}).get("set_match") is False for V in result.V_values]
                     for I in result.I_values], dtype=bool)


def plot_multistability_map(result: Any, path: str | None = None, *, ax: Any = None, fig: Any = None) -> Any:
    """The number of exact attractors at each point (reached from at least ``set_min_share`` of the starts;
    an atlas with sets), 0 to 5 and "6+", the cells whose primary prediction matches no attractor of the set
    outlined.  ``path``, ``ax``, ``fig`` as :func:`plot_error_map`.

    Returns
    -------
    matplotlib.figure.Figure
    """
    n = result.multistability()
    codes = np.where(np.ma.getmaskarray(n), -1, np.minimum(n.filled(0), 6)).astype(int)
    names = ["0", "1", "2", "3", "4", "5", "6+"]
    colours = ["#ffffff", "#c6dbef", "#6baed6", "#2171b5", "#08306b", "#54278f", "#000000"]
    multi = int((codes >= 2).sum())
    title = f"exact attractors per point (share >= {result.options.get('set_min_share', 0.1):g}): " \
            f"{multi}/{codes.size} points multistable"
    return _categories(ax, fig, result, codes, names, colours, title, path, _missed(result))


def plot_confidence_map(result: Any, path: str | None = None, *, ax: Any = None, fig: Any = None) -> Any:
    """The primary prediction's confidence at each point (high, low; an atlas with sets), the cells whose
    primary prediction matches no attractor of the set outlined: a calibrated confidence has no outlined high
    cell.  ``path``, ``ax``, ``fig`` as :func:`plot_error_map`.

    Returns
    -------
    matplotlib.figure.Figure
    """
    conf = result.confidence()
    names = ["high", "low", "not computed / failed"]
    codes = np.array([[0 if c == "high" else 1 if c == "low" else 2 for c in row] for row in conf], dtype=int)
    high = int((codes == 0).sum())
    title = f"confidence of approximate_attractor's primary prediction: high at {high}/{codes.size} points"
    return _categories(ax, fig, result, codes, names, ["#4daf4a", "#ff7f00", "#bdbdbd"], title, path,
                       _missed(result))


def write_maps(result: Any, directory, progress: Callable[[int, int, str], Any] | None = None) -> list[str]:
    """Every map of the atlas as a PNG in ``directory`` (created): ``dynamics.png``;
    ``error_<approximation>_<observable>.png`` for each approximation and observable (the approximation's
    :func:`~comparisons.atlas.approximations.key_of`); ``segments_dt_median.png`` and
    ``segments_dF_median.png``; with sets ``multistability.png`` and ``confidence.png``.  ``progress(i, n,
    path)`` is called after each map is written.  Returns the
    paths."""
    os.makedirs(directory, exist_ok=True)
    jobs: list[tuple[str, Callable[..., Any], tuple]] = [
        (os.path.join(directory, "dynamics.png"), plot_dynamics_map, ())]
    for name in result.approximations:
        for obs in OBSERVABLES:
            jobs.append((os.path.join(directory, f"error_{key_of(name)}_{obs}.png"), plot_error_map, (name, obs)))
    if result.reductions:
        for stat in ("dt_median", "dF_median"):
            jobs.append((os.path.join(directory, f"segments_{stat}.png"), plot_segment_maps, (stat,)))
    if getattr(result, "has_sets", False):
        jobs.append((os.path.join(directory, "multistability.png"), plot_multistability_map, ()))
        jobs.append((os.path.join(directory, "confidence.png"), plot_confidence_map, ()))
    paths = []
    for i, (path, draw, extra) in enumerate(jobs):
        draw(result, *extra, path)
        paths.append(path)
        if progress is not None:
            progress(i + 1, len(jobs), path)
    return paths

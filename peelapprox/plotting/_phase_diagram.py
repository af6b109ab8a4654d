"""A sweep quantity over the (V, I) plane (:func:`plot_phase_diagram`) and its cells (:func:`cell_edges`)."""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

import numpy as np

from ._figure import _canvas, _save, params_label

__all__ = ["cell_edges", "plot_phase_diagram"]


def cell_edges(x: np.ndarray, log: bool = False) -> np.ndarray:
    """Cell edges around increasing grid values ``x`` for ``pcolormesh``: the midpoints (of log10 x if ``log``),
    the outer edges mirrored; one value gets a cell of half a decade (``log``) or 10 % of it either side."""
    y = np.log10(x) if log else np.asarray(x, float)
    if y.size == 1:
        h = 0.5 if log else max(0.1 * abs(y[0]), 1e-12)
        e = np.array([y[0] - h, y[0] + h])
    else:
        mid = 0.5 * (y[1:] + y[:-1])
        e = np.concatenate([[2 * y[0] - mid[0]], mid, [2 * y[-1] - mid[-1]]])
    return 10.0 ** e if log else e


def _label(result: Any, key: str) -> str:
    """The colour bar's label: the key's description and unit where the result describes its keys (a sweep's
    ``describe``), else the key."""
    describe = getattr(result, "describe", None)
    if describe is None:
        return key
    unit, text = describe(key)
    return f"{text} [{unit}]" if unit else text


def _mark_missing(ax: Any, result: Any, vals: np.ndarray, I: np.ndarray, V: np.ndarray, oi: np.ndarray,
                  ov: np.ndarray) -> None:
    """An "x" on each blank cell whose point has a record (a breakdown, a failed measure), with its status in a
    legend: a white cell is explained, not left to guess."""
    try:
        status = result.values("status")[np.ix_(oi, ov)]
    except (KeyError, ValueError, AttributeError):
        return
    blank = ~np.isfinite(np.asarray(vals, dtype=float))
    seen: dict[str, list[tuple[float, float]]] = {}
    for i, j in zip(*np.nonzero(blank)):
        st = status[i, j]
        if st is not None and st != "ok":
            seen.setdefault(str(st), []).append((float(V[j]), float(I[i])))
    for n, (st, pts) in enumerate(seen.items()):
        xs, ys = zip(*pts)
        ax.scatter(xs, ys, marker="x", s=30, color=("0.3", "tab:red", "tab:orange", "tab:purple")[n % 4],
                   label=f"no value: {st}")
    if seen:
        ax.legend(loc="upper left", bbox_to_anchor=(0.0, -0.12), fontsize=8, frameon=False)


def plot_phase_diagram(result: Any, key: str, path: str | None = None, *, log_I: bool = True,
                       log_V: bool = False, title: str | None = None, ax: Any = None, fig: Any = None):
    """A sweep quantity over the (V, I) plane, one cell per grid point (pcolormesh).

    Parameters
    ----------
    result : peelapprox.SweepResult
        From :func:`peelapprox.sweep` or :func:`peelapprox.load_sweep`.
    key : str
        A record key, e.g. ``"regime_label"`` or ``"jumps_mean_period"``.
        Numbers get a colour bar; anything else (labels, statuses) is
        categorical: one discrete colour per value, with a legend.  Points
        without a value are left blank (white).
    path : str, optional
        Also write the figure there (format from the extension).
    log_I, log_V : bool
        Logarithmic I (default) / V axis; cell edges are the midpoints
        between grid values on that scale.
    title : str, optional
    ax : matplotlib axes, optional
        Draw there (the colour bar or legend beside it).
    fig : matplotlib.figure.Figure, optional
        Draw into this (empty) figure.  Neither: a new :func:`new_figure`.

    Returns
    -------
    matplotlib.figure.Figure
        The figure drawn into (that of ``ax`` when given).
    """
    from matplotlib import colormaps
    from matplotlib.colors import BoundaryNorm, ListedColormap
    from matplotlib.patches import Patch

    vals = result.values(key)
    I = np.asarray(result.I_values, float)
    V = np.asarray(result.V_values, float)
    oi, ov = np.argsort(I), np.argsort(V)
    I, V, vals = I[oi], V[ov], vals[np.ix_(oi, ov)]

    VE, IE = cell_edges(V, log_V), cell_edges(I, log_I)
    fig, axs = _canvas(ax, fig, (1, 1), (8, 5.5))
    ax = axs[0, 0]
    if vals.dtype == object:
        cats = list(dict.fromkeys(v for v in vals.ravel() if v is not None))
        cmap_name = "tab10" if len(cats) <= 10 else "tab20"
        base = colormaps[cmap_name]
        colours = [base(i % base.N) for i in range(max(len(cats), 1))]
        codes = np.full(vals.shape, np.nan)
        for n, c in enumerate(cats):
            codes[vals == c] = n
        cmap = ListedColormap(colours).with_extremes(bad="white")
        norm = BoundaryNorm(np.arange(-0.5, len(colours) + 0.5), len(colours))
        ax.pcolormesh(VE, IE, np.ma.masked_invalid(codes), cmap=cmap, norm=norm, edgecolors="face")
        ax.legend(handles=[Patch(facecolor=colours[n], label=str(c)) for n, c in enumerate(cats)],
                  loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8, title=key, title_fontsize=8)
    else:
        cmap = colormaps["viridis"].with_extremes(bad="white")
        mesh = ax.pcolormesh(VE, IE, np.ma.masked_invalid(vals), cmap=cmap, edgecolors="face")
        fig.colorbar(mesh, ax=ax, label=_label(result, key))
        _mark_missing(ax, result, vals, I, V, oi, ov)
    if log_I:
        ax.set_yscale("log")
    if log_V:
        ax.set_xscale("log")
    ax.set(xlabel="V [m/s]", ylabel="I [kg m²]", xlim=(VE[0], VE[-1]), ylim=(IE[0], IE[-1]))
    n_done = sum(1 for _ in result.records)
    opts = dict(getattr(result, "options", None) or {})
    fixed = params_label(SimpleNamespace(**{**{n: None for n in ("tape_mass", "load", "load_mass")}, **opts,
                                            "force": getattr(result, "force", None)}), skip=("V", "I"))
    ax.set_title(title or f"{key} over (V, I){', ' + fixed if fixed else ''}: {n_done}/{I.size * V.size} points")
    _save(fig, path)
    return fig

"""A burst-size distribution with its fitted laws (:func:`plot_burst_distribution`)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from ._figure import _canvas, _save

__all__ = ["plot_burst_distribution"]


def plot_burst_distribution(sizes: Any, fits: Sequence[Any] = (), path: str | None = None, *,
                            xlabel: str = "burst size", title: str | None = None, ax: Any = None, fig: Any = None):
    """The empirical CCDF ``P(S >= s)`` of burst sizes on log-log axes, with the fitted laws.

    Parameters
    ----------
    sizes : array_like or PowerLawFit or BrokenPowerLawFit
        The sizes (values > 0), or a fit, whose data are drawn.
    fits : sequence
        :class:`peelapprox.PowerLawFit` and :class:`peelapprox.BrokenPowerLawFit` to draw: each fit's CCDF from
        its xmin on, scaled by the share of the sizes it describes (so that it meets the data there).
    path : str, optional
        Also write the figure there.
    xlabel, title : str
    ax : matplotlib axes, optional
    fig : matplotlib.figure.Figure, optional

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    ValueError
        No size > 0.
    """
    data = getattr(sizes, "data", sizes)
    x = np.sort(np.asarray(data, dtype=float).ravel())
    x = x[np.isfinite(x) & (x > 0)]
    if x.size == 0:
        raise ValueError("sizes must hold at least one finite size > 0")
    if hasattr(sizes, "data") and not fits:
        fits = [sizes]
    fig, axs = _canvas(ax, fig, (1, 1), (6, 4.5))
    a = axs[0, 0]
    ccdf = 1.0 - np.arange(x.size) / x.size
    a.loglog(x, ccdf, ".", ms=3, color="0.3", label=f"data ({x.size} bursts)")
    for k, f in enumerate(fits):
        lo = float(f.xmin)
        hi = float(x[-1]) if getattr(f, "xmax", None) is None else float(f.xmax)
        s = np.geomspace(lo, max(hi, lo * 1.0001), 200)
        share = float(np.mean(x >= lo))
        if hasattr(f, "alpha1"):
            label = (f"broken: {f.alpha1:.3g} | {f.alpha2:.3g} at {f.x_break:.3g}")
        else:
            label = f"power law: alpha {f.alpha:.3g}, xmin {f.xmin:.3g}"
        a.loglog(s, share * f.ccdf(s), "-", lw=1.5, color=f"C{k}", label=label)
    a.set_xlabel(xlabel)
    a.set_ylabel("P(S >= s)")
    if title:
        a.set_title(title)
    a.legend(fontsize="small")
    _save(fig, path)
    return fig

"""The peel front's space-time image (``exact.simulate_front``'s result)."""

from __future__ import annotations

import os
from typing import Any

import numpy as np

from ._figure import new_figure, save_figure

__all__ = ["plot_front"]


def plot_front(tr: Any, *, fig: Any = None, path: str | os.PathLike | None = None, max_columns: int = 2000) -> Any:
    """The front in space and time: ``log10 v_j`` as an image (strip j across, time up the page), the AE power
    ``R_AE`` and the pull force F below it.

    Parameters
    ----------
    tr : exact.FrontTrajectory
        A run with the front stored (``store_front=True``) and at least 2 points.
    fig : matplotlib Figure, optional
        An empty figure to draw into; default a new one (:func:`new_figure`).
    path : path, optional
        Also write the figure there (:func:`save_figure`).
    max_columns : int
        At most this many time points in the image (evenly chosen: an image of 1e5 rows would be drawn at the
        screen's resolution anyway).

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    ValueError
        The run holds no front or fewer than 2 points.
    """
    v = getattr(tr, "front_v", None)
    if v is None or len(tr.t) < 2:
        raise ValueError("tr must be a FrontTrajectory with the front stored (store_front=True) and at least 2 points")
    if not isinstance(max_columns, int) or max_columns < 2:
        raise ValueError(f"max_columns must be an integer >= 2, got {max_columns!r}")
    fig = fig if fig is not None else new_figure(figsize=(7.0, 7.0))
    axes = fig.subplots(3, 1, sharex=True, gridspec_kw={"height_ratios": [3, 1, 1]})
    idx = np.unique(np.linspace(0, len(tr.t) - 1, min(max_columns, len(tr.t))).astype(int))
    t = tr.t[idx]
    n = v.shape[1]
    img = np.log10(v[idx].T)
    edges = np.concatenate([[t[0]], (t[1:] + t[:-1]) / 2, [t[-1]]])
    mesh = axes[0].pcolormesh(edges, np.arange(n + 1) - 0.5, img, shading="flat", cmap="viridis")
    fig.colorbar(mesh, ax=axes[0], label="log10 v_j [m/s]")
    axes[0].set_ylabel("strip j")
    p = tr.params
    axes[0].set_title(f"N={n}, gamma={p.gamma:.3g}, kappa={p.kappa:.3g}, {p.ends} ends\n"
                      f"V={p.base.V:g} m/s, I={p.base.I:g} kg m^2, m={p.m:g} kg", fontsize=10)
    axes[1].plot(tr.t, tr.ae_power, lw=0.7, color="C3")
    axes[1].set_ylabel("R_AE [W]")
    axes[2].plot(tr.t, tr.F, lw=0.8, color="C0")
    axes[2].set_ylabel("F [N]")
    axes[2].set_xlabel("t [s]")
    if path is not None:
        save_figure(fig, path)
    return fig

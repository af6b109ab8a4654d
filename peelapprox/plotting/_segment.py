"""A reduced branch solution against time (:func:`plot_segment`, the paper's Figs. 8 and 9)."""

from __future__ import annotations

from typing import Any

from ._figure import _canvas, _save

__all__ = ["plot_segment"]


def plot_segment(seg: Any, path: str | None = None, *, exact: Any = None, title: str | None = None,
                 ax: Any = None, fig: Any = None):
    """v(t), α(t) and F(t) of a reduced branch solution (as the paper's Figs. 8 and 9).

    Parameters
    ----------
    seg : peelapprox.ReducedSegment
        From :func:`peelapprox.reduced_segment` with stored curves.
    path : str, optional
        Also write the figure there (format from the extension).
    exact : object, optional
        Anything with arrays ``t`` (from the branch entry), ``v``, ``alpha``,
        ``F``: drawn dotted for comparison (the paper's "numerically exact").
    title : str, optional
    ax : sequence of 3 matplotlib axes, optional
        Draw there, in the order v(t), α(t), F(t).
    fig : matplotlib.figure.Figure, optional
        Draw into this (empty) figure, as 3 panels sharing t.  Neither: a new :func:`new_figure`.

    Returns
    -------
    matplotlib.figure.Figure
        The figure drawn into (that of ``ax`` when given).
    """
    fig, axs = _canvas(ax, fig, (3, 1), (7, 8), sharex=True)
    ax = axs[:, 0]
    label = f"{seg.alpha_model} + {seg.v_equation}"
    for a, y, name in ((ax[0], "v", "v [m/s]"), (ax[1], "alpha", r"$\alpha$ [rad]"), (ax[2], "F", "F [N]")):
        a.plot(seg.t, getattr(seg, y), lw=1.2, color="C0", label=label)
        if exact is not None:
            a.plot(exact.t, getattr(exact, y), ":", lw=1.5, color="k", label="exact")
        a.set_ylabel(name)
    if seg.branch == "AB":
        ax[0].set_yscale("log")
    ax[0].axhline(seg.v_f, color="C1", lw=0.8, ls="--", label=f"v_f = {seg.v_f:.4g}")
    ax[0].legend(loc="best", fontsize=8)
    ax[2].set_xlabel("t since branch entry [s]")
    fig.suptitle(title or f"{seg.branch}: Δt = {seg.dt:.4g} s, ΔF = {seg.dF:.4g} N")
    _save(fig, path)
    return fig

"""Plots.  matplotlib is imported here, lazily, and nowhere else."""

from __future__ import annotations

from typing import Any, Optional

import numpy as np

from ._peelforce import branch_structure, peel_force

__all__ = ["plot_trajectory", "plot_segment"]


def _pyplot():
    import matplotlib

    if matplotlib.get_backend().lower() not in ("agg", "module://matplotlib_inline.backend_inline"):
        try:
            matplotlib.use("Agg")
        except Exception:  # pragma: no cover - backend already fixed by the user
            pass
    import matplotlib.pyplot as plt

    return plt


def plot_trajectory(traj: Any, path: Optional[str] = None, *, title: Optional[str] = None):
    """F(t), α(t), v(t) and the v–F phase plane with f(v, V) (as the paper's Fig. 3).

    Parameters
    ----------
    traj : exact.Trajectory
        Any object with ``t, alpha, F, v, branch`` arrays, ``jumps`` and ``params``.
    path : str, optional
        Write the figure there (format from the extension) and close it.
    title : str, optional

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = _pyplot()
    p = traj.params
    fig, ax = plt.subplots(2, 2, figsize=(11, 7.5), constrained_layout=True)
    t = traj.t
    ax[0, 0].plot(t, traj.F, lw=0.8, color="C0")
    ax[0, 0].set(xlabel="t [s]", ylabel="F [N]", title="pull force F(t)")
    ax[0, 1].plot(t, traj.alpha, lw=0.8, color="C2")
    ax[0, 1].set(xlabel="t [s]", ylabel=r"$\alpha$ [rad]", title=r"peel angle $\alpha(t)$")
    ax[1, 0].semilogy(t, traj.v, lw=0.8, color="C3")
    ax[1, 0].set(xlabel="t [s]", ylabel="v [m/s]", title="peel velocity v(t)")
    bs = branch_structure(p.V)
    vlo = float(np.min(traj.v)) / 2 if len(traj.v) else 1e-4
    vhi = float(np.max(traj.v)) * 1.3 if len(traj.v) else 30.0
    vv = np.logspace(np.log10(vlo), np.log10(vhi), 600)
    ax[1, 1].semilogx(vv, peel_force(vv, p.V), color="k", lw=1.5, label="f(v, V)")
    ax[1, 1].semilogx(traj.v, traj.F, lw=0.6, color="C0", label="orbit (v, F)")
    if bs.has_folds:
        ax[1, 1].plot([bs.v_max, bs.v_min], [bs.f_max, bs.f_min], "o", color="C1", label="folds B, D")
    if len(traj.F):
        lo, hi = float(np.min(traj.F)), float(np.max(traj.F))
        pad = 0.08 * (hi - lo + 1.0)
        ax[1, 1].set_ylim(min(lo, bs.f_min if bs.has_folds else lo) - pad, max(hi, bs.f_max if bs.has_folds else hi) + pad)
    ax[1, 1].set(xlabel="v [m/s]", ylabel="F [N]", title="v–F phase plane")
    ax[1, 1].legend(loc="best", fontsize=8)
    ttl = title or f"V = {p.V} m/s, I = {p.I:g} kg m², k = {p.k:g} N/m, method = {traj.method}"
    fig.suptitle(ttl)
    if path:
        fig.savefig(path, dpi=120)
        plt.close(fig)
    return fig


def plot_segment(seg: Any, path: Optional[str] = None, *, exact: Any = None, title: Optional[str] = None):
    """v(t), α(t) and F(t) of a reduced branch solution (as the paper's Figs. 8 and 9).

    Parameters
    ----------
    seg : peelapprox.ReducedSegment
        From :func:`peelapprox.reduced_segment` with stored curves.
    path : str, optional
        Write the figure there (format from the extension) and close it.
    exact : object, optional
        Anything with arrays ``t`` (from the branch entry), ``v``, ``alpha``,
        ``F``: drawn dotted for comparison (the paper's "numerically exact").
    title : str, optional

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = _pyplot()
    fig, ax = plt.subplots(3, 1, figsize=(7, 8), sharex=True, constrained_layout=True)
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
    if path:
        fig.savefig(path, dpi=120)
        plt.close(fig)
    return fig

"""Plots.  matplotlib is set up here (:func:`pyplot`, imported lazily) and nowhere else; the CLI's output-path
check (:mod:`peelapprox.cli._checks`) only asks matplotlib, lazily too, which image formats it can write."""

from __future__ import annotations

from typing import Any, cast

import numpy as np

__all__ = ["plot_bifurcation", "plot_phase_diagram", "plot_segment", "plot_trajectory", "pyplot"]


def pyplot():
    """``matplotlib.pyplot``, imported on first use, on the file backend Agg (an inline notebook backend is kept).

    The one place that sets matplotlib up: every figure of the three packages is drawn with it.
    """
    import matplotlib

    if matplotlib.get_backend().lower() not in ("agg", "module://matplotlib_inline.backend_inline"):
        try:
            matplotlib.use("Agg")
        except Exception:  # pragma: no cover - backend already fixed by the user
            pass
    import matplotlib.pyplot as plt

    return plt


def plot_trajectory(traj: Any, path: str | None = None, *, title: str | None = None):
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
    plt = pyplot()
    p = traj.params
    fig, ax = plt.subplots(2, 2, figsize=(11, 7.5), constrained_layout=True)
    t = traj.t
    ax[0, 0].plot(t, traj.F, lw=0.8, color="C0")
    ax[0, 0].set(xlabel="t [s]", ylabel="F [N]", title="pull force F(t)")
    ax[0, 1].plot(t, traj.alpha, lw=0.8, color="C2")
    ax[0, 1].set(xlabel="t [s]", ylabel=r"$\alpha$ [rad]", title=r"peel angle $\alpha(t)$")
    ax[1, 0].semilogy(t, traj.v, lw=0.8, color="C3")
    ax[1, 0].set(xlabel="t [s]", ylabel="v [m/s]", title="peel velocity v(t)")
    vlo = float(np.min(traj.v)) / 2 if len(traj.v) else 1e-4
    vhi = float(np.max(traj.v)) * 1.3 if len(traj.v) else 30.0
    vv = np.logspace(np.log10(vlo), np.log10(vhi), 600)
    bs = p.force.folds(p.V)  # the run's own law (the paper's: branch_structure's folds, peel_force itself)
    ax[1, 1].semilogx(vv, p.force.f(vv, p.V), color="k", lw=1.5, label="f(v, V)")
    ax[1, 1].semilogx(traj.v, traj.F, lw=0.6, color="C0", label="orbit (v, F)")
    if bs.has_folds:
        ax[1, 1].plot([bs.v_max, bs.v_min], [bs.f_max, bs.f_min], "o", color="C1", label="folds B, D")
    if len(traj.F):
        lo, hi = float(np.min(traj.F)), float(np.max(traj.F))
        pad = 0.08 * (hi - lo + 1.0)
        ax[1, 1].set_ylim(min(lo, cast(float, bs.f_min) if bs.has_folds else lo) - pad,
                          max(hi, cast(float, bs.f_max) if bs.has_folds else hi) + pad)
    ax[1, 1].set(xlabel="v [m/s]", ylabel="F [N]", title="v–F phase plane")
    ax[1, 1].legend(loc="best", fontsize=8)
    ttl = title or f"V = {p.V} m/s, I = {p.I:g} kg m², k = {p.k:g} N/m, method = {traj.method}"
    fig.suptitle(ttl)
    if path:
        fig.savefig(path, dpi=120)
        plt.close(fig)
    return fig


def plot_segment(seg: Any, path: str | None = None, *, exact: Any = None, title: str | None = None):
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
    plt = pyplot()
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


def plot_phase_diagram(result: Any, key: str, path: str | None = None, *, log_I: bool = True,
                       log_V: bool = False, title: str | None = None):
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
        Write the figure there (format from the extension) and close it.
    log_I, log_V : bool
        Logarithmic I (default) / V axis; cell edges are the midpoints
        between grid values on that scale.
    title : str, optional

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = pyplot()
    from matplotlib.colors import BoundaryNorm, ListedColormap
    from matplotlib.patches import Patch

    vals = result.values(key)
    I = np.asarray(result.I_values, float)
    V = np.asarray(result.V_values, float)
    oi, ov = np.argsort(I), np.argsort(V)
    I, V, vals = I[oi], V[ov], vals[np.ix_(oi, ov)]

    def edges(x: np.ndarray, log: bool) -> np.ndarray:
        y = np.log10(x) if log else x
        if y.size == 1:
            h = 0.5 if log else max(0.1 * abs(y[0]), 1e-12)
            e = np.array([y[0] - h, y[0] + h])
        else:
            mid = 0.5 * (y[1:] + y[:-1])
            e = np.concatenate([[2 * y[0] - mid[0]], mid, [2 * y[-1] - mid[-1]]])
        return 10.0 ** e if log else e

    VE, IE = edges(V, log_V), edges(I, log_I)
    fig, ax = plt.subplots(figsize=(8, 5.5), constrained_layout=True)
    if vals.dtype == object:
        cats = list(dict.fromkeys(v for v in vals.ravel() if v is not None))
        cmap_name = "tab10" if len(cats) <= 10 else "tab20"
        base = plt.get_cmap(cmap_name)
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
        cmap = plt.get_cmap("viridis").with_extremes(bad="white")
        mesh = ax.pcolormesh(VE, IE, np.ma.masked_invalid(vals), cmap=cmap, edgecolors="face")
        fig.colorbar(mesh, ax=ax, label=key)
    if log_I:
        ax.set_yscale("log")
    if log_V:
        ax.set_xscale("log")
    ax.set(xlabel="V [m/s]", ylabel="I [kg m²]", xlim=(VE[0], VE[-1]), ylim=(IE[0], IE[-1]))
    n_done = sum(1 for _ in result.records)
    ax.set_title(title or f"{key} over (V, I): {n_done}/{I.size * V.size} points")
    if path:
        fig.savefig(path, dpi=120)
        plt.close(fig)
    return fig




_BIFURCATION_MARKERS = {"fold": ("s", "C3"), "period_doubling": ("D", "C1"), "neimark_sacker": ("*", "C4")}
_END_MARKERS = {"grazing": "x", "crest": "+", "breakdown": "1"}


def plot_bifurcation(diagram: Any = None, branches: Any = (), path: str | None = None, *,
                     title: str | None = None):
    """The brute-force orbit diagram with continued branches of periodic orbits drawn over it.

    Parameters
    ----------
    diagram : exact.OrbitDiagram, optional
        Grey dots: F at the AB→CD jumps after the transient, at each value of the parameter.
    branches : sequence of exact.OrbitBranch
        Each branch's return-map values (F at its n jumps) against the parameter (one colour per starting
        orbit): solid where the orbit is stable, dashed where it is unstable; its bifurcations marked
        (square: fold, diamond: period doubling, star: Neimark–Sacker) and its non-smooth end (``end_value``:
        x grazing, + crest event, tri breakdown).
    path : str, optional
        Write the figure there (format from the extension) and close it.
    title : str, optional

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(9, 5.5), constrained_layout=True)
    name = getattr(diagram, "parameter", None)
    if diagram is not None:
        for x, F in zip(diagram.values, diagram.returns):
            ax.plot(np.full(F.size, x), F, ".", color="0.45", ms=2.5, alpha=0.8)
    branches = list(branches)
    label_branches = len({id(b.points[0].orbit) for b in branches}) <= 6  # else only the markers are listed
    k, start = -1, None
    for br in branches:
        name = br.parameter
        if br.points[0].orbit is not start:  # branches continued from one orbit (both ways) share a colour
            k, start = k + 1, br.points[0].orbit
        color = f"C{k % 10}"
        xs = np.array([p.value for p in br.points])
        stable = np.array([p.orbit.stable for p in br.points])
        n = br.points[0].orbit.n
        # (points, n), each point's values sorted: the set of F at its jumps, as the diagram shows them (the
        # cyclic order of an orbit's jumps is not kept from point to point)
        Fs = np.sort(np.array([p.orbit.return_map_values for p in br.points]), axis=1)
        for i in range(len(xs) - 1):  # each piece solid if both its ends are stable, else dashed
            style = "-" if stable[i] and stable[i + 1] else "--"
            for j in range(n):
                ax.plot(xs[i:i + 2], Fs[i:i + 2, j], style, color=color, lw=1.4,
                        label=f"period-{n} branch {k + 1}" if i == 0 and j == 0 and label_branches else None)
        for b in br.bifurcations:
            marker, c = _BIFURCATION_MARKERS.get(b.kind, ("o", "k"))
            ax.plot(np.full(n, b.value), b.orbit.return_map_values, marker, color=c, ms=8, mec="k",
                    label=b.kind.replace("_", " "))
        if br.stopped in _END_MARKERS:  # the non-smooth end, at its (extrapolated) parameter value
            ax.plot(np.full(n, br.end_value), Fs[-1], _END_MARKERS[br.stopped], color="k", ms=7,
                    label=br.stopped)
    handles, labels = ax.get_legend_handles_labels()
    uniq = dict(zip(labels, handles))
    if uniq:
        ax.legend(uniq.values(), uniq.keys(), loc="best", fontsize=8)
    ax.set(xlabel=str(name), ylabel="F at the AB→CD jumps [N]", title=title or "orbit diagram and branches")
    if path:
        fig.savefig(path, dpi=130)
        plt.close(fig)
    return fig

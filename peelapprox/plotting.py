"""Plots.  Every plot function draws into ``ax=`` (its axes) or ``fig=`` (an empty figure) when given, else into a
new :class:`matplotlib.figure.Figure` made without pyplot (:func:`new_figure`), and returns the figure.

The package never calls ``matplotlib.use`` and never changes the backend of the session it runs in.  A figure it
makes itself is not registered with pyplot: it needs no backend, nothing has to close it, and in Jupyter it is
displayed once, as the value of the cell (``display(fig)`` shows it elsewhere).  To draw into a pyplot window,
pass your own: ``plot_trajectory(traj, fig=plt.figure())`` then ``plt.show()``.  matplotlib is imported on
first use only (``import peelapprox`` loads none); the CLI's output-path check (``peelapprox.cli._checks``)
only asks it, lazily too, which image formats it can write.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, cast

import numpy as np

__all__ = ["cell_edges", "new_figure", "plot_bifurcation", "plot_phase_diagram", "plot_segment", "plot_trajectory",
           "pyplot", "TRAJECTORY_CYCLES"]

#: The stick-slip cycles (AB→CD jump to AB→CD jump) :func:`plot_trajectory` shows by default: the last ones.
TRAJECTORY_CYCLES = 5


def pyplot():
    """``matplotlib.pyplot``, imported on first use.  It does not choose or change the backend (the session's,
    or matplotlib's automatic choice: Agg without a display); the package's own figures do not need it
    (:func:`new_figure`)."""
    import matplotlib.pyplot as plt

    return plt


def new_figure(*, figsize: tuple[float, float] | None = None, layout: Any = "constrained", **kwargs: Any):
    """A :class:`matplotlib.figure.Figure` made without pyplot: no backend, no global state, nothing to close.

    It is saved with ``fig.savefig(path)`` (the format from the extension), and shown in Jupyter as a cell's
    value.  ``kwargs`` go to ``Figure``.
    """
    from matplotlib.figure import Figure

    return Figure(figsize=figsize, layout=layout, **kwargs)


def _canvas(ax: Any, fig: Any, shape: tuple[int, int], figsize: tuple[float, float], **subplot_kw: Any):
    """``(figure, axes)``: ``axes`` an object array of ``shape``, from ``ax`` (that many axes), from ``fig``
    (its new subplots) or from a :func:`new_figure`.

    Raises
    ------
    ValueError
        ``ax`` and ``fig`` both given, or ``ax`` not ``shape[0] * shape[1]`` axes.
    TypeError
        ``ax`` not matplotlib axes, ``fig`` not a figure.
    """
    n = shape[0] * shape[1]
    if ax is not None and fig is not None:
        raise ValueError("ax and fig: give one of them (the figure of ax is where it is drawn)")
    if ax is not None:
        flat = list(np.ravel(np.asarray(ax, dtype=object))) if isinstance(ax, (Sequence, np.ndarray)) else [ax]
        if len(flat) != n:
            raise ValueError(f"ax must be {n} axes (this plot has {shape[0]} x {shape[1]} panels), got {len(flat)}")
        for a in flat:
            if not (hasattr(a, "plot") and hasattr(a, "figure")):
                raise TypeError(f"ax must be matplotlib axes, got {type(a).__name__}")
        return flat[0].figure, np.array(flat, dtype=object).reshape(shape)
    if fig is None:
        fig = new_figure(figsize=figsize)
    elif not hasattr(fig, "subplots"):
        raise TypeError(f"fig must be a matplotlib figure, got {type(fig).__name__}")
    axs = fig.subplots(*shape, squeeze=False, **subplot_kw)
    return fig, axs


def _save(fig: Any, path: str | None, dpi: int = 120) -> None:
    """Write ``fig`` to ``path`` (format from the extension) when given; the figure stays open (whoever made it
    owns it: a :func:`new_figure` needs no closing)."""
    if path:
        fig.savefig(path, dpi=dpi)


def _window(traj: Any, cycles: int | None) -> tuple[float, float, int, int]:
    """``(t_lo, t_hi, shown, total)``: the span of the last ``cycles`` stick-slip cycles of ``traj`` (from the
    AB→CD jump ``cycles`` returns before its last one to its end), ``shown`` and ``total`` cycles; the whole
    run when ``cycles`` is None or the run has no more cycles than that."""
    t = np.asarray(traj.t, float)
    lo, hi = (float(t[0]), float(t[-1])) if t.size else (0.0, 0.0)
    jumps = getattr(traj, "jumps", None)
    if jumps is None or not len(t):
        return lo, hi, 0, 0
    from ._returnmap import return_map

    t_k, _ = return_map(traj, with_times=True)
    t_k = t_k[(t_k >= lo) & (t_k <= hi)]
    total = max(int(t_k.size) - 1, 0)
    if cycles is None or total <= cycles:
        return lo, hi, total, total
    return float(t_k[-cycles - 1]), hi, cycles, total


def plot_trajectory(traj: Any, path: str | None = None, *, title: str | None = None,
                    cycles: int | None = TRAJECTORY_CYCLES, ax: Any = None, fig: Any = None):
    """F(t), α(t), v(t) and the v–F phase plane with f(v, V) (as the paper's Fig. 3), over the last few cycles.

    Parameters
    ----------
    traj : exact.Trajectory
        Any object with ``t, alpha, F, v, branch`` arrays, ``jumps`` and ``params``.
    path : str, optional
        Also write the figure there (format from the extension).
    title : str, optional
        Default: V, I, k, the model variant if any (its tape mass, its load), the method and the span
        shown.
    cycles : int or None
        Show the last ``cycles`` stick-slip cycles (AB→CD jump to AB→CD jump; default
        :data:`TRAJECTORY_CYCLES`): seconds of stick-slip at a few cycles per 0.1 s are a solid block of
        lines.  None: the whole run (as does a run with no more cycles than that).
    ax : sequence of 4 matplotlib axes, optional
        Draw there, in the order F(t), α(t), v(t), v–F plane.
    fig : matplotlib.figure.Figure, optional
        Draw into this (empty) figure, as 2 x 2 panels.  Neither: a new :func:`new_figure`.

    Returns
    -------
    matplotlib.figure.Figure
        The figure drawn into (that of ``ax`` when given).

    Notes
    -----
    Under a load (``traj.Vp`` not None: ``params.loading == "load"``), the F(t) panel also shows the pull
    speed V_p(t) on a twin axis (right, dashed), with the load's speed scale.
    """
    if cycles is not None:
        from .validate import integer

        cycles = integer("cycles", cycles, lo=1)
    fig, ax = _canvas(ax, fig, (2, 2), (11, 7.5))
    p = traj.params
    lo, hi, shown, total = _window(traj, cycles)
    t_all = np.asarray(traj.t, float)
    m = (t_all >= lo) & (t_all <= hi)
    t, F, alpha, v = t_all[m], np.asarray(traj.F)[m], np.asarray(traj.alpha)[m], np.asarray(traj.v)[m]
    ax[0, 0].plot(t, F, lw=0.8, color="C0")
    ax[0, 0].set(xlabel="t [s]", ylabel="F [N]", title="pull force F(t)")
    Vp = getattr(traj, "Vp", None)
    if Vp is not None:  # under a load the pull speed is a state: on a twin axis of the force panel
        tw = ax[0, 0].twinx()
        tw.plot(t, np.asarray(Vp, float)[m], lw=0.8, ls="--", color="C4")
        tw.set_ylabel("$V_p$ [m/s]", color="C4")
        ax[0, 0].set_title("pull force F(t), pull speed $V_p(t)$ (dashed)")
    ax[0, 1].plot(t, alpha, lw=0.8, color="C2")
    ax[0, 1].set(xlabel="t [s]", ylabel=r"$\alpha$ [rad]", title=r"peel angle $\alpha(t)$")
    ax[1, 0].semilogy(t, v, lw=0.8, color="C3")
    ax[1, 0].set(xlabel="t [s]", ylabel="v [m/s]", title="peel velocity v(t)")
    # f(v, V) over the orbit's own velocities (not out to the law's whole range): the orbit fills the panel
    vlo = float(np.min(v)) / 2 if len(v) else 1e-4
    vhi = float(np.max(v)) * 1.3 if len(v) else 30.0
    vv = np.logspace(np.log10(vlo), np.log10(vhi), 600)
    bs = p.force.folds(p.V)  # the run's own law (the paper's: branch_structure's folds, peel_force itself)
    ax[1, 1].semilogx(vv, p.force.f(vv, p.V), color="k", lw=1.5, label="f(v, V)")
    ax[1, 1].semilogx(v, F, lw=0.6, color="C0", label="orbit (v, F)")
    if bs.has_folds:
        ax[1, 1].plot([bs.v_max, bs.v_min], [bs.f_max, bs.f_min], "o", color="C1", label="folds B, D")
    if len(F):
        flo, fhi = float(np.min(F)), float(np.max(F))
        pad = 0.08 * (fhi - flo + 1.0)
        ax[1, 1].set_ylim(min(flo, cast(float, bs.f_min) if bs.has_folds else flo) - pad,
                          max(fhi, cast(float, bs.f_max) if bs.has_folds else fhi) + pad)
        ax[1, 1].set_xlim(vlo, vhi)
    ax[1, 1].set(xlabel="v [m/s]", ylabel="F [N]", title="v–F phase plane")
    ax[1, 1].legend(loc="best", fontsize=8)
    span = f"t = {lo:.4g}–{hi:.4g} s" + (f", the last {shown} of {total} cycles" if shown < total else "")
    fig.suptitle(title or f"V = {p.V:g} m/s, I = {p.I:g} kg m², k = {p.k:g} N/m{_model_label(p)}, {traj.method}; "
                          f"{span}")
    _save(fig, path)
    return fig


def _model_label(params: Any) -> str:
    """A model variant of ``params`` in words, for a title, with a leading ``", "``: ``", tape mass m = 0.0001
    kg"``, ``", load F_L = 245 N on M = 25 kg"`` (both, for a massive tape under a load); ``""`` for the paper's
    model (its titles as before the variants existed)."""
    parts = []
    m = getattr(params, "tape_mass", None)
    if m:
        parts.append(f"tape mass m = {m:g} kg")
    if getattr(params, "loading", "velocity") == "load":
        if not m:
            parts.append("massless tape")
        parts.append(f"load F_L = {params.load:.4g} N on M = {params.load_mass:g} kg")
    return "".join(", " + x for x in parts)


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
        fig.colorbar(mesh, ax=ax, label=key)
    if log_I:
        ax.set_yscale("log")
    if log_V:
        ax.set_xscale("log")
    ax.set(xlabel="V [m/s]", ylabel="I [kg m²]", xlim=(VE[0], VE[-1]), ylim=(IE[0], IE[-1]))
    n_done = sum(1 for _ in result.records)
    ax.set_title(title or f"{key} over (V, I): {n_done}/{I.size * V.size} points")
    _save(fig, path)
    return fig


def plot_bifurcation(diagram: Any = None, branches: Any = (), path: str | None = None, *,
                     title: str | None = None, ax: Any = None, fig: Any = None):
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
        Also write the figure there (format from the extension).
    title : str, optional
    ax : matplotlib axes, optional
        Draw there.
    fig : matplotlib.figure.Figure, optional
        Draw into this (empty) figure.  Neither: a new :func:`new_figure`.

    Returns
    -------
    matplotlib.figure.Figure
        The figure drawn into (that of ``ax`` when given).
    """
    fig, axs = _canvas(ax, fig, (1, 1), (9, 5.5))
    ax = axs[0, 0]
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
            marker, c = b.marker  # from the kinds' table of exact.orbits
            ax.plot(np.full(n, b.value), b.orbit.return_map_values, marker, color=c, ms=8, mec="k",
                    label=b.kind.replace("_", " "))
        if br.end_marker is not None:  # the non-smooth end, at its (extrapolated) parameter value
            ax.plot(np.full(n, br.end_value), Fs[-1], br.end_marker, color="k", ms=7,
                    label=br.stopped)
    handles, labels = ax.get_legend_handles_labels()
    uniq = dict(zip(labels, handles))
    if uniq:
        ax.legend(uniq.values(), uniq.keys(), loc="best", fontsize=8)
    ax.set(xlabel=str(name), ylabel="F at the AB→CD jumps [N]", title=title or "orbit diagram and branches")
    _save(fig, path, dpi=130)
    return fig

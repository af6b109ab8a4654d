"""A run in time and in the v–F plane (:func:`plot_trajectory`), over a window that shows its attractor
(:func:`trajectory_window`: whole periods of the return map when the run has settled on a periodic orbit)."""

from __future__ import annotations

import math
from typing import Any, NamedTuple, cast

import numpy as np

from ._figure import _canvas, _save, params_label

__all__ = ["TRAJECTORY_PANELS", "TRAJECTORY_CYCLES", "TrajectoryWindow", "plot_trajectory", "trajectory_window"]

#: The stick-slip cycles (AB→CD jump to AB→CD jump) :func:`plot_trajectory` shows by default: the last ones,
#: rounded up to whole periods of the return map when the run is periodic.
TRAJECTORY_CYCLES = 5

#: The panels of :func:`plot_trajectory`, in their order: F(t), α(t), v(t) and the v–F phase plane.
TRAJECTORY_PANELS = ("F", "alpha", "v", "phase")

#: The return map counts as periodic for the window when its returns repeat within this fraction of max |F|:
#: 1e-3 of ~300 N is 0.3 N, under a pixel of a figure's force axis, so the window's periods look closed.
_PERIOD_RTOL = 1e-3

#: The returns the period is read from: the last ones, enough for period 32 twice over.
_PERIOD_TAIL = 96


class TrajectoryWindow(NamedTuple):
    """The span :func:`plot_trajectory` draws: ``start``, ``end`` [s], the stick-slip ``cycles`` in it and the
    ``total`` in the run, and ``period``: the return map's period n when the window is ``cycles / n`` whole
    periods (it then starts and ends at an AB→CD jump), else None."""

    start: float
    end: float
    cycles: int
    total: int
    period: int | None


def trajectory_window(traj: Any, cycles: int | None = TRAJECTORY_CYCLES) -> TrajectoryWindow:
    """The span of ``traj`` that :func:`plot_trajectory` shows: the attractor, not the last few slips.

    Parameters
    ----------
    traj : exact.Trajectory
        Any object with a ``t`` array and ``jumps`` (the AB→CD jumps give the cycles).
    cycles : int or None
        At least this many stick-slip cycles (AB→CD jump to AB→CD jump).  When the last returns repeat with a
        period n (within 1e-3 of the largest F: closed to the eye), the window is the last whole periods holding
        at least ``cycles`` returns (``n * ceil(cycles / n)``, fewer periods if the run has fewer), from one
        AB→CD jump to the last; otherwise it runs from the jump ``cycles`` returns before the last one to the
        run's end.  None, or a run with no more cycles than that: the whole run.

    Returns
    -------
    TrajectoryWindow
    """
    from ..validate import integer

    if cycles is not None:
        cycles = integer("cycles", cycles, lo=1)
    t = np.asarray(traj.t, float)
    lo, hi = (float(t[0]), float(t[-1])) if t.size else (0.0, 0.0)
    jumps = getattr(traj, "jumps", None)
    if jumps is None or not len(t):
        return TrajectoryWindow(lo, hi, 0, 0, None)
    from .._returnmap import periodicity, return_map

    t_k, x = return_map(traj, with_times=True)
    inside = (t_k >= lo) & (t_k <= hi)
    t_k, x = t_k[inside], x[inside]
    total = max(int(t_k.size) - 1, 0)
    if cycles is None:
        return TrajectoryWindow(lo, hi, total, total, None)
    n = periodicity(x[-_PERIOD_TAIL:], rtol=_PERIOD_RTOL).period if x.size >= 2 else None
    if n is not None:
        m = n * math.ceil(cycles / n)
        if m > total:
            m = n * (total // n)
        if m > 0:
            return TrajectoryWindow(float(t_k[-m - 1]), float(t_k[-1]), m, total, n)
    if total <= cycles:
        return TrajectoryWindow(lo, hi, total, total, None)
    return TrajectoryWindow(float(t_k[-cycles - 1]), hi, cycles, total, None)


def _panel_shape(k: int) -> tuple[tuple[int, int], tuple[float, float]]:
    """Grid and figure size of ``k`` panels: one row up to 3, 2 x 2 for 4."""
    return ((2, 2), (11, 7.5)) if k == 4 else ((1, k), (5.5 * k, 4.2))


def _samples(traj: Any, dense: Any, lo: float, hi: float) -> dict[str, np.ndarray]:
    """The arrays drawn over ``[lo, hi]``: ``traj``'s points there, with ``dense``'s merged in by time when
    given (``traj``'s own jump states kept, so a jump stays a vertical line)."""
    names = ["t", "F", "alpha", "v"] + (["Vp"] if getattr(traj, "Vp", None) is not None else [])
    parts = []
    for src in (traj,) if dense is None else (traj, dense):
        t = np.asarray(src.t, float)
        m = (t >= lo) & (t <= hi)
        parts.append({k: np.asarray(getattr(src, k), float)[m] for k in names})
    out = {k: np.concatenate([p[k] for p in parts]) for k in names}
    order = np.argsort(out["t"], kind="stable")
    return {k: a[order] for k, a in out.items()}


def _phase_panel(a: Any, p: Any, v: np.ndarray, F: np.ndarray) -> None:
    """f(v, V) over the orbit's own velocities (not out to the law's whole range: the orbit fills the panel),
    the orbit and the folds."""
    vlo = float(np.min(v)) / 2 if len(v) else 1e-4
    vhi = float(np.max(v)) * 1.3 if len(v) else 30.0
    vv = np.logspace(np.log10(vlo), np.log10(vhi), 600)
    bs = p.force.folds(p.V)  # the run's own law (the paper's: branch_structure's folds, peel_force itself)
    a.semilogx(vv, p.force.f(vv, p.V), color="k", lw=1.5, label="f(v, V)")
    a.semilogx(v, F, lw=0.6, color="C0", label="orbit (v, F)")
    if bs.has_folds:
        a.plot([bs.v_max, bs.v_min], [bs.f_max, bs.f_min], "o", color="C1", label="folds B, D")
    if len(F):
        flo, fhi = float(np.min(F)), float(np.max(F))
        pad = 0.08 * (fhi - flo + 1.0)
        a.set_ylim(min(flo, cast(float, bs.f_min) if bs.has_folds else flo) - pad,
                   max(fhi, cast(float, bs.f_max) if bs.has_folds else fhi) + pad)
        a.set_xlim(vlo, vhi)
    a.set(xlabel="v [m/s]", ylabel="F [N]", title="v–F phase plane")
    a.legend(loc="best", fontsize=8)


def plot_trajectory(traj: Any, path: str | None = None, *, title: str | None = None,
                    cycles: int | None = TRAJECTORY_CYCLES, panels: tuple[str, ...] = TRAJECTORY_PANELS,
                    dense: Any = None, ax: Any = None, fig: Any = None):
    """F(t), α(t), v(t) and the v–F phase plane with f(v, V) (as the paper's Fig. 3), over the attractor.

    Parameters
    ----------
    traj : exact.Trajectory
        Any object with ``t, alpha, F, v`` arrays, ``jumps``, ``params`` and ``method``.
    path : str, optional
        Also write the figure there (:func:`save_figure`: the format from the extension, reproducible bytes).
    title : str, optional
        Default: V, I, k/R/l where not the default, the law where not the paper's, the model variant if any,
        the method, and the window (its periods of the return map, or the cycles of the run it shows).
    cycles : int or None
        Show at least the last ``cycles`` stick-slip cycles (default :data:`TRAJECTORY_CYCLES`), rounded up to
        whole periods of the return map when the run has settled on a periodic orbit
        (:func:`trajectory_window`).  None: the whole run.
    panels : tuple of str
        Any of :data:`TRAJECTORY_PANELS` (``"F"``, ``"alpha"``, ``"v"``, ``"phase"``), drawn in that order of the tuple:
        ``panels=("F",)`` is F(t) alone.  One row for up to 3, 2 x 2 for 4.
    dense : exact.Trajectory, optional
        The same run sampled densely over the window (``exact.simulate(..., t_eval=np.linspace(w.start,
        w.end, 4000))`` with ``w = trajectory_window(traj)``): its points are merged with ``traj``'s, so the
        curves are smooth where the solver's steps are long (``save="steps"`` stores one point a step).
    ax : matplotlib axes, optional
        Draw there: one Axes per panel, in the order of ``panels`` (one Axes, not a list, for one panel).
    fig : matplotlib.figure.Figure, optional
        Draw into this (empty) figure.  Neither: a new :func:`new_figure` (constrained layout).

    Returns
    -------
    matplotlib.figure.Figure
        The figure drawn into (that of ``ax`` when given).

    Raises
    ------
    ValueError
        ``panels`` empty, repeated or not of :data:`TRAJECTORY_PANELS`; ``cycles`` below 1; ``ax`` the wrong
        number of axes.

    Notes
    -----
    Under a load (``traj.Vp`` not None: ``params.loading == "load"``), the F(t) panel also shows the pull
    speed V_p(t) on a twin axis (right, dashed), with the load's speed scale.
    """
    cycles, panels = _checked_options(cycles, panels, dense)
    shape, size = _panel_shape(len(panels))
    fig, axs = _canvas(ax, fig, shape, size)
    at = dict(zip(panels, np.ravel(axs)))
    p = traj.params
    w = trajectory_window(traj, cycles)
    s = _samples(traj, dense, w.start, w.end)
    _time_panels(at, s, w)
    if "phase" in at:
        _phase_panel(at["phase"], p, s["v"], s["F"])
    fig.suptitle(title or f"{params_label(p)}, {traj.method}\n{_window_text(w)}")
    _save(fig, path)
    return fig


def _checked_options(cycles: int | None, panels: Any, dense: Any) -> tuple[int | None, tuple[str, ...]]:
    """:func:`plot_trajectory`'s ``cycles`` and ``panels`` checked (a name alone: one panel), and ``dense``."""
    from ..validate import integer

    if cycles is not None:
        cycles = integer("cycles", cycles, lo=1)
    if isinstance(panels, str):
        panels = (panels,)
    if not isinstance(panels, (tuple, list)) or not all(isinstance(x, str) for x in panels):
        raise TypeError(f"panels must be a tuple of names of {TRAJECTORY_PANELS}, got {panels!r}")
    panels = tuple(panels)
    if not panels or len(set(panels)) != len(panels) or not set(panels) <= set(TRAJECTORY_PANELS):
        raise ValueError(f"panels must be distinct names of {TRAJECTORY_PANELS}, got {panels!r}")
    if dense is not None and not all(hasattr(dense, a) for a in ("t", "F", "alpha", "v")):
        raise TypeError(f"dense must be a Trajectory of the same run (exact.simulate(..., t_eval=...)), got "
                        f"{type(dense).__name__}")
    return cycles, panels


def _time_panels(at: dict[str, Any], s: dict[str, np.ndarray], w: TrajectoryWindow) -> None:
    """The F(t), α(t) and v(t) panels among ``at`` over the window ``w``; under a load V_p(t) on a twin axis of
    the force panel."""
    t = s["t"]
    label = {"F": ("F [N]", "pull force F(t)", "C0"), "alpha": (r"$\alpha$ [rad]", r"peel angle $\alpha(t)$", "C2"),
             "v": ("v [m/s]", "peel velocity v(t)", "C3")}
    for name, (ylabel, panel_title, color) in label.items():
        if name not in at:
            continue
        a = at[name]
        a.plot(t, s[name], lw=0.8, color=color, label=name if name != "alpha" else "α")
        a.set(xlabel="t [s]", ylabel=ylabel, title=panel_title)
        if name == "v":
            a.set_yscale("log")
        if t.size > 1:
            a.set_xlim(w.start, w.end)
    if "F" in at and "Vp" in s:  # under a load the pull speed is a state: on a twin axis of the force panel
        tw = at["F"].twinx()
        tw.plot(t, s["Vp"], lw=0.8, ls="--", color="C4", label="$V_p$")
        tw.set_ylabel("$V_p$ [m/s]", color="C4")
        at["F"].set_title("pull force F(t), pull speed $V_p(t)$ (dashed)")
        at["F"].legend(handles=at["F"].lines + tw.lines, loc="best", fontsize=8)


def _window_text(w: TrajectoryWindow) -> str:
    """The title's line on the window: its periods of the return map, or the cycles of the run it shows."""
    if w.period is not None:
        k = w.cycles // w.period
        return (f"{k} period{'s' if k > 1 else ''} of the period-{w.period} return map ({w.cycles} cycles), "
                f"T = {(w.end - w.start) / k:.5g} s")
    return f"t = {w.start:.4g}–{w.end:.4g} s" + (f", the last {w.cycles} of {w.total} cycles"
                                                 if w.cycles < w.total else "")

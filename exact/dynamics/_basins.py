"""Basins of attraction: label every start of a grid over (α0, F0) or (α0, ω0) by the attractor it reaches.

Each start is one :func:`exact.simulate` run (``save="jumps"``) past a transient; its window's return map
(:func:`peelapprox.return_map`, the pull force F at the AB→CD jumps) is classified by
:func:`peelapprox.periodicity`.  Periodic starts are grouped into attractors: two starts reach the same
attractor when their periods n agree and their sorted return-map cycles agree to :data:`MATCH_RTOL`
relative (a cycle is the same set of jump forces whatever its phase).  The starts run in this process or on
a pool of :mod:`peelapprox.parallel` or any :class:`concurrent.futures.Executor` (as the (I, V) sweep);
the result does not depend on which, nor on the order in which the starts finish.

Every call is bounded: a grid of at most :data:`MAX_BASIN_STARTS` starts (refused before any run) and a
wall-clock budget ``max_wall`` for all of it (:mod:`exact.dynamics._basins_run`: the starts it leaves out or cuts are
failures, ``"failure:max_wall"``).
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable, Sequence
from concurrent.futures import Executor
from dataclasses import dataclass, field
from typing import Any, NamedTuple

import numpy as np

from peelapprox import WINDOW_DEFAULTS, ModelBreakdown, PeelParams, SolverBudgetExceeded, SolverFailure
from peelapprox.errors import WallBudget
from peelapprox.io import fmt_number, jsonable
from peelapprox.parallel import POOL_KINDS
from peelapprox.validate import ArgumentTypeError, duration, flag, integer, optional, positive, states
from peelapprox.validate import params as _params
from peelapprox.validate import rtol as _rtol

from .._method_contract import method_option
from .._shared import DEFAULT_MAX_WALL, paper_model_only
from .._simulate import simulate
from ..orbits import PeriodicOrbit, periodic_orbit
from ._basins_run import APERIODIC, BREAKDOWN, FAILURE, INVALID, UNDETERMINED, msg, reporter, run_all

__all__ = ["MATCH_RTOL", "CYCLE_DIGITS", "INVALID", "APERIODIC", "BREAKDOWN", "UNDETERMINED", "FAILURE",
           "MAX_BASIN_STARTS", "BasinAttractor", "BasinResult", "basins"]

#: Two periodic starts reach the same attractor when n is equal and their sorted cycles agree to this (relative).
MATCH_RTOL = 1e-6
#: Significant digits of an attractor's stored ``cycle`` (its first start's, rounded): 5e-10 relative, far
#: below :data:`MATCH_RTOL`, far above the ~1e-12 scatter of a periodic orbit's jump forces at rtol 1e-10.
CYCLE_DIGITS = 10
#: Most starts of one :func:`basins` grid: a 1000 x 1000 picture, each start a run of ``t_transient + window``
#: (50 s of model time, ~0.1-1 s of wall time): days of computing on a cluster, while the pictures of
#: docs/dynamics.md have ~100 starts.  A larger grid is a typo, refused before the first run (the executor would
#: otherwise hold a future per start).
MAX_BASIN_STARTS = 1_000_000
_CODE_TEXT = {INVALID: "invalid start", APERIODIC: "aperiodic", BREAKDOWN: "breakdown",
              UNDETERMINED: "undetermined", FAILURE: "failure"}
_AXES = ("F0", "omega0")


@dataclass(frozen=True)
class BasinAttractor:
    """One periodic attractor reached from a basin grid (:func:`basins`).

    Attributes
    ----------
    id : int
        Its index in ``BasinResult.attractors`` and its code in ``BasinResult.labels`` (numbered in the order
        first reached along the grid, α0 major).
    n : int
        AB→CD jumps per period.
    cycle : tuple of float
        The sorted return-map cycle [N] (F at the n AB→CD jumps of one period) of its first start, to
        :data:`CYCLE_DIGITS` significant digits; every start labelled with it agrees to :data:`MATCH_RTOL`.
    count : int
        Starts of the grid that reach it.
    start : (float, float)
        Its first start ``(α0, F0 or ω0)``.
    orbit : exact.PeriodicOrbit or None
        With ``orbits=True``: :func:`exact.periodic_orbit` from the first start's run (n given), with its
        Floquet multipliers; None when not asked for or when it failed (``orbit_error`` says why).
    orbit_error : str or None
    """

    id: int
    n: int
    cycle: tuple[float, ...]
    count: int
    start: tuple[float, float]
    orbit: PeriodicOrbit | None = field(default=None, compare=False)
    orbit_error: str | None = None

    @property
    def label(self) -> str:
        """``"period-n"``."""
        return f"period-{self.n}"

    def describe(self) -> str:
        """``"period-1: F = 240.0602 N"``: the cycle to 7 digits (up to 3 values; else its range, min … max)."""
        shown = self.cycle if len(self.cycle) <= 3 else (self.cycle[0], "…", self.cycle[-1])
        return f"{self.label}: F = {', '.join(c if isinstance(c, str) else fmt_number(c, 7) for c in shown)} N"


@dataclass(frozen=True, eq=False)
class BasinResult:
    """The basins of a grid of starts (:func:`basins`).

    Attributes
    ----------
    params : PeelParams
    alpha0 : ndarray, shape (m,)
        Initial peel angles [rad] (first axis).
    axis : {"F0", "omega0"}
        The second axis: initial pull force [N] or roller angular velocity [rad/s].
    values : ndarray, shape (k,)
        Its values.
    labels : ndarray of int, shape (m, k)
        ``labels[i, j]`` for ``alpha0[i]``, ``values[j]``: the attractor id (>= 0), or :data:`INVALID` (-1: no
        root of CONSTR at the start), :data:`APERIODIC` (-2), :data:`BREAKDOWN` (-3: ``ModelBreakdown``),
        :data:`UNDETERMINED` (-4: fewer than 2 returns, or too few to decide for ``max_period``),
        :data:`FAILURE` (-5: the solver failed or ran out of budget, the call's ``max_wall`` left the start out
        or cut it, or the executor lost the start).
    texts : ndarray of str, shape (m, k)
        Each start's outcome: ``"period-n"``, ``"aperiodic"``, ``"breakdown:<reason>"``, ``"invalid start"``,
        ``"undetermined:<why>"``, ``"failure:<exception type>"``, ``"failure:max_wall"`` (the call's budget).
    cycles : tuple of tuple of float
        Each start's own sorted cycle (periodic starts; empty otherwise), flattened α0 major.
    n_returns : ndarray of int, shape (m, k)
        AB→CD jumps in each start's window (0 for invalid or failed starts).
    messages : tuple of str
        Each start's error message ("" when none), flattened α0 major.
    attractors : tuple of BasinAttractor
    t_transient, window, rtol : float
    max_period : int
    wall_time : float
        Seconds for the whole grid.
    """

    params: PeelParams
    alpha0: np.ndarray
    axis: str
    values: np.ndarray
    labels: np.ndarray
    texts: np.ndarray
    cycles: tuple[tuple[float, ...], ...]
    n_returns: np.ndarray
    messages: tuple[str, ...]
    attractors: tuple[BasinAttractor, ...]
    t_transient: float
    window: float
    rtol: float
    max_period: int
    wall_time: float = 0.0

    def counts(self) -> dict[str, int]:
        """Starts per outcome: ``"A<id> period-n"`` for each attractor, then the codes that occur."""
        out = {f"A{a.id} {a.label}": a.count for a in self.attractors}
        for code, text in _CODE_TEXT.items():
            c = int(np.count_nonzero(self.labels == code))
            if c:
                out[text] = c
        return out

    def rows(self) -> list[dict[str, Any]]:
        """One row per start (α0 major), plain scalars for CSV or JSON (:func:`peelapprox.io.write_rows`):
        ``alpha0``, the second axis, ``label`` (code), ``outcome`` (text), ``n``, ``cycle`` (the start's sorted
        cycle, space-separated, full precision), ``n_returns``, ``message``."""
        rows = []
        for i, a in enumerate(self.alpha0):
            for j, v in enumerate(self.values):
                k = i * len(self.values) + j
                lab = int(self.labels[i, j])
                rows.append({"alpha0": float(a), self.axis: float(v), "label": lab, "outcome": str(self.texts[i, j]),
                             "n": self.attractors[lab].n if lab >= 0 else None,
                             "cycle": " ".join(repr(c) for c in self.cycles[k]),
                             "n_returns": int(self.n_returns[i, j]), "message": self.messages[k]})
        return rows

    def to_json(self) -> str:
        """The grid, the settings, the attractors (with the orbits' multipliers when computed) and :meth:`rows`
        as JSON text (strict: no NaN)."""
        atts = []
        for a in self.attractors:
            d: dict[str, Any] = {"id": a.id, "n": a.n, "cycle": list(a.cycle), "count": a.count,
                                 "start": list(a.start), "orbit_error": a.orbit_error}
            if a.orbit is not None:
                d["orbit"] = {"period": a.orbit.period, "stable": a.orbit.stable, "residual": a.orbit.residual,
                              "multipliers": [[float(m.real), float(m.imag)]
                                              for m in np.atleast_1d(a.orbit.multipliers)],
                              "return_map_values": a.orbit.return_map_values}
            atts.append(d)
        doc = {"params": repr(self.params), "axis": self.axis, "alpha0": self.alpha0, "values": self.values,
               "t_transient": self.t_transient, "window": self.window, "rtol": self.rtol,
               "max_period": self.max_period, "counts": self.counts(), "attractors": atts, "rows": self.rows()}
        return json.dumps(jsonable(doc), indent=1, allow_nan=False)

    def plot(self, ax: Any = None, *, title: str | None = None, fig: Any = None) -> Any:
        """Draw the label map on ``ax``, or into the (empty) figure ``fig``, or into a new
        :func:`peelapprox.plotting.new_figure` (neither given), one colour per attractor and grey shades for the
        other outcomes, with a legend (outcome and count); returns the figure drawn into."""
        from matplotlib import colormaps
        from matplotlib.colors import ListedColormap
        from matplotlib.patches import Patch

        from peelapprox.plotting import new_figure

        if ax is not None and fig is not None:
            raise ValueError("ax and fig: give one of them (the figure of ax is where it is drawn)")
        if ax is None:
            ax = (fig if fig is not None else new_figure(figsize=(9.0, 4.8))).subplots()
        na = len(self.attractors)
        tab = colormaps["tab10" if na <= 10 else "tab20"]
        colours = [tab(i % tab.N) for i in range(na)]
        greys = {INVALID: "white", APERIODIC: "0.25", BREAKDOWN: "0.55", UNDETERMINED: "0.8", FAILURE: "0.95"}
        codes = sorted(greys) + list(range(na))  # -5 .. -1, then 0 .. na-1
        index = {c: k for k, c in enumerate(codes)}
        img = np.vectorize(index.__getitem__)(self.labels) if self.labels.size else self.labels
        cmap = ListedColormap([greys[c] for c in sorted(greys)] + colours)
        ax.pcolormesh(_edges(self.values), _edges(self.alpha0), img, cmap=cmap, vmin=-0.5,
                      vmax=len(codes) - 0.5, shading="flat", edgecolors="face")
        counts = self.counts()
        handles = [Patch(facecolor=colours[a.id], label=f"{a.describe()} ({a.count})") for a in self.attractors]
        handles += [Patch(facecolor=greys[c], edgecolor="0.5", label=f"{t} ({counts[t]})")
                    for c, t in _CODE_TEXT.items() if t in counts]
        ax.legend(handles=handles, fontsize="small", loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0)
        ax.set_xlabel("F0 [N]" if self.axis == "F0" else "ω0 [rad/s]")
        ax.set_ylabel("α0 [rad]")
        p = self.params
        law = "fvV" if p.force.kind == "paper" else p.force.name or repr(p.force)
        ax.set_title(title or f"basins, {law}, V = {p.V:g} m/s, I = {p.I:g} kg m²")
        return ax.figure

    def to_xarray(self) -> Any:
        """The labels as an :class:`xarray.Dataset` over ``(alpha0, F0 | omega0)`` (coordinates with ``units``):
        ``label`` (:attr:`labels`, with CF ``flag_values``/``flag_meanings``), ``outcome`` (:attr:`texts`), ``n``
        (the period reached, 0 for none), ``n_returns``; attrs: the parameters (``params_V``, ...), the settings
        and the attractors (JSON).  ImportError without xarray (``pip install 'peelapprox[data]'``)."""
        from ._basins_out import basins_xarray

        return basins_xarray(self, _CODE_TEXT)

    def __repr__(self) -> str:
        from ._basins_out import basins_summary

        return basins_summary(self, short=True)

    def _repr_html_(self) -> str:
        from ._basins_out import basins_summary

        return basins_summary(self, short=False)


def _edges(x: np.ndarray) -> np.ndarray:
    """Cell edges around strictly increasing centres (one cell of width 1 around a single value)."""
    if x.size == 1:
        return np.array([x[0] - 0.5, x[0] + 0.5])
    mid = 0.5 * (x[1:] + x[:-1])
    return np.concatenate([[2 * x[0] - mid[0]], mid, [2 * x[-1] - mid[-1]]])


# ---------------------------------------------------------------------------------------------- the grid
def _axis(name: str, x: Any, quantity: str) -> np.ndarray:
    a = states(name, x, quantity)
    if a.ndim != 1:
        raise ValueError(f"{name} must be a 1-D sequence, got shape {a.shape}")
    if a.size > 1 and not np.all(np.diff(a) > 0):
        raise ValueError(f"{name} must be strictly increasing (a grid axis), got {a.tolist()}")
    return a


def _group(outcomes: list[dict], starts: list[tuple[float, float]]) -> tuple[np.ndarray, list[dict]]:
    """Attractor codes of the periodic outcomes (first reached first, in grid order) and the groups."""
    codes = np.empty(len(outcomes), dtype=np.int64)
    groups: list[dict] = []
    for k, o in enumerate(outcomes):
        if o["code"] != 0:
            codes[k] = o["code"]
            continue
        cyc = np.asarray(o["cycle"])
        for g in groups:
            if g["n"] == o["n"] and np.allclose(cyc, g["cycle"], rtol=MATCH_RTOL, atol=0.0):
                g["count"] += 1
                codes[k] = g["id"]
                break
        else:
            codes[k] = len(groups)
            groups.append({"id": len(groups), "n": o["n"], "cycle": cyc, "count": 1, "first": k, "start": starts[k]})
    return codes, groups


def basins(params: PeelParams, *, alpha0: Sequence[float] | np.ndarray, F0: Sequence[float] | np.ndarray | None = None,
           omega0: Sequence[float] | np.ndarray | None = None, t_transient: float = WINDOW_DEFAULTS["t_transient"],
           window: float = WINDOW_DEFAULTS["window"], rtol: float = WINDOW_DEFAULTS["rtol"], max_period: int = 32,
           orbits: bool = False, executor: str | Executor | None = None, max_workers: int | None = None,
           progress: bool | Callable[[int, int, dict], None] | None = True, solver: str | None = None,
           max_wall: float | None = DEFAULT_MAX_WALL) -> BasinResult:
    """Label every start of a grid over (α0, F0) or (α0, ω0) by the attractor it reaches.

    Each start runs ``exact.simulate(params, t_transient + window, alpha0=a, F0=F (or omega0=w), rtol=rtol,
    save="jumps", t_transient=t_transient)`` (the other initial values :func:`exact.initial_state`'s defaults) and
    its window's return map is classified by :func:`peelapprox.periodicity` (rtol 1e-6).  Periodic starts whose n
    are equal and whose sorted cycles agree to :data:`MATCH_RTOL` reach the same attractor.

    Parameters
    ----------
    params : PeelParams
        With any law the hybrid solver runs (the paper's fvV, a cubic, a table, an expression); a model variant
        (a tape mass, a constant load) runs its own method (:func:`exact.simulate`'s default), ``orbits`` then
        refused (the periodic orbits are the massless model's).
    alpha0 : sequence of float
        Initial peel angles [rad]: strictly increasing, each in ``STATE_RANGES["alpha"]``.
    F0, omega0 : sequence of float
        The second axis, exactly one of them: initial pull forces [N] (``STATE_RANGES["F"]``) or roller
        angular velocities [rad/s] (``STATE_RANGES["omega"]``), strictly increasing.  The grid holds at most
        :data:`MAX_BASIN_STARTS` (1e6) starts.
    t_transient, window : float
        Seconds discarded, in [0, 1e6], and seconds whose AB→CD jumps are classified, in (0, 1e6]
        (:data:`peelapprox.WINDOW_DEFAULTS`: 30, 20).
    rtol : float
        Relative tolerance of each run, in :data:`peelapprox.RTOL_RANGE` (1e-10).
    max_period : int
        Largest period looked for, in [1, 1000]; a window needs ``3 max_period`` returns to call a start
        aperiodic (else "undetermined").
    orbits : bool
        Also find each periodic attractor's :class:`exact.PeriodicOrbit` (:func:`exact.periodic_orbit` seeded
        by its first start's run, in this process): Floquet multipliers, stability.
    executor : {"auto", "threads", "processes", "serial"} or concurrent.futures.Executor, optional
        A local pool of :mod:`peelapprox.parallel` (None: ``"auto"``, processes on more than two CPUs and threads
        on one or two; a script needs no ``__main__`` guard either way), or an executor that runs the starts (e.g.
        a dask ``Client.get_executor()``), used as is and left running; the function shipped is ``run_start`` in
        ``exact/dynamics/_basins_run.py``, its arguments plain data (PeelParams pickles with its law).
    max_workers : int, optional
        Of a local pool: 0 runs in this process; n > 0 a pool of n workers; None (default) one worker per CPU
        available, at most one per start.
    progress : bool or callable
        True: a line on stderr per ~5 % of the starts (and per failed start; one updating line in Jupyter); a
        callable gets ``(done, total, outcome)`` after each.
    solver : str, optional
        The scipy solver of a model variant's runs (:func:`exact.simulate`'s; None: its default); a ValueError
        with the massless model's hybrid method.
    max_wall : float or None
        Wall-clock budget [s] of the whole call, the starts and the orbits (None: unbounded; default
        :data:`exact.DEFAULT_MAX_WALL`, 3600 s): a start is run with what is left of it as its ``max_wall``, and
        once it is spent the starts not run are cancelled.  A start it leaves out or cuts is a failure,
        ``"failure:max_wall"``, and an orbit it cuts an ``orbit_error``: outcomes, not exceptions, so the result
        holds every start that finished.  The deadline is a time of the system clock, shared by the workers of a
        cluster to their clocks' skew.

    Returns
    -------
    BasinResult
        The same, bit for bit, in this process or on any executor (the outcomes are grouped in grid order).

    Raises
    ------
    ValueError, TypeError
        A bad argument (named, with its range; a grid of more than :data:`MAX_BASIN_STARTS` starts).  Nothing a
        start does raises: an infeasible start, a breakdown, a solver failure, a spent budget are outcomes.
    """
    wall0 = time.perf_counter()
    a = _checked_arguments(params, alpha0, F0, omega0, t_transient, window, rtol, max_period, orbits, executor,
                           max_workers, progress, solver, max_wall)
    starts = [(float(x), float(v)) for x in a.alpha0 for v in a.values]
    tasks = [(a.params, a.t_transient, a.window, a.rtol, a.max_period, x, a.axis, v, a.solver) for x, v in starts]
    deadline = None if a.wall.limit is None else time.time() + a.wall.limit - (time.perf_counter() - a.wall.t0)
    outcomes = run_all(tasks, a.executor, a.max_workers, reporter(a.progress, len(tasks)), deadline)
    codes, groups = _group(outcomes, starts)
    return _result(a, outcomes, codes, tuple(_attractor(a, g, starts) for g in groups), wall0)


def _result(a: _Arguments, outcomes: list[dict], codes: np.ndarray, atts: tuple[BasinAttractor, ...],
            wall0: float) -> BasinResult:
    """The :class:`BasinResult` of the outcomes in grid order (``wall0``: the call's start)."""
    shape = (a.alpha0.size, a.values.size)
    return BasinResult(
        params=a.params, alpha0=a.alpha0, axis=a.axis, values=a.values, labels=codes.reshape(shape),
        texts=np.array([o["text"] for o in outcomes], dtype=object).reshape(shape),
        cycles=tuple(tuple(o["cycle"]) for o in outcomes),
        n_returns=np.array([o["n_returns"] for o in outcomes], dtype=np.int64).reshape(shape),
        messages=tuple(o["message"] for o in outcomes), attractors=atts, t_transient=a.t_transient,
        window=a.window, rtol=a.rtol, max_period=a.max_period, wall_time=time.perf_counter() - wall0)


def _attractor(a: _Arguments, g: dict, starts: list[tuple[float, float]]) -> BasinAttractor:
    """The :class:`BasinAttractor` of the group ``g`` (with its orbit, from its first start, if asked for)."""
    orbit, err = (_orbit(a.params, starts[g["first"]], a.axis, g["n"], a.t_transient, a.window, a.rtol, a.wall)
                  if a.orbits else (None, None))
    return BasinAttractor(g["id"], g["n"], tuple(float(f"{c:.{CYCLE_DIGITS}g}") for c in g["cycle"]), g["count"],
                          g["start"], orbit, err)


class _Arguments(NamedTuple):
    """:func:`basins`' arguments, checked: the grid's axes (``axis``: "F0" or "omega0", its ``values``)."""

    params: PeelParams
    alpha0: np.ndarray
    axis: str
    values: np.ndarray
    t_transient: float
    window: float
    rtol: float
    max_period: int
    orbits: bool
    executor: str | Executor | None
    max_workers: int | None
    progress: bool | Callable[[int, int, dict], None] | None
    solver: str | None
    wall: WallBudget


def _checked_arguments(params, alpha0, F0, omega0, t_transient, window, rtol, max_period, orbits, executor,
                       max_workers, progress, solver, max_wall) -> _Arguments:
    """:func:`basins`' arguments checked, in this order (the first bad one is named)."""
    params = _params("params", params)
    if (F0 is None) == (omega0 is None):
        raise ValueError("give exactly one of F0 (an (alpha0, F0) grid) and omega0 (an (alpha0, omega0) grid)")
    axis = "F0" if F0 is not None else "omega0"
    _check_size(axis, alpha0, F0 if F0 is not None else omega0)
    a_ax = _axis("alpha0", alpha0, "alpha")
    values = _axis(axis, F0 if F0 is not None else omega0, "F" if axis == "F0" else "omega")
    _check_size(axis, a_ax, values)
    t_transient = duration("t_transient", t_transient, zero=True)
    window = duration("window", window)
    rtol = _rtol("rtol", rtol)
    max_period = integer("max_period", max_period, 1, 1000)
    orbits = flag("orbits", orbits)
    method_option(None, solver=solver, eps=None, rtol=rtol, atol=None, v_floor=None, params=params)
    if orbits:
        paper_model_only(params, "basins(orbits=True) (exact.periodic_orbit)", "pass orbits=False")
    max_workers = optional(integer, "max_workers", max_workers, 0)
    _check_executor(executor, max_workers)
    if not (progress is None or isinstance(progress, bool) or callable(progress)):
        raise ArgumentTypeError(f"progress must be a bool, None or a callable (done, total, outcome), got {progress!r}")
    wall = WallBudget(optional(positive, "max_wall", max_wall))
    return _Arguments(params, a_ax, axis, values, t_transient, window, rtol, max_period, orbits, executor,
                      max_workers, progress, solver, wall)


def _check_executor(executor: Any, max_workers: int | None) -> None:
    """ValueError or ArgumentTypeError unless ``executor`` is None, a local pool's name or an executor (then with
    no ``max_workers``)."""
    if isinstance(executor, str):
        if executor not in POOL_KINDS:
            raise ValueError(f"executor must be None, one of {POOL_KINDS} or a concurrent.futures.Executor, got "
                             f"{executor!r}")
    elif executor is not None:
        if not callable(getattr(executor, "submit", None)):
            raise ArgumentTypeError(f"executor must be None, one of {POOL_KINDS} or a concurrent.futures.Executor, "
                                    f"got {executor!r}")
        if max_workers is not None:
            raise ValueError("max_workers applies only to the local pools (executor None or a pool's name); size "
                             "your executor instead")


def _check_size(axis: str, alpha0: Any, values: Any) -> None:
    """ValueError naming both axes unless the grid holds at most :data:`MAX_BASIN_STARTS` starts; their lengths
    are read before the axes are converted (a typo's 1e9 values would take minutes), and read again after."""
    m, k = (np.size(x) if isinstance(x, np.ndarray) else len(x) if hasattr(x, "__len__") else 0
            for x in (alpha0, values))
    if m * k > MAX_BASIN_STARTS:
        raise ValueError(f"alpha0 x {axis}: the grid must hold at most MAX_BASIN_STARTS = {MAX_BASIN_STARTS} starts "
                         f"(a 1000 x 1000 picture, days of runs: more is most likely a typo), got {m} x {k} = "
                         f"{m * k}")


def _orbit(params: PeelParams, start: tuple[float, float], axis: str, n: int, t_transient: float, window: float,
           rtol: float, wall: WallBudget) -> tuple[PeriodicOrbit | None, str | None]:
    """:func:`exact.periodic_orbit` seeded by the run from ``start``, within what is left of ``wall`` (None and
    why, if it fails)."""
    if wall.limit is not None and time.perf_counter() - wall.t0 >= wall.limit:
        return None, f"max_wall: the call's max_wall={wall.limit:g} s was spent before this orbit was looked for"
    try:
        kw: dict[str, Any] = {"alpha0": start[0], axis: start[1]}
        tr = simulate(params, t_transient + window, rtol=rtol, save="jumps", t_transient=t_transient,
                      max_wall=wall.left(0.0, {"t": 0.0}, t_transient + window), **kw)
        return periodic_orbit(params, start=tr, n=n, max_wall=wall.left(0.0, {"t": 0.0}, 0.0)), None
    except (ValueError, ModelBreakdown, SolverFailure, SolverBudgetExceeded, ArithmeticError) as exc:
        return None, f"{type(exc).__name__}: {msg(exc)}"

"""The brute-force orbit diagram: the return map's values after a transient over a grid of a parameter.

:func:`orbit_diagram` runs ``exact.simulate`` at each value of the parameter (V, I, k or a family law's
coefficient, as :func:`exact.continue_orbit`), drops the transient and keeps F at the AB→CD jumps of the window
(``peelapprox.return_map``), with the period that ``peelapprox.periodicity`` reads off them.  It is the picture
the continued branches are drawn over (``peelapprox.plotting.plot_bifurcation``): where the branches say an
orbit is stable, the diagram should show it.

Every call is bounded: at most :data:`MAX_DIAGRAM_VALUES` values (refused before any run) and a wall-clock budget
``max_wall`` for all the runs together.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from concurrent.futures import Executor
from dataclasses import dataclass
from typing import Any

import numpy as np

from peelapprox import WINDOW_DEFAULTS, PeelParams, periodicity, return_map
from peelapprox.errors import ModelBreakdown, SolverBudgetExceeded, SolverFailure, WallBudget
from peelapprox.io import ProgressLine
from peelapprox.parallel import AUTO, DEADLINE_TEXT, POOL_KINDS, map_points
from peelapprox.validate import duration, function, integer, optional, positive, reals
from peelapprox.validate import params as _params

from .._model import MODELS, model_of
from .._shared import DEFAULT_MAX_WALL
from ..orbits import solve_orbit, with_parameter

__all__ = ["MAX_DIAGRAM_VALUES", "OrbitDiagram", "explain", "orbit_diagram"]

#: Most values of one :func:`orbit_diagram`: each is a run of ``t_transient + window`` (50 s of model time by
#: default, ~0.1-1 s of wall time), so 1e5 values are a day of computing; the diagrams of docs/orbits.md have
#: 20-400.  A larger grid is a typo (one zero too many), refused before the first run.
MAX_DIAGRAM_VALUES = 100_000


@dataclass(frozen=True)
class OrbitDiagram:
    """The brute-force orbit diagram (:func:`orbit_diagram`).

    Attributes
    ----------
    parameter : str
    values : ndarray
        The parameter's values, in the order run.
    returns : tuple of ndarray
        F [N] at the AB→CD jumps of the window, per value (empty where the run broke down or has no jumps).
    labels : tuple of str
        ``"period-n"``, ``"aperiodic"``, ``"no stick-slip"``, ``"breakdown:<reason>"``, ``"budget:<name>"`` or
        ``"solver_failure"`` per value (a failed value does not stop the diagram); ``"budget:max_wall"`` for the
        value whose run the call's ``max_wall`` cut and every value after it, not run.
    wall_time : float
    """

    parameter: str
    values: np.ndarray
    returns: tuple[np.ndarray, ...]
    labels: tuple[str, ...]
    wall_time: float

    def rows(self) -> list[dict]:
        """One row per (value, return): ``parameter, F, label`` (CSV/JSON)."""
        out = []
        for x, F, lab in zip(self.values, self.returns, self.labels):
            if F.size == 0:
                out.append({self.parameter: float(x), "F": None, "label": lab})
            out.extend({self.parameter: float(x), "F": float(f), "label": lab} for f in F)
        return out

    def to_dataframe(self):
        """:meth:`rows` as a :class:`pandas.DataFrame`: one row per (value, return), columns ``<parameter>, F,
        label`` (``F`` NaN where a value has no returns: a breakdown or no stick-slip); ``df.attrs``: ``units``,
        ``parameter``, ``wall_time``.

        Raises
        ------
        ImportError
            If pandas is not installed (``pip install 'peelapprox[data]'``).
        """
        from peelapprox.io import optional_import

        pd = optional_import("pandas", "OrbitDiagram.to_dataframe")
        df = pd.DataFrame(self.rows(), columns=[self.parameter, "F", "label"]).astype({"F": float})
        units = {"V": "m/s", "I": "kg m²", "k": "N/m", **{n: u for m in MODELS.values() for n, u in m.parameters}}
        df.attrs.update({"units": {self.parameter: units.get(self.parameter, ""),
                                   "F": "N", "label": ""},
                         "parameter": self.parameter, "wall_time": self.wall_time})
        return df

    def _summary(self) -> dict:
        from peelapprox.io import fmt_number

        counts: dict[str, int] = {}
        for lab in self.labels:
            counts[lab] = counts.get(lab, 0) + 1
        v = self.values
        return {"parameter": self.parameter, "values": v.size,
                "range": f"{fmt_number(v.min(), 6)} … {fmt_number(v.max(), 6)}" if v.size else "–",
                "returns": sum(F.size for F in self.returns),
                "labels": ", ".join(f"{k} ×{n}" for k, n in list(counts.items())[:5])
                + (f", … ({len(counts) - 5} more)" if len(counts) > 5 else ""), "wall time [s]": self.wall_time}

    def __repr__(self) -> str:
        d = self._summary()
        return (f"OrbitDiagram({d['parameter']} in [{d['range']}], {d['values']} values, {d['returns']} returns; "
                f"{d['labels']})")

    def _repr_html_(self) -> str:
        from peelapprox.io import html_table

        return html_table("OrbitDiagram", self._summary())


def _diagram_value(p: PeelParams, t_transient: float, window: float, alpha0: float, rtol: float, method: str | None,
                   solver: str | None, max_period: int, deadline: float | None) -> tuple[np.ndarray, str]:
    """The return map and label of one value's run (a pool's task; never raises for the run's outcome).
    ``deadline``: the diagram's, a ``time.time()``: a run that begins after it is not run
    (``"budget:max_wall"``), a running one gets what is left of it as its ``max_wall``."""
    from .._simulate import simulate

    left = None if deadline is None else deadline - time.time()
    if left is not None and left <= 0:
        return np.zeros(0), "budget:max_wall"
    try:
        tr = simulate(p, t_transient + window, alpha0=alpha0, rtol=rtol, save="jumps", t_transient=t_transient,
                      method=method, solver=None if model_of(p).has_hybrid else solver, max_wall=left)
        F = return_map(tr)
        label = "no stick-slip" if F.size < 2 else periodicity(F, max_period=max_period).label
    except ModelBreakdown as exc:
        F, label = np.zeros(0), f"breakdown:{exc.reason}"
    except SolverBudgetExceeded as exc:  # one value's budget, not the whole diagram (e.g. a tiny tape mass)
        F, label = np.zeros(0), f"budget:{exc.budget}"
    except SolverFailure:
        F, label = np.zeros(0), "solver_failure"
    return np.asarray(F, dtype=float), label


def orbit_diagram(params: PeelParams, parameter: str, values: Sequence[float] | np.ndarray, *,
                  t_transient: float = WINDOW_DEFAULTS["t_transient"], window: float = WINDOW_DEFAULTS["window"],
                  rtol: float = WINDOW_DEFAULTS["rtol"], alpha0: float = 0.0, max_period: int = 32,
                  progress: bool | Callable[[int, int], None] = False, method: str | None = None,
                  solver: str | None = None, max_wall: float | None = DEFAULT_MAX_WALL,
                  executor: str | Executor | None = None, max_workers: int | None = None) -> OrbitDiagram:
    """The return map after ``t_transient`` over ``values`` of ``parameter`` (module docstring).

    Parameters
    ----------
    params : PeelParams
        The other parameters (and the law, and the model variant: a tape mass or a constant load, whose runs
        use the variant's method).
    parameter : {"V", "I", "k", "tape_mass", "load_mass", "load"} or "force.<coefficient>"
        A model variant's parameter (:func:`exact.with_parameter`) gives the diagram over it: over
        ``"tape_mass"``, 0 is the massless model (the hybrid method) and m > 0 the tape-mass model
        (``method="smooth"``), its jumps the crossings of the inflection velocity.
    values : sequence of float
        At most :data:`MAX_DIAGRAM_VALUES` (1e5), each a valid value of ``parameter`` (PeelParams' range).
    t_transient, window : float
        Dropped and kept time of each run [s].
    rtol, alpha0 : float
        Of each ``exact.simulate`` run.
    max_period : int
        Longest period ``periodicity`` looks for.
    progress : bool or callable
        True: a line on stderr every ~5 % of the values (one updating line in Jupyter); a
        callable ``progress(done, total)``.
    method, solver : str, optional
        Of each ``exact.simulate`` run (None: each run's model's method and its default solver; ``solver``
        is passed to the runs of a model variant only, the massless model's hybrid method having its own).
    max_wall : float or None
        Wall-clock budget [s] of all the runs together (None: unbounded; default :data:`exact.DEFAULT_MAX_WALL`,
        3600 s), passed on to each run as what is left of it.  When it is spent the diagram is returned as
        it stands, the rest of its values labelled ``"budget:max_wall"`` (a value whose run fails is a label, not
        an error, and so is the budget).
    executor : {"auto", "threads", "processes", "serial"} or concurrent.futures.Executor, optional
        Where the values run: a local pool of :mod:`peelapprox.parallel` (None: ``"auto"``, processes on more
        than two CPUs, threads on one or two), or any executor (a dask client's), used as is.  The diagram is
        the same, bit for bit, wherever its values ran.
    max_workers : int, optional
        Of a local pool (default: the CPUs; 0: in this process).

    Returns
    -------
    OrbitDiagram
        With every value given, in order (those the budget left out labelled ``"budget:max_wall"``).

    Raises
    ------
    ValueError, TypeError
        A bad argument (named): more than :data:`MAX_DIAGRAM_VALUES` values, a value ``parameter`` cannot take.
    """
    wall0 = time.perf_counter()
    params = _params("params", params)
    vals = _checked_values(params, parameter, values)
    t_transient = duration("t_transient", t_transient, zero=True)
    window = duration("window", window)
    wall = WallBudget(optional(positive, "max_wall", max_wall))
    max_workers = optional(integer, "max_workers", max_workers, 0)
    _check_executor(executor)
    report: Callable[[int, int], None] | None = None
    line = ProgressLine(f"orbit diagram over {parameter}", vals.size) if progress is True else None
    if line is None:
        report = optional(function, "progress", progress or None)
    flat = vals.ravel()
    found = _run_values(params, parameter, flat, (t_transient, window, alpha0, rtol, method, solver, max_period),
                        wall, line, report, executor, max_workers)
    returns = [np.asarray(found[k][0], dtype=float) for k in range(flat.size)]
    labels = [found[k][1] for k in range(flat.size)]
    return OrbitDiagram(parameter, vals.ravel().copy(), tuple(returns), tuple(labels), time.perf_counter() - wall0)


def _checked_values(params: PeelParams, parameter: str, values: Any) -> np.ndarray:
    """``values`` as an array: at most :data:`MAX_DIAGRAM_VALUES` (counted before converting them: a typo's 1e9
    values would take minutes), each a valid value of ``parameter``."""
    count = np.size(values) if isinstance(values, np.ndarray) else len(values) if hasattr(values, "__len__") else 0
    if count > MAX_DIAGRAM_VALUES:
        raise ValueError(f"values must hold at most MAX_DIAGRAM_VALUES = {MAX_DIAGRAM_VALUES} values (1e5 runs are "
                         f"about a day at ~1 s each: more is most likely a typo), got {count}")
    vals = reals("values", values)
    if vals.size > MAX_DIAGRAM_VALUES:
        raise ValueError(f"values must hold at most MAX_DIAGRAM_VALUES = {MAX_DIAGRAM_VALUES} values, got {vals.size}")
    for x in {float(vals.min()), float(vals.max())}:  # the parameters' ranges are intervals: the ends decide
        try:
            with_parameter(params, parameter, x)
        except ValueError as exc:
            raise ValueError(f"values must be valid values of {parameter}, got {x!r}: {exc}") from None
    return vals


def _check_executor(executor: Any) -> None:
    """ValueError or TypeError unless ``executor`` is None, a local pool's name or an executor."""
    if isinstance(executor, str) and executor not in POOL_KINDS:
        raise ValueError(f"executor must be None, one of {POOL_KINDS} or a concurrent.futures.Executor, got "
                         f"{executor!r}")
    if not (executor is None or isinstance(executor, str) or callable(getattr(executor, "submit", None))):
        raise TypeError(f"executor must be None, one of {POOL_KINDS} or a concurrent.futures.Executor, got "
                        f"{executor!r}")


def _run_values(params: PeelParams, parameter: str, flat: np.ndarray, run: tuple, wall: WallBudget,
                line: ProgressLine | None, report: Callable[[int, int], None] | None,
                executor: str | Executor | None, max_workers: int | None) -> dict[int, tuple[np.ndarray, str]]:
    """Each value's return map and label (:func:`_diagram_value` with the ``run`` arguments ``(t_transient,
    window, alpha0, rtol, method, solver, max_period)``), by its index; those lost labelled."""
    deadline = None if wall.limit is None else time.time() + wall.limit - (time.perf_counter() - wall.t0)
    tasks = [(k, (with_parameter(params, parameter, float(x)), *run, deadline)) for k, x in enumerate(flat)]
    found: dict[int, tuple[np.ndarray, str]] = {}

    def put(k: int, value: tuple[np.ndarray, str]) -> None:
        found[k] = value
        if line is not None:
            line.update(len(found), f"{parameter}={float(flat[k]):.6g} {value[1]}")
        elif report is not None:
            report(len(found), flat.size)

    lost = map_points(_diagram_value, tasks, put, pool=AUTO if executor is None else executor,
                      max_workers=max_workers, deadline=deadline)
    for k, text in sorted(lost, key=lambda kt: kt[0]):  # not begun by the deadline, or the pool lost it
        put(k, (np.zeros(0), "budget:max_wall" if text == DEADLINE_TEXT else "solver_failure"))
    return found


def explain(diagram: OrbitDiagram, branches: Sequence[Any], *, rtol: float = 1e-6,
            max_wall: float | None = DEFAULT_MAX_WALL) -> tuple[int | None, ...]:
    """Which continued branch, if any, explains each value of the brute-force diagram.

    A value whose long run is period n is explained by a branch of period-m orbits, m = n or a divisor of n,
    that spans it (its points' parameter values lie on both sides of it, or one is equal) when Newton at that
    value (``solve_orbit``, from the branch's point nearest to it) closes a **stable** orbit whose return-map
    values, repeated n/m times, equal the run's last n, as sets, to ``rtol`` relative (a run still settling
    onto a period-m orbit with a multiplier near -1 reads as period 2m).

    Parameters
    ----------
    diagram : OrbitDiagram
    branches : sequence of exact.OrbitBranch
        In ``diagram.parameter``.
    rtol : float
        Agreement of the orbit's and the run's cycle.
    max_wall : float or None
        Wall-clock budget [s] of all the Newton solves (None: unbounded; default :data:`exact.DEFAULT_MAX_WALL`):
        once it is spent the values left are not examined (None), like values no branch explains.

    Returns
    -------
    tuple of (int or None)
        Per diagram value, the index into ``branches`` of the first branch that explains it; None where none
        does, the run is not periodic, or ``max_wall`` was spent before the value was examined.
    """
    from ..orbits import OrbitBranch
    from ..orbits._corrector import VARIANT_PARAMETERS

    if diagram.parameter in VARIANT_PARAMETERS:
        raise ValueError(f"diagram: explain reads a diagram against continued branches of the paper's massless, "
                         f"velocity-controlled model, which continue_orbit does not follow in a model variant's "
                         f"parameter; got a diagram over {diagram.parameter!r}")
    wall = WallBudget(optional(positive, "max_wall", max_wall))
    out: list[int | None] = []
    for x, F, lab in zip(diagram.values, diagram.returns, diagram.labels):
        found = None
        n = int(lab.split("-")[1]) if lab.startswith("period-") else 0
        if wall.limit is not None and time.perf_counter() - wall.t0 >= wall.limit:
            n = 0  # the budget is spent: not examined
        for i, b in enumerate(branches if n else ()):
            if not isinstance(b, OrbitBranch):
                raise TypeError(f"branches must hold exact.OrbitBranch, got {type(b).__name__}")
            vals = np.array([p.value for p in b.points])
            m = b.points[0].orbit.n
            if n % m or not vals.min() <= x <= vals.max() or F.size < n:
                continue
            q = b.points[int(np.argmin(np.abs(vals - x)))]
            try:
                o = solve_orbit(with_parameter(q.orbit.params, diagram.parameter, float(x)),
                                q.orbit.section_states[0], m, max_iter=10, wall=wall)
            except (ValueError, ModelBreakdown, SolverFailure, SolverBudgetExceeded):
                continue
            cycle = np.sort(np.tile(o.return_map_values, n // m))
            if o.stable and np.allclose(cycle, np.sort(F[-n:]), rtol=rtol, atol=0):
                found = i
                break
        out.append(found)
    return tuple(out)

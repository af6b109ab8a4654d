"""The atlas itself: :func:`atlas` checks every argument, then runs its measures on the sweep engine."""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping, Sequence
from concurrent.futures import Executor
from typing import Any

import numpy as np

from exact import DEFAULT_MAX_WALL
from peelapprox import PARAM_RANGES, PeelForce, PeelParams, SolverBudgetExceeded
from peelapprox.io import ProgressLine

from ..sweep import sweep
from ..sweep.grid import check_grid_size, grid_length
from ..sweep.store import check_axis, failed
from .approximations import available
from .measures import DEFAULTS, MEASURE_NAMES, check_options
from .records import check_resumable, schema
from .result import AtlasResult
from .sets import SET_DEFAULTS, SET_MEASURE

__all__ = ["atlas", "atlas_options"]


class _Progress:
    """``progress=True``: the sweep's rate-limited line, labelled ``atlas``, showing each point's exact class;
    only a point whose measure raised is flagged as failed (a steady point or a breakdown is a result)."""

    def __init__(self) -> None:
        self.line: ProgressLine | None = None
        self.t0 = time.perf_counter()

    def __call__(self, done: int, total: int, rec: dict) -> None:
        if self.line is None:  # the first point of this run: the ones before it were resumed
            self.line = ProgressLine("atlas", total, done0=done - 1)
            self.line.t0 = self.t0
        cls = rec.get("atlas_exact_class", rec["status"])
        self.line.update(done, f"I={rec['I']:.4g} V={rec['V']:.4g} {cls}",
                         failed=rec["status"][:200] if failed(rec) else None)


def atlas_options(*, approximations: Sequence[str] | None = None, serial: bool = True, k: float | None = None,
                  R: float | None = None, l: float | None = None, geometry: str | None = None,
                  sets: bool = False, **window: Any) -> dict:
    """The sweep options of an atlas, every one explicit (the manifest then states them all), checked.

    ``window`` holds the options of :data:`~comparisons.atlas.measures.DEFAULTS` to change (``t_transient``,
    ``t_window``, ``rtol``, ``alpha0``, ``segments_per_branch``, ``segment_rtol``, ``reductions``); ``k, R, l,
    geometry`` are the :class:`peelapprox.PeelParams` fields of every point (None: its default).  The
    approximations that can run now go in ``approximations`` (name -> how a worker finds it), those whose
    function is not importable in ``skipped_approximations`` (name -> why); ``schema`` is the record schema
    (:func:`comparisons.atlas.records.schema`).  ``sets``: also the options of
    :data:`~comparisons.atlas.sets.SET_DEFAULTS` (``set_min_share``, ``set_stability``), which ``window`` may then
    change; without it they are refused and absent (the manifest of an atlas without sets is unchanged).

    Raises
    ------
    ValueError
        Naming the first invalid option (an unknown one too), before anything runs.
    """
    if not isinstance(sets, bool):
        raise ValueError(f"sets must be True or False, got {sets!r}")
    known = {**DEFAULTS, **SET_DEFAULTS} if sets else DEFAULTS
    unknown = sorted(set(window) - set(known))
    if unknown:
        raise ValueError(f"unknown atlas option(s) {unknown}; known: {sorted(known)} and k, R, l, geometry"
                         + ("" if sets else f" ({sorted(SET_DEFAULTS)} with sets=True)"))
    if isinstance(approximations, str):
        approximations = [a.strip() for a in approximations.split(",") if a.strip()]
    if approximations is not None and not (isinstance(approximations, (list, tuple))
                                           and all(isinstance(a, str) for a in approximations)):
        raise ValueError(f"approximations must be a sequence of names (None: every registered one), got "
                         f"{approximations!r}")
    run, skipped = available(None if approximations is None else list(approximations), serial=serial)
    opts: dict[str, Any] = {**known, **window, "approximations": run, "skipped_approximations": skipped,
                            "schema": schema()}
    fields: dict[str, Any] = {name: value for name, value in (("k", k), ("R", R), ("l", l), ("geometry", geometry))
              if value is not None}
    PeelParams(V=1.0, I=1e-5, **fields)  # ValueError naming a bad field and its range
    opts.update(fields)
    check_options(opts)
    return opts


def atlas(
    I_values: Sequence[float] | np.ndarray, V_values: Sequence[float] | np.ndarray, *, out,
    approximations: Sequence[str] | None = None, force: PeelForce | None = None, k: float | None = None,
    R: float | None = None, l: float | None = None, geometry: str | None = None,
    options: Mapping[str, Any] | None = None, executor: None | str | Executor = None, max_workers: int | None = None,
    progress: bool | Callable[[int, int, dict], None] | None = True, resume: bool = True, retry_failed: bool = False,
    max_wall: float | None = DEFAULT_MAX_WALL, sets: bool = False,
) -> AtlasResult:
    """Where the approximations hold: the exact attractor, every approximation's prediction and each
    reduction's exact-seeded errors at every (I, V) grid point, on the sweep engine.

    The measures of :mod:`comparisons.atlas.measures` run at each point; ``out`` is a sweep directory
    (:mod:`comparisons.sweep`), so a killed atlas loses only its running points and the same call finishes them.

    Parameters
    ----------
    I_values, V_values : sequence of float
        The grid (finite, > 0, no repeats; at most 1e6 points): roller inertias [kg m²] and pull speeds [m/s].
    out : path
        The atlas's directory (created; an atlas already there with the same grid and options is resumed).
    approximations : sequence of str, optional
        Names in :data:`~comparisons.atlas.approximations.APPROXIMATIONS` (default: all); an entry whose
        function is not importable is skipped (:attr:`AtlasResult.skipped` says which and why).
    force : peelapprox.PeelForce, optional
        The peel-force law at every point (default: the paper's).
    k, R, l, geometry : optional
        :class:`peelapprox.PeelParams` fields of every point (None: its defaults, k = 1000 N/m, R = 0.1 m).
    options : mapping, optional
        Changes to :data:`~comparisons.atlas.measures.DEFAULTS` (the window ``t_transient`` 100 s and
        ``t_window`` 20 s, tolerances, ``segments_per_branch``, ``reductions``).
    executor, max_workers, progress, resume, retry_failed, max_wall
        As :func:`comparisons.sweep.sweep`.
    sets : bool
        Also the measure over attractor sets (:mod:`comparisons.atlas.sets`: the exact set of
        :func:`exact.attractor_set` and the predicted set of :func:`peelapprox.approximate_attractor`, the set and
        strict matches, the confidence; about 8 exact runs more per point).  ``options`` may then set
        ``set_min_share`` (0.1) and ``set_stability`` (False).  Default False: the atlas, its options and its
        records as without it.

    Returns
    -------
    AtlasResult
        Every point of ``out`` (resumed and new), with the relative-error maps, tables, plots.

    Raises
    ------
    ValueError
        A bad grid, option or approximation name (named) before any point runs, or ``out`` holds another sweep.
    peelapprox.SolverBudgetExceeded
        ``max_wall`` was spent (``partial``: the :class:`AtlasResult` so far; the same call computes the rest).
    RuntimeError
        ``out`` is locked by another run, or a worker died (the records written stay).
    """
    check_grid_size({"I_values": grid_length(I_values), "V_values": grid_length(V_values)})
    check_axis("I_values", I_values, *PARAM_RANGES["I"])
    check_axis("V_values", V_values, *PARAM_RANGES["V"])
    if options is not None and not isinstance(options, Mapping):
        raise ValueError(f"options must be a mapping of atlas options, got {options!r}")
    serial = executor == "serial" or max_workers == 0
    opts = atlas_options(approximations=approximations, serial=serial, k=k, R=R, l=l, geometry=geometry, sets=sets,
                         **dict(options or {}))
    measures = (*MEASURE_NAMES, SET_MEASURE) if sets else MEASURE_NAMES
    check_resumable(out)
    try:
        res = sweep(I_values, V_values, measures, out=out, executor=executor, max_workers=max_workers,
                    options=opts, progress=_Progress() if progress is True else progress, resume=resume,
                    retry_failed=retry_failed, force=force, max_wall=max_wall)
    except SolverBudgetExceeded as exc:
        if exc.partial is not None:
            exc.partial = AtlasResult(exc.partial)
        raise
    return AtlasResult(res)

"""(I, V) parameter sweeps of any peel-force law, or over a law coefficient, from a laptop to a cluster
(``peelapprox sweep``; docs/usage.md, "sweep").

:func:`sweep` evaluates named *measures* at every point of a grid of roller inertias ``I`` and pull speeds
``V``, one task per point, on any :class:`concurrent.futures.Executor`: a local process pool by default, a
dask cluster with ``executor=Client(...).get_executor()``.  Each finished point is appended to
``out/results.jsonl`` and forced to disk at once, so a killed sweep loses only the points that were running,
and the same call again finishes the rest.

A measure is ``fn(params, options) -> dict`` of JSON scalars (or lists of them, one or two levels deep: the
point's slice of an array, as an atlas's observables per approximation), added with :func:`register_measure` (its keys
are recorded as :func:`record_key` says); the built-ins are ``regime``, ``jumps``, ``period`` and
``lyapunov`` (:mod:`~comparisons.sweep.measures`, which lists the options each reads).  Every option is
checked before the first point, so a bad one is a ValueError naming it and nothing is written.  ``force=``
and ``coef=`` choose the law or sweep a family coefficient as a third axis (:mod:`~comparisons.sweep.law`).
A grid holds at most :data:`MAX_SWEEP_POINTS` points (:func:`check_grid_size`), and ``max_wall`` bounds a
call.

Modules: :mod:`~comparisons.sweep.engine` (:func:`sweep`), :mod:`~comparisons.sweep.measures`,
:mod:`~comparisons.sweep.grid` (:func:`parse_grid`), :mod:`~comparisons.sweep.task` (one point in a worker,
and how measures reach the workers), :mod:`~comparisons.sweep.result` (:class:`SweepResult`,
:func:`load_sweep`), :mod:`~comparisons.sweep.store` (the output directory and its files, :data:`MANIFEST`,
:data:`RESULTS`, :data:`RESERVED`), :mod:`~comparisons.sweep.law`.  ``python -m comparisons.sweep ARGS`` is
``peelapprox sweep ARGS``.
"""

from .engine import sweep
from .grid import MAX_SWEEP_POINTS, check_grid_size, parse_grid
from .measures import MEASURES, record_key, register_measure
from .result import SweepResult, load_sweep
from .store import MANIFEST, RESERVED, RESULTS

__all__ = ["MEASURES", "register_measure", "sweep", "load_sweep", "SweepResult", "parse_grid",
           "record_key", "RESERVED", "MANIFEST", "RESULTS", "MAX_SWEEP_POINTS", "check_grid_size"]

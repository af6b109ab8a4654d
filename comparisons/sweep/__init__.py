"""(I, V) parameter sweeps of any peel-force law, or over a law coefficient, that scale from a laptop to a
cluster (an experiment: ``peelapprox sweep``).

A sweep evaluates named *measures* at every point of a grid of roller
inertias ``I`` and pull speeds ``V``, one task per point, on any
:class:`concurrent.futures.Executor`: a local process pool by default, a dask
cluster by passing ``executor=Client(...).get_executor()``.  Each finished
point is appended to ``out/results.jsonl`` and forced to disk at once, so a
killed sweep loses only the points that were running, and calling
:func:`sweep` again with the same arguments finishes the rest.

Measures
--------
A measure is ``fn(params: PeelParams, options: Mapping) -> dict`` returning a
flat dict of JSON scalars (``float, int, str, bool, None``; numpy scalars are
converted).  Keys are prefixed ``"<name>_"`` by the engine unless they already
equal ``name`` or start with ``"<name>_"``.  Register with
:func:`register_measure`; the built-ins are ``"regime"`` (closed-form regime
estimate, milliseconds), ``"jumps"`` (statistics of the stick-slip jumps of
the exact solution), ``"period"`` (period of the return map) and
``"lyapunov"`` (largest Lyapunov exponent, bits/s), all in
:mod:`comparisons.sweep.measures`.

Options
-------
``options`` is one JSON-serialisable dict passed to every measure.  The engine
itself reads ``k, R, l, geometry`` and the model variant's ``tape_mass, loading,
load_mass, load`` (the :class:`peelapprox.PeelParams` fields other than I and V;
defaults as there: a sweep of (I, V) for a given variant, one sweep per value to
sweep the tape mass); ``jumps`` and ``period`` share one windowed run
(``window_run``, one exact run per point) and read ``t_transient`` (30 s),
``t_end`` (t_transient + 20 s), ``rtol`` (1e-10) and ``alpha0`` (0);
``lyapunov`` reads ``t_transient`` and ``lyapunov_time`` (50 s).  The engine
adds ``max_wall``, the seconds left of the sweep's wall-clock budget when the
point starts (absent without a budget), which the built-in measures pass on to
their runs (a user option of that name is refused).  ``solver``
(None: the method's default, Radau) is the scipy solver of a variant's runs
(``jumps``, ``period``, ``lyapunov``; ignored by the massless model's hybrid
method).  Every option
the chosen measures read is checked before the first point (a measure
registered with ``check_options`` checks its own), so invalid options raise
ValueError naming the option and nothing is written.

Laws
----
``force=`` (a :class:`peelapprox.PeelForce`; default the paper's fvV) is the
peel-force law at every point; ``coef=(name, values)`` sweeps a coefficient of
a family law as a third grid axis (I x V x values: one I or one V to sweep the
coefficient instead of it).  The law travels to the workers pickled (plain
data); the manifest (``force``, ``law``, ``law_key``, ``coef``) and every
record of such a sweep (``law``, ``law_key``, ``coef``) say which law ran; a
sweep of the paper's law writes none of these.  See
:mod:`comparisons.sweep.law`.

Bounds
------
A grid holds at most :data:`MAX_SWEEP_POINTS` (1e6) points, checked before
anything is built or written (:func:`check_grid_size`, also the CLI's check of
``--I x --V``).  ``max_wall`` (default 3600 s, None: unbounded) bounds a call:
once it is spent no point starts, the points it cut are not recorded, and
``SolverBudgetExceeded`` says how many points are done; the same call again
resumes.  Within the limit, the manifest is written before the first point.

Workers
-------
Pool and cluster workers import each measure by ``module:qualname``.  A
measure they cannot import (defined in a notebook or ``__main__``, a lambda, a
local function) is shipped by value with cloudpickle when it is installed;
without it, such a measure is a ValueError before the first point.
``max_workers=0`` (``--workers 0``) runs every point in this process.

Output directory
----------------
``out/sweep.json``
    Manifest: grid values, measures, options, how to import each measure,
    package versions, creation time.  Written once, atomically.
``out/results.jsonl``
    One JSON object per finished point, in completion order: ``I``, ``V``,
    ``status``, then the measures' keys.  ``status`` is ``"ok"`` when every
    measure is; else ``"error: <Type>: <message>"`` of the first measure that
    raised, or else the first non-ok status a measure reported (e.g.
    ``"breakdown:no_root"``, a result, not a failure).  A failing measure
    records ``"<name>_status": "error: ..."`` and the others still run.
    Error points count as finished on resume; ``retry_failed=True``
    (``--retry-failed``) drops their records (the file is rewritten
    atomically) and computes them again.  Non-finite floats are written as
    ``NaN``/``Infinity`` (Python's JSON extension).  Records hold no timings
    or host names, so the same inputs give the same records.
``out/.lock``
    Held (``flock``) while a sweep writes, so two sweeps cannot share ``out``.

Files are opened without following symbolic links (``os.O_NOFOLLOW``) and
must be regular files; a manifest or record that is not what the engine
writes (wrong types, missing keys, non-finite ``I``/``V``) is a ValueError
naming the file (and line) as malformed.  A directory this process cannot
write is read only: a complete sweep there is returned (and reported by the
CLI); computing anything there is a ValueError.  The format itself lives in
:mod:`comparisons.sweep.store`; the names a reader of the directory needs are offered here:
:data:`MANIFEST` and :data:`RESULTS` (the two file names), :data:`RESERVED` (the engine's own record keys)
and :func:`record_key` (the key a measure's returned key is recorded under).

Modules
-------
:mod:`~comparisons.sweep.measures`
    :data:`MEASURES`, :func:`register_measure` and the built-in measures.
:mod:`~comparisons.sweep.grid`
    :func:`parse_grid`, :data:`MAX_SWEEP_POINTS`, :func:`check_grid_size`.
:mod:`~comparisons.sweep.task`
    One grid point in a worker (``run_point``) and how measures reach the
    workers (by import reference or by value).
:mod:`~comparisons.sweep.engine`
    :func:`sweep`: checks, resume and retry, executors (through
    :func:`comparisons._worker.run_tasks`, shared with the stress suite).
:mod:`~comparisons.sweep.result`
    :class:`SweepResult`, :func:`load_sweep`.
:mod:`~comparisons.sweep.store`
    The on-disk format.
:mod:`~comparisons.sweep.law`
    The sweep's law and its coefficient axis: checks, what the manifest and
    records say of the law.

``python -m comparisons.sweep ARGS`` is ``peelapprox sweep ARGS``.
"""

from .engine import sweep
from .grid import MAX_SWEEP_POINTS, check_grid_size, parse_grid
from .measures import MEASURES, record_key, register_measure
from .result import SweepResult, load_sweep
from .store import MANIFEST, RESERVED, RESULTS

__all__ = ["MEASURES", "register_measure", "sweep", "load_sweep", "SweepResult", "parse_grid",
           "record_key", "RESERVED", "MANIFEST", "RESULTS", "MAX_SWEEP_POINTS", "check_grid_size"]

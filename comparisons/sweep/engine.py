"""The sweep itself: :func:`sweep` checks its arguments and every option, then computes the points left in
``out`` (resume, retry of failed points) on an executor and appends each record as it finishes, within its
wall-clock budget ``max_wall``."""

from __future__ import annotations

import datetime as _dt
import math
import os
import time
from collections.abc import Callable, Mapping, Sequence
from concurrent.futures import Executor
from types import MappingProxyType
from typing import Any

import numpy as np

from exact import DEFAULT_MAX_WALL
from peelapprox import PARAM_RANGES, PeelForce, SolverBudgetExceeded
from peelapprox.io import ProgressLine, jsonable
from peelapprox.parallel import resolve_kind
from peelapprox.validate import ArgumentTypeError, flag, integer, optional, positive
from peelapprox.validate import path as _path

from .._worker import AUTO, PROCESSES, SERIAL, THREADS, run_tasks
from .grid import check_grid_size, grid_length
from .law import check_coef, check_force, manifest_fields
from .measures import MEASURES, OPTION_CHECKS, measure_ref
from .result import SweepResult
from .store import (
    FORMAT,
    RESULTS,
    Plan,
    append_records,
    check_axis,
    is_read_only,
    point_key,
    rewrite_records,
    truncate_records,
    versions,
    write_manifest,
    write_record,
)
from .store import lock as _lock
from .task import NOT_RUN, PARAM_OPTIONS, make_params, run_point, worker_refs

__all__ = ["sweep"]


def _progress_line(total: int, done0: int) -> Callable[[int, int, dict], None]:
    """``progress=True``: a line on stderr for this run's first point, the last, every ~5 % and every failed
    point (with its status); one updating line in Jupyter (:class:`peelapprox.io.ProgressLine`)."""
    line = ProgressLine("sweep", total, done0=done0)

    def report(done: int, total: int, rec: dict) -> None:
        c = f" coef={rec['coef']:.6g}" if "coef" in rec else ""
        status = rec["status"]
        line.update(done, f"I={rec['I']:.4g} V={rec['V']:.4g}{c}",
                    failed=None if status == "ok" else status[:200])

    return report


def sweep(
    I_values: Sequence[float] | np.ndarray, V_values: Sequence[float] | np.ndarray,
    measures: str | Sequence[str] = ("regime",), *, out, executor: None | str | Executor = None,
    max_workers: int | None = None, options: Mapping[str, Any] | None = None,
    progress: bool | Callable[[int, int, dict], None] | None = True, resume: bool = True,
    retry_failed: bool = False, force: PeelForce | None = None,
    coef: tuple[str, Sequence[float] | np.ndarray] | None = None, max_wall: float | None = DEFAULT_MAX_WALL,
) -> SweepResult:
    """Evaluate ``measures`` at every (I, V) grid point, writing each finished point to ``out`` at once.

    Parameters
    ----------
    I_values, V_values : sequence of float
        Grid axes (finite, > 0, no repeats); every pair (with ``coef``, every triple) is one task.
    measures : str or sequence of str
        Names in :data:`MEASURES` (``"regime,jumps"`` is split at commas).
    out : path
        Output directory, created; its files: :mod:`comparisons.sweep.store`.
    executor : None, "auto", "threads", "processes", "serial" or concurrent.futures.Executor
        A local pool of :mod:`peelapprox.parallel` of ``max_workers`` workers (default: the CPUs; 0 runs in this
        process, as ``"serial"``): None or "auto" is processes on more than two CPUs and threads on one or two;
        "threads" a thread pool (the compiled kernels release the GIL); "processes" loky's reusable process pool.
        Either way a script or notebook needs no ``__main__`` guard.  Any Executor is used as is, e.g. a dask
        client's.  The points are submitted the smallest I first (the longest runs), whatever the executor.
    options : mapping, optional
        JSON-serialisable settings passed to every measure (:mod:`comparisons.sweep.measures`).
    progress : bool or callable
        True: rate-limited progress with an ETA on stderr; a callable gets ``(done, total, record)``.
    resume, retry_failed : bool
        Skip the finished points of the same sweep in ``out`` (another sweep there is a ValueError naming what
        differs; ``resume=False`` refuses a non-empty ``out``); compute its failed points again.
    force, coef : PeelForce, (str, sequence of float), optional
        The law at every point (default fvV), and a coefficient of that family law swept as a third axis.
    max_wall : float or None
        Wall-clock budget [s] (default :data:`exact.DEFAULT_MAX_WALL`); each point's measures get what is left as
        the option ``max_wall``.  Once spent no point starts and the points it cut are not recorded.

    Returns
    -------
    SweepResult
        All records in ``out``, the resumed and the new ones.

    Raises
    ------
    ValueError
        An invalid argument or option, unknown measure, or unusable ``out``, before anything is written.
    RuntimeError
        ``out`` is locked by another sweep, or a worker died (the records written stay: call again).
    peelapprox.SolverBudgetExceeded
        ``max_wall`` was spent; ``partial`` is the result so far, and the same call again computes the rest.
    """
    t0 = time.time()
    I_vals, V_vals, force, coef_axis = _check_grid(I_values, V_values, force, coef)
    max_wall = optional(positive, "max_wall", max_wall)
    measures = _check_measures(measures)
    options = _checked_options(options, measures, force)
    executor, max_workers = _check_executor(executor, max_workers, progress)
    resume = flag("resume", resume)
    retry_failed = flag("retry_failed", retry_failed)
    refs = {name: measure_ref(MEASURES[name]) for name in measures}
    # in this process (serial, threads) the measures are the objects themselves; elsewhere import references
    task_refs = refs if executor in (SERIAL, THREADS) else worker_refs(measures)

    out = _make_out(out)
    plan = dict(out=out, I_vals=I_vals, V_vals=V_vals, measures=measures, options=options, resume=resume,
                retry_failed=retry_failed, force=force, coef=coef_axis)
    try:
        lock = _lock(out)
    except OSError as exc:
        if not is_read_only(exc):
            raise
        return _sweep_read_only(exc, **plan)
    deadline = None if max_wall is None else t0 + max_wall
    try:
        return _sweep_locked(Plan(**plan), refs, task_refs, executor, max_workers, progress, deadline, max_wall)
    finally:
        lock.close()


def _check_grid(I_values: Any, V_values: Any, force: PeelForce | None, coef: Any
                ) -> tuple[list[float], list[float], PeelForce, tuple[str, list[float]] | None]:
    """The checked axes, law and coefficient axis (ValueError naming the first bad one); the grid's size is checked
    before the axes are converted (a typo's 1e8 values would take minutes) and after."""
    sizes = {"I_values": grid_length(I_values), "V_values": grid_length(V_values)}
    if isinstance(coef, (tuple, list)) and len(coef) == 2:
        sizes["coef values"] = grid_length(coef[1])
    check_grid_size(sizes)
    I_vals = check_axis("I_values", I_values, *PARAM_RANGES["I"])
    V_vals = check_axis("V_values", V_values, *PARAM_RANGES["V"])
    force = check_force(force)
    coef_axis = check_coef(force, coef)
    check_grid_size({"I_values": len(I_vals), "V_values": len(V_vals),
                     **({"coef values": len(coef_axis[1])} if coef_axis else {})})
    return I_vals, V_vals, force, coef_axis


def _check_measures(measures: str | Sequence[str]) -> list[str]:
    """``measures`` as a list of registered names (a str split at commas), each once; ValueError or
    ArgumentTypeError naming it otherwise."""
    if isinstance(measures, str):
        measures = [m.strip() for m in measures.split(",") if m.strip()]
    if not isinstance(measures, (list, tuple)) or not all(isinstance(m, str) for m in measures):
        raise ArgumentTypeError(f"measures must be a str or a sequence of str (names in MEASURES), got {measures!r}")
    measures = list(measures)
    if not measures:
        raise ValueError(f"measures must name at least one measure; known: {sorted(MEASURES)}")
    if len(set(measures)) != len(measures):
        raise ValueError(f"measures must not repeat a name, got {measures}")
    unknown = [m for m in measures if m not in MEASURES]
    if unknown:
        raise ValueError(f"measures: unknown measure(s) {unknown}; known: {sorted(MEASURES)}")
    return measures


def _checked_options(options: Any, measures: Sequence[str], force: PeelForce) -> dict:
    """``options`` as plain JSON data, every option the engine and ``measures`` read checked (ValueError naming
    it)."""
    options = {} if options is None else options
    if not isinstance(options, Mapping) or not all(isinstance(k, str) for k in options):
        raise ValueError(f"options must be a mapping with str keys, got {options!r}")
    try:
        options = jsonable(dict(options), keep_nonfinite=True)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"options must be JSON-serialisable (str, numbers, bools, None, lists, dicts): {exc}") \
            from None
    if "max_wall" in options:
        raise ValueError("options: max_wall is the sweep's own argument, sweep(max_wall=...) (the engine passes "
                         "each point's measures what is left of it), not an option")
    _check_options(measures, options, force)
    return options


def _check_executor(executor: Any, max_workers: int | None, progress: Any) -> tuple[Any, int | None]:
    """The executor to run on and ``max_workers`` (0: in this process), checked against each other; ``progress``
    checked (ValueError naming the argument).  None or "auto" resolves to processes on more than two CPUs, threads
    on two (:mod:`peelapprox.parallel`); ``max_workers=0`` to serial."""
    max_workers = optional(integer, "max_workers", max_workers, lo=0)  # 0: in this process
    local = (None, AUTO, THREADS, PROCESSES)
    if max_workers is not None and not any(executor is x or executor == x for x in local):
        raise ValueError("max_workers applies only to the local pools (executor None, 'threads' or 'processes'); "
                         "size your executor instead")
    if not (executor is None or (isinstance(executor, str) and executor in (AUTO, SERIAL, THREADS, PROCESSES))
            or callable(getattr(executor, "submit", None))):
        raise ValueError(f"executor must be None, 'auto', 'threads', 'processes', 'serial' or a "
                         f"concurrent.futures.Executor, got {executor!r}")
    if not (isinstance(progress, bool) or progress is None or callable(progress)):
        raise ValueError("progress must be a bool, None or a callable (done, total, record)")
    if max_workers == 0:
        executor = SERIAL
    elif executor is None or executor == AUTO:
        executor = resolve_kind(AUTO)
    return executor, max_workers


def _make_out(out: Any) -> str:
    """The checked path ``out``, created as a directory (ValueError if it cannot be)."""
    out = _path("out", out)
    if os.path.exists(out) and not os.path.isdir(out):
        raise ValueError(f"out={out!r} exists and is not a directory")
    try:
        os.makedirs(out, exist_ok=True)
    except OSError as exc:
        raise ValueError(f"out={out!r}: cannot create the directory ({exc})") from None
    return out


def _check_options(measures: Sequence[str], options: Mapping, force: PeelForce | None = None) -> None:
    """Every option the engine and ``measures`` read, checked before any point (ValueError naming it)."""
    try:
        make_params(1.0, 1.0, options, force)
    except (TypeError, ValueError) as exc:
        raise ValueError(f"options: invalid PeelParams fields {[k for k in PARAM_OPTIONS if k in options]}: {exc}") \
            from None
    frozen = MappingProxyType(options)
    for name in measures:
        check = OPTION_CHECKS.get(name)
        if check is not None:
            try:
                check(frozen)
            except (TypeError, ValueError) as exc:
                raise ValueError(f"options (read by measure {name!r}): {exc}") from None


def _sweep_read_only(exc: OSError, **plan) -> SweepResult:
    """``out`` cannot be written: return its sweep if nothing is left to compute, else ValueError."""
    p = Plan(**plan)
    if p.manifest is not None and not p.todo:
        return _result(p)
    left = f"{len(p.todo)} of {p.total} points are still to compute" if p.manifest else "it holds no sweep yet"
    raise ValueError(f"out={p.out!r} is not writable ({exc}) and {left}: make it writable or use another directory")


def _sweep_locked(p: Plan, refs, task_refs, executor, max_workers, progress, deadline: float | None = None,
                  max_wall: float | None = None) -> SweepResult:
    out = p.out
    if p.manifest is None:
        p.manifest = {
            "format": FORMAT,
            "I_values": p.I_vals,
            "V_values": p.V_vals,
            "measures": p.measures,
            "options": p.options,
            "measure_refs": refs,
            "grid_order": "I major: results arrays are [i, j] for I_values[i], V_values[j]" if p.coef is None else
                          "I major, then V, then coef: results arrays are [i, j, k] for I_values[i], V_values[j], "
                          "coef values[k]",
            **manifest_fields(p.force, p.coef),
            "versions": versions(),
            "created": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        }
        write_manifest(out, p.manifest)
    with_coef = p.coef is not None
    if p.retry:  # drop the failed points' records (and any partial tail) before computing them again
        rewrite_records(out, [r for r in p.records if point_key(r, with_coef) not in p.retry])
    elif p.partial:  # the last write was cut off: drop it so appends start on a clean line
        truncate_records(out, p.end)
    done, todo, total = p.done, p.todo, p.total
    report = _progress_line(total, len(done)) if progress is True else (progress or None)

    if todo:
        _compile_law_here(p.force, deadline)
    cut: list[tuple[float, ...]] = []
    with append_records(out) as fh:
        def write(key: tuple[float, ...], rec: dict) -> None:
            if point_key(rec, with_coef) != key:  # pragma: no cover - defensive
                raise RuntimeError(f"executor returned the record of {point_key(rec, with_coef)} for {key}")
            if rec["status"] == NOT_RUN:  # left out or cut by max_wall: not recorded, computed on resume
                cut.append(key)
                return
            write_record(fh, rec)
            done[key] = rec
            if report:
                report(len(done), total, rec)

        lost = run_tasks(run_point, [(key, _task(key, p, task_refs, deadline)) for key in todo], write,
                         executor=executor, max_workers=max_workers, deadline=deadline,
                         cost=[_point_cost(key) for key in todo])
    if deadline is not None and max_wall is not None and (cut or lost) and time.time() >= deadline:
        raise SolverBudgetExceeded(
            f"sweep: the wall-clock budget max_wall={max_wall:g} s was spent with {len(done)}/{total} points done "
            f"(in {os.path.join(out, RESULTS)}; {len(cut) + len(lost)} not run or cut, not recorded): call sweep() "
            "again with the same arguments to compute the rest, with a larger max_wall or None",
            budget="max_wall", limit=max_wall, t=0.0, state={"t": 0.0}, partial=_result(p))
    if lost:
        hint = ""
        died = sorted({name for _, err in lost for name in ("TerminatedWorkerError", "BrokenProcessPool")
                       if name in err})
        if died:
            hint = f"; a worker process died ({', '.join(died)}: a crash, out of memory, killed) or could not start"
        first = ", ".join(f"{n}={x}" for n, x in zip(("I", "V", "coef"), lost[0][0]))
        raise RuntimeError(f"{len(lost)} of {len(todo)} points were lost by the executor (first: {first}: "
                           f"{lost[0][1]}); {len(done)}/{total} points are in "
                           f"{os.path.join(out, RESULTS)}; call sweep() again with the same arguments to compute "
                           "the rest" + hint)
    return _result(p)


def _compile_law_here(force: PeelForce, deadline: float | None) -> None:
    """Compile an expression law's kernel in the calling thread, under what is left of the sweep's budget, before
    any point: in a worker thread no timer interrupts the compilation (a 55-factor law compiled for 176 s under
    ``max_wall=10``), in the main thread the budget does (``peelapprox.kernels.caller_budget``).  A budget spent
    here is not an error of its own: every point then finds the deadline passed and the sweep stops as usual."""
    if force.kind != "expression":
        return
    from peelapprox import kernels

    left = None if deadline is None else max(deadline - time.time(), 1e-3)
    try:
        with kernels.caller_budget(left):
            kernels.expression_kernel(str(force.source))
    except kernels.BuildExpired:
        pass


def _point_cost(key: tuple[float, ...]) -> float:
    """A point's predicted relative cost, 1/sqrt(I): an exact run's steps follow the α oscillation, whose period
    shrinks as sqrt(I) (docs/atlas.md, "Cost": the costliest points are at the smallest I).  Orders the tasks
    (longest first, so that the tail does not idle the pool), never their values."""
    return 1.0 / math.sqrt(key[0])


def _task(key: tuple[float, ...], p: Plan, task_refs, deadline: float | None = None) -> tuple:
    """The arguments of :func:`run_point` at ``key``: the paper's law without a coefficient axis passes no law
    (the records of before); any other law travels pickled, with the point's coefficient value; and the sweep's
    ``deadline``, when it has one."""
    args: tuple = (key[0], key[1], p.measures, p.options, task_refs)
    if deadline is not None:
        law = p.force if p.coef is not None or p.force.kind != "paper" else None
        return (*args, law, None if p.coef is None else (p.coef[0], key[2]), deadline)
    if p.coef is not None:
        return (*args, p.force, (p.coef[0], key[2]))
    if p.force.kind != "paper":
        return (*args, p.force)
    return args


def _result(p: Plan) -> SweepResult:
    return SweepResult(p.I_vals, p.V_vals, p.measures, p.options, p.done.values(), manifest=p.manifest, out=p.out,
                       force=p.force, coef=p.coef)

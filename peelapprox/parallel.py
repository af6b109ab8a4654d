"""Local worker pools for grids of independent points: the one pool sweeps, atlases, basins and the other grid
runs share (:func:`map_points`, :func:`worker_pool`).

Three kinds of pool, and any :class:`concurrent.futures.Executor` (a dask client's ``get_executor()``):

* ``"processes"`` — loky's reusable process executor (joblib's): tasks travel by cloudpickle, so a function
  defined in a script or a notebook works, and no worker re-imports ``__main__``, so a script needs no
  ``if __name__ == "__main__":`` guard.  The workers start once and are reused by the next call of the same
  size (they exit after :data:`IDLE_TIMEOUT` s idle, or with this process); each starts with BLAS thread pools
  of one thread (:data:`WORKER_ENV`, set before it imports numpy).  A worker that dies (a crash, the kernel's
  out-of-memory killer) loses the tasks it held: :func:`map_points` returns them as lost, with loky's
  ``TerminatedWorkerError`` named in their text, never a hang.  Without loky installed, the standard library's
  spawned process pool (which re-imports ``__main__``: a script then needs the guard).
* ``"threads"`` — a thread pool: the compiled kernels release the GIL, but the Python between them (the
  harness, the observables, the store) holds it, so threads scale less than processes past two or three cores.
* ``"serial"`` — in this process, one task after the other.

``"auto"`` (the default of every grid run): processes where the machine has more than two CPUs (and loky is
installed), threads on one or two (where the two measure alike and threads start at once: docs/performance.md,
"Parallel grids"); serial inside a worker of this module's pools (no nested pools); the environment variable
``PEELAPPROX_POOL`` (one of :data:`POOL_KINDS`) overrides it.  ``python -m comparisons.benchmark.scaling``
measures the kinds on the machine it runs on.
"""

from __future__ import annotations

import contextlib
import os
import threading
import time
from collections.abc import Callable, Hashable, Iterable, Iterator, Sequence
from concurrent.futures import FIRST_COMPLETED, Executor, Future, ProcessPoolExecutor, ThreadPoolExecutor, wait
from typing import Any

__all__ = ["AUTO", "DEADLINE_TEXT", "IDLE_TIMEOUT", "POOL_KINDS", "PROCESSES", "SERIAL", "THREADS", "WORKER_ENV",
           "cpu_count", "default_kind", "error_text", "map_points", "resolve_kind", "worker_pool"]

#: ``pool`` value: processes on more than two CPUs, else threads (module docstring).
AUTO = "auto"
#: ``pool`` value: a local thread pool.
THREADS = "threads"
#: ``pool`` value: loky's reusable process pool (module docstring).
PROCESSES = "processes"
#: ``pool`` value: every task in this process, in order.
SERIAL = "serial"
#: The pool kinds by name.
POOL_KINDS = (AUTO, THREADS, PROCESSES, SERIAL)
#: Seconds a reusable process worker waits idle for the next task before it exits.
IDLE_TIMEOUT = 300.0
#: The environment of a process worker, set before it imports anything: one BLAS/OpenMP thread (a worker's numpy
#: calls are small; a pool of N workers each spinning N BLAS threads oversubscribes the machine) and the marker
#: that makes ``"auto"`` serial inside a worker.
WORKER_ENV = {"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1",
              "BLIS_NUM_THREADS": "1", "VECLIB_MAXIMUM_THREADS": "1", "NUMEXPR_NUM_THREADS": "1",
              "PEELAPPROX_WORKER": "1"}
#: The error text of a task :func:`map_points` did not start because its ``deadline`` had passed.
DEADLINE_TEXT = "not run: the deadline passed before it began"


def cpu_count() -> int:
    """The CPUs this process may run on (its affinity mask where the platform has one)."""
    if hasattr(os, "sched_getaffinity"):
        return max(1, len(os.sched_getaffinity(0)))
    return os.cpu_count() or 1


def _loky() -> Any:
    """The loky module, or None when it is not installed."""
    try:
        import loky
    except ImportError:
        return None
    return loky


def default_kind() -> str:
    """What ``"auto"`` means here: :data:`SERIAL` inside a pool's worker, else ``PEELAPPROX_POOL`` if set, else
    :data:`PROCESSES` on more than two CPUs with loky installed, else :data:`THREADS`."""
    if os.environ.get("PEELAPPROX_WORKER") == "1":
        return SERIAL
    env = os.environ.get("PEELAPPROX_POOL", "").strip().lower()
    if env in (THREADS, PROCESSES, SERIAL):
        return env
    return PROCESSES if cpu_count() > 2 and _loky() is not None else THREADS


def resolve_kind(pool: str | None) -> str:
    """``pool`` (None or one of :data:`POOL_KINDS`) as a concrete kind: threads, processes or serial.

    Raises
    ------
    ValueError
        ``pool`` is not one of :data:`POOL_KINDS`.
    """
    if pool is None or pool == AUTO:
        return default_kind()
    if pool in (THREADS, PROCESSES, SERIAL):
        return pool
    raise ValueError(f"pool must be one of {POOL_KINDS} or an Executor, got {pool!r}")


def error_text(exc: BaseException, limit: int = 500) -> str:
    """``"error: <Type>: <message>"`` on one line (whitespace collapsed), at most ``limit`` characters of
    message (cut with ``...``)."""
    msg = " ".join(str(exc).split())
    if len(msg) > limit:
        msg = msg[:limit - 3] + "..."
    return f"error: {type(exc).__name__}: {msg}"


def _limit_blas() -> None:  # pragma: no cover - runs in the workers of the standard library's pool
    """Initializer of the standard library's process workers (no loky): the environment of :data:`WORKER_ENV`
    for what they import next, and threadpoolctl's limit for what they imported already, if installed."""
    os.environ.update(WORKER_ENV)
    try:
        from threadpoolctl import threadpool_limits
    except ImportError:
        return
    threadpool_limits(1)


def _watch_parent(parent_pid: int) -> None:  # pragma: no cover - runs in the workers
    """Exit this worker when ``parent_pid`` is no longer its parent (checked every 0.5 s): a worker does not
    outlive a parent killed by SIGKILL, as an orphan idling or running its point."""

    def watch() -> None:
        while True:
            time.sleep(0.5)
            if os.getppid() != parent_pid:
                os._exit(1)

    threading.Thread(target=watch, name="peelapprox-orphan-watch", daemon=True).start()


def _std_worker_init(parent_pid: int) -> None:  # pragma: no cover - runs in the workers
    _watch_parent(parent_pid)
    _limit_blas()


def _process_pool(n: int) -> Executor:
    loky = _loky()
    if loky is not None:
        return loky.get_reusable_executor(max_workers=n, timeout=IDLE_TIMEOUT, env=dict(WORKER_ENV),
                                          initializer=_watch_parent, initargs=(os.getpid(),))
    import multiprocessing as mp
    return ProcessPoolExecutor(max_workers=n, mp_context=mp.get_context("spawn"), initializer=_std_worker_init,
                               initargs=(os.getpid(),))


@contextlib.contextmanager
def worker_pool(pool: str | None = AUTO, max_workers: int | None = None,
                n_tasks: int | None = None) -> Iterator[tuple[Executor | None, str, int]]:
    """A local pool as ``(executor, kind, workers)``: ``executor`` None for :data:`SERIAL`.

    Parameters
    ----------
    pool : {"auto", "threads", "processes", "serial"} or None
        The kind (module docstring; None: ``"auto"``).
    max_workers : int, optional
        Workers (default: :func:`cpu_count`), at most ``n_tasks``; 0 means serial.
    n_tasks : int, optional
        The tasks to come (the pool is no larger).

    Notes
    -----
    On leaving, a thread pool is shut down (after its tasks); loky's process pool is left running for the next
    call (its workers exit when idle for :data:`IDLE_TIMEOUT` s), unless an exception (KeyboardInterrupt
    included) leaves the block: then its workers are killed at once, with whatever they were running.
    """
    kind = SERIAL if max_workers == 0 else resolve_kind(pool)
    n = max_workers or cpu_count()
    if n_tasks is not None:
        n = min(n, max(1, n_tasks))
    n = max(1, n)
    if kind == SERIAL:
        yield None, SERIAL, 1
        return
    ex = ThreadPoolExecutor(max_workers=n, thread_name_prefix="peelapprox-task") if kind == THREADS \
        else _process_pool(n)
    reusable = kind == PROCESSES and _loky() is not None
    try:
        yield ex, kind, n
    except BaseException:
        if reusable:
            ex.shutdown(wait=False, kill_workers=True)  # type: ignore[call-arg]
        else:
            ex.shutdown(wait=False, cancel_futures=True)
        raise
    if not reusable:
        ex.shutdown(wait=True, cancel_futures=True)


def _run_chunk(fn: Callable[..., Any], chunk: Sequence[tuple[Any, tuple]]) -> list[tuple[bool, Any]]:
    """``fn(*args)`` for each ``(key, args)`` of ``chunk``: ``(True, value)``, or ``(False, error text)`` where
    it raised (one task's exception loses that task only)."""
    out: list[tuple[bool, Any]] = []
    for _, args in chunk:
        try:
            out.append((True, fn(*args)))
        except Exception as exc:  # reported as a lost task by the caller
            out.append((False, error_text(exc)))
    return out


def _order(n: int, cost: Sequence[float] | None) -> list[int]:
    """Task indices, the most costly first (stable: equal costs keep their order); as given without ``cost``."""
    if cost is None:
        return list(range(n))
    if len(cost) != n:
        raise ValueError(f"cost must hold one number per task ({n}), got {len(cost)}")
    return sorted(range(n), key=lambda i: -float(cost[i]))


def _auto_chunk(kind: str, n_tasks: int, workers: int) -> int:
    """Tasks per submission: 1 for threads, serial and foreign executors; for processes enough that a chunk's
    transport is small beside its work yet the pool gets at least ~16 chunks per worker (the tail), at most 8."""
    if kind != PROCESSES:
        return 1
    return max(1, min(8, n_tasks // (16 * workers)))


def map_points(fn: Callable[..., Any], tasks: Sequence[tuple[Hashable, Iterable[Any]]],
               on_result: Callable[[Any, Any], None], *, pool: None | str | Executor = AUTO,
               max_workers: int | None = None, deadline: float | None = None,
               cost: Sequence[float] | None = None, chunksize: int | None = None) -> list[tuple[Any, str]]:
    """Run ``fn(*args)`` for every ``(key, args)`` of ``tasks``; ``on_result(key, value)`` as each one finishes.

    Parameters
    ----------
    fn : callable
        Picklable by cloudpickle for a process pool (a module-level function, or one defined in a script or a
        notebook); it should not raise (catch into the value: a task that raises is returned as lost).
    tasks : sequence of (key, args)
    on_result : callable
        Called in this process, in completion order (task order when serial).
    pool : {"auto", "threads", "processes", "serial"}, None or concurrent.futures.Executor
        A local pool (:func:`worker_pool`; None: ``"auto"``), or any executor, used as is and left running
        (e.g. a dask client's ``get_executor()``).
    max_workers : int, optional
        Size of a local pool (default: the CPUs; 0: serial).
    deadline : float, optional
        A ``time.time()`` after which no task is started: the tasks not begun are returned as lost
        (:data:`DEADLINE_TEXT`); the running ones are waited for (bound them with the deadline themselves).
    cost : sequence of float, optional
        A predicted cost per task: on a pool the most costly are submitted first, so that the last to finish
        are short and the tail does not idle the pool (the values do not depend on the order; serial runs keep
        the task order).
    chunksize : int, optional
        Tasks per submission (default: 1, or a few for a process pool with many tasks per worker).

    Returns
    -------
    list of (key, error text)
        The tasks lost (a worker died: loky's ``TerminatedWorkerError`` or ``BrokenProcessPool`` named in the
        text; a task raised; the deadline passed before it began): to run again.  An exception of
        ``on_result`` cancels the tasks not yet finished and propagates.
    """
    items = [(key, tuple(args)) for key, args in tasks]
    order = _order(len(items), cost)
    lost: list[tuple[Any, str]] = []
    if not items:
        return lost
    if isinstance(pool, str) or pool is None:
        with worker_pool(pool, max_workers, len(items)) as (ex, kind, n):
            if ex is None:
                for key, args in items:  # in task order: ``cost`` orders a pool's submissions only
                    if deadline is not None and time.time() >= deadline:
                        lost.append((key, DEADLINE_TEXT))
                        continue
                    try:
                        value = fn(*args)
                    except Exception as exc:
                        lost.append((key, error_text(exc)))
                        continue
                    on_result(key, value)
                return lost
            size = chunksize or _auto_chunk(kind, len(items), n)
            return _submit_all(ex, fn, [items[i] for i in order], on_result, size, deadline)
    if not callable(getattr(pool, "submit", None)):
        raise ValueError(f"pool must be one of {POOL_KINDS} or a concurrent.futures.Executor, got {pool!r}")
    return _submit_all(pool, fn, [items[i] for i in order], on_result, chunksize or 1, deadline)


def _submit_all(ex: Executor, fn: Callable[..., Any], tasks: list[tuple[Any, tuple]],
                on_result: Callable[[Any, Any], None], size: int, deadline: float | None) -> list[tuple[Any, str]]:
    """:func:`map_points` on an executor: ``tasks`` (in submission order) in chunks of ``size``."""
    lost: list[tuple[Any, str]] = []
    futs: dict[Future, list[tuple[Any, tuple]]] = {}
    try:
        for k in range(0, len(tasks), size):
            chunk = tasks[k:k + size]
            futs[ex.submit(_run_chunk, fn, chunk)] = chunk
        pending, expired = set(futs), False
        while pending:
            timeout = None if deadline is None or expired else max(0.0, deadline - time.time())
            finished, pending = wait(pending, timeout=timeout, return_when=FIRST_COMPLETED)
            if deadline is not None and not expired and time.time() >= deadline:
                expired = True  # cancel the tasks not begun (a cancelled future is never "finished" by wait)
                cancelled = {fut for fut in pending if fut.cancel()}
                pending -= cancelled
                for fut in cancelled:
                    lost.extend((key, DEADLINE_TEXT) for key, _ in futs.pop(fut))
            for fut in finished:
                chunk = futs.pop(fut)
                try:
                    values = fut.result()
                except Exception as exc:  # the executor lost the chunk (a worker died, cancelled): not results
                    lost.extend((key, error_text(exc)) for key, _ in chunk)
                    continue
                for (key, _), (ok, value) in zip(chunk, values):
                    if ok:
                        on_result(key, value)
                    else:
                        lost.append((key, value))
    finally:
        for fut in futs:
            fut.cancel()
    return lost

"""Workers shared by the experiments that run many points: the stress suite and the (I, V) sweep.

The stress suite runs each point in a spawned process it can kill; the sweep on a thread pool by default (the
compiled kernels release the GIL), a spawned process pool or any executor.  Both turn whatever a point raises
into fields of its record instead of a crash of the whole run, and report progress on stderr (rate-limited:
``peelapprox.io.ProgressLine``).

* :func:`watch_parent` — a worker exits when the process that started it dies (e.g. SIGKILL), instead of
  idling (or hanging in a point) as an orphan.
* :class:`TimedWorker` — one worker that runs tasks one at a time with a wall-clock timeout; a hung task is
  killed with its worker and a crashed worker is noticed, and either is restarted for the next task (the
  stress suite's :class:`~comparisons.stress.StressRunner`).
* :func:`run_tasks` — many tasks on a :class:`concurrent.futures.Executor`: in this process, on a local
  thread pool (the default) or spawned process pool, or on any executor (a dask cluster); tasks the executor
  loses (a worker died) are returned, not raised (the sweep's engine).
* :func:`message`, :func:`error_text` — an exception as record fields; :func:`write_line` — a progress
  line (the stress suite's; the sweep's is :class:`peelapprox.io.ProgressLine`).
"""

from __future__ import annotations

import multiprocessing as mp
import os
import sys
import threading
import time
from collections.abc import Callable, Hashable, Iterable, Sequence
from concurrent.futures import FIRST_COMPLETED, Executor, Future, ProcessPoolExecutor, ThreadPoolExecutor, wait
from typing import Any

__all__ = ["spawn_context", "watch_parent", "message", "error_text", "write_line", "TimedWorker", "run_tasks",
           "SERIAL", "THREADS", "PROCESSES", "DEADLINE_TEXT"]

#: ``executor`` value of :func:`run_tasks` that runs every task in this process, one after the other.
SERIAL = "serial"
#: ``executor`` value of :func:`run_tasks`: a local thread pool (the default).  The compiled kernels release the
#: GIL (``nogil``), so threads run points in parallel; no process starts, so a script, a notebook or ``python -c``
#: needs no ``if __name__ == "__main__":`` guard.  Measured on 2 cores, a 6 x 6 sweep of the "period" measure:
#: serial 10.4 s, 2 threads 5.3 s, 2 spawned processes 6.4 s (each imports the package), records identical.
THREADS = "threads"
#: ``executor`` value of :func:`run_tasks`: a local spawned process pool (a point that hangs in compiled code
#: cannot stop a thread, but a process dies with its pool; needs the ``__main__`` guard in a script).
PROCESSES = "processes"
#: The error text of a task :func:`run_tasks` did not start because its ``deadline`` had passed.
DEADLINE_TEXT = "not run: the deadline passed before it began"


def spawn_context() -> Any:
    """The ``spawn`` multiprocessing context: a worker starts from a fresh interpreter (no forked locks or
    numba state) on every platform."""
    return mp.get_context("spawn")


def watch_parent(parent_pid: int) -> None:  # pragma: no cover - runs in the workers
    """Exit this (worker) process when ``parent_pid`` is no longer its parent, checked every 0.5 s."""

    def watch() -> None:
        while True:
            time.sleep(0.5)
            if os.getppid() != parent_pid:
                os._exit(1)

    threading.Thread(target=watch, name="orphan-watch", daemon=True).start()


# --------------------------------------------------------------------------------------------- records

def message(exc: BaseException, limit: int = 300) -> str:
    """``str(exc)`` cut to ``limit`` characters (the stress suite's ``message`` field)."""
    return str(exc)[:limit]


def error_text(exc: BaseException, limit: int = 500) -> str:
    """``"error: <Type>: <message>"`` on one line (whitespace collapsed), at most ``limit`` characters of
    message (cut with ``...``): the sweep's status of a point whose measure raised."""
    msg = " ".join(str(exc).split())
    if len(msg) > limit:
        msg = msg[:limit - 3] + "..."
    return f"error: {type(exc).__name__}: {msg}"


# --------------------------------------------------------------------------------------------- progress

def write_line(text: str) -> None:
    """One progress line on stderr, flushed at once."""
    sys.stderr.write(text + "\n")
    sys.stderr.flush()


# --------------------------------------------------------------------------------------------- one timed worker

def _timed_main(conn: Any, func: Callable[[Any], Any], init: Callable[[], Any] | None, parent_pid: int) -> None:
    """Worker loop of :class:`TimedWorker`: receive a task, send back ``func(task)``; ``None`` stops.

    Whatever ``func`` raises is sent back as ``{"outcome": "unexpected:<Type>", "exception", "message"}``.
    """
    watch_parent(parent_pid)
    if init is not None:
        init()
    conn.send(("ready", None))
    while True:
        try:
            task = conn.recv()
        except (EOFError, OSError):
            return
        if task is None:
            return
        try:
            res = func(task)
        except BaseException as e:  # noqa: BLE001 - reported to the parent
            res = {"outcome": f"unexpected:{type(e).__name__}", "exception": type(e).__name__,
                   "message": message(e)}
        conn.send(("result", res))


class TimedWorker:
    """One spawned worker process that runs ``func(task)`` for one task at a time, with a wall-clock timeout.

    :meth:`call` returns ``("result", value, wall)``, ``("timeout", None, wall)`` (the worker was killed;
    the next call starts a fresh one) or ``("crash", exit_code, wall)`` (the worker died).  Use as a context
    manager, or call :meth:`close`.

    Parameters
    ----------
    func : callable
        Module-level (picklable) function called in the worker.
    start_timeout : float
        Seconds allowed for a worker to start (import, ``init``).
    init : callable, optional
        Module-level function called once when a worker starts (e.g. to load compiled kernels).
    name : str
        Named in the errors of a worker that cannot start.
    """

    def __init__(self, func: Callable[[Any], Any], start_timeout: float, init: Callable[[], Any] | None = None,
                 name: str = "worker"):
        self.func, self.start_timeout, self.init, self.name = func, start_timeout, init, name
        self._ctx = spawn_context()
        self._proc: Any = None
        self._conn: Any = None
        self.restarts = 0

    def _start(self) -> None:
        parent, child = self._ctx.Pipe()
        proc = self._ctx.Process(target=_timed_main, args=(child, self.func, self.init, os.getpid()), daemon=True)
        proc.start()
        child.close()
        if not parent.poll(self.start_timeout):
            proc.kill()
            proc.join()
            raise RuntimeError(f"{self.name} did not start within start_timeout={self.start_timeout} s")
        try:
            parent.recv()
        except EOFError:
            proc.join()
            raise RuntimeError(f"{self.name} died while starting (exit code {proc.exitcode})") from None
        self._proc, self._conn = proc, parent

    def _kill(self) -> None:
        if self._proc is not None:
            if self._proc.is_alive():
                self._proc.kill()
            self._proc.join()
            self._conn.close()
        self._proc = self._conn = None

    def call(self, task: Any, timeout: float) -> tuple[str, Any, float]:
        """Run ``func(task)`` in the worker (started if needed); see the class docstring for the result."""
        if self._proc is None or not self._proc.is_alive():
            if self._proc is not None:
                self._kill()
            self._start()
        t0 = time.perf_counter()
        try:
            self._conn.send(task)
            answered = self._conn.poll(timeout)
        except (BrokenPipeError, EOFError, OSError):
            answered = True  # recv below reports the crash
        if not answered:
            self._kill()
            self.restarts += 1
            return "timeout", None, time.perf_counter() - t0
        try:
            _, res = self._conn.recv()
        except (EOFError, OSError):
            self._proc.join()
            code = self._proc.exitcode
            self._kill()
            self.restarts += 1
            return "crash", code, time.perf_counter() - t0
        return "result", res, time.perf_counter() - t0

    def close(self) -> None:
        """Stop the worker (politely, then by kill)."""
        if self._proc is not None and self._proc.is_alive():
            try:
                self._conn.send(None)
            except (BrokenPipeError, OSError):
                pass
            self._proc.join(5.0)
        self._kill()

    def __enter__(self) -> TimedWorker:
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()


# --------------------------------------------------------------------------------------------- many tasks

def _local_pool(kind: str, max_workers: int | None, n_tasks: int) -> Executor:
    """A local pool of ``max_workers`` (default: the CPUs available) but at most ``n_tasks`` workers: threads
    (:data:`THREADS`), or spawned processes that exit when this process dies (:data:`PROCESSES`)."""
    n = max_workers or (len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1))
    n = max(1, min(n, n_tasks))
    if kind == THREADS:
        return ThreadPoolExecutor(max_workers=n, thread_name_prefix="peelapprox-task")
    return ProcessPoolExecutor(max_workers=n, mp_context=spawn_context(), initializer=watch_parent,
                               initargs=(os.getpid(),))


def run_tasks(fn: Callable[..., Any], tasks: Sequence[tuple[Hashable, Iterable[Any]]],
              on_result: Callable[[Any, Any], None], *, executor: None | str | Executor = None,
              max_workers: int | None = None, deadline: float | None = None) -> list[tuple[Any, str]]:
    """Run ``fn(*args)`` for every ``(key, args)`` of ``tasks``; ``on_result(key, value)`` as each one finishes.

    Parameters
    ----------
    fn : callable
        Module level, so any executor can ship it; it should not raise (catch into the value).
    tasks : sequence of (key, args)
    on_result : callable
        Called in this process, in completion order (task order when serial).
    executor : None, "threads", "processes", "serial" or concurrent.futures.Executor
        ``None`` or ``"threads"``: a local thread pool (:data:`THREADS`; ``max_workers`` threads, at most one
        per task; shut down at the end).  ``"processes"``: a local spawned process pool (:func:`watch_parent`
        in every worker).  ``"serial"``: in this process.  Any Executor: used as is and left running.
    max_workers : int, optional
        Size of the local pool.
    deadline : float, optional
        A ``time.time()`` after which no task is started: the tasks not begun are cancelled (returned as lost,
        :data:`DEADLINE_TEXT`); the running ones are waited for (bound them with the deadline themselves).

    Returns
    -------
    list of (key, error text)
        The tasks the executor lost (a worker died, a task was cancelled, the deadline passed before it began):
        not values, to run again.  An exception of ``on_result`` cancels the tasks not yet finished and
        propagates.
    """
    lost: list[tuple[Any, str]] = []
    if executor == SERIAL:
        for key, args in tasks:
            if deadline is not None and time.time() >= deadline:
                lost.append((key, DEADLINE_TEXT))
                continue
            on_result(key, fn(*args))
        return lost
    if not tasks:
        return lost
    own = executor is None or isinstance(executor, str)
    ex: Executor
    if executor is None or isinstance(executor, str):  # SERIAL is handled above
        ex = _local_pool(THREADS if executor is None else executor, max_workers, len(tasks))
    else:
        ex = executor
    futs: dict[Future, Any] = {}
    try:
        for key, args in tasks:
            futs[ex.submit(fn, *args)] = key
        pending, expired = set(futs), False
        while pending:
            timeout = None if deadline is None or expired else max(0.0, deadline - time.time())
            finished, pending = wait(pending, timeout=timeout, return_when=FIRST_COMPLETED)
            if deadline is not None and not expired and time.time() >= deadline:
                expired = True  # cancel the tasks not begun (a cancelled future is never "finished" by wait)
                cancelled = {fut for fut in pending if fut.cancel()}
                pending -= cancelled
                lost.extend((futs.pop(fut), DEADLINE_TEXT) for fut in cancelled)
            for fut in finished:
                key = futs.pop(fut)
                try:
                    value = fut.result()
                except Exception as exc:  # the executor lost the task (worker died, cancelled): not a result
                    lost.append((key, error_text(exc)))
                    continue
                on_result(key, value)
    finally:
        for fut in futs:
            fut.cancel()
        if own:
            ex.shutdown(wait=not futs, cancel_futures=True)
    return lost

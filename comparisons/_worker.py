"""Workers shared by the experiments that run many points: the stress suite and the (I, V) sweep.

The stress suite runs each point in a spawned process it can kill; the sweep on the pool of
:mod:`peelapprox.parallel` (processes on more than two CPUs, threads on two) or any executor.  Both turn
whatever a point raises into fields of its record instead of a crash of the whole run, and report progress on
stderr (rate-limited: ``peelapprox.io.ProgressLine``).

* :func:`watch_parent` — a worker exits when the process that started it dies (e.g. SIGKILL), instead of
  idling (or hanging in a point) as an orphan.
* :class:`TimedWorker` — one worker that runs tasks one at a time with a wall-clock timeout; a hung task is
  killed with its worker and a crashed worker is noticed, and either is restarted for the next task (the
  stress suite's :class:`~comparisons.stress.StressRunner`).
* :func:`run_tasks` — many tasks on :func:`peelapprox.parallel.map_points`: in this process, on a local thread
  or process pool (``"auto"`` by default), or on any executor (a dask cluster); tasks the executor loses (a
  worker died) are returned, not raised (the sweep's engine).
* :func:`message`, :func:`error_text` (:func:`peelapprox.parallel.error_text`) — an exception as record
  fields; :func:`write_line` — a progress line (the stress suite's; the sweep's is
  :class:`peelapprox.io.ProgressLine`).
"""

from __future__ import annotations

import multiprocessing as mp
import os
import sys
import threading
import time
from collections.abc import Callable, Hashable, Iterable, Sequence
from concurrent.futures import Executor
from typing import Any

from peelapprox.parallel import AUTO, DEADLINE_TEXT, PROCESSES, SERIAL, THREADS, error_text, map_points

__all__ = ["spawn_context", "watch_parent", "message", "error_text", "write_line", "TimedWorker", "run_tasks",
           "AUTO", "SERIAL", "THREADS", "PROCESSES", "DEADLINE_TEXT"]

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

def run_tasks(fn: Callable[..., Any], tasks: Sequence[tuple[Hashable, Iterable[Any]]],
              on_result: Callable[[Any, Any], None], *, executor: None | str | Executor = None,
              max_workers: int | None = None, deadline: float | None = None,
              cost: Sequence[float] | None = None) -> list[tuple[Any, str]]:
    """Run ``fn(*args)`` for every ``(key, args)`` of ``tasks``; ``on_result(key, value)`` as each one finishes:
    :func:`peelapprox.parallel.map_points` (``executor`` is its ``pool``: None is ``"auto"``, processes on more
    than two CPUs, threads on two).  Returns the tasks lost, ``(key, error text)``."""
    return map_points(fn, tasks, on_result, pool=AUTO if executor is None else executor, max_workers=max_workers,
                      deadline=deadline, cost=cost)

"""A first call without a compile wait: :func:`compile_kernels` compiles (or loads) every kernel a user's first
calls need into the private kernel cache, and records it (``peelapprox warmup``, ``peelapprox doctor``)."""

from __future__ import annotations

import gc
import json
import os
import subprocess
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from numba.core import event
from numba.core.registry import CPUDispatcher

from peelapprox.kernels import cache_status, cpu_name, record_warmup

from ._hybrid_driver import load_hybrid

__all__ = ["FIRST_CALLS", "WarmupReport", "compile_kernels"]

#: The first calls a warm-up runs, by name: ``simulate`` with the paper's law (the hybrid driver), the reduced
#: equations' attractor (the segment driver) and the exact attractor's observables, on the low-inertia scene.
FIRST_CALLS: tuple[str, ...] = ("simulate", "approximate_attractor", "attractor_observables")


@dataclass(frozen=True)
class WarmupReport:
    """What :func:`compile_kernels` did.

    Attributes
    ----------
    status : int
        0: every job ran; 1: a job failed (its ``error`` says how; the others still ran).
    message : str
        One line: what was compiled and loaded, where, for which CPU.
    cpu : str
        The CPU numba compiled for (``generic``: any machine of the architecture).
    cache : str or None
        The private kernel cache's root; None when there is none (nothing was cached).
    seconds : float
        Wall time of the warm-up [s].
    jobs : tuple of dict
        One row per job: ``name``, ``seconds``, ``compiled`` (numba compilations, callees included: 0 when every
        kernel was loaded), ``loaded`` (kernels loaded from the cache), ``error`` (None, or the exception's line).
    record : str or None
        The warm-up record written in the cache (``peelapprox doctor`` reads it).
    """

    status: int
    message: str
    cpu: str
    cache: str | None
    seconds: float
    jobs: tuple[dict[str, Any], ...] = field(default_factory=tuple)
    record: str | None = None

    def rows(self) -> list[dict[str, Any]]:
        """The jobs as rows (for CSV/JSON, or ``pandas.DataFrame(report.rows())``)."""
        return [dict(j) for j in self.jobs]


def _calls() -> dict[str, Callable[[float], Any]]:
    """Each first call, taking its wall budget [s]."""
    from peelapprox import PeelParams, approximate_attractor

    from ._simulate import simulate
    from .dynamics import attractor_observables

    p = PeelParams(V=1.0, I=1e-5)
    return {
        "simulate": lambda left: (load_hybrid(), simulate(p, 0.01, max_wall=left)),
        "approximate_attractor": lambda left: approximate_attractor(p, n_transient=2, n_returns=4, max_wall=left),
        "attractor_observables": lambda left: attractor_observables(p, t_transient=0.05, t_window=0.1, max_wall=left),
    }


def _loaded() -> int:
    """Cache hits of every numba dispatcher alive.  By ``type``, not ``isinstance``: gc's objects may include a
    weak proxy whose referent is gone, and ``isinstance`` on it raises ``ReferenceError``."""
    return sum(sum(d.stats.cache_hits.values()) for d in gc.get_objects() if issubclass(type(d), CPUDispatcher))


class _Count(event.Listener):
    def __init__(self) -> None:
        self.n = 0

    def on_start(self, e: Any) -> None:
        self.n += 1

    def on_end(self, e: Any) -> None:
        pass


_DONE: dict[tuple[str, tuple[str, ...]], WarmupReport] = {}
_clock = time.perf_counter  # the warm-up's clock (a test replaces it)


def compile_kernels(*, calls: tuple[str, ...] = FIRST_CALLS, cpu: str | None = None,
                    progress: Callable[[str], None] | None = None, max_wall: float = 600.0) -> WarmupReport:
    """Compile, or load from the private kernel cache, every kernel a user's first calls need (:data:`FIRST_CALLS`:
    ``simulate`` with the paper's law, ``approximate_attractor``, ``attractor_observables``), so that the first
    such call of a later process loads its kernels instead of compiling them (``docs/performance.md``, "Cold
    start"); then write the warm-up record that ``peelapprox doctor`` reads.  Memoised per process.

    A kernel already in the cache but stale (written by other sources, another numba or Python) or not private
    (another user's, writable by others) is compiled anew and replaces it, never loaded.

    Parameters
    ----------
    calls : tuple of str
        The first calls to warm, a subset of :data:`FIRST_CALLS` (default all; ``("simulate",)`` loads the hybrid
        driver only, as a benchmark or a worker process does before timing).  The warm-up record is written only
        for all of them, when none failed.
    cpu : str, optional
        The CPU to compile for, numba's ``NUMBA_CPU_NAME``: ``"generic"`` for a cache shared by several machines of
        one architecture (each process that should load it then runs with ``NUMBA_CPU_NAME=generic``); default
        this process's (the host's, unless ``NUMBA_CPU_NAME`` is set).  Another CPU than this process's is
        compiled in a child process.
    progress : callable, optional
        Called with one line per job.
    max_wall : float
        Wall-time budget of the whole warm-up [s] (a child process is stopped at it; in this process each job gets
        what is left as its ``max_wall``, and a job is not started once it is spent; a numba compilation under way
        is not interrupted, so one job may overrun it by its compile time).

    Returns
    -------
    WarmupReport
    """
    if (not isinstance(calls, tuple) or not calls or len(set(calls)) != len(calls)
            or not all(isinstance(c, str) and c in FIRST_CALLS for c in calls)):
        raise ValueError(f"calls must be a tuple of distinct names from {FIRST_CALLS}, got {calls!r}")
    if cpu is not None and (not isinstance(cpu, str) or not cpu.strip() or cpu != cpu.strip()):
        raise ValueError(f"cpu must be a CPU name of numba's (e.g. 'generic'), got {cpu!r}")
    if not (isinstance(max_wall, (int, float)) and 0 < max_wall <= 86400):
        raise ValueError(f"max_wall must be in (0, 86400] s, got {max_wall!r}")
    if cpu is not None and cpu != cpu_name():
        return _in_child(cpu, calls, max_wall, progress)
    key = (cpu_name(), calls)
    if key in _DONE:
        return _DONE[key]
    t0 = _clock()
    rows = []
    jobs = _calls()
    for name in calls:
        call = jobs[name]
        count, before, t = _Count(), _loaded(), _clock()
        error, left = None, max_wall - (_clock() - t0)
        try:
            if left <= 0:
                raise TimeoutError(f"not run: the warm-up's max_wall={max_wall:g} s was spent")
            with event.install_listener("numba:compile", count):
                call(left)
        except Exception as exc:  # reported in the row, the other jobs still run
            error = f"{type(exc).__name__}: {exc}".splitlines()[0][:300]
        row = dict(name=name, seconds=round(_clock() - t, 3), compiled=count.n,
                   loaded=_loaded() - before, error=error)
        rows.append(row)
        if progress is not None:
            progress(f"{name}: {row['seconds']:.1f} s, {count.n} compiled, {row['loaded']} loaded"
                     + (f" ({error})" if error else ""))
    record = record_warmup(rows) if set(calls) == set(FIRST_CALLS) and not any(r["error"] for r in rows) else None
    status = cache_status()
    report = _report(rows, key[0], status.get("kernel_root"), _clock() - t0, record)
    if report.status == 0:
        _DONE[key] = report
    return report


def _report(rows: list[dict[str, Any]], cpu: str, root: str | None, seconds: float, record: Any) -> WarmupReport:
    failed = [r["name"] for r in rows if r["error"]]
    compiled, loaded = sum(r["compiled"] for r in rows), sum(r["loaded"] for r in rows)
    where = f"cached in {root}" if root else "NOT cached (no private kernel cache: see peelapprox doctor)"
    msg = (f"{len(rows) - len(failed)} of {len(rows)} first calls warmed for CPU {cpu} in {seconds:.1f} s "
           f"({compiled} compiled, {loaded} loaded), {where}" + (f"; failed: {', '.join(failed)}" if failed else ""))
    return WarmupReport(status=1 if failed else 0, message=msg, cpu=cpu, cache=root, seconds=seconds,
                        jobs=tuple(rows), record=str(record) if record else None)


_CHILD = ("import json, exact; r = exact.compile_kernels(calls={calls!r}, max_wall={max_wall!r}); "
          "print(json.dumps(dict(jobs=r.rows(), cpu=r.cpu, cache=r.cache, record=r.record)))")


def _in_child(cpu: str, calls: tuple[str, ...], max_wall: float,
              progress: Callable[[str], None] | None) -> WarmupReport:
    """:func:`compile_kernels` for another CPU than this process's: a child process with ``NUMBA_CPU_NAME``."""
    env = dict(os.environ, NUMBA_CPU_NAME=cpu)
    env.pop("NUMBA_CPU_FEATURES", None)
    if progress is not None:
        progress(f"compiling for CPU {cpu} in a child process ...")
    t0 = time.perf_counter()
    try:
        r = subprocess.run([sys.executable, "-c", _CHILD.format(calls=calls, max_wall=float(max_wall))], env=env,
                           capture_output=True, text=True, timeout=max_wall)
    except subprocess.TimeoutExpired:
        return WarmupReport(status=1, message=f"the warm-up for CPU {cpu} took more than max_wall={max_wall:g} s",
                            cpu=cpu, cache=None, seconds=time.perf_counter() - t0)
    lines = r.stdout.strip().splitlines()
    if r.returncode != 0 or not lines:
        tail = (r.stderr.strip().splitlines() or ["no output"])[-1][:300]
        return WarmupReport(status=1, message=f"the warm-up for CPU {cpu} failed: {tail}", cpu=cpu, cache=None,
                            seconds=time.perf_counter() - t0)
    out = json.loads(lines[-1])
    report = _report(out["jobs"], out["cpu"], out["cache"], time.perf_counter() - t0, out["record"])
    if progress is not None:
        for j in report.jobs:
            progress(f"{j['name']}: {j['seconds']:.1f} s, {j['compiled']} compiled, {j['loaded']} loaded")
    return report

"""Runs of stress points that cannot hang the suite.

:class:`StressRunner` runs tasks in one spawned worker process with a
wall-clock timeout (killing and restarting the worker on a hang or a crash;
the process handling is :class:`comparisons._worker.TimedWorker`, shared with
the sweep's workers), turning a timeout or crash into a point's record;
:func:`run_points` runs a list of points through it, and
:func:`budget_edge_probes` checks that budgets equal to a run's needs do not
raise.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

from peelapprox.validate import positive

from .._worker import TimedWorker, write_line
from .points import StressPoint
from .run import _empty_record, _finish, is_bug, run_point

__all__ = ["StressRunner", "run_points", "budget_edge_probes"]


def _run_task(task: Any) -> dict:
    """Worker-side default: ``run_point(task)`` or ``run_point(*task)`` for ``(point, keep_jump_times)``."""
    if isinstance(task, tuple):
        return run_point(*task)
    return run_point(task)


def _warm() -> None:
    """Load the hybrid kernel in a starting worker, so the first task's wall time does not include it."""
    import exact

    exact.compile_kernels(calls=("simulate",))


class StressRunner:
    """One worker process that runs tasks with a wall-clock timeout (:class:`comparisons._worker.TimedWorker`).

    A task that does not answer within ``timeout`` seconds is recorded as
    ``outcome="timeout"``, the worker (this runner's own process, by its
    handle) is killed and a fresh one is started for the next task; a worker
    that dies is recorded as ``outcome="crash"``.  Use as a context manager.

    Parameters
    ----------
    timeout : float
        Seconds per task, > 0.
    func : callable, optional
        Module-level (picklable) function called in the worker as
        ``func(task)``; it should return a dict.  Default: :func:`run_point`
        on a :class:`StressPoint` task, ``run_point(point, keep_jump_times)``
        on a ``(point, keep_jump_times)`` task.
    start_timeout : float
        Seconds allowed for a worker to start (import, load the compiled
        kernels), > 0.
    warm : bool
        Load the hybrid kernel when the worker starts (default True), so the
        first task's wall time does not include it.
    """

    def __init__(self, timeout: float = 60.0, func: Callable[[Any], Any] | None = None, start_timeout: float = 300.0,
                 warm: bool = True):
        self.timeout = positive("timeout", timeout)
        self.start_timeout = positive("start_timeout", start_timeout)
        self.func = _run_task if func is None else func
        if not callable(self.func):
            raise ValueError(f"func must be a picklable module-level callable, got {func!r}")
        self.warm = bool(warm)
        self._worker = TimedWorker(self.func, self.start_timeout, init=_warm if self.warm else None,
                                   name="stress worker")

    @property
    def restarts(self) -> int:
        """Workers killed (timeout) or found dead (crash) so far."""
        return self._worker.restarts

    def run(self, task: Any, timeout: float | None = None) -> dict:
        """Run one task in the worker; returns its record (or a timeout/crash record).

        Parameters
        ----------
        task : StressPoint, (StressPoint, bool) or any picklable argument of ``func``
        timeout : float, optional
            Overrides the runner's timeout for this task (> 0).
        """
        tmo = self.timeout if timeout is None else positive("timeout", timeout)
        pt = task[0] if isinstance(task, tuple) and task and isinstance(task[0], StressPoint) else task
        task_is_point = isinstance(pt, StressPoint)
        base = _empty_record(pt) if task_is_point else {"task": repr(task)}
        kind, res, wall = self._worker.call(task, tmo)
        if kind != "result":
            if kind == "timeout":
                base.update(outcome="timeout", wall=wall, message=f"no answer within timeout={tmo} s; worker killed")
            else:
                base.update(outcome="crash", wall=wall, message=f"worker died (exit code {res})")
            return _finish(pt, base) if task_is_point else base
        if not isinstance(res, dict):
            res = {"outcome": "ok", "result": res}
        if "wall" not in res or not isinstance(res.get("wall"), float):
            res["wall"] = wall
        if task_is_point and res.get("outcome", "").startswith("unexpected:") and "V" not in res:
            base.update(res)
            res = _finish(pt, base)
        return res

    def close(self) -> None:
        """Stop the worker (politely, then by kill)."""
        self._worker.close()

    def __enter__(self) -> StressRunner:
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()


def _fmt_point(p: StressPoint) -> str:
    s = f"V={p.V:g} I={p.I:g} k={p.k:g} a0={p.alpha0:g}"
    if p.method != "hybrid":
        s += f" {p.method}"
    if p.geometry != "paper":
        s += f" geometry={p.geometry}"
    if p.group in ("tol", "long", "budget"):
        s += f" rtol={p.rtol:g} t_end={p.t_end:g}"
    return f"[{p.group}] {s}" + (f" ({p.label})" if p.label else "")


def run_points(points: Sequence[StressPoint], timeout: float = 60.0, progress: bool = True,
               runner: StressRunner | None = None, keep_jump_times: Callable[[StressPoint], bool] | None = None
               ) -> list[dict]:
    """Run points one after the other in a worker process, each with a timeout.

    Parameters
    ----------
    points : sequence of StressPoint
    timeout : float
        Wall-clock seconds per point (> 0); long runs get 10× this.
    progress : bool
        One line per point on stderr.
    runner : StressRunner, optional
        Reuse a runner (its own timeout is then overridden per point).
    keep_jump_times : callable, optional
        ``keep_jump_times(point)`` → keep the jump times (default: for the
        ``"tol"`` and ``"long"`` groups).

    Returns
    -------
    list of dict
        One record per point, in order (see :func:`run_point`).
    """
    timeout = positive("timeout", timeout)
    for p in points:
        if not isinstance(p, StressPoint):
            raise ValueError(f"points must contain StressPoint instances, got {type(p).__name__}")
    keep = keep_jump_times or (lambda p: p.group in ("tol", "long"))
    own = runner is None
    runner = runner or StressRunner(timeout=timeout)
    recs = []
    try:
        n = len(points)
        for i, p in enumerate(points, 1):
            tmo = timeout * (10 if p.group == "long" else 1)
            rec = runner.run((p, True) if keep(p) else p, timeout=tmo)
            recs.append(rec)
            if progress:
                flag = "" if not is_bug(rec) else "   <-- BUG"
                if p.expect and not rec["expect_met"]:
                    flag += f"   <-- expected {p.expect}"
                write_line(f"{i:4d}/{n} {_fmt_point(p)} -> {rec['outcome']} "
                           f"({rec['wall']:.3g} s, {rec['n_jumps']} jumps){flag}")
    finally:
        if own:
            runner.close()
    return recs


def budget_edge_probes(runner: StressRunner | None = None, timeout: float = 60.0) -> list[dict]:
    """Budgets set exactly to what a run needs must not raise.

    ``simulate``'s contract: *exceeding* a budget raises.  Runs V=4, I=1e-2,
    α0=0.3 to 0.1 s once, then again with ``max_jumps``, ``max_steps`` and
    ``max_points`` equal to the counts of that run (expected: ``ok``).

    Parameters
    ----------
    runner : StressRunner, optional
    timeout : float
        Seconds per run, > 0.

    Returns
    -------
    list of dict
        The reference record and the three edge records (``expect="ok"``).
    """
    timeout = positive("timeout", timeout)
    own = runner is None
    runner = runner or StressRunner(timeout=timeout)
    try:
        base = dict(V=4.0, I=1e-2, alpha0=0.3, t_end=0.1, group="budget")
        ref = runner.run(StressPoint(**base, label="edge reference"), timeout=timeout)
        out = [ref]
        if ref["outcome"] == "ok":
            for name, val in (("max_jumps", ref["n_jumps"]), ("max_steps", ref["n_steps"]),
                              ("max_points", ref["n_points"])):
                if val >= 1:
                    p = StressPoint(**base, **{name: val}, label=f"{name}=exact count {val}", expect="ok")
                    out.append(runner.run(p, timeout=timeout))
    finally:
        if own:
            runner.close()
    return out


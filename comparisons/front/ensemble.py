"""Ensembles of peel fronts on the sweep engine: seeds × pull speed V × dissipation γ × the tape/roller inertia
ratio r_m = m R²/I (docs/peel-front.md, "Ensembles").

:func:`front_ensemble` runs one :func:`comparisons.sweep.sweep` of the measure ``front``
(:mod:`comparisons.front.measure`) over the (I, V) grid of the inertia ratios for every (γ, seed), each into its
own subdirectory of ``out`` (``g<i>_s<seed>``: resumable, a killed ensemble loses only the points that were
running), all of them on **one** shared executor, so their points fill the pool together.  ``executor=`` is any
:class:`concurrent.futures.Executor`: a dask cluster's is ``Client(...).get_executor()``.  The result,
:class:`FrontEnsemble`, is every record with its ``gamma``, ``seed`` and ``r_m``, as rows (CSV/JSON through
:func:`peelapprox.io.write_rows`, a pandas DataFrame), and the burst energies pooled over the seeds of a cell.
"""

from __future__ import annotations

import os
import threading
from collections.abc import Callable, Mapping, Sequence
from concurrent.futures import Executor, ThreadPoolExecutor
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from peelapprox.io import ProgressLine, optional_import, write_rows
from peelapprox.parallel import SERIAL, resolve_kind, worker_pool
from peelapprox.validate import flag, integer, positive, reals

from ..sweep import sweep
from . import measure as _measure_module  # registers the measure "front"
from .measure import check_front_options

__all__ = ["front_ensemble", "FrontEnsemble", "ENSEMBLE_COLUMNS", "inertia_of_ratio"]

#: The leading columns of :meth:`FrontEnsemble.rows` (then the measure's keys, ``front_*``).
ENSEMBLE_COLUMNS = ("gamma", "seed", "r_m", "I", "V", "status")

_ = _measure_module


def inertia_of_ratio(r_m: float, tape_mass: float, R: float) -> float:
    """The roller inertia I = m R²/r_m [kg m²] of a tape/roller inertia ratio r_m (docs/peel-front.md)."""
    return tape_mass * R * R / r_m


@dataclass(frozen=True, eq=False)
class FrontEnsemble:
    """The records of :func:`front_ensemble`: ``records`` (one dict per run, the columns
    :data:`ENSEMBLE_COLUMNS` then the measure's ``front_*`` keys), the axes, ``out``, and the counters
    ``n_runs`` and ``cpu_s`` (the sum of the runs' CPU seconds)."""

    records: list[dict]
    inertia_ratios: np.ndarray
    V_values: np.ndarray
    gammas: np.ndarray
    seeds: tuple[int, ...]
    options: dict
    out: str
    n_runs: int = 0
    cpu_s: float = 0.0
    extra: dict = field(default_factory=dict)

    def rows(self, *, energies: bool = False) -> list[dict]:
        """The records as table rows (``energies=False`` leaves out the long ``front_burst_energies`` text)."""
        return [{k: v for k, v in r.items() if energies or k != "front_burst_energies"} for r in self.records]

    def write(self, path: str, *, energies: bool = False) -> str:
        """Write :meth:`rows` as CSV or JSON (by the extension; :func:`peelapprox.io.write_rows`)."""
        rows = self.rows(energies=energies)
        cols = list(dict.fromkeys(k for r in rows for k in r))
        write_rows(path, rows, fields=cols)
        return path

    def to_dataframe(self) -> Any:
        """The rows as a pandas DataFrame (needs pandas)."""
        pd = optional_import("pandas", "FrontEnsemble.to_dataframe")
        return pd.DataFrame(self.rows(energies=True))

    def select(self, **where: Any) -> list[dict]:
        """The records whose fields equal ``where`` (floats compared to 1e-12 relative)."""
        def same(a: Any, b: Any) -> bool:
            return abs(a - b) <= 1e-12 * max(abs(a), abs(b)) if isinstance(a, float) else a == b
        return [r for r in self.records if all(same(r.get(k), v) for k, v in where.items())]

    def burst_energies(self, **where: Any) -> np.ndarray:
        """The burst energies [J] of the selected runs (:meth:`select`) pooled, e.g. over the seeds of one
        (r_m, V, gamma) cell; runs that failed or had no bursts add none."""
        parts = [np.array(r["front_burst_energies"].split(), dtype=float) for r in self.select(**where)
                 if r.get("status") == "ok" and r.get("front_burst_energies")]
        return np.concatenate(parts) if parts else np.empty(0)


def _subdir(i: int, seed: int) -> str:
    return f"g{i}_s{seed}"


def front_ensemble(inertia_ratios: Sequence[float], V_values: Sequence[float], *, gammas: Sequence[float] = (0.1,),
                   seeds: Sequence[int] = (0,), out: str, tape_mass: float = 1e-3, R: float = 0.1,
                   options: Mapping[str, Any] | None = None, executor: None | str | Executor = None,
                   max_workers: int | None = None, progress: bool | Callable[[int, int, dict], None] = True,
                   max_wall: float | None = None, resume: bool = True, retry_failed: bool = False) -> FrontEnsemble:
    """Run the ``front`` measure over inertia ratios × V for every (γ, seed), on one executor, resumably.

    Parameters
    ----------
    inertia_ratios : sequence of float
        r_m = m R²/I (> 0, no repeats); each gives the sweep's I (:func:`inertia_of_ratio`).
    V_values : sequence of float
        Pull speeds [m/s].
    gammas, seeds : sequences
        The dissipations γ (``front_gamma``) and heterogeneity seeds (``front_seed``) of the ensemble.
    out : path
        A directory: one sweep per (γ, seed) in ``out/g<i>_s<seed>`` (:mod:`comparisons.sweep.store`).
    tape_mass, R : float
        The tape mass m [kg] and roller radius R [m] of every run (the sweep's options ``tape_mass``, ``R``).
    options : mapping, optional
        The ``front`` measure's options (:data:`comparisons.front.measure.FRONT_DEFAULTS`) and other sweep
        options (``k``, ``l``, ...); ``front_gamma``, ``front_seed``, ``tape_mass`` and ``R`` are set here.
    executor, max_workers : optional
        As for :func:`comparisons.sweep.sweep`; a local pool is made once and shared by all the sweeps; any
        Executor (a dask client's ``get_executor()``) is used as is.
    progress : bool or callable
        True: one line on stderr as runs finish (rate-limited); a callable gets ``(done, total, record)``.
    max_wall : float, optional
        Each sweep's wall-clock budget [s] (None: none); a spent budget raises from the sweep, and the same call
        again computes the rest.
    resume, retry_failed : bool
        Keep the finished points in ``out`` (a different ensemble there is a ValueError from the sweep); compute
        its failed points again.

    Returns
    -------
    FrontEnsemble
    """
    rm = reals("inertia_ratios", inertia_ratios, 0.0, 1e6, lo_open=True)
    V = reals("V_values", V_values, 0.0, 100.0, lo_open=True)
    gs = reals("gammas", gammas, 0.0, 1e6)
    sd = tuple(integer("seeds", s, 0, 2**32 - 1) for s in seeds)
    if not sd or len(set(sd)) != len(sd) or len(set(gs.tolist())) != gs.size or len(set(rm.tolist())) != rm.size:
        raise ValueError("inertia_ratios, gammas and seeds must be non-empty and hold no repeats")
    m, R = positive("tape_mass", tape_mass), positive("R", R)
    resume, retry_failed = flag("resume", resume), flag("retry_failed", retry_failed)
    opts = {**(options or {}), "tape_mass": m, "R": R}
    check_front_options(opts)
    I_of = {inertia_of_ratio(float(r), m, R): float(r) for r in rm}
    I_vals = sorted(I_of)
    total = len(I_vals) * V.size * gs.size * len(sd)
    report = _reporter(progress, total)
    os.makedirs(out, exist_ok=True)
    jobs = [(i, float(g), s) for i, g in enumerate(gs) for s in sd]

    def one(job: tuple[int, float, int], ex: Any) -> list[dict]:
        i, g, s = job
        res = sweep(I_vals, V, "front", out=os.path.join(out, _subdir(i, s)), executor=ex,
                    options={**opts, "front_gamma": g, "front_seed": s}, progress=report, max_wall=max_wall,
                    resume=resume, retry_failed=retry_failed, **({} if ex is not None else {"max_workers": 0}))
        return [{"gamma": g, "seed": s, "r_m": I_of[min(I_of, key=lambda x: abs(x - r["I"]))], **r}
                for r in res.records]

    kind = SERIAL if max_workers == 0 else (resolve_kind(executor) if isinstance(executor, (str, type(None)))
                                           else None)
    records: list[dict] = []
    if kind is None:  # the caller's executor
        records = _concurrent(jobs, one, executor)
    elif kind == SERIAL:
        for job in jobs:
            records += one(job, None)
    else:
        with worker_pool(kind, max_workers, n_tasks=total) as (ex, _, _):
            records = _concurrent(jobs, one, ex)
    key = {name: j for j, name in enumerate(ENSEMBLE_COLUMNS)}
    records = [{**{c: r.get(c) for c in key}, **{k: v for k, v in r.items() if k not in key}} for r in records]
    records.sort(key=lambda r: (r["gamma"], r["seed"], r["r_m"], r["V"]))
    cpu = float(sum(r.get("front_cpu_s") or 0.0 for r in records))
    return FrontEnsemble(records, rm, V, gs, sd, opts, str(out), n_runs=len(records), cpu_s=cpu)


def _concurrent(jobs: list, one: Callable, ex: Any) -> list[dict]:
    """Run the sweeps of ``jobs`` at once, from threads of this process, all submitting to ``ex``."""
    if len(jobs) == 1:
        return one(jobs[0], ex)
    with ThreadPoolExecutor(max_workers=len(jobs), thread_name_prefix="front-ensemble") as tp:
        futures = [tp.submit(one, job, ex) for job in jobs]
        return [rec for f in futures for rec in f.result()]


def _reporter(progress: Any, total: int) -> Callable[[int, int, dict], None] | None:
    """One progress counter for all the sweeps (they run in threads)."""
    if progress is False or progress is None:
        return None
    lock = threading.Lock()
    done = [0]
    line = ProgressLine("front ensemble", total) if progress is True else None

    def report(_d: int, _t: int, rec: dict) -> None:
        with lock:
            done[0] += 1
            if line is not None:
                line.update(done[0], f"I={rec['I']:.4g} V={rec['V']:.4g}",
                            failed=None if rec["status"] == "ok" else str(rec["status"])[:200])
            else:
                progress(done[0], total, rec)

    return report

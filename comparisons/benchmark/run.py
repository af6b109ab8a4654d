"""The whole benchmark in one process: work precision on every scene, the ε study, the speed targets and the
compilation costs (:func:`run_benchmark`, behind ``peelapprox benchmark``)."""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from exact import compile_kernels

from .eps import eps_study, fit_power_law, small_eps_check
from .peers import available_peers
from .report import BenchmarkReport
from .scenes import BENCH_SCENES
from .targets import compile_costs, speed_targets
from .work_precision import matched_ratios, work_precision

__all__ = ["run_benchmark"]


def run_benchmark(*, quick: bool = False, peers: Sequence[str] | None = None,
                  progress: Callable[[str], None] | None = None) -> BenchmarkReport:
    """Run the whole benchmark (module docstring).  ``quick`` thins the tolerance grids, uses 3 repeats,
    only ε = 1e-7 for the scipy sweep and a 20 s long run; it is meant to finish in well under 5 minutes.
    ``peers=None`` uses every installed peer (:func:`comparisons.benchmark.peers.available_peers`)."""
    import platform

    t_start = time.perf_counter()
    compile_kernels(calls=("simulate",))
    if peers is None:
        try:
            peers = available_peers()
        except ImportError:
            peers = ()
    peers = tuple(peers)
    kw: dict[str, Any]
    if quick:
        kw = dict(hybrid_rtols=(1e-4, 1e-6, 1e-8, 1e-10, 1e-12), eps_values=(1e-7,), reg_rtols=(1e-5, 1e-8),
                  repeats=3)
    else:
        kw = dict()
    rows, refs = [], []
    for sc in BENCH_SCENES:
        r, ref = work_precision(sc, peers=peers, progress=progress, **kw)
        rows += r
        refs.append(ref)
    eps_values = (1e-4, 1e-6, 1e-8, 1e-10, 1e-15) if quick else \
        (1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12, 1e-15)
    eps_rows = eps_study(BENCH_SCENES[0], eps_values, max_steps=60_000, progress=progress)
    small_eps = small_eps_check(BENCH_SCENES[0], peers=peers, progress=progress)
    eps_fit = {}
    for key in ("delay_ab", "delay_cd"):
        ok = [e for e in eps_rows if e.status == "ok" and 1e-12 <= e.eps <= 1e-5]
        try:
            eps_fit[key] = fit_power_law(np.array([e.eps for e in ok]), np.array([getattr(e, key) for e in ok]))
        except ValueError:
            pass
    targets = speed_targets(repeats=3 if quick else 5, long_run=20.0 if quick else 200.0, progress=progress)
    if progress:
        progress("compile costs (fresh processes, cold and cached)")
    compile_ = compile_costs()
    machine = (f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, "
               f"Python {platform.python_version()}")
    return BenchmarkReport(rows, refs, matched_ratios(rows), eps_rows, eps_fit, small_eps, targets, peers, quick,
                           time.perf_counter() - t_start, machine, compile_)

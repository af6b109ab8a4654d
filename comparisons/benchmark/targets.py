"""The exact solver's speed targets, measured: µs per step, the long run, the share of the time spent in field
evaluations, and the kernels' compilation cost in fresh processes."""

from __future__ import annotations

import math
import os
import sys
import time
from collections.abc import Callable

import numpy as np

from exact import hybrid_field, simulate
from peelapprox import PeelParams

from .scenes import BENCH_SCENES
from .timing import timed

__all__ = ["speed_targets", "compile_costs"]


def _rhs_cost_ns(n: int = 200_000) -> float:
    """Wall time of one hybrid field evaluation [ns], measured in a compiled loop."""
    from numba import njit

    rhs, p = hybrid_field(PeelParams(V=1.0, I=1e-5), 1e-9)

    @njit
    def loop(y, p, out, n):
        acc = 0.0
        for i in range(n):
            y[3] = -1.2 + 1e-9 * i  # u = ln v, v ~ 0.3 m/s
            rhs(y, p, out)
            acc += out[3]
        return acc

    y, out = np.array([0.0, 0.01, 10.0, -1.2]), np.empty(4)
    loop(y, p, out, 10)
    best = math.inf
    for _ in range(5):
        t0 = time.perf_counter()
        loop(y, p, out, n)
        best = min(best, time.perf_counter() - t0)
    return 1e9 * best / n


def speed_targets(*, repeats: int = 5, long_run: float = 200.0,
                  progress: Callable[[str], None] | None = None) -> list[dict]:
    """The exact model's speed targets, measured: per-step cost on each scene (rtol 1e-8, 1 s, or the
    long run), the long V=4 run, and the share of the time spent in field evaluations."""
    say = progress or (lambda msg: None)
    rhs_ns = _rhs_cost_ns()
    out = []
    for sc, t_end in ((BENCH_SCENES[0], 1.0), (BENCH_SCENES[1], 5.0), (BENCH_SCENES[2], long_run)):
        say(f"targets: {sc.name}, {t_end:g} s at rtol 1e-8")
        rep = 1 if t_end > 20 else repeats
        wall, tr = timed(lambda: simulate(sc.params, t_end, alpha0=sc.alpha0, rtol=1e-8, save="jumps"), rep)
        s = tr.stats
        out.append(dict(scene=sc.name, t_end=t_end, wall=wall, steps=s.n_steps, rejected=s.n_rejected, rhs=s.n_rhs,
                        jumps=s.n_jumps, us_per_step=1e6 * wall / s.n_steps, rhs_per_step=s.n_rhs / s.n_steps,
                        rhs_ns=rhs_ns, rhs_share=s.n_rhs * rhs_ns * 1e-9 / wall,
                        steps_per_jump=s.n_steps / max(s.n_jumps, 1)))
    return out


def compile_costs() -> tuple[float, float]:
    """Cold compilation (empty numba cache) and cached load of the hybrid kernels, each in a fresh process [s]."""
    import subprocess
    import tempfile

    code = ("import time; t=time.perf_counter(); import exact; exact.compile_kernels(calls=('simulate',)); "
            "print(time.perf_counter()-t)")
    with tempfile.TemporaryDirectory() as d:
        env = dict(os.environ, NUMBA_CACHE_DIR=d)
        cold = float(subprocess.check_output([sys.executable, "-c", code], env=env).decode().split()[-1])
        warm = float(subprocess.check_output([sys.executable, "-c", code], env=env).decode().split()[-1])
    return cold, warm

"""Cost of :func:`exact.attractor_set` against one :func:`exact.attractor_observables` call, on seeded random points.

    python -m comparisons.benchmark.attractor_sets [--points 12] [--seed 35] [--workers 2] [--json FILE] [--csv FILE]

Target: ``attractor_set`` at the median point at most 10 times one ``attractor_observables`` call, on 2
cores.  The points are drawn uniformly in V over [0.3, 4.8] m/s and log-uniformly in I over [2e-6, 8e-2] kg m^2
(``numpy.random.default_rng(seed)``), the paper's law at the default k and R.  At each point, in one process and one
after the other: ``attractor_observables(p)`` (its defaults: 30 s transient, 20 s window, rtol 1e-10; each point's
parameters are new, so its window cache does not help it), then ``attractor_set(p, workers=workers)`` with its
defaults (8 starts, multipliers and exponents).  The ratio of the two wall times is taken per point; the report
gives its median, and the ratio of the median times.  A breakdown of the exact run is recorded, and the point's
ratio taken all the same (the set's starts still run).  The kernels are compiled by an untimed call first.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from typing import Any

import numpy as np

import exact
from peelapprox import ModelBreakdown, PeelParams, SolverBudgetExceeded
from peelapprox.io import fmt_number

from ._rows import add_row_files, write_row_files

__all__ = ["points", "measure", "main"]


def points(n: int, seed: int) -> list[tuple[float, float]]:
    """``n`` seeded random (V, I): V uniform in [0.3, 4.8] m/s, I log-uniform in [2e-6, 8e-2] kg m^2."""
    rng = np.random.default_rng(seed)
    V = rng.uniform(0.3, 4.8, n)
    I = 10 ** rng.uniform(np.log10(2e-6), np.log10(8e-2), n)
    return [(float(f"{v:.4g}"), float(f"{i:.4g}")) for v, i in zip(V, I, strict=True)]


def measure(V: float, I: float, workers: int) -> dict[str, Any]:
    """One point's row: both wall times, their ratio, the set's status, attractors and counters."""
    p = PeelParams(V=V, I=I)
    t0 = time.perf_counter()
    try:
        obs = exact.attractor_observables(p)
        obs_status = obs.status + (f" {obs.period_label}" if obs.n_slips else "")
    except (ModelBreakdown, SolverBudgetExceeded) as exc:
        obs_status = type(exc).__name__
    t_obs = time.perf_counter() - t0
    t0 = time.perf_counter()
    s = exact.attractor_set(p, workers=workers)
    t_set = time.perf_counter() - t0
    return {"V": V, "I": I, "observables_s": t_obs, "attractor_set_s": t_set, "ratio": t_set / t_obs,
            "observables": obs_status, "set_status": s.status,
            "attractors": "; ".join(f"{a.label} {100 * a.share:.0f}%" for a in s.attractors),
            "transients": len(s.transients), "orbits": s.counters["orbits"], "lyapunov": s.counters["lyapunov"],
            "run_wall_s": s.counters["run_wall"]}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m comparisons.benchmark.attractor_sets", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--points", type=int, default=12, help="random points (12)")
    ap.add_argument("--seed", type=int, default=35, help="the points' seed (35)")
    ap.add_argument("--workers", type=int, default=2, help="attractor_set's threads (2)")
    add_row_files(ap)
    a = ap.parse_args(argv)
    if a.points < 1 or a.workers < 0:
        ap.error("--points must be >= 1 and --workers >= 0")
    exact.attractor_set(PeelParams(V=2.0, I=1e-3), t_transient=1.0, t_window=1.0, workers=a.workers)  # compile
    rows = []
    for k, (V, I) in enumerate(points(a.points, a.seed)):
        rows.append(measure(V, I, a.workers))
        r = rows[-1]
        print(f"[{k + 1}/{a.points}] V={V:g} I={I:g}: observables {fmt_number(r['observables_s'], 3)} s "
              f"({r['observables']}), set {fmt_number(r['attractor_set_s'], 3)} s, ratio {fmt_number(r['ratio'], 3)}"
              f" [{r['attractors']}]", file=sys.stderr, flush=True)
    ratios = [r["ratio"] for r in rows]
    med_obs = statistics.median(r["observables_s"] for r in rows)
    med_set = statistics.median(r["attractor_set_s"] for r in rows)
    print(f"points {len(rows)} (seed {a.seed}), workers {a.workers}: median ratio "
          f"{fmt_number(statistics.median(ratios), 3)}"
          f" (max {fmt_number(max(ratios), 3)}); median times: attractor_observables {fmt_number(med_obs, 3)} s, "
          f"attractor_set {fmt_number(med_set, 3)} s, their ratio {fmt_number(med_set / med_obs, 3)}")
    write_row_files(a, rows)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

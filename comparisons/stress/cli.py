"""The command line of the stress suite: :func:`main`.

    python -m comparisons.stress [--quick] [--out DIR] [--timeout S] [--t-end S] [--n-random N]

Runs every point of :func:`~comparisons.stress.points.all_points` and the
budget edge probes in a worker process, then writes ``stress.csv``,
``stress.json`` and ``robustness.md`` to ``--out``.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time
from collections.abc import Sequence

from .points import GRID_T_END, N_RANDOM, all_points
from .report import _count_table, pair_long_runs, robustness_markdown, write_records
from .run import is_bug
from .runner import StressRunner, budget_edge_probes, run_points

__all__ = ["main"]

#: How the suite is invoked (argparse's ``prog`` and the command shown at the top of the report).
PROG = "python -m comparisons.stress"


def _package_doc() -> str:
    """The package docstring, whose first line describes the suite."""
    import comparisons.stress

    return comparisons.stress.__doc__ or ""


def main(argv: Sequence[str] | None = None) -> int:
    """Command-line entry point; returns 0 if no run shows a bug, 1 otherwise."""
    ap = argparse.ArgumentParser(prog=PROG, description=_package_doc().splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="corner subset of the grid, shorter long run")
    ap.add_argument("--out", default="stress_out", help="output directory for stress.csv/.json/robustness.md")
    ap.add_argument("--timeout", type=float, default=60.0, help="wall-clock seconds per point (long runs: 10x)")
    ap.add_argument("--t-end", type=float, default=GRID_T_END, help="simulated horizon of grid and random points [s]")
    ap.add_argument("--n-random", type=int, default=N_RANDOM, help="size of the seeded random sample")
    ap.add_argument("--no-progress", action="store_true", help="no per-point lines on stderr")
    a = ap.parse_args(argv)
    if not (math.isfinite(a.timeout) and a.timeout > 0):
        ap.error(f"--timeout must be in (0, inf), got {a.timeout}")
    if not (math.isfinite(a.t_end) and a.t_end > 0):
        ap.error(f"--t-end must be in (0, inf), got {a.t_end}")
    if a.n_random < 0:
        ap.error(f"--n-random must be >= 0, got {a.n_random}")
    cmd = PROG + (" --quick" if a.quick else "") + f" --out {a.out}"
    if a.t_end != GRID_T_END:
        cmd += f" --t-end {a.t_end:g}"
    if a.n_random != N_RANDOM:
        cmd += f" --n-random {a.n_random}"
    t0 = time.perf_counter()
    with StressRunner(timeout=a.timeout) as runner:
        recs = run_points(all_points(a.quick, a.t_end, a.n_random), timeout=a.timeout, progress=not a.no_progress,
                          runner=runner)
        recs += budget_edge_probes(runner, timeout=a.timeout)
    pair_long_runs(recs)
    wall = time.perf_counter() - t0
    md = robustness_markdown(recs, command=cmd, wall_time=wall)
    write_records(recs, a.out)
    with open(os.path.join(a.out, "robustness.md"), "w") as fh:
        fh.write(md + "\n")
    sys.stdout.write("\n".join(_count_table(recs, "outcome (all runs)")) + "\n\n")
    g = [r for r in recs if r["group"] == "grid"]
    if g:
        sys.stdout.write("\n".join(_count_table(g, "outcome (grid)")) + "\n\n")
    nbug = sum(is_bug(r) for r in recs)
    sys.stdout.write(f"bugs (nan/timeout/crash/unexpected/non-monotone): {nbug}; "
                     f"unmet expectations: {sum(not r.get('expect_met', True) for r in recs)}; "
                     f"wall time {wall:.1f} s; wrote {a.out}/stress.csv, stress.json, robustness.md\n")
    return 1 if nbug else 0

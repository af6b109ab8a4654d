"""Cost of the main job, ``peelapprox compare``, cold and warm, with the breakdown per exact run and scene.

    python -m comparisons.benchmark.compare_cost [--repeats N] [--csv out.csv]

Targets (issue "comparison harness"): the whole ``peelapprox compare`` (all scenes, statistics and
Figs. 8-9) <= 60 s cold, compilation included, and <= 15 s warm on this 2-core machine.

Methodology: every measurement is a fresh process running exactly the README command
``peelapprox compare --out DIR`` (plus ``--format json`` so the per-step timings can be read back).
*Cold* points ``NUMBA_CACHE_DIR`` at an empty directory, so every compiled kernel is compiled;
*warm* reuses that directory (kernels load from numba's on-disk cache).  The process wall time
includes the interpreter, imports and matplotlib.  Warm is the minimum over ``--repeats`` runs; the
breakdown is the one of that fastest warm run, and of the single cold run.
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import subprocess
import sys
import tempfile
import time

__all__ = ["main"]


def _run(cache_dir: str, out_dir: str):
    env = dict(os.environ, NUMBA_CACHE_DIR=cache_dir)
    t0 = time.perf_counter()
    res = subprocess.run([sys.executable, "-m", "peelapprox.cli", "compare", "--format", "json", "--out", out_dir],
                         env=env, capture_output=True, text=True, check=True)
    wall = time.perf_counter() - t0
    return wall, json.loads(res.stdout)["timings"]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=3, help="warm runs (the minimum is reported)")
    ap.add_argument("--csv", help="also write the table to this CSV")
    args = ap.parse_args(argv)
    with tempfile.TemporaryDirectory() as cache, tempfile.TemporaryDirectory() as out:
        print("cold run (empty numba cache) ...", file=sys.stderr, flush=True)
        cold_wall, cold = _run(cache, out)
        warm_runs = []
        for i in range(args.repeats):
            print(f"warm run {i + 1}/{args.repeats} ...", file=sys.stderr, flush=True)
            warm_runs.append(_run(cache, out))
    warm_wall, warm = min(warm_runs, key=lambda w: w[0])
    rows = [dict(step="whole process (python -m peelapprox.cli compare --out DIR)", cold=cold_wall, warm=warm_wall,
                 target_cold=60.0, target_warm=15.0)]
    for k in cold:
        rows.append(dict(step=k, cold=cold[k], warm=warm.get(k), target_cold=None, target_warm=None))
    print(f"| step | cold [s] | warm [s] (min of {args.repeats}) |")
    print("|---|---|---|")
    for r in rows:
        print(f"| {r['step']} | {r['cold']:.2f} | {r['warm']:.2f} |")
    print(f"\ncold {cold_wall:.1f} s (target <= 60 s), warm {warm_wall:.1f} s (target <= 15 s); "
          f"cold/warm = {cold_wall / warm_wall:.1f}")
    if args.csv:
        with open(args.csv, "w", newline="") as fh:
            w = csv.DictWriter(fh, fieldnames=list(rows[0]))
            w.writeheader()
            w.writerows(rows)
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())

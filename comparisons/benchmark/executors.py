"""The sweep's local executors measured in one run: serial, a thread pool, a spawned process pool.

    python -m comparisons.benchmark.executors [--I 1e-6:1e-2:6:log] [--V 0.5:4.5:6] [--workers 2] [--measure period]

Each executor sweeps the same grid into its own temporary directory (kernels already compiled: one untimed
serial point first), and the records are compared with the serial ones (every field but wall times).  The
thread pool is the default because the compiled kernels release the GIL; the process pool pays a package import
per worker.  Measured on 2 cores, 6 x 6, ``period``: serial 10.4 s, 2 threads 5.3 s, 2 processes 6.4 s.
"""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
import time

from ..sweep import parse_grid, sweep

__all__ = ["main"]


def _records(res) -> list[str]:
    return sorted(json.dumps({k: v for k, v in r.items() if "wall" not in k}, sort_keys=True, default=str)
                  for r in res.records)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m comparisons.benchmark.executors", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--I", default="1e-6:1e-2:6:log", help="moments of inertia [kg m^2], start:stop:num[:log]")
    ap.add_argument("--V", default="0.5:4.5:6", help="pull speeds [m/s], start:stop:num")
    ap.add_argument("--workers", type=int, default=2, help="threads or processes of the pools (2)")
    ap.add_argument("--measure", default="period", help="the sweep's measures (period)")
    args = ap.parse_args(argv)
    I_values, V_values = parse_grid(args.I, name="--I"), parse_grid(args.V, name="--V")
    with tempfile.TemporaryDirectory() as tmp:
        sweep(I_values[:1], V_values[:1], args.measure, out=f"{tmp}/warm", max_workers=0, progress=False)
        rows, serial = [], None
        for label, kw in (("serial", {"max_workers": 0}),
                          (f"{args.workers} threads", {"executor": "threads", "max_workers": args.workers}),
                          (f"{args.workers} processes", {"executor": "processes", "max_workers": args.workers})):
            t0 = time.perf_counter()
            res = sweep(I_values, V_values, args.measure, out=f"{tmp}/{label.replace(' ', '_')}", progress=False,
                        **kw)
            wall = time.perf_counter() - t0
            recs = _records(res)
            serial = recs if serial is None else serial
            rows.append((label, wall, len(res.records), recs == serial))
    print(f"grid {args.I} x {args.V} ({len(I_values) * len(V_values)} points), measure {args.measure}")
    print("| executor | wall [s] | records | equal to serial |\n|---|---|---|---|")
    for label, wall, n, same in rows:
        print(f"| {label} | {wall:.1f} | {n} | {same} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""Grid throughput per worker count for every pool kind, measured in one run on the machine it runs on.

    python -m comparisons.benchmark.scaling [--grid atlas|sweep] [--I 1e-6:1e-1:4:log] [--V 0.2:5:4]
        [--workers 1,2] [--kinds threads,processes,dask] [--t-transient 30] [--window 10] [--repeat 3]
        [--out FILE.csv|.json]

The same grid runs on each pool (:mod:`peelapprox.parallel`: ``threads``, ``processes`` — loky's reusable process
pool — and a dask ``LocalCluster`` of single-threaded worker processes when dask.distributed is installed) with
each worker count, each into its own temporary directory: an atlas (``comparisons.atlas.atlas``, every measure
of every point) or a sweep of the ``period`` measure.  Before the timed runs, one untimed point in this
process compiles or loads the kernels, and each pool is started and warmed with one untimed point per worker
(its "warm-up" column: a reusable pool pays the start once per session); then, for each worker count, the kinds'
runs alternate (threads, processes, dask, threads, ...), so that a change of the machine's load during the
measurement falls on every kind alike.  Each row gives the wall
time (the best of ``--repeat`` runs, the least disturbed by other jobs, and their median), the throughput
(points/s, of the best run), the speed-up over the same kind's one worker and the efficiency
(throughput / (workers x one worker's throughput): the issue's target is at least 0.75), the throughput
relative to the thread pool with as many workers, the CPU time of this process and its workers during the best
run (``cores used`` = CPU time / wall time: on a machine shared with other jobs a pool of N workers may get far
fewer than N cores, which then, not the pool, bounds its speed-up; CPU s/point is the work per point, what a
pool's overhead would raise), and whether its records equal the first run's (bitwise:
every field of every record).  The load average before and after is printed with the table: on a shared
machine the figures are only as quiet as it was.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import statistics
import sys
import tempfile
import time
from collections.abc import Iterator, Sequence
from typing import Any

from peelapprox.io import fmt_number, write_rows
from peelapprox.parallel import cpu_count

from ..sweep import parse_grid, sweep

__all__ = ["KINDS", "main", "measure"]

#: The pool kinds measured: the two local pools and a dask LocalCluster.
KINDS = ("threads", "processes", "dask")


def _cpu_seconds() -> float:
    """CPU time [s] of this process (all its threads) and of its live child processes (a pool's workers), from
    ``/proc`` (NaN where there is none: not Linux).  A pool's work is then measured even when the machine's
    other jobs decide its wall time."""
    try:
        tick = os.sysconf("SC_CLK_TCK")
        pid = os.getpid()
        with open(f"/proc/{pid}/task/{pid}/children") as fh:
            pids = [pid, *(int(c) for c in fh.read().split())]
        total = 0.0
        for p in pids:
            try:
                with open(f"/proc/{p}/stat") as fh:
                    fields = fh.read().rsplit(")", 1)[1].split()
            except FileNotFoundError:  # a child that has just exited
                continue
            total += (int(fields[11]) + int(fields[12])) / tick  # utime, stime
        return total
    except (OSError, ValueError, AttributeError):
        return float("nan")


def _records(res: Any) -> list[str]:
    return sorted(json.dumps(r, sort_keys=True, default=str) for r in res.records)


def _run(grid: str, I_values, V_values, out: str, executor: Any, max_workers: int | None, opts: dict) -> Any:
    """One grid on ``executor``; the sweep's records."""
    if grid == "atlas":
        from ..atlas import atlas

        return atlas(I_values, V_values, out=out, executor=executor, max_workers=max_workers, progress=False,
                     options={"t_transient": opts["t_transient"], "t_window": opts["window"]}).sweep
    return sweep(I_values, V_values, "period", out=out, executor=executor, max_workers=max_workers,
                 progress=False, options={"t_transient": opts["t_transient"], "window": opts["window"]})


@contextlib.contextmanager
def _pool(kind: str, n: int) -> Iterator[tuple[Any, int | None]]:
    """``(executor, max_workers)`` of ``kind`` with ``n`` workers (a dask cluster started and closed here)."""
    if kind != "dask":
        yield kind, n
        return
    from distributed import Client, LocalCluster

    with LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            Client(cluster) as client:
        yield client.get_executor(), None


def measure(grid: str, I_values: Sequence[float], V_values: Sequence[float], workers: Sequence[int],
            kinds: Sequence[str], *, t_transient: float = 30.0, window: float = 10.0, repeat: int = 3,
            progress: bool = True) -> list[dict]:
    """The rows of the table (module docstring): one per (kind, workers), kinds first; ``wall_s`` the best of
    ``repeat`` runs (the least disturbed by other jobs), ``wall_median_s`` their median.  For each worker count
    the kinds' runs alternate (threads, processes, dask, threads, ...), so that a change of the machine's load
    during the measurement falls on every kind alike."""
    opts = {"t_transient": t_transient, "window": window}
    n_points = len(I_values) * len(V_values)
    first: list[str] | None = None
    got: dict[tuple[str, int], dict] = {}
    with tempfile.TemporaryDirectory() as tmp, contextlib.ExitStack() as stack:
        _run(grid, I_values[:1], V_values[:1], f"{tmp}/warm", "serial", None, opts)
        for n in workers:
            pools: dict[str, tuple[Any, int | None]] = {}
            for kind in kinds:  # started and warmed, untimed: one point per worker
                t0 = time.perf_counter()
                pools[kind] = stack.enter_context(_pool(kind, n))
                _run(grid, I_values[:1], V_values[:max(1, min(n, len(V_values)))], f"{tmp}/w_{kind}_{n}",
                     *pools[kind], opts)
                got[kind, n] = {"warmup_s": time.perf_counter() - t0, "walls": [], "cpus": [], "same": True}
            for r in range(repeat):
                for kind in kinds:
                    g = got[kind, n]
                    c0, t0 = _cpu_seconds(), time.perf_counter()
                    res = _run(grid, I_values, V_values, f"{tmp}/{kind}_{n}_{r}", *pools[kind], opts)
                    g["walls"].append(time.perf_counter() - t0)
                    g["cpus"].append(_cpu_seconds() - c0)
                    recs = _records(res)
                    first = recs if first is None else first
                    g["same"] = g["same"] and recs == first
                    if progress:
                        print(f"{kind} x{n} run {r + 1}: {g['walls'][-1]:.2f} s", file=sys.stderr, flush=True)
            stack.close()  # a dask cluster per worker count, closed once measured
    return _rows(got, kinds, workers, n_points, repeat)


def _rows(got: dict, kinds: Sequence[str], workers: Sequence[int], n_points: int, repeat: int) -> list[dict]:
    rows = []
    for kind in kinds:
        for n in workers:
            g = got[kind, n]
            best = min(range(repeat), key=g["walls"].__getitem__)
            wall, cpu = g["walls"][best], g["cpus"][best]
            rate = n_points / wall
            base = n_points / min(got[kind, workers[0]]["walls"])  # the smallest worker count's throughput
            threads = n_points / min(got["threads", n]["walls"]) if "threads" in kinds else None
            rows.append({"kind": kind, "workers": n, "points": n_points, "warmup_s": g["warmup_s"], "wall_s": wall,
                         "wall_median_s": statistics.median(g["walls"]), "repeats": repeat, "points_per_s": rate,
                         "speedup": rate / base, "efficiency": rate / (base * n / workers[0]),
                         "vs_threads": None if threads is None else rate / threads,
                         "cpu_s": cpu, "cores_used": cpu / wall, "cpu_s_per_point": cpu / n_points,
                         "records_equal": g["same"]})
    return rows


def _markdown(rows: list[dict]) -> str:
    head = ("| pool | workers | warm-up [s] | best wall [s] | median wall [s] | points/s | speed-up | efficiency | "
            "vs threads | cores used | CPU s/point | records equal |\n" + "|---" * 12 + "|")
    body = [f"| {r['kind']} | {r['workers']} | {fmt_number(r['warmup_s'], 3)} | {fmt_number(r['wall_s'], 3)} | "
            f"{fmt_number(r['wall_median_s'], 3)} | "
            f"{fmt_number(r['points_per_s'], 3)} | {fmt_number(r['speedup'], 3)} | {fmt_number(r['efficiency'], 3)} "
            f"| {fmt_number(r['vs_threads'], 3, missing='')} | {fmt_number(r['cores_used'], 3)} | "
            f"{fmt_number(r['cpu_s_per_point'], 3)} | {r['records_equal']} |" for r in rows]
    return "\n".join([head, *body])


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m comparisons.benchmark.scaling", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--grid", choices=("atlas", "sweep"), default="atlas",
                    help="an atlas (every measure) or a sweep of the period measure (atlas)")
    ap.add_argument("--I", default="1e-6:1e-1:4:log", help="moments of inertia [kg m^2], start:stop:num[:log]")
    ap.add_argument("--V", default="0.2:5:4", help="pull speeds [m/s], start:stop:num")
    ap.add_argument("--workers", default=None,
                    help="comma-separated worker counts (default: 1, 2, 4, ... up to the CPUs)")
    ap.add_argument("--kinds", default=",".join(KINDS),
                    help="comma-separated pool kinds among threads, processes, dask (dask skipped if not installed)")
    ap.add_argument("--t-transient", type=float, default=30.0, help="transient of each exact run [s] (30)")
    ap.add_argument("--window", type=float, default=10.0, help="measured window of each exact run [s] (10)")
    ap.add_argument("--repeat", type=int, default=3, help="timed runs per pool and worker count; the best counts (3)")
    ap.add_argument("--out", default=None, help="also write the rows to FILE.csv or FILE.json")
    args = ap.parse_args(argv)
    I_values, V_values = parse_grid(args.I, name="--I"), parse_grid(args.V, name="--V")
    cpus = cpu_count()
    if args.workers:
        workers = sorted({int(w) for w in args.workers.split(",")})
        if workers[0] < 1:
            ap.error("--workers: counts must be >= 1")
    else:
        workers = sorted({1, *(2 ** k for k in range(1, cpus.bit_length())), cpus})
    kinds = [k.strip() for k in args.kinds.split(",") if k.strip()]
    bad = [k for k in kinds if k not in KINDS]
    if bad:
        ap.error(f"--kinds: {bad} not among {KINDS}")
    if "dask" in kinds:
        try:
            import distributed  # noqa: F401
        except ImportError:
            print("dask.distributed is not installed: dask skipped (pip install 'peelapprox[distributed]')",
                  file=sys.stderr)
            kinds.remove("dask")
    load0 = os.getloadavg()
    if args.repeat < 1:
        ap.error("--repeat must be >= 1")
    rows = measure(args.grid, I_values, V_values, workers, kinds, t_transient=args.t_transient, window=args.window,
                   repeat=args.repeat)
    load1 = os.getloadavg()
    print(f"{args.grid} {args.I} x {args.V} ({len(I_values) * len(V_values)} points), t_transient "
          f"{args.t_transient:g} s + window {args.window:g} s; {cpus} CPUs; load average (1, 5, 15 min) before "
          f"{load0[0]:.2f} {load0[1]:.2f} {load0[2]:.2f}, after {load1[0]:.2f} {load1[1]:.2f} {load1[2]:.2f}")
    print(_markdown(rows))
    if args.out:
        print(f"wrote {write_rows(args.out, rows)}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())

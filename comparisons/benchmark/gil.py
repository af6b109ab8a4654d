"""What holds the GIL in an atlas point: the share of its CPU time a thread pool cannot overlap.

    python -m comparisons.benchmark.gil [--I 1e-6:1e-1:4:log] [--V 0.2:5:4] [--t-transient 30] [--window 10]

Every compiled kernel is compiled with ``nogil=True`` (``peelapprox/_compiled/_jit.py``), so a thread running one does
not
hold the GIL; whatever else a point does (the Python around the kernels, numpy and scipy calls, the store's
write) does.  This runs an atlas (:func:`comparisons.atlas.atlas`, every measure) serially in this thread after
one untimed point (kernels loaded), and measures with the thread's CPU time (``time.thread_time``: the CPU this
thread got, which other jobs' load on a shared machine does not enter, where wall time would):

* ``cpu`` -- the thread's CPU time over the grid;
* ``kernels`` -- the CPU time inside calls of numba dispatchers from Python (numba's ``Dispatcher.__call__``
  wrapped while it runs);
* ``unboxing`` -- the Python that numba runs, under the GIL, inside those calls: a first-class function argument
  (a peel-force law, ``peelapprox.law``'s ABI) is unboxed by calling ``_get_wrapper_address`` and
  ``_get_jit_address`` of ``numba/experimental/function_type.py`` and unpickling its signature
  (``_numba_unpickle`` of ``numba/core/serialize.py``) on every call;
* ``held = cpu - kernels + unboxing``, its ``share = held / cpu`` and the thread ceiling ``1 / share``
  (Amdahl: the most cores a thread pool can keep busy).

numpy and scipy calls count as held (numpy releases the GIL in large array loops only), and so does numba's
C-level dispatch (argument typing and unboxing of arrays; a no-op kernel with the segment driver's arguments
measured ~5 us a call): ``share`` is then a bound from below by about that much per call.  The same split is
given per measure (``atlas_exact``, ``atlas_segments``, ``atlas_approx``) and for the rest (the sweep engine, the
store's write).
"""

from __future__ import annotations

import argparse
import contextlib
import tempfile
import time
from collections.abc import Iterator
from typing import Any

__all__ = ["measure", "main"]

_tt = time.thread_time


@contextlib.contextmanager
def _instrumented() -> Iterator[dict[str, float]]:
    """Wrap numba's dispatcher call and its first-class-function unboxing helpers with thread-CPU timers; undone
    on exit."""
    import numba._dispatcher as nd
    import numba.core.serialize as ser
    import numba.experimental.function_type as ft
    from numba.core import dispatcher as dm

    unboxing = ((ft, "_get_wrapper_address"), (ft, "_get_jit_address"), (ser, "_numba_unpickle"))
    acc = {"kernels": 0.0, "calls": 0.0, "unboxing": 0.0, "depth": 0.0}
    base = nd.Dispatcher.__call__

    def call(self: Any, *args: Any, **kws: Any) -> Any:
        if acc["depth"]:
            return base(self, *args, **kws)
        acc["depth"] = 1.0
        t0 = _tt()
        try:
            return base(self, *args, **kws)
        finally:
            acc["kernels"] += _tt() - t0
            acc["calls"] += 1
            acc["depth"] = 0.0

    def timed(fn: Any) -> Any:
        def inner(*args: Any) -> Any:
            if not acc["depth"]:  # not inside a kernel call: not subtracted from one
                return fn(*args)
            t0 = _tt()
            try:
                return fn(*args)
            finally:
                acc["unboxing"] += _tt() - t0
        return inner

    had_call = "__call__" in vars(dm.Dispatcher)
    saved = [(mod, name, getattr(mod, name)) for mod, name in unboxing]
    dm.Dispatcher.__call__ = call  # type: ignore[method-assign, assignment]
    for mod, name, fn in saved:
        setattr(mod, name, timed(fn))
    try:
        yield acc
    finally:
        if had_call:  # pragma: no cover - numba's class defines none
            dm.Dispatcher.__call__ = base  # type: ignore[method-assign]
        else:
            del dm.Dispatcher.__call__
        for mod, name, fn in saved:
            setattr(mod, name, fn)


def _split(cpu: float, acc: dict[str, float], n: int) -> dict[str, float]:
    held = cpu - acc["kernels"] + acc["unboxing"]
    return {"cpu_ms": 1e3 * cpu / n, "kernels_ms": 1e3 * acc["kernels"] / n, "unboxing_ms": 1e3 * acc["unboxing"] / n,
            "held_ms": 1e3 * held / n, "share": held / cpu if cpu > 0 else float("nan")}


def measure(I_values: Any, V_values: Any, *, t_transient: float = 30.0, window: float = 10.0) -> dict[str, Any]:
    """The GIL-held split of one serial atlas over the grid (module docstring), per point.

    Returns
    -------
    dict
        ``points``, ``calls`` (dispatcher calls per point), ``total`` and one entry per measure and ``rest``:
        each ``{"cpu_ms", "kernels_ms", "unboxing_ms", "held_ms", "share"}`` (ms per point; ``share`` of that
        part's own CPU), and ``ceiling`` = 1 / the total share.
    """
    from ..atlas import atlas
    from ..atlas.measures import MEASURE_NAMES
    from ..sweep.measures import MEASURES

    opts = {"t_transient": t_transient, "t_window": window}
    with tempfile.TemporaryDirectory() as d:  # kernels compiled or loaded, outside the measurement
        atlas([1e-4], [1.0], out=f"{d}/warm", executor="serial", progress=False, options=opts)
    parts: dict[str, list[float]] = {}
    saved = {name: MEASURES[name] for name in MEASURE_NAMES}
    with _instrumented() as acc, tempfile.TemporaryDirectory() as d:
        def timed(name: str, fn: Any) -> Any:
            def run(params: Any, options: Any) -> Any:
                c0, k0, u0 = _tt(), acc["kernels"], acc["unboxing"]
                try:
                    return fn(params, options)
                finally:
                    p = parts.setdefault(name, [0.0, 0.0, 0.0])
                    p[0] += _tt() - c0
                    p[1] += acc["kernels"] - k0
                    p[2] += acc["unboxing"] - u0
            return run

        MEASURES.update({name: timed(name, fn) for name, fn in saved.items()})
        try:
            c0 = _tt()
            atlas(I_values, V_values, out=f"{d}/atlas", executor="serial", progress=False, options=opts,
                  max_wall=None)
            cpu = _tt() - c0
        finally:
            MEASURES.update(saved)
    n = len(I_values) * len(V_values)
    out: dict[str, Any] = {"points": n, "calls": acc["calls"] / n, "total": _split(cpu, acc, n)}
    rest = [cpu, acc["kernels"], acc["unboxing"]]
    for name, (c, k, u) in parts.items():
        out[name] = _split(c, {"kernels": k, "unboxing": u}, n)
        rest = [rest[0] - c, rest[1] - k, rest[2] - u]
    out["rest"] = _split(rest[0], {"kernels": rest[1], "unboxing": rest[2]}, n)
    out["ceiling"] = 1.0 / out["total"]["share"]
    return out


def main(argv: list[str] | None = None) -> int:
    """The command line (module docstring): prints the split as a markdown table."""
    import os
    import warnings

    from ..sweep import parse_grid

    ap = argparse.ArgumentParser(prog="python -m comparisons.benchmark.gil", description=__doc__.split("\n")[0])
    ap.add_argument("--I", default="1e-6:1e-1:4:log", help="inertias, as the sweep's --I (1e-6:1e-1:4:log)")
    ap.add_argument("--V", default="0.2:5:4", help="pull speeds, as the sweep's --V (0.2:5:4)")
    ap.add_argument("--t-transient", type=float, default=30.0, help="transient of each exact run [s] (30)")
    ap.add_argument("--window", type=float, default=10.0, help="measured window of each exact run [s] (10)")
    args = ap.parse_args(argv)
    load0 = os.getloadavg()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the approximations' low-confidence warnings
        res = measure(parse_grid(args.I, name="--I"), parse_grid(args.V, name="--V"), t_transient=args.t_transient,
                      window=args.window)
    print(f"{res['points']} points, {res['calls']:.0f} kernel calls a point; load average {load0[0]:.1f} before, "
          f"{os.getloadavg()[0]:.1f} after")
    print("| part | CPU [ms/point] | in kernels | numba's unboxing | GIL held | share |\n|---|---|---|---|---|---|")
    for name in ("atlas_exact", "atlas_segments", "atlas_approx", "rest", "total"):
        r = res[name]
        print(f"| {name} | {r['cpu_ms']:.1f} | {r['kernels_ms']:.1f} | {r['unboxing_ms']:.1f} | {r['held_ms']:.1f} | "
              f"{r['share']:.3f} |")
    print(f"thread ceiling (1 / share): {res['ceiling']:.2f} cores")
    return 0


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())

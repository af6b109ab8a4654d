"""Cost of the peel-force law as a function argument of the hybrid driver (a law other than the inlined fvV).

    python -m comparisons.benchmark.law_cost [--before PATH] [--rounds N] [--json FILE]

One run prints a table of:

* **field**: ns per evaluation of the hybrid field with the paper's law inlined (``hybrid_field``, the pattern
  every driver uses by default) and through the law argument (``law(u, coef, LAW_LNV)``, an indirect call) for
  each kind of law, all of them fvV or a sample of it at V = 1 m/s (:data:`LAWS_OF_FVV`), and the cubic
  (compiled loops, the best of 5; the law loop is compiled for the law's function type, as the driver is, so
  the call is not specialised away);
* **per step**: µs per accepted step of ``exact.simulate`` (rtol 1e-8, save="jumps", the best of the rounds)
  on the benchmark scenes, with the paper's law inlined (the default), and with fvV given as each other kind
  of law -- the paper family (its 14 numbers as data), the expression typed as text, a table of 600 points
  sampled from it (PCHIP in ln v), the same points smoothed (``PeelForce.smoothed``) -- which follow the same
  orbits (to rounding, or to the table's
  interpolation error), so the ratios are the cost of the law alone; each in its own process, alternating, so
  all see the same machine load; optionally for the tree at ``--before`` too;
* **second law**: the wall time of the first ``simulate`` with a second cubic (other coefficients) in a
  process that has already run a first one, with the number of numba compilations during it (numba's event
  recorder);
* **driver load**: ``import exact; exact.compile_kernels()`` in a new process, from a warm cache and from an
  empty one (``NUMBA_CACHE_DIR``), for both trees.

An expression law's own compile and cached-load times are ``python -m comparisons.benchmark.expression_cost``'s.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from exact import hybrid_field
from peelapprox import PeelForce, PeelParams, peel_force
from peelapprox.io import fmt_number
from peelapprox.kernels import LAW_TYPE, LAWS, compiled_law, paper_coefficients

from .expression_cost import FVV_TEXT
from .scenes import BENCH_SCENES

__all__ = ["CUBIC_COEF", "CUBIC_COEF_2", "LAWS_OF_FVV", "field_costs", "fvv_as", "main"]

_ROOT = Path(__file__).resolve().parents[2]
#: f = 150 + 300 v - 300 v^2 + 80 v^3 [N] (folds at 0.691 and 1.809 m/s; tests/test_law_abi.py).
CUBIC_COEF = (150.0, 300.0, 300.0, 80.0)
#: A second cubic of the same family (other coefficients: data, not code).
CUBIC_COEF_2 = (100.0, 250.0, 280.0, 90.0)
#: (name, t_end) of the per-step scenes: the benchmark's three, as in targets.py (1 s, 5 s, 20 s).
_T_END = {"V1-I1e-5": 1.0, "V1-I1e-2": 5.0, "V4-I1e-2": 20.0}


def _cubic_params(I: float) -> PeelParams:
    return PeelParams(V=1.2, I=I, force=PeelForce.cubic(*CUBIC_COEF))


#: fvV as every kind of law, by name: the law each per-step and field figure is measured with (module docstring).
LAWS_OF_FVV = ("paper_family", "expression", "tabulated", "smoothed")


def fvv_as(kind: str, V: float) -> PeelForce:
    """fvV as a law of ``kind`` (:data:`LAWS_OF_FVV`; a table: 600 points log-spaced over 1e-8-100 m/s at V; smoothed:
    the same points through ``PeelForce.smoothed``, a C⁴ spline in ln v, its penalty by GCV)."""
    if kind == "paper_family":
        return PeelForce.paper_family()
    if kind == "expression":
        return PeelForce.expression(FVV_TEXT)
    v = np.logspace(-8.0, 2.0, 600)
    if kind == "smoothed":
        return PeelForce.smoothed(v, peel_force(v, V))
    return PeelForce.tabulated(v, peel_force(v, V))


def field_costs(n: int = 200_000) -> dict[str, float]:
    """ns per hybrid field evaluation: the paper's law inlined, and through the law argument (fvV as each kind
    of law, the cubic)."""
    from numba import njit, types

    rhs, p = hybrid_field(PeelParams(V=1.0, I=1e-5), 1e-9)
    rhs_law, _ = hybrid_field(PeelParams(V=1.0, I=1e-5), 1e-9, law_argument=True)

    @njit
    def loop_inline(y, p, out, n):
        acc = 0.0
        for i in range(n):
            y[3] = -1.2 + 1e-9 * i
            rhs(y, p, out)
            acc += out[3]
        return acc

    a1 = types.float64[::1]

    @njit(types.float64(a1, a1, LAW_TYPE, a1, a1, types.int64))
    def loop_law(y, p, law, coef, out, n):
        acc = 0.0
        P = (p, law, coef)
        for i in range(n):
            y[3] = -1.2 + 1e-9 * i
            rhs_law(y, P, out)
            acc += out[3]
        return acc

    def best(fn) -> float:
        fn(10)
        t = math.inf
        for _ in range(5):
            t0 = time.perf_counter()
            fn(n)
            t = min(t, time.perf_counter() - t0)
        return 1e9 * t / n

    y, out = np.array([0.0, 0.01, 10.0, -1.2]), np.empty(4)
    laws = {"paper": (LAWS["paper"], paper_coefficients(1.0))}
    for kind in (*LAWS_OF_FVV, "cubic"):
        cl = compiled_law(PeelForce.cubic(*CUBIC_COEF) if kind == "cubic" else fvv_as(kind, 1.0), 1.0)
        laws[kind] = (cl.fn, cl.coef)
    res: dict[str, float] = {}
    for _ in range(2):  # alternate, keep the best
        res["inline"] = min(res.get("inline", math.inf), best(lambda k: loop_inline(y, p, out, k)))
        for key, (law, coef) in laws.items():
            res[key] = min(res.get(key, math.inf),
                           best(lambda k, law=law, coef=coef: loop_law(y, p, law, coef, out, k)))
    return res


_STEP_CODE = r"""
import json, time, sys
import exact
from peelapprox import PeelParams
scenes, kind = json.loads(sys.argv[1]), sys.argv[2]
if kind == "default":
    make = lambda V, I: PeelParams(V=V, I=I)
else:
    from comparisons.benchmark.law_cost import fvv_as
    make = lambda V, I: PeelParams(V=V, I=I, force=fvv_as(kind, V))
out = {}
for name, V, I, alpha0, t_end in scenes:
    p = make(V, I)
    exact.simulate(p, min(t_end, 0.2), alpha0=alpha0, rtol=1e-8, save="jumps")
    best = 1e9
    for _ in range(3 if t_end < 10 else 1):
        t0 = time.perf_counter()
        tr = exact.simulate(p, t_end, alpha0=alpha0, rtol=1e-8, save="jumps")
        best = min(best, time.perf_counter() - t0)
    out[name] = 1e6 * best / tr.stats.n_steps
print(json.dumps(out))
"""


def _per_step(tree: Path, kind: str = "default") -> dict[str, float]:
    """µs per step on the benchmark scenes with fvV as the law ``kind`` ("default": the paper's law inlined, or
    one of :data:`LAWS_OF_FVV`), measured in a new process running the package of ``tree``."""
    scenes = [(s.name, s.V, s.I, s.alpha0, _T_END[s.name]) for s in BENCH_SCENES]
    env = dict(os.environ, PYTHONPATH=str(tree))
    r = subprocess.run([sys.executable, "-c", _STEP_CODE, json.dumps(scenes), kind], env=env, capture_output=True,
                       text=True, check=True, cwd=tempfile.gettempdir())
    return json.loads(r.stdout.strip().splitlines()[-1])


_SECOND_CODE = r"""
import json, time
from numba.core import event
import exact
from peelapprox import PeelForce, PeelParams, peel_force
from comparisons.benchmark.law_cost import CUBIC_COEF_2, _cubic_params
p = _cubic_params(1e-5)
t0 = time.perf_counter()
exact.simulate(p, 0.05, save="jumps")   # warm: a first law run loads the law driver from the cache
t_first_law = time.perf_counter() - t0
t0 = time.perf_counter()
exact.simulate(p, 0.05, save="jumps")
t_paper = time.perf_counter() - t0
with event.install_recorder("numba:compile") as rec:
    t0 = time.perf_counter()
    tr = exact.simulate(PeelParams(V=1.2, I=1e-5, force=PeelForce.cubic(*CUBIC_COEF_2)), 0.05, save="jumps")
    t_cubic = time.perf_counter() - t0
n_compiles = sum(1 for _, e in rec.buffer if e.is_start)
print(json.dumps(dict(t_first_law=t_first_law, t_paper=t_paper, t_cubic=t_cubic, compiles=n_compiles,
                      jumps=len(tr.jumps.t))))
"""

_LOAD_CODE = ("import time; t=time.perf_counter(); import exact; exact.compile_kernels(); "
              "print(time.perf_counter()-t)")


def _load_times(tree: Path) -> tuple[float, float]:
    """(cold, warm) seconds of ``import exact; exact.compile_kernels()`` in new processes on an empty cache."""
    with tempfile.TemporaryDirectory() as d:
        env = dict(os.environ, NUMBA_CACHE_DIR=d, PYTHONPATH=str(tree))
        run = lambda: float(subprocess.check_output([sys.executable, "-c", _LOAD_CODE], env=env,  # noqa: E731
                                                    cwd=tempfile.gettempdir()).decode().split()[-1])
        cold = run()
        warm = min(run() for _ in range(3))
    return cold, warm


def _steps(args: argparse.Namespace, res: dict | None) -> dict[str, dict[str, float]]:
    """µs per step of each run (the default, each kind of :data:`LAWS_OF_FVV`, optionally the tree ``--before``),
    the best of ``--rounds`` alternating rounds; stored in ``res["us_per_step"]`` if ``res`` is given."""
    runs = [("after", _ROOT, "default")] + [(k, _ROOT, k) for k in LAWS_OF_FVV]
    runs += [("before", args.before.resolve(), "default")] if args.before else []
    steps: dict[str, dict[str, float]] = {k: {} for k, _, _ in runs}
    for _ in range(args.rounds):
        for k, tree, kind in runs:
            for name, us in _per_step(tree, kind).items():
                steps[k][name] = min(steps[k].get(name, math.inf), us)
    if res is not None:
        res["us_per_step"] = steps
    return steps


def _print_steps(steps: dict[str, dict[str, float]], args: argparse.Namespace | None) -> int:
    """Print the per-step table (and write it as JSON with ``--per-step-only --json``)."""
    print("\nper step [us], best of rounds: fvV inlined ('after', the default) and as each kind of law (ratio)")
    print("  scene        " + "".join(f"{k:>24}" for k in steps))
    for name in steps["after"]:
        row = "".join(f"{fmt_number(steps[k][name], 4):>14} ({fmt_number(steps[k][name] / steps['after'][name], 3):>7})"
                      for k in steps)
        print(f"  {name:<12} {row}")
    if args is not None and args.json:
        args.json.write_text(json.dumps({"us_per_step": steps}, indent=1))
    return 0


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m comparisons.benchmark.law_cost", description=__doc__.split("\n")[0])
    ap.add_argument("--before", type=Path, default=None,
                    help="a checkout of an earlier tree to compare the default path's per-step cost with")
    ap.add_argument("--rounds", type=int, default=3, help="alternating rounds of the per-step runs (default 3)")
    ap.add_argument("--json", type=Path, default=None, help="also write the figures as JSON")
    ap.add_argument("--per-step-only", action="store_true",
                    help="measure and print the per-step table only (no field, second-law or load timings)")
    args = ap.parse_args(argv)
    if args.per_step_only:
        return _print_steps(_steps(args, None), args)
    res: dict = {"field_ns": field_costs()}
    trees = {"after": _ROOT} | ({"before": args.before.resolve()} if args.before else {})
    steps = _steps(args, res)
    env = dict(os.environ, PYTHONPATH=str(_ROOT))
    res["second_law"] = json.loads(subprocess.check_output([sys.executable, "-c", _SECOND_CODE], env=env,
                                                           cwd=tempfile.gettempdir()).decode().splitlines()[-1])
    res["load_s"] = {k: dict(zip(("cold", "warm"), _load_times(tree))) for k, tree in trees.items()}

    f = res["field_ns"]
    print("field evaluation [ns] (fvV at V = 1 as each kind of law; the cubic)     ns   / paper inlined")
    for key, ns in f.items():
        print(f"  {key:<24} {fmt_number(ns, 4):>10}   {fmt_number(ns / f['inline'], 3):>8}")
    _print_steps(steps, None)
    s = res["second_law"]
    print("\nsecond cubic (other coefficients), first simulate (0.05 s) in a process that ran a first cubic: "
          f"{fmt_number(1e3 * s['t_cubic'], 3)} ms, {s['compiles']} numba compilations\n  (the first cubic's first "
          f"simulate, loading the law driver from the cache: {fmt_number(1e3 * s['t_first_law'], 3)} ms; "
          f"its second: {fmt_number(1e3 * s['t_paper'], 3)} ms)")
    print("\nimport exact + compile_kernels() in a new process [s]:   cold (empty cache)   warm (cache)")
    for k, v in res["load_s"].items():
        print(f"  {k:<54} {fmt_number(v['cold'], 3):>8}   {fmt_number(v['warm'], 3):>12}")
    if args.json:
        args.json.write_text(json.dumps(res, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

"""Cost of the peel-force law as a function argument of the hybrid driver (issue 15, the compiled side).

    python -m comparisons.benchmark.law_cost [--before PATH] [--rounds N] [--json FILE]

One run prints a table of:

* **field**: ns per evaluation of the hybrid field with the paper's law inlined (``hybrid_field``, the pattern
  every driver used before) and through the law argument (``law(u, coef, LAW_LNV)``, an indirect call) for the
  paper's law and the test cubic ``cubic_v`` (compiled loops, the best of 5; the law loop is compiled for the
  law's function type, as the driver is, so the call is not specialised away);
* **per step**: µs per accepted step of ``exact.simulate`` (rtol 1e-8, save="jumps", the best of the rounds)
  on the benchmark scenes, for the tree at ``--before`` (default ``/work/main`` when it exists: the inlined
  law) and for this tree, default (the driver with the law inlined) and with the paper's law given as a law
  (the driver taking the law as an argument), each measured in its own process, alternating, so all see the
  same machine load; and for the cubic law on stick-slip scenes of its own;
* **second law**: the wall time of the first ``simulate`` with the cubic law in a process that has already run
  a first law (the paper's, given as a law), with the number of numba compilations during it (numba's event
  recorder);
* **driver load**: ``import exact; exact.compile_kernels()`` in a new process, from a warm cache and from an
  empty one (``NUMBA_CACHE_DIR``), for both trees.
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

from exact import hybrid_field, simulate
from peelapprox import PeelForce, PeelParams
from peelapprox.io import fmt_number
from peelapprox.kernels import LAW_TYPE, LAWS, paper_coefficients

from .scenes import BENCH_SCENES

__all__ = ["CUBIC_COEF", "CUBIC_COEF_2", "field_costs", "main"]

_ROOT = Path(__file__).resolve().parents[2]
#: f = 150 + 300 v - 300 v^2 + 80 v^3 [N] (folds at 0.691 and 1.809 m/s; tests/test_law_abi.py).
CUBIC_COEF = (150.0, 300.0, 300.0, 80.0)
#: A second cubic of the same family (other coefficients: data, not code).
CUBIC_COEF_2 = (100.0, 250.0, 280.0, 90.0)
#: (name, t_end) of the per-step scenes: the benchmark's three, as in targets.py (1 s, 5 s, 20 s).
_T_END = {"V1-I1e-5": 1.0, "V1-I1e-2": 5.0, "V4-I1e-2": 20.0}


def _cubic_params(I: float) -> PeelParams:
    return PeelParams(V=1.2, I=I, force=PeelForce.cubic(*CUBIC_COEF))


def field_costs(n: int = 200_000) -> dict[str, float]:
    """ns per hybrid field evaluation: the paper's law inlined, and through the law argument (paper, cubic)."""
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
    cp, cc = paper_coefficients(1.0), np.array(CUBIC_COEF)
    res = {}
    for _ in range(2):  # alternate, keep the best
        for key, fn in (("inline", lambda k: loop_inline(y, p, out, k)),
                        ("paper", lambda k: loop_law(y, p, LAWS["paper"], cp, out, k)),
                        ("cubic", lambda k: loop_law(y, p, LAWS["cubic_v"], cc, out, k))):
            res[key] = min(res.get(key, math.inf), best(fn))
    return res


_STEP_CODE = r"""
import json, time, sys
import exact
from peelapprox import PeelParams
scenes = json.loads(sys.argv[1])
make = lambda V, I: PeelParams(V=V, I=I)
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


def _per_step(tree: Path) -> dict[str, float]:
    """µs per step on the benchmark scenes (the paper's law, the default path), measured in a new process
    running the package of ``tree``."""
    scenes = [(s.name, s.V, s.I, s.alpha0, _T_END[s.name]) for s in BENCH_SCENES]
    env = dict(os.environ, PYTHONPATH=str(tree))
    r = subprocess.run([sys.executable, "-c", _STEP_CODE, json.dumps(scenes)], env=env, capture_output=True,
                       text=True, check=True, cwd=tempfile.gettempdir())
    return json.loads(r.stdout.strip().splitlines()[-1])


def _cubic_per_step(rounds: int) -> dict[str, float]:
    out = {}
    for I, t_end in ((1e-5, 1.0), (1e-2, 5.0)):
        p = _cubic_params(I)
        simulate(p, 0.2, rtol=1e-8, save="jumps")
        best, n = math.inf, 1
        for _ in range(max(rounds, 2)):
            t0 = time.perf_counter()
            tr = simulate(p, t_end, rtol=1e-8, save="jumps")
            best, n = min(best, time.perf_counter() - t0), tr.stats.n_steps
        out[f"cubic V1.2-I{I:g}"] = 1e6 * best / n
    return out


_SECOND_CODE = r"""
import json, time
from numba.core import event
import exact
from peelapprox import PeelForce, PeelParams
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


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m comparisons.benchmark.law_cost", description=__doc__.split("\n")[0])
    ap.add_argument("--before", type=Path, default=None,
                    help="a checkout of an earlier tree to compare the default path's per-step cost with")
    ap.add_argument("--rounds", type=int, default=3, help="alternating rounds of the per-step runs (default 3)")
    ap.add_argument("--json", type=Path, default=None, help="also write the figures as JSON")
    args = ap.parse_args(argv)
    res: dict = {"field_ns": field_costs()}
    trees = {"after": _ROOT} | ({"before": args.before.resolve()} if args.before else {})
    runs = [("after", _ROOT)] + ([("before", args.before.resolve())] if args.before else [])
    steps: dict[str, dict[str, float]] = {k: {} for k, _ in runs}
    for _ in range(args.rounds):
        for k, tree in runs:
            for name, us in _per_step(tree).items():
                steps[k][name] = min(steps[k].get(name, math.inf), us)
    res["us_per_step"] = steps
    res["cubic_us_per_step"] = _cubic_per_step(args.rounds)
    env = dict(os.environ, PYTHONPATH=str(_ROOT))
    res["second_law"] = json.loads(subprocess.check_output([sys.executable, "-c", _SECOND_CODE], env=env,
                                                           cwd=tempfile.gettempdir()).decode().splitlines()[-1])
    res["load_s"] = {k: dict(zip(("cold", "warm"), _load_times(tree))) for k, tree in trees.items()}

    f = res["field_ns"]
    print("field evaluation [ns]        inlined paper  paper via law  cubic via law  paper law/inlined")
    print(f"                             {fmt_number(f['inline'], 4):>13}  {fmt_number(f['paper'], 4):>13}  "
          f"{fmt_number(f['cubic'], 4):>13}  {fmt_number(f['paper'] / f['inline'], 4):>17}")
    print("\nper step [us], best of rounds   before   after (paper's law, inlined)   after / before")
    for name, us in steps["after"].items():
        b = steps.get("before", {}).get(name)
        print(f"  {name:<28} {fmt_number(b, 4) if b else '-':>7}  {fmt_number(us, 4):>29}   "
              f"{fmt_number(us / b, 3) if b else '-'}")
    paper_mean = float(np.mean(list(steps["after"].values())))
    for name, us in res["cubic_us_per_step"].items():
        print(f"  {name:<28} {'':>7}  {fmt_number(us, 4):>29}   (the cubic through the law argument / mean "
              f"paper inlined: {fmt_number(us / paper_mean, 3)})")
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

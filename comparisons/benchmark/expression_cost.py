"""Cost of the generated peel-force laws (a tape's own law, peelapprox.law.codegen): compile, load and per call.

    python -m comparisons.benchmark.expression_cost [--n N] [--json FILE]

One run prints:

* **expression law, first process**: a new process with an empty law cache (``PEELAPPROX_CACHE_DIR``) and an
  empty numba cache (``NUMBA_CACHE_DIR``) builds ``PeelForce.expression(...)`` and calls
  ``expression_kernel(force.source)``: the wall time of that call (render with sympy, write, compile), and of
  ``from peelapprox.kernels import expression_kernel`` before it (which compiles the package's kernels into the
  empty cache);
* **expression law, second process**: the same in a new process with both caches kept: the call loads the law
  (numba's cache hits and misses are reported);
* **per call**: ns per law call in a loop compiled for the law's function type ``FunctionType(LAW_SIG)`` (the
  drivers' pattern: an indirect call, not specialised away), for each form (LAW_LNV, LAW_FP, LAW_FPP), the best
  of 5, for the built-in ``paper_law``, the generated paper family at the paper's coefficients, the generated
  ``power_branches`` and ``cubic``, and fvV typed as an expression law; with
  the ratio to ``paper_law``.
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

__all__ = ["FVV_TEXT", "call_costs", "expression_costs", "main"]

_ROOT = Path(__file__).resolve().parents[2]
#: fvV typed by a user as an expression law.
FVV_TEXT = "400*v**0.35 + 110*v**0.15 + 130*exp(v/11) - 2*V**1.5 - (415 - 45*V**0.4 - 0.35*V**2.15)*v**0.5"

_CHILD = """
import json, time
t0 = time.perf_counter()
from peelapprox.kernels import expression_kernel
t1 = time.perf_counter()
from peelapprox import PeelForce
force = PeelForce.expression({text!r})
t2 = time.perf_counter()
law, pack = expression_kernel(force.source)
t3 = time.perf_counter()
print(json.dumps(dict(import_s=t1 - t0, kernel_s=t3 - t2, hits=sum(law.stats.cache_hits.values()),
                      misses=sum(law.stats.cache_misses.values()))))
"""


def expression_costs(text: str = FVV_TEXT) -> list[dict]:
    """Two new processes sharing fresh caches: [first (compiles), second (loads)] timings (module docstring)."""
    with tempfile.TemporaryDirectory(prefix="peelapprox-expr-cost-") as tmp:
        env = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_")}
        env.update(PYTHONPATH=str(_ROOT), PEELAPPROX_CACHE_DIR=str(Path(tmp) / "laws"),
                   NUMBA_CACHE_DIR=str(Path(tmp) / "numba"))
        out = []
        for _ in range(2):
            r = subprocess.run([sys.executable, "-c", _CHILD.format(text=text)], cwd=tmp, env=env,
                               capture_output=True, text=True, timeout=900)
            if r.returncode:
                raise RuntimeError(r.stderr[-3000:])
            out.append(json.loads(r.stdout.strip().splitlines()[-1]))
        return out


def call_costs(n: int = 2_000_000, repeats: int = 5) -> dict[str, dict[str, float]]:
    """ns per law call, per law and form (module docstring)."""
    from numba import njit, types

    from peelapprox import PeelForce
    from peelapprox.kernels import (
        LAW_FP,
        LAW_FPP,
        LAW_LNV,
        LAW_TYPE,
        expression_kernel,
        family_kernel,
        paper_coefficients,
        paper_law,
    )

    @njit(types.float64(LAW_TYPE, types.float64[::1], types.int64, types.int64))
    def loop(law, coef, form, n):
        acc = 0.0
        lo, hi = math.log(0.01), math.log(10.0)  # v over 0.01-10 m/s (the stick-slip range)
        for i in range(n):
            u = lo + (hi - lo) * (i / n)
            x = u if form == 0 else math.exp(u) - 0.0
            r = law(x, coef, form)
            acc += r[1]
        return acc

    @njit(types.float64(types.float64[::1], types.int64, types.int64))
    def loop_x(coef, form, n):  # the loop's own cost: the x of each call, no law
        acc = 0.0
        lo, hi = math.log(0.01), math.log(10.0)
        for i in range(n):
            u = lo + (hi - lo) * (i / n)
            x = u if form == 0 else math.exp(u) - 0.0
            acc += x + coef[0]
        return acc

    V = 1.0

    def defaults(name: str) -> tuple:
        return tuple(x for _, x in PeelForce.family(name).coefficients)

    laws = {"paper_law": (paper_law, paper_coefficients(V))}
    for name in ("paper", "power_branches", "cubic"):
        law, pack = family_kernel(name)
        laws[f"family {name}"] = (law, pack(V, defaults(name)))
    law, pack = expression_kernel(PeelForce.expression(FVV_TEXT).source)
    laws["expression fvV"] = (law, pack(V))
    out: dict[str, dict[str, float]] = {}
    for form_name, form in (("LAW_LNV", LAW_LNV), ("LAW_FP", LAW_FP), ("LAW_FPP", LAW_FPP)):
        c0 = laws["paper_law"][1]
        loop_x(c0, form, 10)
        base = min(_timed(lambda c0=c0, f=form: loop_x(c0, f, n)) for _ in range(repeats)) / n * 1e9
        out.setdefault("loop alone", {})[form_name] = base
        for label, (law, coef) in laws.items():
            loop(law, coef, form, 10)
            t = min(_timed(lambda law=law, coef=coef, f=form: loop(law, coef, f, n)) for _ in range(repeats))
            out.setdefault(label, {})[form_name] = t / n * 1e9
    return out


def _timed(fn) -> float:
    t = time.perf_counter()
    fn()
    return time.perf_counter() - t


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m comparisons.benchmark.expression_cost", description=__doc__)
    ap.add_argument("--n", type=int, default=2_000_000, help="law calls per timed loop (default 2e6)")
    ap.add_argument("--json", help="also write the figures to this JSON file")
    a = ap.parse_args(argv)
    first, second = expression_costs()
    print(f"expression law (fvV typed as text), first process, empty caches: expression_kernel "
          f"{first['kernel_s'] * 1e3:.0f} ms (cache hits {first['hits']}, misses {first['misses']}); "
          f"import peelapprox.kernels {first['import_s'] * 1e3:.0f} ms")
    print(f"expression law, second process: expression_kernel {second['kernel_s'] * 1e3:.1f} ms "
          f"(cache hits {second['hits']}, misses {second['misses']}); import {second['import_s'] * 1e3:.0f} ms")
    calls = call_costs(a.n)
    ref = calls["paper_law"]
    print(f"\nns per law call (loop over v in 0.01-10 m/s compiled for FunctionType(LAW_SIG), best of 5, {a.n} calls)")
    print(f"{'law':<24}" + "".join(f"{f:>18}" for f in ref))
    for label, row in calls.items():
        cells = "".join(f"{row[f]:>9.1f} ({row[f] / ref[f]:4.2f}x)" for f in ref)
        print(f"{label:<24}{cells}")
    if a.json:
        Path(a.json).write_text(json.dumps(dict(first=first, second=second, calls=calls), indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())

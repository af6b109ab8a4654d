"""The targets of the stability-aware reduced map (issue 35, item 2) measured on seeded random off-grid points.

    python -m comparisons.benchmark.approx_targets --points N --seed S [--reference-only] [--json FILE]

Points: V uniform in [0.3, 4.8] m/s, I log-uniform in [2e-6, 8e-2] kg m^2 (``numpy.random.default_rng(seed)``),
the paper's law at the default k and R.

**Reference** (cached, computed once per seed and point count): at every point :func:`exact.attractor_observables`
(30 s transient, 20 s window, rtol 1e-10) from the five starts α0 in {0, ±0.15, ±0.3}, the multi-start set
the issue used; a breakdown or budget stop is recorded as the start's status.  The cache is a JSON file
``comparisons/benchmark/data/approx_targets_seed<S>_n<N>.json`` written after every point, so an interrupted
run resumes.  The strict reference is the α0 = 0 start (the solver's default start).

**Measures**, over the points whose default start is stick-slip:

* ``set``: the primary prediction of :func:`peelapprox.approximate_attractor` matches (slip interval and force
  drop both within 10 %) the stick-slip attractor of some start;
* ``strict``: it matches the α0 = 0 start's;
* ``calibration``: of the predictions with ``confidence == "high"``, the fraction that match the set, and the
  fraction of all points that are high;
* the median wall time of a call (one untimed call first, then ``--repeats``);
* the points where every start of the exact run breaks down and the prediction's status and confidence there.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import time
import warnings
from pathlib import Path
from typing import Any

import numpy as np

import exact
from peelapprox import ModelBreakdown, PeelParams, SolverBudgetExceeded, approximate_attractor, estimate
from peelapprox.io import fmt_number

__all__ = ["ALPHA0S", "DATA", "main", "points", "reference", "score"]

#: The exact run's starts: α0 of :func:`exact.attractor_observables` (0 first: the strict reference).
ALPHA0S = (0.0, 0.15, -0.15, 0.3, -0.3)
#: Where the cached references live.
DATA = Path(__file__).parent / "data"
_OBS = ("slip_interval", "force_drop", "F_max", "F_min", "period")


def points(n: int, seed: int) -> list[tuple[float, float]]:
    """``n`` seeded random points ``(V, I)`` (module docstring)."""
    rng = np.random.default_rng(seed)
    V = rng.uniform(0.3, 4.8, n)
    I = np.exp(rng.uniform(np.log(2e-6), np.log(8e-2), n))
    return [(float(v), float(i)) for v, i in zip(V, I)]


def _exact(p: PeelParams, a0: float) -> dict[str, Any]:
    t0 = time.perf_counter()
    try:
        o = exact.attractor_observables(p, alpha0=a0, max_wall=300.0)
        row: dict[str, Any] = {"status": o.status, "label": o.period_label, **{k: getattr(o, k) for k in _OBS}}
    except (ModelBreakdown, SolverBudgetExceeded) as exc:
        row = {"status": f"exact {type(exc).__name__}", "label": None, **dict.fromkeys(_OBS)}
    row["alpha0"], row["wall"] = a0, time.perf_counter() - t0
    return row


def reference(n: int, seed: int, path: Path | None = None) -> list[dict[str, Any]]:
    """The exact multi-start reference of the ``n`` points of ``seed``, from its cache file or computed (and
    cached after every point)."""
    path = path or DATA / f"approx_targets_seed{seed}_n{n}.json"
    done: list[dict[str, Any]] = []
    if path.exists():
        done = json.loads(path.read_text())["points"]
    pts = points(n, seed)
    t_all = time.perf_counter()
    for i, (V, I) in enumerate(pts[len(done):], start=len(done)):
        p = PeelParams(V=V, I=I)
        done.append({"V": V, "I": I, "starts": [_exact(p, a0) for a0 in ALPHA0S]})
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_suffix(".tmp")
        tmp.write_text(json.dumps({"seed": seed, "n": n, "alpha0s": ALPHA0S, "points": done}, indent=0))
        os.replace(tmp, path)
        print(f"\rreference seed {seed}: {i + 1}/{n} points, {time.perf_counter() - t_all:.0f} s", end="",
              file=sys.stderr, flush=True)
    print(file=sys.stderr)
    return done


def _match(pred: Any, e: dict[str, Any]) -> bool:
    if e["status"] != "stick-slip" or pred is None or getattr(pred, "status", None) != "stick-slip":
        return False
    return all(abs(getattr(pred, k) / e[k] - 1.0) < 0.1 for k in ("slip_interval", "force_drop"))


def score(ref: list[dict[str, Any]], repeats: int = 1, **options: Any) -> dict[str, Any]:
    """Every point's prediction and the measures of the module docstring."""
    rows = []
    for r in ref:
        p = PeelParams(V=r["V"], I=r["I"])
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            o = approximate_attractor(p, **options)
            times = []
            for _ in range(repeats):
                t0 = time.perf_counter()
                approximate_attractor(p, **options)
                times.append(time.perf_counter() - t0)
        starts = r["starts"]
        rows.append({"V": r["V"], "I": r["I"], "regime": estimate(p).label, "pred": o,
                     "ms": 1e3 * statistics.median(times),
                     "strict_ss": starts[0]["status"] == "stick-slip",
                     "any_ss": any(s["status"] == "stick-slip" for s in starts),
                     "all_break": all(s["status"].startswith("exact") for s in starts),
                     "set": any(_match(o, s) for s in starts), "strict": _match(o, starts[0]),
                     "high": getattr(o, "confidence", "high") == "high"})
    sel = [r for r in rows if r["strict_ss"]]
    high = [r for r in sel if r["high"]]
    return {"rows": rows, "n": len(sel), "set": sum(r["set"] for r in sel) / max(1, len(sel)),
            "strict": sum(r["strict"] for r in sel) / max(1, len(sel)),
            "high_share": len(high) / max(1, len(sel)),
            "high_match": sum(r["set"] for r in high) / max(1, len(high)),
            "ms_median": float(np.median([r["ms"] for r in rows])) if rows else None}


def _pct(x: float) -> str:
    return fmt_number(100 * x, 3)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m comparisons.benchmark.approx_targets", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--points", type=int, default=60, help="random points (default 60)")
    ap.add_argument("--seed", type=int, default=1, help="the points' seed (default 1)")
    ap.add_argument("--repeats", type=int, default=1, help="timed calls per point after one untimed (default 1)")
    ap.add_argument("--reference-only", action="store_true", help="compute (or load) the exact reference, no more")
    ap.add_argument("--cached", action="store_true", help="score only the points already in the cache")
    ap.add_argument("--json", help="write the rows and the measures as JSON")
    args = ap.parse_args(argv)
    if args.points < 1 or args.repeats < 1:
        ap.error("--points and --repeats must be >= 1")
    path = DATA / f"approx_targets_seed{args.seed}_n{args.points}.json"
    ref = json.loads(path.read_text())["points"] if args.cached else reference(args.points, args.seed)
    if args.reference_only:
        return 0
    s = score(ref, repeats=args.repeats)
    print(f"seed {args.seed}, {args.points} points, {s['n']} stick-slip from the default start: set "
          f"{_pct(s['set'])} %, strict {_pct(s['strict'])} %, unflagged {_pct(s['high_share'])} % of which match "
          f"{_pct(s['high_match'])} %, median call {fmt_number(s['ms_median'], 3)} ms")
    for r in s["rows"]:
        o = r["pred"]
        if (r["strict_ss"] and not r["set"]) or r["all_break"]:
            ex = r["all_break"] and "all starts break down" or "miss"
            print(f"  {ex}: V={r['V']:.4g} I={r['I']:.3g} [{r['regime']}] pred {o.status} {o.period_label} "
                  f"{getattr(o, 'confidence', '-')}: {getattr(o, 'confidence_reason', '')}")
    if args.json:
        out = {k: v for k, v in s.items() if k != "rows"}
        out["rows"] = [{**{k: v for k, v in r.items() if k != "pred"}, "pred": r["pred"].as_dict()} for r in s["rows"]]
        Path(args.json).write_text(json.dumps(out, indent=1, default=str))
    return 0


if __name__ == "__main__":
    sys.exit(main())

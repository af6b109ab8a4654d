"""The targets of the stability-aware reduced map measured on seeded random off-grid points.

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
* ``labels``: where the primary prediction and the α0 = 0 start are both periodic, whether their periods are equal
  (strict); ``labels_matched``: the same against the exact attractor the prediction matches (of the starts within
  10 %, the closest: the largest of the two relative differences smallest), or the α0 = 0 start's where it matches
  none, where both are periodic;
* the median wall time of a call (one untimed call first, then ``--repeats``);
* ``--chain full``: the same measures for the full branch dynamics linearised in α (genalpha + fullvdot on both
  branches, :data:`CHAINS`; the default at every inertia since 29 Nov) instead of the default reductions, ``--chain
  airy1`` for Airy1 + approxvdot on both branches (the default at high inertia before);
* the points where every start of the exact run breaks down and the prediction's status and confidence there;
* ``--multipliers K``: at the first K points whose primary prediction is a periodic orbit (n <= 12),
  :func:`exact.periodic_orbit` with the same n, and the difference of the largest |μ| (the reduction's multiplier
  error the confidence rule uses);
* ``--escapes K``: at the first K points where the solver's start either left an unstable orbit or settled on
  one the map finds weakly stable and the full chain unstable (``kind`` "left", "stays"; a left orbit first), with
  the escape law's |μ| - 1 in [1e-4, 1e-2]: the exact run from the solver's default start (``save="jumps"``, up to
  1.5 times the predicted escape, at most 300 s) and the exact orbit of that period (:func:`exact.periodic_orbit`
  seeded by the run).  The exact escape return is the first AB→CD jump after the run's closest approach to the
  orbit's return-map values whose force deviates from them by more than the orbit's force drop
  (``ESCAPE_FRACTION``, as the map's), the predicted one the map's ``escape_returns``; beside it the map's own |μ|,
  the escape law's (``escape_multiplier``, the full chain's, where the map's is in [0.99, 1.02]), the exact
  orbit's, and the same law with the exact orbit's |μ| (what is left of a miss with the exact multiplier).  An
  orbit with no predicted return (the map's deviation already one force drop at its Newton) counts as a miss.
  The exact side (escape return, |μ|, returns run, the run's length) is kept per point and period in
  ``comparisons/benchmark/data/approx_escapes_seed<S>_n<N>.json`` (or ``--escape-cache FILE``), read where it holds
  the point (run again where it found no escape in a shorter run than now asked), written after each new one.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import re
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

__all__ = ["ALPHA0S", "CHAINS", "DATA", "escapes", "main", "matched_start", "multiplier_errors", "points", "reference",
           "score", "within"]

#: The exact run's starts: α0 of :func:`exact.attractor_observables` (0 first: the strict reference).
ALPHA0S = (0.0, 0.15, -0.15, 0.3, -0.3)
#: Where the cached references live.
DATA = Path(__file__).parent / "data"
#: The deviation, in force drops of the orbit, at which a run has left an unstable orbit: the map's own
#: ``ESCAPE_FRACTION`` (peelapprox/_reduced/_approximate.py).
ESCAPE_FRACTION = 1.0
_OBS = ("slip_interval", "force_drop", "F_max", "F_min", "period")
#: The chains ``--chain`` selects: the options of :func:`peelapprox.approximate_attractor` (``default``: none).
CHAINS: dict[str, dict[str, str]] = {
    "default": {},
    "full": {"alpha_model": "genalpha", "v_equation": "fullvdot", "cd_alpha_model": "genalpha",
             "cd_v_equation": "fullvdot"},
    "airy1": {"alpha_model": "airy1", "v_equation": "approxvdot", "cd_alpha_model": "airy1",
              "cd_v_equation": "approxvdot"},
}


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


def within(pred: Any, e: dict[str, Any], key: str) -> bool:
    """Whether the prediction's ``key`` (an observable) lies within 10 % of the exact start's, both stick-slip: the
    criterion of every measure here and of ``approx_grid``."""
    if e["status"] != "stick-slip" or pred is None or getattr(pred, "status", None) != "stick-slip":
        return False
    return abs(getattr(pred, key) / e[key] - 1.0) < 0.1


def _match(pred: Any, e: dict[str, Any]) -> bool:
    return all(within(pred, e, k) for k in ("slip_interval", "force_drop"))


def _distance(pred: Any, e: dict[str, Any]) -> float:
    """The larger relative difference of the slip interval and the force drop (:func:`_match`: below 0.1)."""
    return max(abs(getattr(pred, k) / e[k] - 1.0) for k in ("slip_interval", "force_drop"))


def matched_start(pred: Any, starts: list[dict[str, Any]]) -> dict[str, Any] | None:
    """The exact start whose stick-slip attractor ``pred`` matches (:func:`_match`), the closest of those (the
    larger of the two relative differences smallest, the first of equals); None where it matches none."""
    near = [s for s in starts if _match(pred, s)]
    return min(near, key=lambda s: _distance(pred, s)) if near else None


def _labels(o: Any, e: dict[str, Any]) -> bool | None:
    """Whether the prediction's period equals the exact start's, None unless both are periodic."""
    if o.status != "stick-slip" or o.period is None or e["period"] is None:
        return None
    return bool(o.period == e["period"])


def score(ref: list[dict[str, Any]], repeats: int = 1, **options: Any) -> dict[str, Any]:
    """Every point's prediction and the measures of the module docstring."""
    with warnings.catch_warnings():  # the kernels compiled or loaded first, not inside a point's max_wall
        warnings.simplefilter("ignore")
        approximate_attractor(PeelParams(V=1.0, I=1e-2), max_wall=None, **options)
    rows = []
    for r in ref:
        p = PeelParams(V=r["V"], I=r["I"])
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            o = approximate_attractor(p, **options)
            times, cpu = [], []
            for _ in range(repeats):
                t0, c0 = time.perf_counter(), time.process_time()
                approximate_attractor(p, **options)
                times.append(time.perf_counter() - t0)
                cpu.append(time.process_time() - c0)
        starts = r["starts"]
        rows.append({"V": r["V"], "I": r["I"], "regime": estimate(p).label, "pred": o,
                     "ms": 1e3 * statistics.median(times), "cpu_ms": 1e3 * statistics.median(cpu),
                     "strict_ss": starts[0]["status"] == "stick-slip",
                     "any_ss": any(s["status"] == "stick-slip" for s in starts),
                     "all_break": all(s["status"].startswith("exact") for s in starts),
                     "set": any(_match(o, s) for s in starts), "strict": _match(o, starts[0]),
                     "labels": _labels(o, starts[0]),
                     "labels_matched": _labels(o, matched_start(o, starts) or starts[0]),
                     "high": getattr(o, "confidence", "high") == "high"})
    sel = [r for r in rows if r["strict_ss"]]
    high = [r for r in sel if r["high"]]
    both = [r for r in sel if r["labels"] is not None]
    both_m = [r for r in sel if r["labels_matched"] is not None]
    return {"rows": rows, "n": len(sel), "set": sum(r["set"] for r in sel) / max(1, len(sel)),
            "labels_equal": sum(r["labels"] for r in both), "labels_both_periodic": len(both),
            "labels_matched_equal": sum(r["labels_matched"] for r in both_m),
            "labels_matched_both_periodic": len(both_m),
            "strict": sum(r["strict"] for r in sel) / max(1, len(sel)),
            "high_share": len(high) / max(1, len(sel)),
            "high_match": sum(r["set"] for r in high) / max(1, len(high)),
            "ms_median": float(np.median([r["ms"] for r in rows])) if rows else None,
            "cpu_ms_median": float(np.median([r["cpu_ms"] for r in rows])) if rows else None,
            "cpu_ms_median_periodic": _median([r["cpu_ms"] for r in rows if r["pred"].period is not None]),
            "cpu_ms_median_aperiodic": _median([r["cpu_ms"] for r in rows if r["pred"].period is None])}


def _median(x: list[float]) -> float | None:
    return float(np.median(x)) if x else None


def _cpu_rows(ref: list[dict[str, Any]], **options: Any) -> list[tuple[dict[str, Any], Any]]:
    out = []
    for r in ref:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            out.append((r, approximate_attractor(PeelParams(V=r["V"], I=r["I"]), **options)))
    return out


def multiplier_errors(ref: list[dict[str, Any]], k: int) -> list[dict[str, Any]]:
    """The largest |μ| of the primary prediction's periodic orbit against :func:`exact.periodic_orbit`'s at the
    first ``k`` points where the prediction is periodic (module docstring)."""
    rows: list[dict[str, Any]] = []
    for r, o in _cpu_rows(ref):
        if len(rows) >= k:
            break
        if o.status != "stick-slip" or o.multipliers is None or o.period is None or o.period > 12:
            continue
        p = PeelParams(V=r["V"], I=r["I"])
        try:
            orbit = exact.periodic_orbit(p, n=o.period, max_wall=120.0)
        except Exception as exc:  # a failed exact orbit is recorded, not fatal to the benchmark
            rows.append({"V": r["V"], "I": r["I"], "n": o.period, "error": f"{type(exc).__name__}: {exc}"[:200]})
            continue
        mu_a, mu_e = max(abs(m) for m in o.multipliers), max(abs(m) for m in orbit.multipliers)
        assert o.slip_interval is not None
        # the same orbit: the exact orbit's period within 10 % of n reduced slip intervals
        same = abs(orbit.period / (o.period * o.slip_interval) - 1.0) < 0.1
        rows.append({"V": r["V"], "I": r["I"], "n": o.period, "mu_approx": mu_a, "mu_exact": mu_e,
                     "diff": mu_a - mu_e, "same_orbit": same})
        print(f"  multipliers V={r['V']:.4g} I={r['I']:.3g} n={o.period}: |mu| {mu_a:.5f} approx, {mu_e:.5f} exact"
              f"{'' if same else ' (another orbit)'}", file=sys.stderr)
    return rows


def escapes(ref: list[dict[str, Any]], k: int, cache: Path | None = None) -> list[dict[str, Any]]:
    """The predicted against the exact escape return from the solver's start (module docstring); the exact side
    read from ``cache`` where it holds the point (:func:`_exact_escape`)."""
    rows: list[dict[str, Any]] = []
    done: dict[str, Any] = json.loads(cache.read_text()) if cache is not None and cache.exists() else {}
    for r, o in _cpu_rows(ref, start="solver"):
        if len(rows) >= k:
            break
        # an orbit left (an alternative with |mu| > 1) whether or not it got a return; the primary where it has an
        # unstable full-chain rate (escape_multiplier) or a return
        left = [a for a in (*o.alternatives, o) if (a is not o or a.escape_returns is not None
                                                    or a.escape_multiplier is not None)
                and a.multipliers is not None and 1e-4 <= _law_mu(a) - 1.0 <= 1e-2]
        if not left:
            continue
        a = left[0]  # escape_returns None: an unstable orbit without a predicted return, counted as a miss
        assert a.slip_interval is not None and a.force_drop is not None
        t_end = min(300.0, 1.5 * (a.escape_returns or 200.0) * a.slip_interval + 1.0)
        mu_map = max(abs(m) for m in a.multipliers or ())
        row: dict[str, Any] = {"V": r["V"], "I": r["I"], "n": a.period, "predicted": a.escape_returns,
                               "mu_map": mu_map, "mu": _law_mu(a), "kind": "stays" if a is o else "left"}
        key = f"{r['V']!r} {r['I']!r} {a.period}"
        got = done.get(key)
        if got is None or (got.get("exact") is None and got["t_end"] < t_end):
            got = done[key] = _exact_escape(PeelParams(V=r["V"], I=r["I"]), a.period, ESCAPE_FRACTION * a.force_drop,
                                            t_end)
            if cache is not None:
                cache.parent.mkdir(parents=True, exist_ok=True)
                cache.write_text(json.dumps(done, indent=1))
        row.update({k_: v for k_, v in got.items() if k_ != "t_end"})
        if "error" in got:
            rows.append(row)
            continue
        row.update(_decomposed(a, row["mu"], row["exact_mu"]))
        rows.append(row)
        print(f"  escape ({row['kind']}) V={r['V']:.4g} I={r['I']:.3g}: predicted {_f0(a.escape_returns)}, "
              f"exact {row['exact']} "
              f"(|mu| {row['mu_map']:.5f} map, {row['mu']:.5f} escape law, {row['exact_mu']:.5f} exact; with the "
              f"exact |mu| {_f0(row.get('with_exact_mu'))})", file=sys.stderr)
    return rows


def _law_mu(a: Any) -> float:
    """The |μ| that sets the escape law's rate: ``escape_multiplier``'s where there is one, else the map's own."""
    return abs(a.escape_multiplier) if a.escape_multiplier is not None else max(abs(m) for m in a.multipliers)


def _exact_escape(p: PeelParams, n: int, thr: float, t_end: float) -> dict[str, Any]:
    """The exact escape return from the solver's default start (module docstring) in a run of ``t_end`` s, the
    exact orbit's largest |μ| and the returns run (an error recorded, not fatal)."""
    try:
        tr = exact.simulate(p, t_end, rtol=1e-10, save="jumps", max_wall=300.0)
        orbit = exact.periodic_orbit(p, start=tr, n=n, max_wall=120.0)
    except Exception as exc:  # recorded, not fatal
        return {"error": f"{type(exc).__name__}: {exc}"[:200], "t_end": t_end}
    F = np.asarray(tr.jumps.F)[np.asarray(tr.jumps.from_branch) == 0]
    dev = np.min(np.abs(F[:, None] - np.asarray(orbit.return_map_values)[None, :]), axis=1)
    closest = int(np.argmin(dev))
    out = np.flatnonzero((dev > thr) & (np.arange(dev.size) > closest)) if dev[closest] < thr else np.array([])
    return {"exact": int(out[0]) + 1 if out.size else None, "exact_mu": float(max(abs(m) for m in orbit.multipliers)),
            "returns_run": int(F.size), "t_end": t_end}


def _f0(x: float | None) -> str:
    return "-" if x is None else f"{x:.0f}"


def _decomposed(a: Any, mu: float, mu_exact: float) -> dict[str, Any]:
    """The map's escape prediction ``k0 + n ln(thr/A)/ln|mu|`` (``k0`` the returns before its Newton, from its
    ``method``; ``A`` its amplitude) redone with the exact orbit's |mu|: what is left of a miss when the multiplier
    is the exact one."""
    m = re.search(r"after (\d+) returns", a.method)
    if m is None or not mu > 1.0 or not mu_exact > 1.0 or a.escape_returns is None:
        return {}
    k0 = int(m.group(1))
    return {"k0": k0, "with_exact_mu": k0 + (a.escape_returns - k0) * math.log(mu) / math.log(mu_exact)}


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
    ap.add_argument("--chain", choices=sorted(CHAINS), default="default", help="the reductions: the default ones, "
                    "the full branch dynamics linearised in alpha (genalpha + fullvdot on both branches, the default "
                    "everywhere) or Airy1 + approxvdot on both branches")
    ap.add_argument("--labels", action="store_true", help="list the points whose period label differs from the "
                    "default start's, with the five starts' periods")
    ap.add_argument("--json", help="write the rows and the measures as JSON")
    ap.add_argument("--multipliers", type=int, default=0, help="compare multipliers with exact.periodic_orbit at K "
                    "points (module docstring)")
    ap.add_argument("--escapes", type=int, default=0, help="compare escape returns with the exact run at K points")
    ap.add_argument("--escape-cache", help="the JSON file of the exact escape runs, read where it holds a point, "
                    "written after each new one (the exact runs take up to 300 s simulated each); default "
                    "data/approx_escapes_seed<S>_n<N>.json beside the reference")
    args = ap.parse_args(argv)
    if args.points < 1 or args.repeats < 1:
        ap.error("--points and --repeats must be >= 1")
    path = DATA / f"approx_targets_seed{args.seed}_n{args.points}.json"
    ref = json.loads(path.read_text())["points"] if args.cached else reference(args.points, args.seed)
    if args.reference_only:
        return 0
    if args.multipliers or args.escapes:
        extra = {"multipliers": multiplier_errors(ref, args.multipliers) if args.multipliers else [],
                 "escapes": escapes(ref, args.escapes, Path(args.escape_cache) if args.escape_cache
                                     else DATA / f"approx_escapes_seed{args.seed}_n{args.points}.json")
                 if args.escapes else []}
        d = [abs(x["diff"]) for x in extra["multipliers"] if x.get("same_orbit")]
        if d:
            print(f"multipliers: {len(d)} orbits (of {len(extra['multipliers'])} tried) the same on both sides, "
                  f"|d|mu|| median {np.median(d):.4f}, 90th percentile {np.percentile(d, 90):.4f}, max {max(d):.4f}")
        e = [x for x in extra["escapes"] if x.get("exact")]
        for kind in ("left", "stays", None):
            ek = [x for x in e if kind is None or x["kind"] == kind]
            where = {"left": " (orbits the map leaves)", "stays": " (orbits the map stays on)", None: ", all"}[kind]
            for key, what in (("predicted", "predicted"), ("with_exact_mu", "with the exact orbit's |mu|")):
                within = sum(x.get(key) is not None and abs(x[key] / x["exact"] - 1.0) <= 0.2 for x in ek)
                made = sum(x.get(key) is not None for x in ek)
                print(f"escapes{where}: {within} of {len(ek)} {what} within 20 % of the exact escape return "
                      f"({within} of the {made} with a return predicted)")
        if len(e) < len(extra["escapes"]):
            print(f"escapes: {len(extra['escapes']) - len(e)} exact runs without an escape or with an error")
        if args.json:
            Path(args.json).write_text(json.dumps(extra, indent=1, default=str))
        return 0
    s = score(ref, repeats=args.repeats, **CHAINS[args.chain])
    print(f"seed {args.seed}, {args.points} points, {args.chain} chain, {s['n']} stick-slip from the default start: "
          f"set "
          f"{_pct(s['set'])} %, strict {_pct(s['strict'])} %, unflagged {_pct(s['high_share'])} % of which match "
          f"{_pct(s['high_match'])} %, median call {fmt_number(s['ms_median'], 3)} ms wall, "
          f"{fmt_number(s['cpu_ms_median'], 3)} ms CPU (periodic predictions "
          f"{fmt_number(s['cpu_ms_median_periodic'], 3)}, "
          f"aperiodic {fmt_number(s['cpu_ms_median_aperiodic'], 3)}); period labels equal to the default start's "
          f"where both are periodic: {s['labels_equal']} of {s['labels_both_periodic']}, to the matched attractor's: "
          f"{s['labels_matched_equal']} of {s['labels_matched_both_periodic']}")
    for r in s["rows"]:
        o = r["pred"]
        if (r["strict_ss"] and not r["set"]) or r["all_break"]:
            ex = r["all_break"] and "all starts break down" or "miss"
            print(f"  {ex}: V={r['V']:.4g} I={r['I']:.3g} [{r['regime']}] pred {o.status} {o.period_label} "
                  f"{getattr(o, 'confidence', '-')}: {getattr(o, 'confidence_reason', '')}")
    if args.labels:
        for r, p in zip(s["rows"], ref):
            if r["strict_ss"] and r["labels"] is False:
                o = r["pred"]
                print(f"  label: V={r['V']:.4g} I={r['I']:.3g} [{r['regime']}] pred {o.period_label} ({o.start} start, "
                      f"{getattr(o, 'confidence', '-')}), starts {[e['period'] for e in p['starts']]}, "
                      f"{'matches' if r['set'] else 'misses'} the set, matched attractor's label "
                      f"{'equal' if r['labels_matched'] else 'different'}")
    if args.json:
        out = {k: v for k, v in s.items() if k != "rows"}
        out["rows"] = [{**{k: v for k, v in r.items() if k != "pred"}, "pred": r["pred"].as_dict()} for r in s["rows"]]
        Path(args.json).write_text(json.dumps(out, indent=1, default=str))
    return 0


if __name__ == "__main__":
    sys.exit(main())

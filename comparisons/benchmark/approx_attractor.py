"""Accuracy and cost of the reduced return map, ``peelapprox.approximate_attractor``, against the exact attractor.

    python -m comparisons.benchmark.approx_attractor [--V 0.2:5:8] [--I 1e-6:1e-1:8:log] [--repeats 3]
        [--chains default,paper,check] [--exact-json FILE] [--json FILE] [--csv FILE]

Target (the library's accuracy goal for its namesake): the default chain within 10 % of the exact ``slip_interval``
and ``force_drop`` on at least 90 % of the stick-slip points of a 40 x 40 grid over V in [0.2, 5] m/s and I in
[1e-6, 1e-1] kg m^2 (log), the paper's law at the default k and R; at most 10 ms median per call.

At every grid point, in one process: :func:`exact.attractor_observables` (its defaults: 30 s transient, 20 s
window, rtol 1e-10; a breakdown of the exact run is recorded as its status), :func:`peelapprox.estimate`'s
regime label, and each chain of ``--chains``:

* ``default``: ``approximate_attractor(p)``, its default reductions and start;
* ``solver``: the default reductions from the solver's start only (``start="solver"``);
* ``paper``: the paper's Sec. V prescriptions taken literally: Case I and II (low V) approxalpha + approxvdot on
  AB, airy2 + approxvdot on CD; Case III (high V at intermediate or high inertia) genalpha + approxvdot on both;
* ``caseI``: approxalpha + approxvdot on AB, airy2 + approxvdot on CD at every point (the paper's Case I);
* ``check``: genalpha + fullvdot on both branches, the full branch dynamics linearised in α (not a prediction).

Every chain but ``solver`` uses the default start (``"auto"``).

Timing: each chain's call is repeated ``--repeats`` times after one untimed call, the median per point; the
table gives the median and 90th percentile of those over the exact stick-slip points.  A point counts as within
10 % for an observable when the chain's status is "stick-slip" and ``|approx/exact - 1| < 0.1``.
``--exact-json`` reuses the exact rows of an earlier ``--json`` (same grid), so the chains can be re-measured
without the exact runs.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from typing import Any

import numpy as np

import exact
from peelapprox import (
    ModelBreakdown,
    PeelParams,
    SolverBudgetExceeded,
    StickSlipObservables,
    approximate_attractor,
    estimate,
)
from peelapprox.io import fmt_number, write_rows

from ..sweep import parse_grid

__all__ = ["CHAINS", "main", "summarize"]

_PAPER_LOW_V = dict(alpha_model="approxalpha", v_equation="approxvdot", cd_alpha_model="airy2",
                    cd_v_equation="approxvdot")
_CASE_III = dict(alpha_model="genalpha", v_equation="approxvdot", cd_alpha_model="genalpha",
                 cd_v_equation="approxvdot")


def _paper(p: PeelParams, label: tuple[str, str]) -> dict:
    """The paper's literal prescription at a regime label ``(inertia, velocity)`` (module docstring)."""
    inertia, velocity = label
    return _CASE_III if velocity == "high" and inertia != "low" else _PAPER_LOW_V


#: chain name -> ``fn(params, (inertia, velocity)) -> keyword arguments of approximate_attractor``
CHAINS = {
    "default": lambda p, label: {},
    "paper": _paper,
    "check": lambda p, label: dict(alpha_model="genalpha", v_equation="fullvdot", cd_alpha_model="genalpha",
                                   cd_v_equation="fullvdot"),
    "solver": lambda p, label: dict(start="solver"),
    "caseI": lambda p, label: _PAPER_LOW_V,
}
_OBS = StickSlipObservables.OBSERVABLES


def _exact_row(p: PeelParams, t_transient: float) -> dict[str, Any]:
    t0 = time.perf_counter()
    try:
        o = exact.attractor_observables(p, t_transient=t_transient, max_wall=300.0)
        row = {"status": o.status, "period": o.period_label, **{k: getattr(o, k) for k in _OBS}}
    except (ModelBreakdown, SolverBudgetExceeded) as exc:
        row = {"status": f"exact {type(exc).__name__}", "period": None, **dict.fromkeys(_OBS)}
    row["wall"] = time.perf_counter() - t0
    return row


def _chain_row(p: PeelParams, kwargs: dict, repeats: int) -> dict[str, Any]:
    o = approximate_attractor(p, **kwargs)
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        approximate_attractor(p, **kwargs)
        times.append(time.perf_counter() - t0)
    return {"status": o.status, "period": o.period_label, "method": o.method, "reason": o.reason,
            "ms": 1e3 * statistics.median(times), **{k: getattr(o, k) for k in _OBS}}


def _rel(a: float | None, e: float | None) -> float | None:
    return None if a is None or e is None or e == 0 else a / e - 1.0


def summarize(rows: list[dict], chain: str) -> list[dict]:
    """Per regime label and over all: the exact stick-slip points, the fractions within 10 % (slip_interval,
    force_drop, both), the median |relative error| of each, the chain's other statuses, the call times."""
    out = []
    labels = sorted({r["regime"] for r in rows if r["exact"]["status"] == "stick-slip"})
    for lab in [*labels, "all"]:
        sel = [r for r in rows if r["exact"]["status"] == "stick-slip" and lab in ("all", r["regime"])]
        if not sel:
            continue
        errs = {k: [_rel(r[chain][k], r["exact"][k]) if r[chain]["status"] == "stick-slip" else None for r in sel]
                for k in ("slip_interval", "force_drop")}
        ok = {k: [e is not None and abs(e) < 0.1 for e in v] for k, v in errs.items()}
        both = [a and b for a, b in zip(ok["slip_interval"], ok["force_drop"])]
        ms = [r[chain]["ms"] for r in sel]

        def med(v: list) -> float | None:
            v = [abs(x) for x in v if x is not None]
            return float(np.median(v)) if v else None

        out.append({"chain": chain, "regime": lab, "n": len(sel),
                    "slip_interval_within_10": sum(ok["slip_interval"]) / len(sel),
                    "force_drop_within_10": sum(ok["force_drop"]) / len(sel), "both_within_10": sum(both) / len(sel),
                    "slip_interval_median_err": med(errs["slip_interval"]),
                    "force_drop_median_err": med(errs["force_drop"]),
                    "not_stick_slip": sum(r[chain]["status"] != "stick-slip" for r in sel),
                    "ms_median": float(np.median(ms)), "ms_p90": float(np.percentile(ms, 90))})
    return out


def _within(r: dict, chain: str) -> bool:
    """Both observables of ``chain`` within 10 % of the exact ones at the point ``r``."""
    return r[chain]["status"] == "stick-slip" and all(
        (e := _rel(r[chain][k], r["exact"][k])) is not None and abs(e) < 0.1 for k in ("slip_interval", "force_drop"))


def _mark(r: dict) -> str:
    return " " if r["exact"]["status"] != "stick-slip" else ("." if _within(r, "default") else "x")


def _pct(x: float | None) -> str:
    return fmt_number(None if x is None else 100 * x, 3, missing="-")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m comparisons.benchmark.approx_attractor", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--V", default="0.2:5:8", help="pull speeds [m/s], start:stop:num or a list")
    ap.add_argument("--I", default="1e-6:1e-1:8:log", help="moments of inertia [kg m^2], start:stop:num:log")
    ap.add_argument("--chains", default="default,paper,check", help=f"comma list of {', '.join(CHAINS)}")
    ap.add_argument("--repeats", type=int, default=3, help="timed calls per chain and point (after one untimed)")
    ap.add_argument("--t-transient", type=float, default=30.0,
                    help="the exact run's transient [s] before its 20 s window (default 30, attractor_observables')")
    ap.add_argument("--exact-json", help="reuse the exact rows of an earlier --json of the same grid")
    ap.add_argument("--json", help="write every point's rows and the summary as JSON")
    ap.add_argument("--csv", help="write the summary table as CSV")
    args = ap.parse_args(argv)
    Vs, Is = parse_grid(args.V, name="--V"), parse_grid(args.I, name="--I")
    chains = [c.strip() for c in args.chains.split(",") if c.strip()]
    for c in chains:
        if c not in CHAINS:
            ap.error(f"--chains: unknown chain {c!r}, choose from {', '.join(CHAINS)}")
    if args.repeats < 1:
        ap.error("--repeats must be >= 1")
    if not 0.0 <= args.t_transient <= 1e4:
        ap.error("--t-transient must be in [0, 1e4] s")
    cached: dict[str, dict] = {}
    if args.exact_json:
        with open(args.exact_json) as fh:
            cached = {f"{r['V']!r},{r['I']!r}": r["exact"] for r in json.load(fh)["points"]}
    rows = []
    t_all = time.perf_counter()
    n_pts = len(Vs) * len(Is)
    for i, (V, I) in enumerate((float(V), float(I)) for V in Vs for I in Is):
        p = PeelParams(V=V, I=I)
        e = estimate(p)
        row: dict[str, Any] = {"V": V, "I": I, "regime": e.label,
                               "exact": cached.get(f"{V!r},{I!r}") or _exact_row(p, args.t_transient)}
        for c in chains:
            row[c] = _chain_row(p, CHAINS[c](p, (e.inertia, e.velocity)), args.repeats)
        rows.append(row)
        print(f"\r{i + 1}/{n_pts} points, {time.perf_counter() - t_all:.0f} s", end="", file=sys.stderr, flush=True)
    print(file=sys.stderr)
    summary = [s for c in chains for s in summarize(rows, c)]
    n_ss = sum(r["exact"]["status"] == "stick-slip" for r in rows)
    statuses: dict[str, int] = {}
    for r in rows:
        statuses[r["exact"]["status"]] = statuses.get(r["exact"]["status"], 0) + 1
    print(f"grid: V {args.V} x I {args.I} ({n_pts} points), paper's law, default k and R; exact statuses: "
          + ", ".join(f"{k} {v}" for k, v in sorted(statuses.items())) + f"; {time.perf_counter() - t_all:.0f} s")
    print("\n| chain | regime | stick-slip points | slip_interval within 10 % | force_drop within 10 % | both | "
          "median abs err slip_interval | median abs err force_drop | chain not stick-slip | call median [ms] | "
          "call p90 [ms] |\n|---|---|---|---|---|---|---|---|---|---|---|")
    for s in summary:
        print(f"| {s['chain']} | {s['regime']} | {s['n']} | {_pct(s['slip_interval_within_10'])} % | "
              f"{_pct(s['force_drop_within_10'])} % | {_pct(s['both_within_10'])} % | "
              f"{_pct(s['slip_interval_median_err'])} % | {_pct(s['force_drop_median_err'])} % | "
              f"{s['not_stick_slip']} | {fmt_number(s['ms_median'], 3)} | {fmt_number(s['ms_p90'], 3)} |")
    if "default" in chains and n_ss:
        print("\nwhere the default chain holds: rows V (top: lowest), columns I (left: lowest, log); '.' both "
              "observables within 10 %, 'x' not, blank: the exact attractor is not stick-slip")
        for V in Vs:
            line = "".join(_mark(next(r for r in rows if r["V"] == float(V) and r["I"] == float(I))) for I in Is)
            print(f"  {float(V):6.3f} |{line}|")
        fails = [r for r in rows if r["exact"]["status"] == "stick-slip" and not _within(r, "default")]
        print(f"\nthe default chain's misses ({len(fails)} of {n_ss} stick-slip points): V, I, regime, relative "
              "errors of slip_interval and force_drop, periods (approximate / exact), status")
        for r in fails:
            d = r["default"]
            print(f"  V={r['V']:.4g} I={r['I']:.3g} [{r['regime']}] "
                  f"{_pct(_rel(d['slip_interval'], r['exact']['slip_interval']))} % "
                  f"{_pct(_rel(d['force_drop'], r['exact']['force_drop']))} % {d['period']} / "
                  f"{r['exact']['period']} {d['status']}")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump({"grid": {"V": args.V, "I": args.I}, "chains": chains, "summary": summary, "points": rows},
                      fh, indent=1, default=float)
        print(f"wrote {args.json}", file=sys.stderr)
    if args.csv:
        write_rows(args.csv, summary)
        print(f"wrote {args.csv}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())

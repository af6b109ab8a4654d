"""The approximate attractor against the exact attractor set on the atlas's 40 x 40 grid, at the cost 2 cores allow.

    python -m comparisons.benchmark.approx_grid --n 40 [--workers 2] [--json FILE] [--tables DIR] [--plot FILE]

Points: the atlas's grid (docs/atlas.md), V in [0.2, 5] m/s linear and I in [1e-6, 1e-1] kg m^2 logarithmic, n x n,
the paper's law at the default k and R.

**Reference** (the same exact protocol as ``comparisons.benchmark.approx_targets``: :func:`exact.attractor_observables`,
30 s transient, 20 s window, rtol 1e-10, from the starts α0 in {0, ±0.15, ±0.3}), in two stages that give the same
measures as running all five starts everywhere:

1. the α0 = 0 start (the solver's default start, the strict reference) at every point;
2. the other four starts only where they can change a measure: where the α0 = 0 start does not stick-slip, or where
   :func:`peelapprox.approximate_attractor`'s primary prediction (today's, at scoring time) does not match it.

A prediction that matches the α0 = 0 start's attractor matches the set whatever the other starts reach, so the
``set``, ``strict`` and calibration measures are those of the full five-start set.  (``labels_matched`` takes the
closest matched start among those run, which at a stage-1 point is the α0 = 0 start.)  A later map whose
prediction misses where an earlier one matched gets its four starts run then.  The cache
(``data/approx_grid_n<N>.json``) is written after every point, so an interrupted run resumes.

**Outputs**: the measures of ``approx_targets.score``; per regime label of :func:`peelapprox.estimate`, the
stick-slip points and the fractions within 10 % of the α0 = 0 start (slip interval, force drop, both) and of the set
(both), as the rows of an atlas's ``atlas_regimes.csv`` (:func:`regime_table`; ``--tables DIR`` writes
``approx_grid_regimes.csv``/``.json``), from which ``python -m comparisons.atlas.validity --from FILE`` writes the
table ``estimate().validity`` reads; a map of where the prediction matches (``--plot``).
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import sys
import time
import warnings
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path
from typing import Any

import numpy as np

from peelapprox import PeelParams, approximate_attractor
from peelapprox.io import fmt_number

from .approx_targets import ALPHA0S, DATA, _exact, _match, score, within

__all__ = ["REGIME_CLAUSE", "grid", "main", "other_rules_high", "reference", "regime_table"]


def grid(n: int) -> list[tuple[float, float]]:
    """The ``n`` x ``n`` atlas grid as ``(V, I)`` points, I major (the atlas's order: ``[i, j]`` is I_values[i],
    V_values[j])."""
    V = np.linspace(0.2, 5.0, n)
    I = np.geomspace(1e-6, 1e-1, n)
    return [(float(v), float(i)) for i in I for v in V]


def _needs_set(p: PeelParams, start0: dict[str, Any]) -> bool:
    """Whether the other four starts can change a measure at ``p`` (module docstring, stage 2)."""
    if start0["status"] != "stick-slip":
        return True
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return not _match(approximate_attractor(p), start0)


def _point(V: float, I: float, starts: list[dict[str, Any]], more: bool | None = None) -> dict[str, Any]:
    """One grid point: its α0 = 0 start (run unless given), and the other starts where they are needed (``more``:
    already decided by the caller; None: decided here)."""
    p = PeelParams(V=V, I=I)
    starts = list(starts) or [_exact(p, ALPHA0S[0])]
    if len(starts) < len(ALPHA0S) and (_needs_set(p, starts[0]) if more is None else more):
        starts += [_exact(p, a0) for a0 in ALPHA0S[len(starts):]]
    return {"V": V, "I": I, "starts": starts}


def reference(n: int, workers: int = 2, path: Path | None = None) -> list[dict[str, Any]]:
    """The two-stage exact reference on the ``n`` x ``n`` grid (module docstring), from its cache where it holds a
    point and today's prediction needs no more starts there, else computed on ``workers`` processes (the cache
    written after every point)."""
    path = path or DATA / f"approx_grid_n{n}.json"
    pts = grid(n)
    done: dict[str, dict[str, Any]] = json.loads(path.read_text())["points"] if path.exists() else {}
    todo: list[tuple[int, bool | None]] = [(i, None) for i in range(len(pts)) if str(i) not in done]
    todo += [(i, True) for i in range(len(pts)) if str(i) in done and len(done[str(i)]["starts"]) < len(ALPHA0S)
             and _needs_set(PeelParams(V=pts[i][0], I=pts[i][1]), done[str(i)]["starts"][0])]
    t0, k = time.perf_counter(), 0
    with ProcessPoolExecutor(max_workers=workers) as pool:  # a held point's need is decided once, here
        futs = {pool.submit(_point, *pts[i], done.get(str(i), {}).get("starts", []), more): i for i, more in todo}
        for fut in as_completed(futs):
            done[str(futs[fut])] = fut.result()
            k += 1
            tmp = path.with_suffix(".tmp")
            tmp.write_text(json.dumps({"n": n, "alpha0s": ALPHA0S, "points": done}, indent=0))
            os.replace(tmp, path)
            print(f"\rgrid reference: {k}/{len(todo)} points run, {len(done)}/{len(pts)} held, "
                  f"{time.perf_counter() - t0:.0f} s", end="", file=sys.stderr, flush=True)
    print(file=sys.stderr)
    return [done[str(i)] for i in range(len(pts))]


#: How the regime rule's clause of ``confidence_reason`` begins: the rule is applied last
#: (``peelapprox/_reduced/_approx_result.py``, ``confidence``), so a reason that begins with it holds no other rule's.
REGIME_CLAUSE = "in its regime "


def other_rules_high(rows: list[dict[str, Any]]) -> list[bool]:
    """Per scored row, whether the primary prediction is high confidence by the rules other than its regime's
    measured calibration: high, or low by that rule alone (its reason begins with :data:`REGIME_CLAUSE`).  These are
    the points on which the rule's table is calibrated (:func:`regime_table`'s ``approx:default:unflagged``)."""
    return [r["pred"].confidence == "high" or (r["pred"].confidence_reason or "").startswith(REGIME_CLAUSE)
            for r in rows]


def regime_table(ref: list[dict[str, Any]], rows: list[dict[str, Any]], others_high: list[bool] | None = None
                 ) -> list[dict[str, Any]]:
    """Per regime label of :func:`peelapprox.estimate`, the rows of an atlas's ``atlas_regimes.csv``
    (``approximation, regime, observable, stick_slip, compared, within, fraction``): ``approx:default`` for the slip
    interval, the force drop and both within 10 % of the α0 = 0 start's (the rows
    ``python -m comparisons.atlas.validity --from`` reads), and ``approx:default:set`` for both matching an attractor
    of the set (module docstring).  ``stick_slip``: the points whose α0 = 0 start stick-slips; ``compared``: those
    of them where the prediction stick-slips too; ``fraction``: ``within / stick_slip``.  With ``others_high``
    (:func:`other_rules_high`), also ``approx:default:unflagged``: of the points high by the other rules, those
    matching the set (the calibration of the regime rule)."""
    counts: dict[tuple[str, str, str], list[int]] = {}
    for idx, (r, row) in enumerate(zip(ref, rows)):
        e, o = r["starts"][0], row["pred"]
        if e["status"] != "stick-slip":
            continue
        ss = o.status == "stick-slip"
        ok = {k: within(o, e, k) for k in ("slip_interval", "force_drop")}
        for name, obs, hit in (("approx:default", "slip_interval", ok["slip_interval"]),
                               ("approx:default", "force_drop", ok["force_drop"]),
                               ("approx:default", "slip_interval+force_drop", all(ok.values())),
                               ("approx:default:set", "slip_interval+force_drop", bool(row["set"])),
                               *((("approx:default:unflagged", "slip_interval+force_drop", bool(row["set"])),)
                                 if others_high is not None and others_high[idx] else ())):
            c = counts.setdefault((name, row["regime"], obs), [0, 0, 0])
            c[0], c[1], c[2] = c[0] + 1, c[1] + ss, c[2] + hit
    return [{"approximation": name, "regime": regime, "observable": obs, "stick_slip": n, "compared": m,
             "within": w, "fraction": w / n} for (name, regime, obs), (n, m, w) in sorted(counts.items())]


def plot(ref: list[dict[str, Any]], rows: list[dict[str, Any]], n: int, path: str) -> None:
    """A map of the grid: where the primary prediction matches the α0 = 0 start, matches only another start of the
    set, misses, or the α0 = 0 start does not stick-slip; unflagged (high-confidence) predictions filled."""
    from peelapprox.plotting import pyplot, save_figure

    plt = pyplot()
    V = np.linspace(0.2, 5.0, n)
    I = np.geomspace(1e-6, 1e-1, n)
    fig, ax = plt.subplots(figsize=(7.5, 7), layout="constrained")
    kinds = (("strict", "tab:green", "matches the default start"), ("set", "tab:blue", "matches another start only"),
             ("miss", "tab:red", "misses the set"), ("none", "0.7", "default start does not stick-slip"))
    for kind, colour, text in kinds:
        for high, marker in ((True, "o"), (False, "x")):
            sel = [(r["V"], r["I"]) for r, row in zip(ref, rows) if _kind(row) == kind and row["high"] == high]
            if sel:
                x, y = zip(*sel)
                ax.scatter(x, y, s=14, marker=marker, color=colour,
                           label=f"{text} ({'high' if high else 'low'} confidence)")
    ax.set(xscale="linear", yscale="log", xlabel="V [m/s]", ylabel="I [kg m$^2$]", xlim=(V[0] - 0.1, V[-1] + 0.1),
           ylim=(I[0] / 1.5, I[-1] * 1.5), title="approximate_attractor against the exact set (5 starts)")
    fig.legend(fontsize=7, loc="outside lower center", ncol=2)
    save_figure(fig, path)
    plt.close(fig)


def _kind(row: dict[str, Any]) -> str:
    if not row["strict_ss"]:
        return "none"
    return "strict" if row["strict"] else "set" if row["set"] else "miss"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m comparisons.benchmark.approx_grid", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, default=40, help="points per axis (default 40, the atlas's)")
    ap.add_argument("--workers", type=int, default=2, help="processes for the exact runs (default 2)")
    ap.add_argument("--json", help="write the measures, the rows and the regime table as JSON")
    ap.add_argument("--tables", help="write approx_grid_regimes.csv/.json into this directory")
    ap.add_argument("--plot", help="draw the map of matches into this file (PNG)")
    args = ap.parse_args(argv)
    if args.n < 2 or args.workers < 1:
        ap.error("--n must be >= 2 and --workers >= 1")
    ref = reference(args.n, args.workers)
    s = score(ref)
    pct = lambda x: fmt_number(100 * x, 3)  # noqa: E731
    full = sum(len(r["starts"]) == len(ALPHA0S) for r in ref)
    print(f"{args.n} x {args.n} grid, {s['n']} stick-slip from the default start ({full} points with all five "
          f"starts): set {pct(s['set'])} %, strict {pct(s['strict'])} %, unflagged {pct(s['high_share'])} % of which "
          f"match {pct(s['high_match'])} %, median call {fmt_number(s['cpu_ms_median'], 3)} ms CPU; period labels "
          f"equal to the default start's {s['labels_equal']} of {s['labels_both_periodic']}")
    table = regime_table(ref, s["rows"], other_rules_high(s["rows"]))
    for t in table:
        print(f"  {t['approximation']:<18} {t['regime']:<36} {t['observable']:<24} {t['within']:>4} of "
              f"{t['stick_slip']:>4} ({pct(t['fraction'])} %)")
    if args.tables:
        d = Path(args.tables)
        d.mkdir(parents=True, exist_ok=True)
        with open(d / "approx_grid_regimes.csv", "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(table[0]))
            w.writeheader()
            w.writerows(table)
        (d / "approx_grid_regimes.json").write_text(json.dumps(table, indent=1))
    if args.plot:
        plot(ref, s["rows"], args.n, args.plot)
    if args.json:
        out = {k: v for k, v in s.items() if k != "rows"}
        out["regimes"] = table
        out["rows"] = [{**{k: v for k, v in r.items() if k != "pred"}, "pred": r["pred"].as_dict()} for r in s["rows"]]
        Path(args.json).write_text(json.dumps(out, indent=1, default=str))
    return 0


if __name__ == "__main__":
    sys.exit(main())

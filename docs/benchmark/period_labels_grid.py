"""The measurements of docs/theory.md, "Period labels", on the atlas's 40 x 40 grid (an analysis script, not part of
the package: it reads the reduced map's internals, which no public name offers).

    python -m comparisons.benchmark.approx_grid --n 40 --json grid40.json        # today's predictions, scored
    python docs/benchmark/period_labels_grid.py classify grid40.json OUT.json    # each differing label, class evidence
    python docs/benchmark/period_labels_grid.py relabel grid40.json JUMPS.npz    # exact windows re-run and re-read

``classify``: at every point whose primary prediction's period differs from the matched exact start's (the grid's
``labels_matched`` False), the map's orbit of the predicted period (Newton on P^n from the end of 600 (then 2600)
returns of the prediction's start) and :func:`exact.periodic_orbit` with n the map's period seeded from the map's
own orbit (the exact state on AB at v = v_max with the map's section point α, α̇ and F on CONSTR less 1e-9, run 3 periods
before Newton): its period, leading |μ|, stability and F range at the slips beside the map's.

``relabel``: every stick-slip start of ``comparisons/benchmark/data/approx_grid_n40.json`` re-run (30 s transient, 20 s
window, rtol 1e-10, as :func:`exact.attractor_observables`), its jumps saved to JUMPS.npz (re-used when present), the
old rule (:func:`peelapprox.periodicity` alone) checked against the cached label and slip interval, and the labels
measure recounted with today's :func:`peelapprox.StickSlipObservables` period (~25 min of CPU on 2 loaded cores).

``write``: the same windows (JUMPS.npz, made by ``relabel``) re-read with today's rule and the cache's ``period`` and
``label`` rewritten where they changed, after checking that every other cached observable is today's to the last
digit (it refuses otherwise): the cache then holds what :func:`exact.attractor_observables` returns today.

    python docs/benchmark/period_labels_grid.py write JUMPS.npz
"""

from __future__ import annotations

import json
import sys
import warnings
from pathlib import Path
from types import SimpleNamespace

import numpy as np

import exact
from comparisons.benchmark.approx_targets import _distance, _match
from peelapprox import PeelParams, periodicity
from peelapprox._observables import jump_statistics
from peelapprox._reduced import _approximate as A
from peelapprox._reduced._reducedmap import NEWTON_RTOL, ReturnMap, newton
from peelapprox.law._compiled import compiled_law

CACHE = Path(__file__).resolve().parents[2] / "comparisons/benchmark/data/approx_grid_n40.json"


def classify(scored: str, out: str) -> None:
    rows = json.loads(Path(scored).read_text())["rows"]
    cache = json.loads(CACHE.read_text())["points"]
    found = []
    for i, r in enumerate(rows):
        if not r["strict_ss"] or r["labels_matched"] is not False:
            continue
        pred, pp = r["pred"], r["pred"]["period"]
        row = dict(i=i, V=r["V"], I=r["I"], exact=[s["period"] for s in cache[str(i)]["starts"]], pred=pp,
                   start=pred["start"], newton=pred["multipliers"] is not None)
        p = PeelParams(V=r["V"], I=r["I"])
        law = compiled_law(p.force, p.V)
        bs = law.structure
        _, _, models, _ = A._chain(p, law, [None] * 4)
        lo = ReturnMap(p, law, models, 1e-6)
        hi = lo.at(NEWTON_RTOL)
        x, _ = lo.run(lo.enter(A._solver_start(p, law) if pred["start"] == "solver" else A._rest(law)), 600)
        res = newton(hi, x.copy(), pp)
        if res is None:
            x, _ = lo.run(x, 2000)
            res = newton(hi, x.copy(), pp)
        if res is not None:
            xs, J = res
            _, rr = hi.run(xs, pp)
            row["map"] = dict(mu=float(max(abs(np.linalg.eigvals(J)))), Fmin=float(rr[:, 0].min()),
                              Fmax=float(rr[:, 0].max()))
            a, ad, v = float(xs[0]), float(xs[1]), float(bs.v_max) * (1 - 1e-9)
            st = exact.State(t=0.0, alpha=a, omega=ad + v / p.R, F=lo.force(0, a) * (1 - 1e-9), v=v, branch="AB")
            try:
                po = exact.periodic_orbit(p, start=st, n=pp, t_transient=0.0,
                                          window=max(0.5, 3 * pp * pred["slip_interval"]), max_wall=90)
                rv = po.return_map_values
                row["exact_orbit"] = dict(n=po.n, mu=float(max(abs(po.multipliers))), stable=bool(po.stable),
                                          Fmin=float(rv.min()), Fmax=float(rv.max()))
            except Exception as exc:  # an analysis: record why Newton did not close
                row["exact_orbit"] = f"{type(exc).__name__}: {str(exc)[:100]}"
        print(row, flush=True)
        found.append(row)
    Path(out).write_text(json.dumps(found, indent=1))


def _windows(npz: str) -> dict:
    if Path(npz).exists():
        z = np.load(npz)
        return {k: (z[k + "_t"], z[k + "_F"], z[k + "_b"]) for k in {f.rsplit("_", 1)[0] for f in z.files}}
    cache = json.loads(CACHE.read_text())["points"]
    out = {}
    for k in sorted(cache, key=int):
        for s in cache[k]["starts"]:
            if s["status"] != "stick-slip":
                continue
            tr = exact.simulate(PeelParams(V=cache[k]["V"], I=cache[k]["I"]), 50.0, alpha0=s["alpha0"], rtol=1e-10,
                                t_transient=30.0, save="jumps", max_wall=300)
            t, F, fb = (np.asarray(a) for a in (tr.jumps.t, tr.jumps.F, tr.jumps.from_branch))
            keep = t >= 30.0
            out[f"{k}_{s['alpha0']}"] = (t[keep], F[keep], fb[keep])
    np.savez_compressed(npz, **{f"{k}_{n}": a for k, v in out.items() for n, a in zip("tFb", v)})
    return out


def relabel(scored: str, npz: str) -> None:
    cache = json.loads(CACHE.read_text())["points"]
    new, bad, changed = {}, 0, []
    for key, (t, F, fb) in sorted(_windows(npz).items()):
        i, a0 = key.split("_")
        st = next(s for s in cache[i]["starts"] if s["alpha0"] == float(a0))
        old = periodicity(np.ascontiguousarray(F[fb == 0]), rtol=1e-6, max_period=32).period
        stats, _ = jump_statistics(t, F, fb, period_rtol=1e-6, max_period=32)
        bad += old != st["period"] or stats["slip_interval"] != st["slip_interval"]
        new[(i, float(a0))] = stats["period"]
        if stats["period"] != old:
            changed.append((int(i), float(a0), old, stats["period"]))
    print(f"{len(new)} windows; the old rule's label or the slip interval not the cache's at {bad}; "
          f"labels changed at {changed}")
    eq = both = 0
    for i, r in enumerate(json.loads(Path(scored).read_text())["rows"]):
        if not r["strict_ss"]:
            continue
        p, starts = SimpleNamespace(**r["pred"]), cache[str(i)]["starts"]
        near = [s for s in starts if _match(p, s)]
        m = min(near, key=lambda s: _distance(p, s)) if near else starts[0]
        pe = new.get((str(i), m["alpha0"]))
        if p.status == "stick-slip" and p.period is not None and pe is not None:
            both, eq = both + 1, eq + (p.period == pe)
    print(f"labels equal to the matched attractor's: {eq} of {both}")


def write(npz: str) -> None:
    data = json.loads(CACHE.read_text())
    cache, changed = data["points"], []
    for key, (t, F, fb) in sorted(_windows(npz).items()):
        i, a0 = key.split("_")
        st = next(s for s in cache[i]["starts"] if s["alpha0"] == float(a0))
        stats, _ = jump_statistics(t, F, fb, period_rtol=1e-6, max_period=32)
        differ = [k for k in ("slip_interval", "force_drop", "F_max", "F_min") if stats[k] != st[k]]
        if differ:
            raise SystemExit(f"point {i}, alpha0 {a0}: {differ} not the cache's; refusing to write")
        if (stats["period"], stats["period_label"]) != (st["period"], st["label"]):
            changed.append((int(i), float(a0), st["label"], stats["period_label"]))
            st["period"], st["label"] = stats["period"], stats["period_label"]
    CACHE.write_text(json.dumps(data, indent=0))
    print(f"{len(changed)} windows relabelled: {changed}")


if __name__ == "__main__":
    warnings.simplefilter("ignore")
    {"classify": classify, "relabel": relabel, "write": write}[sys.argv[1]](*sys.argv[2:4])

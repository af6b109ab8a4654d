"""The 40 x 40 grid benchmark's bookkeeping (``comparisons.benchmark.approx_grid``): its two-stage reference runs the
four further starts exactly where they can change a measure, and its regime table counts as the atlas's does.  The
exact runs are replaced by a stub here: what is tested is which starts run and how rows are counted, both decided by
hand below."""

from __future__ import annotations

import json
from types import SimpleNamespace

import numpy as np
import pytest

from comparisons.benchmark import approx_grid as g
from comparisons.benchmark.approx_targets import ALPHA0S


def test_grid_is_the_atlas_grid_in_its_order():
    """Hypothesis: the grid is the atlas's (V linear in [0.2, 5], I logarithmic in [1e-6, 1e-1]), I major: point
    ``i * n + j`` is (V_values[j], I_values[i]).  Exact to 1e-15 relative: the same numpy constructors."""
    n = 5
    pts = g.grid(n)
    V, I = np.linspace(0.2, 5.0, n), np.geomspace(1e-6, 1e-1, n)
    assert len(pts) == n * n
    for i in range(n):
        for j in range(n):
            assert pts[i * n + j] == pytest.approx((V[j], I[i]), rel=1e-15)


def _start(status: str, si: float = 0.1, fd: float = 10.0, a0: float = 0.0) -> dict:
    return {"status": status, "label": "period-1", "slip_interval": si, "force_drop": fd, "F_max": 1.0,
            "F_min": 0.0, "period": 1, "alpha0": a0, "wall": 0.0}


def test_second_stage_runs_only_where_a_measure_can_change(monkeypatch):
    """Hypothesis: a point whose default start stick-slips and is matched by the prediction keeps one start; a
    prediction off by 20 % (outside the 10 % match) or a default start that does not stick-slip gets all five.
    Counted exactly: the stub records every α0 run."""
    ran: list[float] = []

    def fake_exact(p, a0):
        ran.append(a0)
        return _start("stick-slip" if p.V < 3 else "steady", a0=a0)

    pred = {"value": 0.1}
    monkeypatch.setattr(g, "_exact", fake_exact)
    monkeypatch.setattr(g, "approximate_attractor", lambda p: SimpleNamespace(
        status="stick-slip", slip_interval=pred["value"], force_drop=10.0))
    assert len(g._point(1.0, 1e-3, [])["starts"]) == 1 and ran == [0.0]
    pred["value"] = 0.12  # 20 % off: a miss of the default start
    ran.clear()
    assert [s["alpha0"] for s in g._point(1.0, 1e-3, [])["starts"]] == list(ALPHA0S)
    pred["value"] = 0.1
    ran.clear()
    assert len(g._point(4.0, 1e-3, [])["starts"]) == len(ALPHA0S)  # the default start does not stick-slip
    ran.clear()
    held = [_start("stick-slip")]
    pred["value"] = 0.12  # a cached stage-1 point that a new prediction misses: only the four others run
    out = g._point(1.0, 1e-3, held)
    assert ran == list(ALPHA0S[1:]) and out["starts"][0] is held[0]


def test_reference_resumes_from_its_cache(monkeypatch, tmp_path):
    """Hypothesis: with every point in the cache and matched, ``reference`` runs nothing and returns the cached
    points in grid order (the cache is the record: an interrupted run loses nothing)."""
    n = 2
    path = tmp_path / "grid.json"
    pts = {str(i): {"V": v, "I": i_, "starts": [_start("stick-slip")]} for i, (v, i_) in enumerate(g.grid(n))}
    path.write_text(json.dumps({"n": n, "alpha0s": ALPHA0S, "points": pts}))
    monkeypatch.setattr(g, "_exact", lambda p, a0: pytest.fail("no exact run expected"))
    monkeypatch.setattr(g, "approximate_attractor", lambda p: SimpleNamespace(
        status="stick-slip", slip_interval=0.1, force_drop=10.0))
    ref = g.reference(n, 1, path)
    assert [(r["V"], r["I"]) for r in ref] == g.grid(n)


def test_regime_table_counts_like_the_atlas():
    """Hypothesis: per regime, ``stick_slip`` counts the points whose default start stick-slips, ``within`` those
    within 10 % (each observable, both, and the set's match), ``fraction = within / stick_slip``.  Four points
    built by hand: one exact match, one slip interval 5 % / drop 15 % off (interval only), one non-stick-slip
    prediction, one whose default start is steady (not counted)."""
    ref = [{"starts": [_start("stick-slip")]}] * 3 + [{"starts": [_start("steady")]}]
    pred = [SimpleNamespace(status="stick-slip", slip_interval=0.1, force_drop=10.0),
            SimpleNamespace(status="stick-slip", slip_interval=0.105, force_drop=11.5),
            SimpleNamespace(status="steady", slip_interval=None, force_drop=None),
            SimpleNamespace(status="stick-slip", slip_interval=0.1, force_drop=10.0)]
    rows = [{"pred": o, "regime": "R", "set": s} for o, s in zip(pred, (True, True, False, True))]
    t = {(r["approximation"], r["observable"]): r for r in g.regime_table(ref, rows)}
    assert {k: (r["stick_slip"], r["compared"], r["within"]) for k, r in t.items()} == {
        ("approx:default", "slip_interval"): (3, 2, 2), ("approx:default", "force_drop"): (3, 2, 1),
        ("approx:default", "slip_interval+force_drop"): (3, 2, 1),
        ("approx:default:set", "slip_interval+force_drop"): (3, 2, 2)}
    assert t[("approx:default", "slip_interval")]["fraction"] == pytest.approx(2 / 3, rel=1e-15)


def test_unflagged_rows_count_only_points_high_by_the_other_rules():
    """Hypothesis: ``approx:default:unflagged`` counts, of the stick-slip points that ``others_high`` marks, those
    matching the set.  Three points by hand: high and matched, high and missed, low (not counted): 1 of 2."""
    ref = [{"starts": [_start("stick-slip")]}] * 3
    o = SimpleNamespace(status="stick-slip", slip_interval=0.1, force_drop=10.0)
    rows = [{"pred": o, "regime": "R", "set": s} for s in (True, False, True)]
    t = {(r["approximation"], r["observable"]): r for r in g.regime_table(ref, rows, [True, True, False])}
    u = t[("approx:default:unflagged", "slip_interval+force_drop")]
    assert (u["stick_slip"], u["within"], u["fraction"]) == (2, 1, 0.5)


def test_other_rules_are_read_off_the_reason(monkeypatch):
    """Hypothesis: a prediction low by the regime rule alone counts as high by the other rules, one low by another
    rule (whose clause comes first) does not, and the rule's own clause begins with REGIME_CLAUSE (the text
    ``confidence`` writes, produced here with a hand-set table: 0.5 of 100 points, below the floor)."""
    import dataclasses

    from peelapprox import PeelParams, approximate_attractor
    from peelapprox._reduced import _approx_result as ar
    from peelapprox._reduced._validity import Validity

    o = dataclasses.replace(approximate_attractor(PeelParams(V=1.0, I=1e-5)), multipliers=None)
    monkeypatch.setitem(ar.VALIDITY, "R", Validity(300, 0.9, 0.9, 0.9, 100, 0.5))
    conf, why = ar.confidence(o, "R", None, (), None)
    assert conf == "low" and why.startswith(g.REGIME_CLAUSE)
    rows = [{"pred": SimpleNamespace(confidence=c, confidence_reason=r)} for c, r in
            (("high", "no rule of low confidence applies"), ("low", why),
             ("low", "its orbit has a multiplier |mu| = 0.99 within ...; " + why))]
    assert g.other_rules_high(rows) == [True, True, False]

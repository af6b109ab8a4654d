"""The atlas over attractor sets (``atlas(..., sets=True)``, :mod:`comparisons.atlas.sets`): the match rule on
hand-built observables, the opt-in (an atlas without sets unchanged), the set records against direct
``exact.attractor_set`` and ``peelapprox.approximate_attractor`` calls, the summary, the maps and the CLI.

Short windows (5 s of transient, 3 s measured) on a 2 x 2 grid: the records are compared with direct calls at
the same window, not with the long-window physics, so the window's length does not matter to what is checked.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from comparisons.atlas import AtlasResult, atlas, load_atlas
from comparisons.atlas.sets import SET_DEFAULTS, match_set, set_summary
from exact import attractor_set
from peelapprox import PeelParams, approximate_attractor
from peelapprox.cli import main

OPTS = {"t_transient": 5.0, "t_window": 3.0, "segments_per_branch": 2}
I_GRID, V_GRID = [1e-5, 1e-3], [0.5, 2.0]


@pytest.fixture(scope="module")
def both(tmp_path_factory) -> tuple[AtlasResult, AtlasResult]:
    """The same 2 x 2 atlas without and with sets, in this process."""
    root = tmp_path_factory.mktemp("sets")
    plain = atlas(I_GRID, V_GRID, out=root / "plain", options=OPTS, max_workers=0, progress=False,
                  approximations=["estimate", "approx:default"])
    sets = atlas(I_GRID, V_GRID, out=root / "sets", options=OPTS, max_workers=0, progress=False,
                 approximations=["estimate", "approx:default"], sets=True)
    return plain, sets


def test_match_rule_on_hand_built_observables():
    """Hypothesis: ``match_set`` takes the exact attractor with the smallest ``max |pred - exact| / |exact|`` over
    slip interval and force drop and matches it iff that is <= 10 %.  Seeded random sets of 1-5 attractors and
    predictions perturbed by known factors: a prediction 5-9 % off one attractor (and >= 30 % off the others)
    matches it with the distance recomputed here to 1e-12 relative (the same arithmetic); one 11-20 % off every
    attractor matches none; a field None or an exact 0 is not compared; a bad tol is a ValueError."""
    rng = np.random.default_rng(35)
    for _ in range(200):
        n = int(rng.integers(1, 6))
        # attractors spaced by factors >= 1.5 in slip interval, so a prediction within 20 % of one is >= 30 % off others
        base = 0.01 * 1.5 ** np.arange(n) * rng.uniform(1.0, 1.05)
        exact = [{"slip_interval": float(t), "force_drop": float(rng.uniform(10, 500))} for t in base]
        k = int(rng.integers(n))
        f = rng.uniform(0.05, 0.09) * rng.choice([-1, 1], 2)
        pred = {"slip_interval": exact[k]["slip_interval"] * (1 + f[0]),
                "force_drop": exact[k]["force_drop"] * (1 + f[1])}
        idx, d = match_set(pred, exact)
        assert idx == k and d == pytest.approx(max(abs(f)), rel=1e-12)
        g = rng.uniform(0.11, 0.2)
        far = {"slip_interval": exact[k]["slip_interval"] * (1 + g), "force_drop": exact[k]["force_drop"]}
        idx, d = match_set(far, exact)
        assert idx is None and d == pytest.approx(g, rel=1e-12)
    assert match_set({"slip_interval": 1.0, "force_drop": None}, [{"slip_interval": 1.0, "force_drop": 2.0}]) \
        == (None, None)
    assert match_set({"slip_interval": 1.0, "force_drop": 2.0}, [{"slip_interval": 0.0, "force_drop": 2.0}]) \
        == (None, None)
    assert match_set({"slip_interval": 1.0, "force_drop": 2.0}, []) == (None, None)
    with pytest.raises(ValueError, match="tol"):
        match_set({"slip_interval": 1.0, "force_drop": 2.0}, [], tol=-0.1)


def test_summary_rates_from_hand_built_rows():
    """Hypothesis: the set rates count as documented on six hand-built rows: set_match 3/5 (a row without a
    stick-slip set not counted), strict 2/4 (default stick-slip rows only), unflagged 2/3 and unflagged share 3/5.
    Exact counts."""
    keys = ("set_match", "strict_match", "default_stick_slip", "confidence", "set_distance")
    rows = [dict(zip(keys, v, strict=True)) for v in (
        (True, True, True, "high", 0.01), (True, False, True, "low", 0.05), (True, None, False, "high", 0.02),
        (False, False, True, "high", 0.5), (False, True, True, "low", None), (None, None, False, "high", None))]
    got = {r["observable"]: (r["within"], r["stick_slip"]) for r in set_summary(rows)}
    assert got == {"set_match": (3, 5), "strict_match": (2, 4), "unflagged_match": (2, 3), "unflagged_share": (3, 5)}


def test_opt_in_leaves_the_atlas_unchanged(both, tmp_path):
    """Hypothesis: without ``sets`` the atlas has no set measure, key or option (its manifest's options are the
    ones it had) and the set queries are refused; with it, every record key of the other measures is equal to the
    atlas's without (exact: deterministic runs; wall-time keys left out), and the summary rows without sets are
    its first rows.  A set option without ``sets`` is a ValueError naming it.  Categorical and exact."""
    plain, sets = both
    assert not plain.has_sets and sets.has_sets
    assert not any(k.startswith("atlas_sets") for r in plain.sweep.records for k in r)
    assert not set(SET_DEFAULTS) & set(plain.options) and set(SET_DEFAULTS) <= set(sets.options)
    with pytest.raises(ValueError, match="sets=True"):
        plain.multistability()

    def strip(r):
        return {k: v for k, v in r.items() if not k.startswith("atlas_sets") and "wall" not in k}
    for I in I_GRID:
        for V in V_GRID:
            assert strip(plain.sweep.record(I, V)) == strip(sets.sweep.record(I, V))
    n = len(plain.summary())
    assert sets.summary()[:n] == plain.summary() and len(sets.summary()) == n + 4
    with pytest.raises(ValueError, match="set_min_share"):
        atlas(I_GRID, V_GRID, out=tmp_path / "x", options={"set_min_share": 0.2}, max_workers=0, progress=False)
    with pytest.raises(ValueError, match="set_min_share"):
        atlas(I_GRID, V_GRID, out=tmp_path / "y", options={"set_min_share": 2.0}, sets=True, max_workers=0,
              progress=False)


def test_set_records_against_direct_calls(both):
    """Hypothesis: at each point the set record is what direct calls give at the same window: the number of
    attractors with share >= 10 % (breakdowns not counted) of ``attractor_set(stability=False)``; the primary's
    confidence from ``approximate_attractor``; ``set_match`` iff some stick-slip attractor of share >= 10 % has
    slip interval and force drop both within 10 % of the prediction's (relative to the exact value, recomputed
    here); ``strict_match`` the same against the set's primary.  Exact (deterministic solvers), the distance to
    1e-12 relative (the same arithmetic); the maps and the xarray Dataset are the records'."""
    _, sets = both
    ms, conf = sets.multistability(), sets.confidence()
    for i, I in enumerate(I_GRID):
        for j, V in enumerate(V_GRID):
            rec = {r: v for r, v in sets.set_rows()[[(x["I"], x["V"]) for x in sets.set_rows()].index((I, V))].items()}
            p = PeelParams(V=V, I=I)
            s = attractor_set(p, t_transient=5.0, t_window=3.0, stability=False, workers=0)
            a = approximate_attractor(p, warn=False)
            counted = [x for x in s.attractors if x.share >= 0.1 and x.kind != "breakdown"]
            assert rec["n_attractors"] == len(counted) == ms[i, j]
            assert rec["confidence"] == a.confidence == conf[i, j]
            ss = [x for x in counted if x.is_stick_slip]

            def err(x, a=a):
                return max(abs(a.slip_interval - x.observables.slip_interval) / abs(x.observables.slip_interval),
                           abs(a.force_drop - x.observables.force_drop) / abs(x.observables.force_drop))
            if not ss or not a.is_stick_slip:
                continue
            assert rec["set_match"] == any(err(x) <= 0.1 for x in ss)
            assert rec["set_distance"] == pytest.approx(min(err(x) for x in ss), rel=1e-12)
            assert rec["strict_match"] == (err(s.primary) <= 0.1)
    ds = sets.to_xarray()
    assert (ds["n_attractors"].values == ms.filled(np.nan)).all() and (ds["confidence"].values == conf).all()
    summary = {r["observable"]: r for r in sets.set_summary()}
    rows = sets.set_rows()
    n_set = sum(r["set_match"] is not None for r in rows)
    assert summary["set_match"]["stick_slip"] == n_set
    assert summary["set_match"]["within"] == sum(bool(r["set_match"]) for r in rows)


def test_cli_sets_tables_and_maps(tmp_path, capsys):
    """Hypothesis: ``peelapprox atlas --sets`` on a 1 x 2 grid exits 0, writes the ``sets`` and ``set_summary``
    tables (CSV and JSON) and, with ``--plot``, every map of the atlas (PNG, > 10 kB): the dynamics map, the
    approximation's six error maps, the two segment maps (``--segments 2``) and the multistability and confidence
    maps; its printed summary is ``load_atlas(DIR).summary()`` (exact, through JSON) and ends with the four set
    rows.  Without ``--sets`` neither table is written.  (The default tier's one ``--plot`` of an atlas: every
    kind of map once.)"""
    out = tmp_path / "at"
    argv = ["atlas", "--V", "0.5,2", "--I", "1e-5", "--out", str(out), "--workers", "0", "--t-transient", "5",
            "--window", "3", "--segments", "2", "--approximations", "estimate", "--format", "json", "--quiet"]
    assert main(argv + ["--sets", "--plot"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary == json.loads(json.dumps(load_atlas(out).summary()))
    assert [r["observable"] for r in summary[-4:]] == ["set_match", "strict_match", "unflagged_match",
                                                      "unflagged_share"]
    for table in ("sets", "set_summary"):
        assert (out / f"atlas_{table}.csv").is_file() and (out / f"atlas_{table}.json").is_file()
    maps = sorted(p.name for p in (out / "maps").iterdir())
    assert {"dynamics.png", "error_estimate_slip_interval.png", "segments_dt_median.png", "segments_dF_median.png",
            "multistability.png", "confidence.png"} <= set(maps)
    assert len(maps) == 1 + 6 + 2 + 2
    assert all((out / "maps" / m).stat().st_size > 10_000 for m in maps)
    plain = tmp_path / "plain"
    assert main([*argv[:6], str(plain), *argv[7:]]) == 0
    assert not (plain / "atlas_sets.csv").exists()


def test_set_stability_compares_multipliers_and_budget_is_the_sweeps():
    """Hypothesis: with ``set_stability`` the measure's exact multiplier is the largest |μ| of the matched
    attractor of a direct ``attractor_set(stability=True)`` call, the predicted one ``approximate_attractor``'s,
    and their difference is recorded (exact: deterministic, the same arithmetic), at a periodic point (V = 2,
    I = 1e-5: both periodic on this window); a sweep budget spent inside the set raises the sweep's
    ``SolverBudgetExceeded("max_wall")`` (the point is then computed on resume), never a partial record; a bad
    ``sets`` is a ValueError naming it."""
    from comparisons.atlas.sets import measure_sets
    from peelapprox import SolverBudgetExceeded

    p = PeelParams(V=2.0, I=1e-5)
    opts = {"t_transient": 5.0, "t_window": 3.0, "set_stability": True}
    rec = measure_sets(p, opts)
    s = attractor_set(p, t_transient=5.0, t_window=3.0, stability=True, workers=0)
    a = approximate_attractor(p, warn=False)
    matched = [x for x in s.attractors if x.share >= 0.1 and x.is_stick_slip and x.label == rec["matched_label"]
               and x.share == rec["matched_share"]]
    assert rec["set_match"] and len(matched) == 1 and matched[0].multipliers and a.multipliers
    assert rec["exact_max_multiplier"] == matched[0].max_multiplier
    assert rec["predicted_max_multiplier"] == max(abs(m) for m in a.multipliers)
    assert rec["multiplier_error"] == abs(rec["predicted_max_multiplier"] - rec["exact_max_multiplier"])
    with pytest.raises(SolverBudgetExceeded) as exc:
        measure_sets(p, {**opts, "max_wall": 1e-4})
    assert exc.value.budget == "max_wall"
    with pytest.raises(ValueError, match="sets"):
        atlas(I_GRID, V_GRID, out="unused", sets="yes", max_workers=0, progress=False)


def test_the_set_measure_reuses_the_default_prediction_of_its_point():
    """Hypothesis: a point's set measure reads the ``approx:default`` prediction its atlas measure made for the same
    ``params`` object (one ``approximate_attractor`` run per point, not two), and computes its own for another
    object.  Identity, not a tolerance: the very object the approximation returned, or a new one with the same
    fields (the map is deterministic); and the record of either is the same."""
    from comparisons.atlas import approximations, sets

    p, q = PeelParams(V=1.0, I=1e-2), PeelParams(V=1.0, I=1e-2)
    rec = approximations.predict("approx:default", p)
    made = approximations.last_output("approx:default", p, approximate_attractor)
    assert made is not None and made.slip_interval == rec["slip_interval"]
    got, fields = sets._predicted(p)
    assert got is made
    other, other_fields = sets._predicted(q)
    assert other is not made and other.as_dict() == made.as_dict() and other_fields == fields
    assert approximations.last_output("approx:default", p, lambda params: None) is None  # another function: none

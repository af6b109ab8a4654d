"""The atlas (comparisons.atlas, ``peelapprox atlas``): end to end on a small grid, resume after a kill, bad input
refused before any point, the command line.

The solvers are deterministic and the records hold no timings, so what the atlas records is compared with
direct calls of the same functions for *exact* equality (JSON round-trips floats exactly); a relative error
recomputed here from those values agrees to rounding (1e-12 relative: the same formula, evaluated again).
The exact windows are short (10 s of transient, 5 s measured) to keep the default tier fast: the atlas's
own defaults (100 s + 20 s) are measured in docs/atlas.md, not here.
"""

import dataclasses
import json
import math
import os
import re
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import _atlas_approximations  # noqa: F401  (test approximations the workers can import)
import numpy as np
import pytest

import peelapprox
from comparisons.atlas import (
    APPROXIMATIONS,
    OBSERVABLES,
    AtlasResult,
    atlas,
    atlas_cost,
    estimate_observables,
    load_atlas,
)
from comparisons.atlas.records import SEGMENT_STATS
from exact import attractor_observables
from peelapprox import ModelBreakdown, PeelParams, StickSlipObservables, estimate
from peelapprox.cli import main

TESTS = str(Path(__file__).resolve().parent)
#: Short windows for the tests (module docstring).
OPTS = {"t_transient": 10.0, "t_window": 5.0, "segments_per_branch": 4}
#: A stick-slip point, a breakdown (V = 0.5, I = 1e-4: docs/dynamics.md) and steady peeling (V = 5).
I_SMALL, V_SMALL = [1e-5, 1e-4], [0.5, 1.0, 5.0]


def _no_nan(text: str) -> list[dict]:
    """The JSON lines of ``results.jsonl``; a NaN or infinity anywhere is an assertion error."""
    def refuse(token):
        raise AssertionError(f"{token} in a record")
    return [json.loads(line, parse_constant=refuse) for line in text.splitlines()]


@pytest.fixture(scope="module")
def small(tmp_path_factory) -> AtlasResult:
    """A 2 x 3 atlas in this process (every registered approximation)."""
    out = tmp_path_factory.mktemp("atlas") / "small"
    return atlas(I_SMALL, V_SMALL, out=out, options=OPTS, max_workers=0, progress=False)


def test_small_atlas_records_and_statuses(small):
    """Hypothesis: each point of the 2 x 3 atlas has one record whose status is the exact dynamics': ``ok``
    (stick-slip) at V = 0.5, 1 (I = 1e-5) and V = 1 (I = 1e-4), ``breakdown:no_root`` at V = 0.5, I = 1e-4,
    ``steady`` at V = 5; every non-ok point has a reason, no value is NaN, and the exact observables are those
    of a direct ``attractor_observables`` call with the same window (exact equality: deterministic solver,
    JSON round-trip), the breakdown that of a direct call (the same reason).  Categorical otherwise."""
    assert small.complete and len(small.sweep.records) == 6 and not small.failed()
    _no_nan((Path(small.out) / "results.jsonl").read_text())
    status = small.status()
    assert list(status[0]) == ["ok", "ok", "steady"] and list(status[1]) == ["breakdown:no_root", "ok", "steady"]
    cls = small.exact_class()
    assert cls[1, 0] == "breakdown" and cls[0, 2] == cls[1, 2] == "steady"
    assert all(str(c).startswith("period-") or c == "aperiodic" for c in (cls[0, 0], cls[0, 1], cls[1, 1]))
    for i, I in enumerate(I_SMALL):
        for j, V in enumerate(V_SMALL):
            rec = small.sweep.record(I, V)
            assert rec["atlas_exact_reason"]
            p = PeelParams(V=V, I=I)
            try:
                obs = attractor_observables(p, t_transient=10.0, t_window=5.0)
            except ModelBreakdown as exc:
                assert rec["atlas_exact_status"] == f"breakdown:{exc.reason}" and rec["atlas_exact_t_breakdown"] > 0
                continue
            assert rec["atlas_exact_period"] == obs.period and rec["atlas_exact_n_slips"] == obs.n_slips
            for name in OBSERVABLES:
                assert small.exact(name)[i, j] is np.ma.masked if getattr(obs, name) is None \
                    else small.exact(name)[i, j] == getattr(obs, name)
    assert small.regime()[0, 0] == estimate(PeelParams(V=0.5, I=1e-5)).label
    has = hasattr(peelapprox, "approximate_attractor")
    assert ("approx:default" in small.approximations) == has and ("approx:default" in small.skipped) != has


def test_small_atlas_relative_errors_recomputed(small):
    """Hypothesis: the atlas's relative error of estimate's prediction is ``|predicted - exact| / |exact|`` with
    the prediction recomputed here from ``peelapprox.estimate`` (quasi-static AB and CD times, the folds'
    forces) and the exact value from a direct ``attractor_observables`` call, at every stick-slip point, to
    1e-12 relative (the same formula evaluated twice); undefined (masked, with its reason) where the exact
    dynamics does not stick-slip."""
    for i, I in enumerate(I_SMALL):
        for j, V in enumerate(V_SMALL):
            p = PeelParams(V=V, I=I)
            if small.status()[i, j] != "ok":
                for obs in OBSERVABLES:
                    assert small.relative_error("estimate", obs)[i, j] is np.ma.masked
                assert small.undefined("estimate", "slip_interval")[i, j] == f"exact: {small.exact_class()[i, j]}"
                continue
            e = estimate(p)
            predicted = {"slip_interval": e.t_ab_quasi_static + e.t_cd_quasi_static, "force_drop": e.f_max - e.f_min,
                         "slip_time": e.t_cd_quasi_static, "stick_time": e.t_ab_quasi_static, "F_max": e.f_max,
                         "F_min": e.f_min}
            exact = attractor_observables(p, t_transient=10.0, t_window=5.0)
            for obs, a in predicted.items():
                want = abs(a - getattr(exact, obs)) / abs(getattr(exact, obs))
                assert math.isclose(small.relative_error("estimate", obs)[i, j], want, rel_tol=1e-12), (I, V, obs)
                assert small.undefined("estimate", obs)[i, j] == ""
    w = small.within("estimate", "stick_time")
    err = [small.relative_error("estimate", "stick_time")[i, j] for i, j in ((0, 0), (0, 1), (1, 1))]
    assert w["stick_slip"] == w["compared"] == 3 and w["within"] == sum(x <= 0.1 for x in err)


def test_small_atlas_segments_and_tables(small, tmp_path):
    """Hypothesis: at a stick-slip point every reduction compared its 4 last stays of the branch (``n`` +
    ``failed`` = 4) and the median error lies between 0 and the worst; at the breakdown and steady points the
    segment maps are masked.  The tables: one errors row per point, approximation and observable (6 x 1 x 6 = 36
    with estimate alone), strict JSON (no NaN) and CSV with the same rows.  Categorical and exact counts."""
    for red in small.reductions:
        n, failed = small.segment_error(red, "n"), small.segment_error(red, "failed")
        assert n[0, 0] + failed[0, 0] == 4
        med, worst = small.segment_error(red, "dt_median"), small.segment_error(red, "dt_worst")
        if n[0, 0]:
            assert 0 <= med[0, 0] <= worst[0, 0]
        assert med[1, 0] is np.ma.masked and med[0, 2] is np.ma.masked
    told: list[tuple[int, int, str]] = []
    paths = small.write_tables(tmp_path, progress=lambda i, n, path: told.append((i, n, path)))
    assert len(paths) == 10
    assert told == [(i + 1, 10, p) for i, p in enumerate(paths)]  # progress after each file (issue 36, item 5)
    # the per-regime table agrees with the maps, counted here from them: for each approximation and observable,
    # the points within 10 % summed over the labels are those of within(), and each label's count is its cells'
    regimes, ss = small.regime(), small.stick_slip()
    by = json.loads((tmp_path / "atlas_regimes.json").read_text())
    for name in small.approximations:
        for obs in OBSERVABLES:
            mine = [r for r in by if r["approximation"] == name and r["observable"] == obs]
            assert sum(r["within"] for r in mine) == small.within(name, obs)["within"]
            err = small.relative_error(name, obs).filled(np.inf)
            for r in mine:
                sel = ss & (regimes == r["regime"])
                assert r["stick_slip"] == int(sel.sum()) and r["within"] == int(((err <= 0.1) & sel).sum())
    rows = json.loads((tmp_path / "atlas_errors.json").read_text())
    assert len(rows) == 6 * len(small.approximations) * len(OBSERVABLES)
    assert (tmp_path / "atlas_errors.csv").read_text().count("\n") == len(rows) + 1
    summary = json.loads((tmp_path / "atlas_summary.json").read_text())
    assert {r["approximation"] for r in summary} >= {"estimate", *(f"segments:{r}" for r in small.reductions)}


def test_small_atlas_to_xarray(small):
    """Hypothesis: ``to_xarray`` holds the same numbers as the maps (exact equality), NaN where a map is masked
    (xarray's missing value), and the classes as strings."""
    pytest.importorskip("xarray", reason="the data extra (xarray) is not installed: pip install 'peelapprox[data]'")
    ds = small.to_xarray()
    assert ds["exact"].shape == (2, 3, len(OBSERVABLES)) and ds["exact_class"].values[1, 0] == "breakdown"
    err = ds["rel_error"].sel(approximation="estimate", observable="stick_time").values
    ours = small.relative_error("estimate", "stick_time", signed=True)
    assert np.array_equal(np.isnan(err), np.ma.getmaskarray(ours))
    assert np.array_equal(err[~np.isnan(err)], ours.compressed())


def test_observables_are_the_fields_of_stick_slip_observables():
    """Hypothesis: the atlas's observables are ``StickSlipObservables``' own list (the very object), each a field
    of the dataclass with its unit, the spreads the means' ``_spread`` fields; no ClassVar leaks into the fields.
    Exact (names and units)."""
    names = [f.name for f in dataclasses.fields(StickSlipObservables)]
    assert OBSERVABLES is StickSlipObservables.OBSERVABLES
    assert OBSERVABLES == ("slip_interval", "force_drop", "slip_time", "stick_time", "F_max", "F_min")
    assert set(OBSERVABLES) <= set(names) and list(StickSlipObservables.__dataclass_fields__) == names
    assert StickSlipObservables.SPREADS == tuple(f"{m}_spread" for m in StickSlipObservables.MEANS)
    assert [StickSlipObservables.UNITS[o] for o in OBSERVABLES] == ["s", "N", "s", "s", "N", "N"]


def test_small_atlas_records_hold_arrays(small):
    """Hypothesis: a record holds each measure's values as arrays in the schema's order (options ``schema``), not
    one key per approximation and observable: no key names an approximation, and every map's value is the
    record's array entry (exact equality: the maps are read from them).  Categorical otherwise."""
    assert small.options["schema"]["observables"] == list(OBSERVABLES)
    assert small.options["schema"]["segment_stats"] == list(SEGMENT_STATS)
    for rec in small.sweep.records:
        assert not [k for k in rec if "estimate" in k or "approx_default" in k], rec
        i, j = list(small.I_values).index(rec["I"]), list(small.V_values).index(rec["V"])
        for a, name in enumerate(small.approximations):
            assert small.prediction_status(name)[i, j] == rec["atlas_approx_prediction_status"][a]
            for k, obs in enumerate(OBSERVABLES):
                v, m = rec["atlas_approx_predicted"][a][k], small.prediction(name, obs)[i, j]
                assert m is np.ma.masked if v is None else m == v
        for k, obs in enumerate(OBSERVABLES):
            v = rec.get("atlas_exact_observables", [None] * len(OBSERVABLES))[k]
            assert small.exact(obs)[i, j] is np.ma.masked if v is None else small.exact(obs)[i, j] == v


def test_records_of_another_schema_are_relabelled():
    """Hypothesis: a record of this format written under another schema (an observable fewer, another order, as
    after a field is added to StickSlipObservables) is read by label: each value lands under its own observable,
    the ones it lacks are None; a record of this schema is returned as it is.  Exact (values moved, not
    computed)."""
    from comparisons.atlas.records import schema, upgrade

    written = {**schema(), "observables": ["F_min", "slip_interval"], "segment_stats": ["n", "dt_median"]}
    rec = {"I": 1e-5, "V": 1.0, "status": "ok", "atlas_exact_observables": [160.5, 0.25],
           "atlas_approx_predicted": [[161.0, 0.26], [None, 0.3]], "atlas_segments_stats": [[4, 0.01]]}
    new = upgrade(rec, ["a", "b"], ["AB_x_y"], written)
    assert new["atlas_exact_observables"] == [0.25, None, None, None, None, 160.5]
    assert new["atlas_approx_predicted"] == [[0.26, None, None, None, None, 161.0], [0.3] + [None] * 5]
    assert new["atlas_segments_stats"] == [[0.01, None, None, None, 4, None]]
    assert upgrade(rec, ["a", "b"], ["AB_x_y"], schema()) is rec


def test_first_format_atlas_reads_and_refuses_to_resume(tmp_path):
    """Hypothesis: an atlas of the first record format (one key per number: ``atlas_approx_<name>_<observable>``,
    3 points of the 2 x 3 grid written before the schema) loads: every map's value is its record's own key's
    (exact equality: the conversion moves values, computes none), absent keys masked; resuming it is a
    ValueError that says it must be regenerated.  Exact and categorical."""
    out = tmp_path / "old"
    shutil.copytree(Path(TESTS) / "data" / "atlas_format1", out)
    res = load_atlas(out)
    recs = _no_nan((out / "results.jsonl").read_text())
    assert len(res.records) == 3 and res.approximations and res.reductions
    for rec in recs:
        i, j = list(res.I_values).index(rec["I"]), list(res.V_values).index(rec["V"])
        assert res.status()[i, j] == rec["status"] and res.exact_class()[i, j] == rec["atlas_exact_class"]
        for obs in OBSERVABLES:
            v = rec.get(f"atlas_exact_{obs}")
            assert res.exact(obs)[i, j] is np.ma.masked if v is None else res.exact(obs)[i, j] == v
            for name in res.approximations:
                v = rec.get(f"atlas_approx_{re.sub(r'[^A-Za-z0-9_]', '_', name)}_{obs}")
                m = res.prediction(name, obs)[i, j]
                assert m is np.ma.masked if v is None else m == v
        for red in res.reductions:
            for stat in SEGMENT_STATS:
                v, m = rec.get(f"atlas_segments_{red}_{stat}"), res.segment_error(red, stat)[i, j]
                assert m is np.ma.masked if v is None else m == v
    assert len(res.error_rows()) == 3 * len(res.approximations) * len(OBSERVABLES)
    with pytest.raises(ValueError, match="first record format.*new directory"):
        atlas(res.I_values, res.V_values, out=out, options=OPTS, max_workers=0, progress=False)


def test_predictions_checked_and_both_return_types(tmp_path, monkeypatch):
    """Hypothesis: an approximation returning a NaN observable is recorded with an ``error: ValueError`` status
    naming the field (never NaN), while one returning a ``StickSlipObservables`` is read like one returning a
    dict: the same predictions as estimate's (exact equality).  One point, in this process."""
    monkeypatch.setitem(APPROXIMATIONS, "test:nan", "_atlas_approximations:nan_slip_interval")
    monkeypatch.setitem(APPROXIMATIONS, "test:obs", _atlas_approximations.as_observables)
    res = atlas([1e-5], [1.0], out=tmp_path / "a", approximations=["estimate", "test:nan", "test:obs"],
                options={**OPTS, "segments_per_branch": 0}, max_workers=0, progress=False)
    rec = _no_nan((tmp_path / "a" / "results.jsonl").read_text())[0]
    nan_status = rec["atlas_approx_prediction_status"][res.approximations.index("test:nan")]
    assert nan_status.startswith("error: ValueError") and "slip_interval must be a finite number" in nan_status
    assert res.undefined("test:nan", "slip_interval")[0, 0].startswith("predicted: error: ValueError")
    for obs in OBSERVABLES:
        assert res.prediction("test:obs", obs)[0, 0] == res.prediction("estimate", obs)[0, 0]
    assert res.prediction("estimate", "stick_time")[0, 0] == estimate_observables(
        PeelParams(V=1.0, I=1e-5))["stick_time"]


def test_approximate_attractor_plugs_in_by_its_registry_entry(tmp_path, monkeypatch):
    """Hypothesis: the built-in entry ``"approx:default"`` (an import reference) is measured as soon as
    ``peelapprox.approximate_attractor`` resolves, with no other change, and an entry whose reference does not
    resolve is skipped, with why; a lambda added as one registry line runs in this process, and a process pool
    refuses it before any point (ValueError naming ``approximations``: its workers could not find it).  Here a
    stand-in for ``approximate_attractor`` returns estimate's prediction, so the two rows are equal (exact
    equality)."""
    def stand_in(params):
        return estimate_observables(params)

    monkeypatch.setattr(peelapprox, "approximate_attractor", stand_in, raising=False)
    monkeypatch.setitem(APPROXIMATIONS, "approx:lambda", lambda p: estimate_observables(p))
    opts = {**OPTS, "segments_per_branch": 0}
    res = atlas([1e-5], [1.0], out=tmp_path / "a", options=opts, max_workers=0, progress=False)
    assert {"estimate", "approx:default", "approx:lambda"} <= set(res.approximations) and not res.skipped
    for obs in OBSERVABLES:
        assert res.prediction("approx:default", obs)[0, 0] == res.prediction("estimate", obs)[0, 0]
        assert res.prediction("approx:lambda", obs)[0, 0] == res.prediction("estimate", obs)[0, 0]
    monkeypatch.setitem(APPROXIMATIONS, "approx:default", "peelapprox:no_such_function_yet")  # not written yet
    res = atlas([1e-5], [1.0], out=tmp_path / "b", approximations=["estimate", "approx:default"], options=opts,
                max_workers=0, progress=False)
    assert res.approximations == ("estimate",) and "not importable" in res.skipped["approx:default"]
    with pytest.raises(ValueError, match="approximations: 'approx:lambda'"):
        atlas([1e-5], [1.0], out=tmp_path / "c", approximations=["approx:lambda"], max_workers=2, progress=False)
    assert not (tmp_path / "c").exists()


@pytest.mark.parametrize("kwargs, match", [
    ({"I_values": []}, "I_values"),
    ({"V_values": [1.0, -2.0]}, "V_values"),
    ({"V_values": [1.0, 1.0]}, "V_values must not repeat"),
    ({"options": {"t_window": -1.0}}, "t_window"),
    ({"options": {"t_transient": 1e6, "t_window": 1.0}}, "t_transient \\+ t_window"),
    ({"options": {"segments_per_branch": 1.5}}, "segments_per_branch"),
    ({"options": {"reductions": {"AB": [["nosuch", "approxvdot"]]}}}, "reductions"),
    ({"options": {"tape_mass": 1e-4}}, "unknown atlas option"),
    ({"options": {"rtol": 1.0}}, "rtol"),
    ({"approximations": ["nosuch"]}, "approximations"),
    ({"k": -1.0}, "k must be"),
    ({"geometry": "flat"}, "geometry"),
    ({"max_wall": -1.0}, "max_wall"),
])
def test_bad_grid_or_option_is_a_value_error_before_any_point(tmp_path, kwargs, match):
    """Hypothesis: a bad grid value, option or approximation name raises ValueError naming it, and nothing is
    written (the output directory is not even made).  Categorical."""
    args = {"I_values": [1e-5], "V_values": [1.0], **kwargs}
    out = tmp_path / "a"
    with pytest.raises(ValueError, match=match):
        atlas(args.pop("I_values"), args.pop("V_values"), out=out, max_workers=0, progress=False, **args)
    assert not out.exists()


def test_kill_and_resume(tmp_path, monkeypatch):
    """Hypothesis: SIGKILL of a running atlas loses no finished point, and running it again computes exactly the
    rest: each (I, V) once in results.jsonl, the records written before the kill unchanged, and all records
    equal to those of an uninterrupted atlas (exact equality: deterministic measures).

    A subprocess runs a 3 x 4 atlas on 2 workers with a test approximation that sleeps 0.3 s per point (only
    there: the sleep changes no value) and is killed once 3 records are on disk; the resume and the reference
    run in this process.
    """
    monkeypatch.setitem(APPROXIMATIONS, "test:slow", _atlas_approximations.slow)
    I, V = [1e-5, 1e-4, 1e-3], [1.0, 2.0, 3.0, 4.0]
    opts = {"t_transient": 2.0, "t_window": 2.0, "segments_per_branch": 2}
    kw = dict(approximations=["estimate", "test:slow"], options=opts, progress=False)
    out = tmp_path / "killed"
    code = (f"import sys; sys.path.insert(0, {TESTS!r})\n"
            "import _atlas_approximations\n"
            "from comparisons.atlas import APPROXIMATIONS, atlas\n"
            "APPROXIMATIONS['test:slow'] = _atlas_approximations.slow\n"
            "if __name__ == '__main__':\n"
            f"    atlas({I!r}, {V!r}, out={str(out)!r}, max_workers=2, approximations=['estimate', 'test:slow'], "
            f"options={opts!r}, progress=False)\n")
    results = out / "results.jsonl"
    log = open(tmp_path / "child.log", "w")
    env = dict(os.environ, PEELAPPROX_TEST_ATLAS_SLEEP="0.3")
    proc = subprocess.Popen([sys.executable, "-c", code], stdout=log, stderr=subprocess.STDOUT, env=env,
                            start_new_session=True)
    try:
        deadline = time.monotonic() + 120
        while not results.exists() or len(results.read_text().splitlines()) < 3:
            assert proc.poll() is None, f"atlas subprocess exited early: {(tmp_path / 'child.log').read_text()}"
            assert time.monotonic() < deadline, "no 3 records within 120 s"
            time.sleep(0.01)
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait(timeout=30)
    finally:
        try:
            os.killpg(proc.pid, signal.SIGKILL)  # the session started above: its workers too
        except (ProcessLookupError, PermissionError):
            pass
        log.close()
    before = _no_nan(results.read_text())
    assert 3 <= len(before) < 12, f"the kill did not interrupt the atlas ({len(before)} records)"
    res = atlas(I, V, out=out, max_workers=0, **kw)
    after = _no_nan(results.read_text())
    keys = [(r["I"], r["V"]) for r in after]
    assert len(keys) == len(set(keys)) == 12 and res.complete
    assert after[:len(before)] == before, "the resume rewrote a finished point"
    fresh = atlas(I, V, out=tmp_path / "fresh", max_workers=0, **kw)
    assert res.sweep.records == fresh.sweep.records
    assert load_atlas(out).sweep.records == fresh.sweep.records


@pytest.mark.parametrize("approximations", [
    ["--approximations", "estimate"],
    pytest.param([], marks=pytest.mark.slow, id="every-approximation"),
], ids=lambda a: "-".join(a[1:]) or "every-approximation")
def test_cli_atlas(tmp_path, capsys, approximations):
    """Hypothesis: ``peelapprox atlas`` on a 1 x 2 grid exits 0, writes the records, the four tables as CSV and
    JSON and (``--plot``) the maps as PNG, and prints the summary, equal to ``load_atlas(DIR).summary()``
    (exact equality through JSON); the same command again resumes (computes nothing: the records unchanged); a
    bad ``--V`` is exit status 2 naming it.  Categorical and exact.

    The default tier runs one approximation (``--approximations estimate``) and draws no maps: ``--plot`` and
    every kind of map (dynamics, errors, segments, sets) are drawn in the default tier by
    tests/test_atlas_sets.py's ``test_cli_sets_tables_and_maps`` (~1 s CPU of matplotlib per map).  Every
    registered approximation with ``--plot`` (33 maps, ~45 s CPU) is the slow case, covered in the default tier
    by the ``estimate`` case and that test (the same command, map writer and checks)."""
    out = tmp_path / "at"
    argv = ["atlas", "--V", "0.5,1", "--I", "1e-5", "--out", str(out), "--workers", "0", "--t-transient", "10",
            "--window", "5", "--segments", "2", *approximations, "--format", "json", "--quiet"]
    plot = not approximations
    assert main(argv + ["--plot"] * plot) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary == json.loads(json.dumps(load_atlas(out).summary()))
    for table in ("points", "errors", "segments", "summary"):
        assert (out / f"atlas_{table}.csv").is_file() and (out / f"atlas_{table}.json").is_file()
    if plot:
        maps = sorted(p.name for p in (out / "maps").iterdir())
        assert "dynamics.png" in maps and "error_estimate_slip_interval.png" in maps
        assert len(maps) == 1 + 6 * len(load_atlas(out).approximations) + 2
        assert all((out / "maps" / m).stat().st_size > 10_000 for m in maps)
    else:
        assert not (out / "maps").exists()
    before = (out / "results.jsonl").read_text()
    assert main(argv) == 0
    assert (out / "results.jsonl").read_text() == before
    capsys.readouterr()
    with pytest.raises(SystemExit) as exc:
        main(["atlas", "--V", "0.5:x:3", "--I", "1e-5", "--out", str(tmp_path / "bad")])
    assert exc.value.code == 2 and "--V" in capsys.readouterr().err
    assert not (tmp_path / "bad").exists()


def test_cost_projection(capsys):
    """Hypothesis: ``atlas_cost`` times every part at the sample points and projects mean-per-point x points /
    workers (the arithmetic exact to rounding, 1e-12 relative); ``peelapprox atlas --cost`` prints it.  The
    timings themselves are not asserted (they depend on the machine)."""
    cost = atlas_cost([1e-5, 1e-3], [1.0, 2.0, 3.0], sample=1, workers=2, options={**OPTS, "t_window": 1.0})
    assert cost.points == [(1e-3, 2.0)] and set(cost.times) >= {"exact", "segments", "regime", "approx:estimate"}
    assert all(len(t) == 1 and t[0] > 0 for t in cost.times.values())
    total = cost.rows()[-1]
    assert math.isclose(total["grid_wall_s"], sum(t[0] for t in cost.times.values()) * 6 / 2, rel_tol=1e-12)
    assert main(["atlas", "--V", "1,2", "--I", "1e-5", "--cost", "1", "--t-transient", "1", "--window", "1",
                 "--quiet"]) == 0
    assert "projected" in capsys.readouterr().out

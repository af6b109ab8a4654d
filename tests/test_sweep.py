"""(I, V) sweeps: the engine, crash safety and resume, executors, the CLI.

The solvers are deterministic and the records hold no timings, so records
from different executors, processes or runs are compared for *exact*
equality throughout: any difference would be a bug in the engine (a lost,
duplicated or mis-keyed point), not round-off.
"""

import json
import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import _sweep_measures  # noqa: F401  (registers "slowprod" and "flaky")
import numpy as np
import pytest

from comparisons.sweep import (
    MEASURES,
    SweepResult,
    load_sweep,
    parse_grid,
    register_measure,
    sweep,
)
from comparisons.sweep.store import lock as _lock
from peelapprox import PeelParams, estimate
from peelapprox.cli import main

TESTS = str(Path(__file__).resolve().parent)
I2, V2 = [1e-5, 1e-2], [1.0, 2.0]


def _lines(out) -> list[str]:
    p = Path(out) / "results.jsonl"
    return p.read_text().splitlines() if p.exists() else []


def _keys_once(out) -> list[tuple[float, float]]:
    keys = [(r["I"], r["V"]) for r in map(json.loads, _lines(out))]
    assert len(keys) == len(set(keys)), "a point was written twice"
    return keys


@pytest.fixture(scope="module")
def pool_result(tmp_path_factory):
    """2x2 sweep of regime and jumps on the default local process pool (2 spawned workers)."""
    out = tmp_path_factory.mktemp("pool") / "sw"
    t0 = time.perf_counter()
    res = sweep(I2, V2, ("regime", "jumps"), out=out, max_workers=2, progress=False)
    res.wall = time.perf_counter() - t0
    return res


def test_pool_values_match_direct_calls(pool_result):
    """Hypothesis: a pool sweep stores, per point, exactly what the measures return when called directly.

    Four records, one line each; ``values(key)[i, j]`` equals the direct call
    at ``(I_values[i], V_values[j])``.  Tolerance: exact equality, since both
    sides run the same deterministic code and JSON round-trips floats exactly.
    """
    res = pool_result
    assert res.complete and len(res.records) == 4 and len(_lines(res.out)) == 4
    assert sorted(_keys_once(res.out)) == sorted((I, V) for I in I2 for V in V2)
    labels, ratio = res.values("regime_label"), res.values("regime_inertia_ratio")
    count, drop = res.values("jumps_count"), res.values("jumps_mean_force_drop")
    assert labels.dtype == object and ratio.dtype == float and ratio.shape == (2, 2)
    for i, I in enumerate(I2):
        for j, V in enumerate(V2):
            p = PeelParams(V=V, I=I)
            e = estimate(p)
            assert labels[i, j] == e.label and ratio[i, j] == e.inertia_ratio
            direct = MEASURES["jumps"](p, {})
            assert direct["status"] == "ok"
            assert count[i, j] == direct["count"] and drop[i, j] == direct["mean_force_drop"]
            assert res.record(I, V)["status"] == "ok"
    m = json.loads((Path(res.out) / "sweep.json").read_text())
    assert m["I_values"] == I2 and m["V_values"] == V2 and m["measures"] == ["regime", "jumps"]
    assert m["options"] == {} and m["versions"]["numba"] and m["created"]


def test_jumps_measure_definitions():
    """Hypothesis: the jumps measure implements its documented statistics on the exact solution's jumps.

    Recomputed by a plain loop over the jump list of the same simulation
    (V=1, I=1e-5, window [10, 20] s): count, AB->CD count, mean interval,
    period between slips, mean force drop (F at AB->CD minus F at the next
    CD->AB).  Tolerance 1e-12 relative: same numbers summed in a different
    order.
    """
    from exact import simulate

    p = PeelParams(V=1.0, I=1e-5)
    got = MEASURES["jumps"](p, {"t_end": 20.0, "t_transient": 10.0})
    j = simulate(p, 20.0, t_transient=10.0, save="jumps", rtol=1e-10).jumps  # the measures' default rtol
    jl = list(j)
    assert jl and all(x.t >= 10.0 for x in jl)
    drops, slips = [], []
    for n, x in enumerate(jl):
        if x.from_branch == "AB" and x.to_branch == "CD":
            slips.append(x.t)
            nxt = next((y for y in jl[n + 1:] if y.from_branch == "CD" and y.to_branch == "AB"), None)
            if nxt is not None:
                drops.append(x.F - nxt.F)
    assert got["count"] == len(jl) and got["n_slips"] == len(slips) and len(drops) >= len(slips) - 1
    assert math.isclose(got["mean_interval"], (jl[-1].t - jl[0].t) / (len(jl) - 1), rel_tol=1e-12)
    assert math.isclose(got["mean_period"], (slips[-1] - slips[0]) / (len(slips) - 1), rel_tol=1e-12)
    assert math.isclose(got["mean_force_drop"], sum(drops) / len(drops), rel_tol=1e-12)
    assert got["mean_force_drop"] > 0


def test_breakdown_is_a_result_not_an_error(tmp_path):
    """Hypothesis: a ModelBreakdown (V=0.5, I=1e-4: F(1 + sin a) falls to f(0+) on AB) is recorded as
    ``jumps_status = "breakdown:no_root"`` (and so the point's status), not as an error, and ``values`` is
    NaN there only.

    No tolerance: categorical outcome; V=0.5, I=1e-5 on the same sweep runs normally.
    """
    res = sweep([1e-5, 1e-4], [0.5], "jumps", out=tmp_path / "sw", executor="serial", progress=False)
    bad, good = res.record(1e-4, 0.5), res.record(1e-5, 0.5)
    assert bad["status"] == bad["jumps_status"] == "breakdown:no_root" and bad["jumps_t_breakdown"] > 0
    assert good["jumps_status"] == "ok"
    c = res.values("jumps_count")
    assert np.isnan(c[1, 0]) and c[0, 0] == good["jumps_count"]
    assert list(res.values("jumps_status")[:, 0]) == ["ok", "breakdown:no_root"]


def test_kill_and_resume(tmp_path):
    """Hypothesis: SIGKILL of a running sweep loses no finished point, and resuming computes exactly the rest.

    A subprocess sweeps 12 points with a measure that sleeps 0.25 s per point
    (2 workers, ~1.5 s of work); it is killed (SIGKILL, the sweeping process
    only) once >= 3 records are on disk.  Then: its orphaned workers exit
    (they watch their parent), every record on disk survives, an in-process
    resume writes each missing point once (each (I, V) exactly once in
    results.jsonl) and the records equal those of a fresh uninterrupted sweep
    (in-process, without the sleep, which changes no value).
    Exact equality: deterministic measures.
    """
    I, V = [1e-5, 1e-4, 1e-3], [0.5, 1.0, 2.0, 4.0]
    measures, opts = ("regime", "slowprod"), {"sleep": 0.25}
    out = tmp_path / "killed"
    code = (f"import sys; sys.path.insert(0, {TESTS!r})\n"
            "import _sweep_measures\n"
            "from comparisons.sweep import sweep\n"
            f"sweep({I!r}, {V!r}, {measures!r}, out={str(out)!r}, max_workers=2, options={opts!r}, progress=False)\n")
    log = open(tmp_path / "child.log", "w")
    proc = subprocess.Popen([sys.executable, "-c", code], stdout=log, stderr=subprocess.STDOUT, start_new_session=True)
    try:
        deadline = time.monotonic() + 90
        while len(_lines(out)) < 3:
            assert proc.poll() is None, f"sweep subprocess exited early: {(tmp_path / 'child.log').read_text()}"
            assert time.monotonic() < deadline, "no 3 records within 90 s"
            time.sleep(0.01)
        try:
            import psutil

            workers = psutil.Process(proc.pid).children(recursive=True)
        except ImportError:  # pragma: no cover - psutil comes with the distributed extra
            workers = []
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait(timeout=30)
        if workers:
            gone, alive = psutil.wait_procs(workers, timeout=10)
            assert not alive, f"orphaned workers still running: {alive}"
    finally:
        try:
            os.killpg(proc.pid, signal.SIGKILL)  # the session started above, in case anything is left
        except (ProcessLookupError, PermissionError):
            pass
        log.close()
    before = [json.loads(line) for line in _lines(out)]  # complete lines survived the kill
    assert 3 <= len(before) < 12, f"kill did not interrupt the sweep ({len(before)} records)"

    res = sweep(I, V, measures, out=out, max_workers=2, options=opts, progress=False)
    keys = _keys_once(out)
    assert len(keys) == 12 and res.complete
    after = {(r["I"], r["V"]): r for r in map(json.loads, _lines(out))}
    assert all(after[(r["I"], r["V"])] == r for r in before), "resume rewrote a finished point"
    # the reference: uninterrupted, in-process, without the sleep (which changes no value)
    fresh = sweep(I, V, measures, out=tmp_path / "fresh", executor="serial", options={"sleep": 0.0}, progress=False)
    assert res.records == fresh.records


def test_truncated_last_line_is_ignored_and_recomputed(tmp_path):
    """Hypothesis: a last line cut off mid-write (no newline) is ignored by ``load_sweep`` and, on resume,
    dropped from the file and recomputed; the earlier lines stay untouched.

    Exact equality: the recomputed record is the same deterministic result.
    """
    out = tmp_path / "sw"
    full = sweep(I2, V2, ("regime", "slowprod"), out=out, executor="serial", progress=False)
    path = out / "results.jsonl"
    text = path.read_text()
    lines = text.splitlines(keepends=True)
    cut = "".join(lines[:-1]) + lines[-1][: len(lines[-1]) // 2]  # killed while writing the 4th record
    path.write_text(cut)
    part = load_sweep(out)
    assert len(part.records) == 3 and not part.complete and len(part.missing()) == 1
    assert path.read_text() == cut  # load_sweep is read-only
    res = sweep(I2, V2, ("regime", "slowprod"), out=out, executor="serial", progress=False)
    assert path.read_text().startswith("".join(lines[:-1]))
    assert len(_keys_once(out)) == 4 and res.records == full.records


def test_malformed_middle_line_raises(tmp_path):
    """Hypothesis: a corrupt *complete* line is not silently dropped: resume raises ValueError naming the line."""
    out = tmp_path / "sw"
    sweep(I2, V2, "slowprod", out=out, executor="serial", progress=False)
    lines = _lines(out)
    (out / "results.jsonl").write_text(lines[0] + "\n" + "{not json\n" + "\n".join(lines[1:]) + "\n")
    with pytest.raises(ValueError, match="line 2"):
        sweep(I2, V2, "slowprod", out=out, executor="serial", progress=False)


def test_manifest_mismatch_and_no_overwrite(tmp_path):
    """Hypothesis: an out directory holding another sweep (grid, measures or options differ) is refused
    with a ValueError naming what differs; resume=False never overwrites; a stranger's directory is refused.
    """
    out = tmp_path / "sw"
    sweep(I2, V2, "slowprod", out=out, executor="serial", progress=False, options={"sleep": 0.0})
    kw = dict(out=out, executor="serial", progress=False)
    with pytest.raises(ValueError, match="V_values: existing"):
        sweep(I2, [1.0, 3.0], "slowprod", options={"sleep": 0.0}, **kw)
    with pytest.raises(ValueError, match="I_values: existing"):
        sweep([1e-5], V2, "slowprod", options={"sleep": 0.0}, **kw)
    with pytest.raises(ValueError, match="measures: existing"):
        sweep(I2, V2, ("slowprod", "regime"), options={"sleep": 0.0}, **kw)
    with pytest.raises(ValueError, match="options differ in 'sleep'"):
        sweep(I2, V2, "slowprod", options={"sleep": 0.1}, **kw)
    with pytest.raises(ValueError, match="resume=False"):
        sweep(I2, V2, "slowprod", options={"sleep": 0.0}, resume=False, **kw)
    assert len(_lines(out)) == 4
    other = tmp_path / "other"
    other.mkdir()
    (other / "notes.txt").write_text("mine")
    with pytest.raises(ValueError, match="not empty"):
        sweep(I2, V2, "slowprod", out=other, executor="serial", progress=False)


def test_resume_tolerates_rebuilt_grid_roundoff(tmp_path):
    """Hypothesis: a grid equal to the manifest's up to 1e-15 relative (a geomspace rebuilt on another
    machine) resumes, and the manifest's exact values stay the record keys (no duplicates).
    """
    out = tmp_path / "sw"
    sweep(I2, V2, "slowprod", out=out, executor="serial", progress=False)
    res = sweep([x * (1 + 1e-15) for x in I2], V2, "slowprod", out=out, executor="serial", progress=False)
    assert list(res.I_values) == I2 and len(_keys_once(out)) == 4


def test_validation_messages(tmp_path):
    """Hypothesis: bad arguments raise ValueError naming the argument and its valid range (or the known measures).
    (max_workers is checked by peelapprox.validate.integer, whose one message pattern replaced the
    hand-written "an integer in [0, inf) (0: in this process)".)"""
    out = tmp_path / "sw"
    with pytest.raises(ValueError, match=r"I_values .*empty array"):
        sweep([], V2, out=out)
    with pytest.raises(ValueError, match=r"V_values must be finite and in \[1e-6, 100\] \(every element\), got -2.0"):
        sweep(I2, [1.0, -2.0], out=out)
    with pytest.raises(ValueError, match="duplicates"):
        sweep(I2, [1.0, 1.0], out=out)
    with pytest.raises(ValueError, match=r"unknown measure\(s\) \['nope'\]; known: \[.*'jumps'.*'regime'"):
        sweep(I2, V2, "regime,nope", out=out)
    with pytest.raises(ValueError, match=r"max_workers must be an integer in \[0, 1e15\], got -1"):
        sweep(I2, V2, out=out, max_workers=-1)
    with pytest.raises(ValueError, match="options must be JSON-serialisable"):
        sweep(I2, V2, out=out, options={"x": object()})
    with pytest.raises(ValueError, match="k must be finite"):
        sweep(I2, V2, out=out, options={"k": -1.0})
    with pytest.raises(ValueError, match=r"tmp_closure.*(cannot be pickled|importable module)"):
        lock = __import__("threading").Lock()
        register_measure("tmp_closure", lambda p, o: {"x": int(lock.locked())}, replace=True)
        try:
            sweep(I2, V2, "tmp_closure", out=out, executor="processes")
        finally:
            MEASURES.pop("tmp_closure")
    with pytest.raises(ValueError, match="already registered"):
        register_measure("regime", _sweep_measures.slowprod)
    assert not out.exists() or not any(out.iterdir())


def test_failing_point_is_recorded_and_sweep_goes_on(tmp_path):
    """Hypothesis: a measure raising at some points records ``status = "error: <Type>: <msg>"`` there,
    the other measures still run at those points, and the remaining points are computed normally.
    """
    res = sweep(I2, [1.0, 2.0, 3.0], ("slowprod", "flaky"), out=tmp_path / "sw", executor="serial",
                progress=False, options={"fail_at_V": 2.0})
    assert res.complete
    for r in res.records:
        if r["V"] >= 2.0:
            assert r["status"] == r["flaky_status"] == f"error: RuntimeError: boom at V={r['V']:g}"
            assert "flaky_x" not in r and r["slowprod_value"] == r["I"] * r["V"]
        else:
            assert r["status"] == "ok" and r["flaky_x"] == 1.0
    x = res.values("flaky_x")
    assert np.all(np.isnan(x[:, 1:])) and np.all(x[:, 0] == 1.0)


def test_progress_callable_and_stderr(tmp_path, capsys):
    """Hypothesis: progress(done, total, record) is called once per computed point with done counting
    resumed points; progress=True prints one line per point with an ETA on stderr.
    """
    calls = []
    out = tmp_path / "sw"
    sweep(I2, [1.0], "slowprod", out=out, executor="serial", progress=lambda d, t, r: calls.append((d, t, r["V"])))
    assert calls == [(1, 2, 1.0), (2, 2, 1.0)]
    sweep(I2, [1.0, 2.0], "slowprod", out=tmp_path / "sw2", executor="serial", progress=True)
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 4 and err[-1].startswith("sweep [4/4]") and "ETA" in err[-1]


def test_locked_out_dir_is_refused(tmp_path):
    """Hypothesis: a second sweep cannot write into a directory another sweep is writing (flock)."""
    out = tmp_path / "sw"
    out.mkdir()
    held = _lock(str(out))
    try:
        with pytest.raises(RuntimeError, match="in use by another sweep"):
            sweep(I2, V2, "slowprod", out=out, executor="serial", progress=False)
    finally:
        held.close()
    assert len(sweep(I2, V2, "slowprod", out=out, executor="serial", progress=False).records) == 4


def test_csv_and_load_roundtrip(pool_result, tmp_path):
    """Hypothesis: load_sweep reproduces the SweepResult exactly and to_csv writes one full-precision row per
    point with the columns of keys() (exact: floats are written with repr).
    """
    res = load_sweep(pool_result.out)
    assert isinstance(res, SweepResult) and res.records == pool_result.records and res.rows() == res.records
    path = tmp_path / "r.csv"
    res.to_csv(path)
    import csv

    rows = list(csv.DictReader(open(path)))
    assert list(rows[0]) == res.keys() and len(rows) == 4
    assert [float(r["regime_inertia_ratio"]) for r in rows] == [r["regime_inertia_ratio"] for r in res.records]


def test_parse_grid():
    """Hypothesis: range specs give linspace / exact-endpoint geometric grids and comma lists; bad specs name the
    flag."""
    assert list(parse_grid("0.4:4:10")) == list(np.linspace(0.4, 4, 10))
    g = parse_grid("1e-5:1e-2:4:log")
    assert g[0] == 1e-5 and g[-1] == 1e-2 and np.allclose(np.diff(np.log10(g)), 1.0, rtol=1e-12)
    assert list(parse_grid("1, 2,3")) == [1.0, 2.0, 3.0]
    with pytest.raises(ValueError, match="--I"):
        parse_grid("1:2", name="--I")
    with pytest.raises(ValueError, match="log range"):
        parse_grid("0:1:3:log")


def test_dask_executor_matches_pool(pool_result, tmp_path):
    """Hypothesis: a dask executor (``Client(LocalCluster(...)).get_executor()``) gives the same records
    as the local process pool: the engine is executor-agnostic.  Exact equality (deterministic measures).
    """
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None) as cl, \
            distributed.Client(cl) as client:
        res = sweep(I2, V2, ("regime", "jumps"), out=tmp_path / "dask", executor=client.get_executor(),
                    progress=False)
    assert res.records == pool_result.records
    assert len(_keys_once(tmp_path / "dask")) == 4


@pytest.mark.slow
def test_dask_worker_processes_match_pool(pool_result, tmp_path):
    """Hypothesis: with separate dask worker processes (tasks pickled, measures imported by the workers)
    the records are still identical to the process pool's.  Exact equality.
    """
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cl, \
            distributed.Client(cl) as client:
        res = sweep(I2, V2, ("regime", "jumps"), out=tmp_path / "dask", executor=client.get_executor(),
                    progress=False)
    assert res.records == pool_result.records


@pytest.mark.slow
def test_pool_equals_serial_on_larger_grid(tmp_path):
    """Hypothesis: on a 4x5 grid spanning all regimes (incl. model breakdowns) pool and in-process sweeps
    give identical records.  Exact equality (deterministic solvers).
    """
    I, V = parse_grid("1e-5:1e-2:4:log"), parse_grid("0.4:4:5")
    a = sweep(I, V, ("regime", "jumps"), out=tmp_path / "a", max_workers=2, progress=False)
    b = sweep(I, V, ("regime", "jumps"), out=tmp_path / "b", executor="serial", progress=False)
    assert a.records == b.records and a.complete
    assert any(r["jumps_status"].startswith("breakdown:") for r in a.records)


def test_cli_smoke(tmp_path, capsys):
    """Hypothesis: ``peelapprox sweep`` on a 2x2 regime grid writes the manifest, one JSONL line per point,
    results.csv and the phase-diagram PNG, prints the table, and a rerun resumes (computes nothing new).
    """
    out = tmp_path / "sw"
    argv = ["sweep", "--I", "1e-5:1e-2:2:log", "--V", "1,2", "--measure", "regime", "--out", str(out),
            "--workers", "0", "--format", "json"]
    assert main(argv + ["--plot", "regime_label"]) == 0
    rows = json.loads(capsys.readouterr().out)
    assert len(rows) == 4 and {r["regime_label"] for r in rows} == {"low inertia, low V", "high inertia, low V"}
    assert rows[0]["I"] == 1e-5 and rows[-1]["I"] == 1e-2
    assert len(_lines(out)) == 4 and (out / "results.csv").exists() and (out / "sweep.json").exists()
    assert (out / "regime_label.png").stat().st_size > 10_000
    before = (out / "results.jsonl").read_text()
    assert main(argv[:-1] + ["md", "--quiet"]) == 0
    cap = capsys.readouterr()
    assert cap.out.startswith("| I | V | status | regime_label") and len(cap.out.splitlines()) == 6
    assert "holds a sweep with 4/4 points done" in cap.err
    assert (out / "results.jsonl").read_text() == before
    with pytest.raises(SystemExit) as exc:
        main(["sweep", "--I", "1e-5", "--V", "1,3", "--out", str(out), "--workers", "0"])
    assert exc.value.code == 2 and "V_values: existing" in capsys.readouterr().err


def test_plot_phase_diagram_numeric(pool_result, tmp_path):
    """Hypothesis: a numeric key draws a pcolormesh with a colour bar over (V, I) (file written, two axes)."""
    from peelapprox.plotting import plot_phase_diagram

    fig = plot_phase_diagram(pool_result, "jumps_mean_period", None)
    assert len(fig.axes) == 2 and fig.axes[0].get_yscale() == "log"
    fig.savefig(tmp_path / "p.png")
    assert (tmp_path / "p.png").stat().st_size > 5_000


# ------------------------------------------------------------------------- poisoned sweeps (bugs once, now refused)

@pytest.mark.parametrize("measures, options, match", [
    ("jumps", {"t_end": 1.0, "t_transient": 5.0}, r"t_end must be greater than t_transient = 5"),
    ("jumps", {"rtol": 1.0}, r"rtol must be finite and in \[1e-14, 0\.01\]"),
    ("period", {"rtol": 1e-16}, r"rtol must be finite and in \[1e-14, 0\.01\]"),
    ("jumps", {"t_transient": -1.0}, r"t_transient must be finite and in \[0, 1e6\]"),
    ("jumps", {"t_transient": 1e6, "t_end": 1e6 + 1}, r"t_end must be finite and in \(0, 1e6\]"),
    ("period", {"alpha0": 4.0}, r"alpha0 must be finite and in \[-3.14159, 3.14159\]"),
    ("period", {"alpha0": float("nan")}, r"alpha0 must be finite"),
    ("period", {"period_rtol": 0.0}, r"period_rtol must be finite and in \(0, inf\)"),
    ("lyapunov", {"lyapunov_time": -1.0}, r"lyapunov_time must be finite and in \[0.01, 1e6\]"),
    ("lyapunov", {"lyapunov_time": 1e300}, r"lyapunov_time must be finite and in \[0.01, 1e6\]"),
    ("lyapunov", {"t_transient": "soon"}, r"t_transient must be a real number"),
    ("regime", {"geometry": "flat"}, r"geometry must be one of"),
    ("regime", {"R": 0.0}, r"R must be finite and in \[0.0001, 10\]"),
])
def test_invalid_options_rejected_before_any_point(tmp_path, measures, options, match):
    """Hypothesis: every option a built-in measure reads is checked before the first point, so an invalid
    one raises ValueError naming it and its valid range, and nothing is written (no manifest to pin the
    bad options, no error records that a resume would keep).

    Reproducer: ``t_end=1, t_transient=5`` or ``rtol=1`` used to compute every point
    as an error record.  No tolerance: categorical outcome.
    """
    out = tmp_path / "sw"
    with pytest.raises(ValueError, match=match):
        sweep(I2, V2, measures, out=out, executor="serial", options=options, progress=False)
    assert not out.exists()


def test_cli_invalid_options_exit_2_and_write_nothing(tmp_path, capsys):
    """Hypothesis: ``peelapprox sweep --t-end 1 --t-transient 5`` stops with exit status 2 and a message
    naming t_end before any point, leaving no directory behind (it used to exit 1 with every point an error
    record, poisoning the directory)."""
    out = tmp_path / "sw"
    with pytest.raises(SystemExit) as exc:
        main(["sweep", "--I", "1e-5", "--V", "1", "--measure", "jumps", "--out", str(out), "--workers", "0",
              "--t-end", "1", "--t-transient", "5", "--quiet"])
    assert exc.value.code == 2 and "t_end must be greater than t_transient" in capsys.readouterr().err
    assert not out.exists()


def test_point_status_reflects_its_measures(tmp_path):
    """Hypothesis: a point's status is the first non-ok status among its measures: a ModelBreakdown of every
    measure (V=0.5, I=1e-4, the level reaches f(0+)) is ``status = "breakdown:no_root"``, not ``"ok"``; a raising
    measure outranks a breakdown; a point whose measures all succeed is ``"ok"``.

    Reproducer of a poisoned sweep.  No tolerance: categorical outcome.
    """
    res = sweep([1e-5, 1e-4], [0.5], ("regime", "jumps", "flaky"), out=tmp_path / "sw", executor="serial",
                progress=False, options={"fail_at_V": 2.0})
    assert res.record(1e-4, 0.5)["status"] == "breakdown:no_root"
    assert res.record(1e-5, 0.5)["status"] == "ok"
    res = sweep([1e-4], [0.5], ("jumps", "flaky"), out=tmp_path / "sw2", executor="serial", progress=False,
                options={"fail_at_V": 0.5})
    rec = res.record(1e-4, 0.5)
    assert rec["status"] == "error: RuntimeError: boom at V=0.5" and rec["jumps_status"] == "breakdown:no_root"


def test_retry_failed(tmp_path, monkeypatch):
    """Hypothesis: error records count as finished on a plain resume (nothing recomputed, the file
    unchanged), and ``retry_failed=True`` recomputes exactly those points, leaving one record per point
    and the ok records byte for byte as they were.

    Reproducer (failed points could never be retried).  Exact equality: deterministic.
    """
    out = tmp_path / "sw"
    monkeypatch.setenv("PEELAPPROX_TEST_FAIL", "1")
    res = sweep(I2, V2, "envfail", out=out, executor="serial", progress=False)
    assert [r["status"] for r in res.records] == ["error: OSError: transient failure at V=1",
                                                   "error: OSError: transient failure at V=2"] * 2
    monkeypatch.delenv("PEELAPPROX_TEST_FAIL")
    before = (out / "results.jsonl").read_text()
    assert sweep(I2, V2, "envfail", out=out, executor="serial", progress=False).records == res.records
    assert (out / "results.jsonl").read_text() == before
    res = sweep(I2, V2, "envfail", out=out, executor="serial", progress=False, retry_failed=True)
    assert res.complete and all(r["status"] == "ok" and r["envfail_x"] == r["I"] + r["V"] for r in res.records)
    assert len(_keys_once(out)) == 4


def test_cli_retry_failed(tmp_path, capsys, monkeypatch):
    """Hypothesis: ``--retry-failed`` recomputes the error points of a CLI sweep (exit 1 while a point failed,
    0 once all are ok) and a plain rerun does not."""
    argv = ["sweep", "--I", "1e-5", "--V", "1,2", "--measure", "envfail", "--out", str(tmp_path / "sw"),
            "--workers", "0", "--quiet", "--format", "json"]
    monkeypatch.setenv("PEELAPPROX_TEST_FAIL", "1")
    assert main(argv) == 1
    monkeypatch.delenv("PEELAPPROX_TEST_FAIL")
    assert main(argv) == 1
    capsys.readouterr()
    assert main(argv + ["--retry-failed"]) == 0
    rows = json.loads(capsys.readouterr().out)
    assert [r["envfail_x"] for r in rows] == [1.00001, 2.00001]


def test_max_workers_0_runs_in_process(tmp_path):
    """Hypothesis: ``max_workers=0`` means "in this process", as the CLI's ``--workers 0`` does, so even a
    lambda (which no worker could import) is evaluated; it used to raise ValueError."""
    register_measure("tmp_inproc", lambda p, o: {"x": p.V * 2}, replace=True)
    try:
        res = sweep(I2, V2, "tmp_inproc", out=tmp_path / "sw", max_workers=0, progress=False)
    finally:
        MEASURES.pop("tmp_inproc")
    assert res.complete and [r["tmp_inproc_x"] for r in res.records] == [2.0, 4.0, 2.0, 4.0]


def test_notebook_measure_on_process_pool(tmp_path):
    """Hypothesis: a measure defined in ``__main__`` without a file (a notebook, ``python -c``) works on the
    default process pool: the engine ships it by value (cloudpickle), since no worker can import it.

    Reproducer: it used to fail at every point with LookupError.  Exact equality of
    I*V: the same float product in the worker.
    """
    pytest.importorskip("cloudpickle")
    code = ("import json, sys\n"
            "from peelapprox import register_measure, sweep\n"
            "def nb(params, options):\n"
            "    return {'x': params.I * params.V}\n"
            "register_measure('nb', nb)\n"
            f"res = sweep([1e-5, 1e-3], [2.0], 'nb', out={str(tmp_path / 'sw')!r}, max_workers=1, progress=False)\n"
            "print(json.dumps(res.records))\n")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    recs = json.loads(proc.stdout)
    assert [(r["status"], r["nb_x"]) for r in recs] == [("ok", 1e-5 * 2.0), ("ok", 1e-3 * 2.0)]


def test_unshippable_measure_fails_before_any_point(tmp_path, monkeypatch):
    """Hypothesis: without cloudpickle, a measure from ``__main__`` (or a lambda) on a process pool is a
    ValueError before any point, saying to define it in an importable module or use max_workers=0; nothing
    is written.  (It used to run every point on the pool as an error record.)"""
    from comparisons.sweep import task as sw

    monkeypatch.setattr(sw, "_cloudpickle", lambda: None)

    def nb(params, options):
        return {"x": 1.0}

    nb.__module__, nb.__qualname__ = "__main__", "nb"
    register_measure("tmp_main", nb, replace=True)
    try:
        with pytest.raises(ValueError, match=r"tmp_main.*importable module.*max_workers=0"):
            sweep(I2, V2, "tmp_main", out=tmp_path / "sw", executor="processes", max_workers=1, progress=False)
    finally:
        MEASURES.pop("tmp_main")
    assert not (tmp_path / "sw").exists()


def _partial_sweep(out):
    """A 2x2 slowprod sweep with its last record removed (one point left to compute)."""
    sweep(I2, V2, "slowprod", out=out, executor="serial", progress=False)
    lines = _lines(out)
    (out / "results.jsonl").write_text("\n".join(lines[:-1]) + "\n")
    return lines


@pytest.mark.parametrize("name", ["results.jsonl", "sweep.json", ".lock"])
def test_symlinks_are_not_followed(tmp_path, name):
    """Hypothesis: a sweep file that is a symbolic link (here to a file outside ``out``) is refused with a
    ValueError naming it, and the file it points to is not changed; load_sweep refuses it too.

    Reproducer: a resume appended to whatever ``results.jsonl`` pointed to.
    """
    out = tmp_path / "sw"
    _partial_sweep(out)
    outside = tmp_path / f"outside-{name}"
    (out / name).rename(outside)
    (out / name).symlink_to(outside)
    before = outside.read_bytes()
    with pytest.raises(ValueError, match=f"{name}.*symbolic link"):
        sweep(I2, V2, "slowprod", out=out, executor="serial", progress=False)
    if name != ".lock":
        with pytest.raises(ValueError, match=f"{name}.*symbolic link"):
            load_sweep(out)
    assert outside.read_bytes() == before


_MANIFEST_DAMAGE = {
    "not an object": lambda m: [m],
    "I_values a string": lambda m: {**m, "I_values": "1e-5"},
    "I_values 1e400": lambda m: {**m, "I_values": [float("inf"), 1e-2]},
    "I_values holding bools": lambda m: {**m, "I_values": [True, 1e-2]},
    "V_values missing": lambda m: {k: v for k, v in m.items() if k != "V_values"},
    "measures a number": lambda m: {**m, "measures": 3},
    "measures missing": lambda m: {k: v for k, v in m.items() if k != "measures"},
    "options a list": lambda m: {**m, "options": [1]},
    "versions a string": lambda m: {**m, "versions": "new"},
}


@pytest.mark.parametrize("damage", sorted(_MANIFEST_DAMAGE))
def test_malformed_manifest_gives_the_clear_error(tmp_path, damage):
    """Hypothesis: a crafted or corrupted manifest (wrong types, missing keys, non-finite grid values) makes
    load_sweep and a resume raise ValueError saying the manifest is malformed, never another exception.

    Reproducer (these gave TypeError/KeyError/AttributeError tracebacks).
    """
    out = tmp_path / "sw"
    _partial_sweep(out)
    path = out / "sweep.json"
    path.write_text(json.dumps(_MANIFEST_DAMAGE[damage](json.loads(path.read_text()))))
    with pytest.raises(ValueError, match="malformed manifest"):
        load_sweep(out)
    with pytest.raises(ValueError, match="malformed manifest"):
        sweep(I2, V2, "slowprod", out=out, executor="serial", progress=False)


@pytest.mark.parametrize("line", [
    '{"I":1e400,"V":1.0,"status":"ok"}',
    '{"I":1e-05,"V":Infinity,"status":"ok"}',
    '{"I":"1e-05","V":1.0,"status":"ok"}',
    '{"I":true,"V":1.0,"status":"ok"}',
    '{"I":1e-05,"V":1.0}',
    '{"I":1e-05,"V":1.0,"status":5}',
    '{"I":1e-05,"V":1.0,"status":"ok","slowprod_value":[[1,[2]]]}',
    '{"I":1e-05,"V":1.0,"status":"ok","slowprod_value":[{"a":1}]}',
    '{"I":1e-05,"V":1.0,"status":"ok","slowprod_value":1' + "0" * 400 + '}',
    '[1, 2]',
    '[' * 100000,
], ids=["I 1e400", "V Infinity", "I a string", "I a bool", "status missing", "status a number", "a 3-deep list",
        "a list of objects",
        "a 401-digit int", "not an object", "deep nesting"])
def test_malformed_record_gives_the_clear_error(tmp_path, line):
    """Hypothesis: a crafted or corrupted complete line of results.jsonl (non-finite or non-numeric I/V,
    missing status, non-scalar values, an int no float can hold, deep nesting) makes load_sweep and a resume
    raise ValueError naming the line as malformed, never another exception.

    Reproducer (``I=1e400`` and wrong types gave tracebacks).
    """
    out = tmp_path / "sw"
    lines = _partial_sweep(out)
    (out / "results.jsonl").write_text(lines[0] + "\n" + line + "\n")
    with pytest.raises(ValueError, match="line 2: malformed record"):
        load_sweep(out)
    with pytest.raises(ValueError, match="line 2: malformed record"):
        sweep(I2, V2, "slowprod", out=out, executor="serial", progress=False)


@pytest.fixture
def read_only(monkeypatch):
    """Make ``out`` (the returned callable's argument) read-only for this process.

    Every open for writing of a path under it fails with EACCES, through ``open`` and ``os.open`` alike:
    ``chmod`` cannot do this here, since the tests may run as root, whom permissions do not stop.
    """
    import builtins
    import errno

    roots: list[str] = []
    real_open, real_os_open = builtins.open, os.open
    write_flags = os.O_WRONLY | os.O_RDWR | os.O_CREAT | os.O_APPEND | os.O_TRUNC

    def denied(path) -> bool:
        p = os.path.abspath(os.fspath(path)) if isinstance(path, (str, bytes, os.PathLike)) else ""
        return any(p == r or p.startswith(r + os.sep) for r in roots)

    def fake_open(file, mode="r", *a, **k):
        if denied(file) and any(c in mode for c in "wax+"):
            raise PermissionError(errno.EACCES, "Permission denied", os.fspath(file))
        return real_open(file, mode, *a, **k)

    def fake_os_open(path, flags, *a, **k):
        if denied(path) and flags & write_flags:
            raise PermissionError(errno.EACCES, "Permission denied", os.fspath(path))
        return real_os_open(path, flags, *a, **k)

    def make(out):
        roots.append(os.path.abspath(os.fspath(out)))
        monkeypatch.setattr(builtins, "open", fake_open)
        monkeypatch.setattr(os, "open", fake_os_open)

    return make


def test_read_only_complete_sweep_loads_and_reports(tmp_path, capsys, read_only):
    """Hypothesis: a complete sweep in a directory this process cannot write is returned by ``sweep`` (nothing
    to compute, so nothing to write) and reported by the CLI (exit 0, the table printed, results.csv skipped
    with a note); an incomplete one is a ValueError saying how many points remain and that out is not
    writable.  Exact equality of the records: they are read back unchanged.

    Reproducer (it failed even to report a complete sweep).
    """
    out = tmp_path / "sw"
    full = sweep(I2, V2, "slowprod", out=out, executor="serial", progress=False)
    part = tmp_path / "part"
    _partial_sweep(part)
    read_only(out)
    read_only(part)
    res = sweep(I2, V2, "slowprod", out=out, executor="serial", progress=False)
    assert res.complete and res.records == full.records
    assert main(["sweep", "--I", "1e-5,1e-2", "--V", "1,2", "--measure", "slowprod", "--out", str(out),
                 "--workers", "0", "--quiet", "--format", "json"]) == 0
    cap = capsys.readouterr()
    assert json.loads(cap.out) == full.records and "cannot write" in cap.err
    with pytest.raises(ValueError, match=r"not writable.*1 of 4 points"):
        sweep(I2, V2, "slowprod", out=part, executor="serial", progress=False)


def test_python_m_comparisons_sweep_is_the_cli(tmp_path):
    """Hypothesis: ``python -m comparisons.sweep ARGS`` is ``peelapprox sweep ARGS``: a one-point ``regime``
    sweep in a subprocess writes the record the in-process API writes (exact equality: deterministic
    closed form)."""
    out = tmp_path / "m"
    proc = subprocess.run([sys.executable, "-m", "comparisons.sweep", "--I", "1e-5", "--V", "1", "--out", str(out),
                           "--workers", "0", "--format", "json"], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    ref = sweep([1e-5], [1.0], "regime", out=tmp_path / "api", max_workers=0, progress=False)
    assert json.loads(proc.stdout) == ref.rows()


def test_a_script_without_main_guard_sweeps_on_threads(tmp_path):
    """Hypothesis: ``sweep()`` at a script's top level (no ``if __name__ == "__main__":``) runs on the default
    thread pool, whose threads re-run nothing of the script: it exits 0, the script's top level ran once, and
    its 4 records are those of a serial sweep (same values, exact)."""
    import subprocess
    import sys

    script = tmp_path / "plain.py"
    script.write_text(
        "import json, sys\n"
        "from comparisons.sweep import sweep\n"
        "print('top level ran', flush=True)\n"
        f"r = sweep([1e-5, 1e-3], [1.0, 2.0], 'regime', out={str(tmp_path / 'thr')!r}, progress=False)\n"
        f"s = sweep([1e-5, 1e-3], [1.0, 2.0], 'regime', out={str(tmp_path / 'ser')!r}, max_workers=0, progress=False)\n"
        "key = lambda x: (x['I'], x['V'])\n"
        "strip = lambda rs: [{k: v for k, v in x.items() if 'wall' not in k} for x in sorted(rs, key=key)]\n"
        "print('equal', strip(r.records) == strip(s.records))\n")
    env = dict(__import__("os").environ, PYTHONPATH=str(Path(__file__).resolve().parents[1]))
    done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=300, env=env,
                          cwd=tmp_path)
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.count("top level ran") == 1 and "equal True" in done.stdout

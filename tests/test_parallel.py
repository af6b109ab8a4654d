"""The local worker pools (peelapprox.parallel): same values on every kind, a script without a ``__main__``
guard, a worker's death as a named loss (not a hang), BLAS limits in the workers, no nested pools, Ctrl-C.

Values from different pools are compared for *exact* equality: the solvers are deterministic and a point's
value cannot depend on where it ran; any difference would be a transport or bookkeeping bug, not round-off.
"""

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from comparisons.sweep import sweep
from peelapprox import parallel
from peelapprox.parallel import map_points

ROOT = str(Path(__file__).resolve().parents[1])
pytest.importorskip("loky")


def _collect(fn, tasks, **kw):
    out: dict = {}
    lost = map_points(fn, tasks, out.__setitem__, **kw)
    return out, lost


def _pid_and_env(x):
    return os.getpid(), os.environ.get("PEELAPPROX_WORKER"), parallel.default_kind()


def _blas_threads(x):
    """The BLAS/OpenMP pools threadpoolctl sees in this process after numpy is imported, and their sizes."""
    import numpy  # noqa: F401  (loads OpenBLAS/MKL)
    from threadpoolctl import threadpool_info

    return [(d["internal_api"], d["num_threads"]) for d in threadpool_info()], os.environ.get("OPENBLAS_NUM_THREADS")


def _die_at_2(x):
    if x == 2:
        os.kill(os.getpid(), signal.SIGKILL)
    time.sleep(0.05)
    return x


def test_sweep_records_identical_on_every_pool_kind(tmp_path):
    """Hypothesis: a sweep (regime and jump statistics of exact runs, 2x2 grid, 10 s windows) stores the
    same records in this process, on 2 threads and on 2 loky processes.  Exact equality (module docstring).
    """
    I, V = [1e-5, 1e-2], [1.0, 2.0]
    opts = {"t_transient": 5.0, "window": 5.0}
    recs = {kind: sweep(I, V, ("regime", "jumps"), out=tmp_path / kind, executor=kind,
                        max_workers=None if kind == "serial" else 2, options=opts, progress=False).records
            for kind in ("serial", "threads", "processes")}
    assert recs["serial"] == recs["threads"] == recs["processes"]
    assert len(recs["serial"]) == 4 and all(r["status"] == "ok" or r["status"].startswith("breakdown")
                                            for r in recs["serial"])
    assert any(np.isfinite(r.get("jumps_mean_interval") or np.nan) for r in recs["serial"])


def test_worker_death_is_a_named_loss_not_a_hang():
    """Hypothesis: a worker killed (SIGKILL) in a task loses that task (and at most the others in flight) with
    loky's TerminatedWorkerError named in its text, within seconds, and the next call gets a fresh pool.
    Bound: 120 s for the call (a hang would never return; a loaded 2-core machine starts workers in ~10 s)."""
    t0 = time.monotonic()
    out, lost = _collect(_die_at_2, [(i, (i,)) for i in range(6)], pool="processes", max_workers=2, chunksize=1)
    assert time.monotonic() - t0 < 120
    assert 2 in dict(lost) and "TerminatedWorkerError" in dict(lost)[2]
    assert set(out) | set(dict(lost)) == set(range(6)) and not set(out) & set(dict(lost))
    out, lost = _collect(abs, [(i, (-i,)) for i in range(4)], pool="processes", max_workers=2)
    assert out == {0: 0, 1: 1, 2: 2, 3: 3} and lost == []


def _kill_in_worker_at_small_I(params, options):
    """A sweep measure that kills its worker process at I < 1e-4 (in a pool's worker only)."""
    if params.I < 1e-4 and os.environ.get("PEELAPPROX_WORKER") == "1":
        os.kill(os.getpid(), signal.SIGKILL)
    return {"I_seen": params.I}


def test_sweep_names_a_dead_worker(tmp_path):
    """Hypothesis: a sweep whose worker dies (SIGKILL in a measure) raises a RuntimeError naming loky's
    TerminatedWorkerError (among the lost tasks' errors, whichever point is named first), within a bounded time
    (120 s: a hang would never return), and the same sweep in this process then computes every point.  The
    value is I itself (exact)."""
    from comparisons.sweep import MEASURES, register_measure

    register_measure("tmp_killer", _kill_in_worker_at_small_I, replace=True)
    try:
        t0 = time.monotonic()
        with pytest.raises(RuntimeError, match="lost by the executor") as err:
            sweep([1e-5, 1e-3], [1.0], "tmp_killer", out=tmp_path / "sw", executor="processes", max_workers=2,
                  progress=False)
        assert "a worker process died (" in str(err.value) and "TerminatedWorkerError" in str(err.value), err.value
        assert time.monotonic() - t0 < 120
        # the directory's lock may stay held a moment after the call (seen under load in the full file, not
        # reproduced alone: a child between fork and exec holding the descriptor?): wait for it, 30 s at most
        t1 = time.monotonic()
        while True:
            try:
                res = sweep([1e-5, 1e-3], [1.0], "tmp_killer", out=tmp_path / "sw", executor="serial", progress=False)
                break
            except RuntimeError as exc:
                assert "is in use" in str(exc) and time.monotonic() - t1 < 30, exc
                time.sleep(0.5)
        assert res.complete and sorted(r["tmp_killer_I_seen"] for r in res.records) == [1e-5, 1e-3]
    finally:
        MEASURES.pop("tmp_killer", None)


def test_blas_limited_and_no_nested_pools_in_workers():
    """Hypothesis: every process worker runs its BLAS/OpenMP pools with one thread (the environment set before
    it imported numpy; threadpoolctl reads the libraries' own counts) and its ``"auto"`` pool is serial (no
    nested pools); this process is not marked a worker."""
    pytest.importorskip("threadpoolctl")
    out, lost = _collect(_blas_threads, [(i, (i,)) for i in range(2)], pool="processes", max_workers=2)
    assert lost == [] and len(out) == 2
    for pools, env in out.values():
        assert env == "1" and pools and all(n == 1 for _, n in pools), pools
    out, lost = _collect(_pid_and_env, [(0, (0,))], pool="processes", max_workers=2)
    pid, marker, kind = out[0]
    assert pid != os.getpid() and marker == "1" and kind == "serial"
    assert os.environ.get("PEELAPPROX_WORKER") is None


def test_costly_tasks_start_first_and_values_do_not_depend_on_it():
    """Hypothesis: with ``cost`` a one-thread pool runs the tasks in decreasing cost (ties in task order), and
    the values are those of the serial run (exact integers)."""
    ran: list = []
    tasks = [(i, (i,)) for i in range(6)]
    cost = [1.0, 5.0, 3.0, 5.0, 0.5, 2.0]
    out, lost = _collect(lambda x: ran.append(x) or x * 3, tasks, pool="threads", max_workers=1, cost=cost)
    assert lost == [] and ran == [1, 3, 2, 5, 0, 4]
    assert out == {i: 3 * i for i in range(6)}
    with pytest.raises(ValueError, match="cost"):
        map_points(abs, tasks, print, pool="threads", cost=[1.0])


def test_bad_pool_and_errors_become_losses(monkeypatch):
    """A pool name outside POOL_KINDS is a ValueError naming ``pool``; a task that raises is lost with its
    exception named, the others delivered; PEELAPPROX_POOL picks the kind of ``"auto"``."""
    with pytest.raises(ValueError, match="pool"):
        map_points(abs, [(0, (1,))], print, pool="fork")
    out, lost = _collect(lambda x: 1 // x, [(i, (i,)) for i in range(3)], pool="threads", max_workers=2)
    assert out == {1: 1, 2: 0} and lost[0][0] == 0 and "ZeroDivisionError" in lost[0][1]
    monkeypatch.setenv("PEELAPPROX_POOL", "serial")
    assert parallel.resolve_kind("auto") == "serial" and parallel.resolve_kind(None) == "serial"
    monkeypatch.setenv("PEELAPPROX_POOL", "")
    assert parallel.default_kind() == ("processes" if parallel.cpu_count() > 2 else "threads")


def _children(pid: int) -> list[int]:
    with open(f"/proc/{pid}/task/{pid}/children") as fh:
        return [int(c) for c in fh.read().split()]


def _alive(pid: int) -> bool:
    """Whether ``pid`` runs (a zombie, dead but not reaped, counts as gone)."""
    try:
        with open(f"/proc/{pid}/stat") as fh:
            return fh.read().rsplit(")", 1)[1].split()[0] != "Z"
    except (FileNotFoundError, ProcessLookupError):
        return False


#: A script with no ``if __name__ == "__main__":`` guard: it maps a function it defines itself on the process pool
#: and prints the values (test_script_without_main_guard_runs_on_processes), then maps 60 s naps on the same pool,
#: to be interrupted (test_keyboard_interrupt_stops_workers).  Python's own SIGINT handler is put back first: a
#: process inherits an ignored SIGINT, and bash ignores it in every command it runs in the background without job
#: control (`bash -c 'cmd &'`): a test suite run so timed out here twice, the workers' third task started, and
#: fails the same way alone under such a parent.
_NO_GUARD = """
import signal, sys, time
signal.signal(signal.SIGINT, signal.default_int_handler)  # as a terminal gives it (see above)
sys.path.insert(0, {root!r})
from peelapprox.parallel import map_points
print("top level", flush=True)
def f(x):
    return x * x + 1
out = {{}}
lost = map_points(f, [(i, (i,)) for i in range(6)], out.__setitem__, pool="processes", max_workers=2)
print(sorted(out.items()), lost, flush=True)
def nap(x):
    print("napping", flush=True)
    time.sleep(60)
    return x
print("ready", flush=True)
map_points(nap, [(i, (i,)) for i in range(4)], lambda k, v: None, pool="processes", max_workers=2)
"""


@pytest.fixture(scope="module")
def no_guard_script(tmp_path_factory):
    """:data:`_NO_GUARD` run as ``python SCRIPT`` and interrupted (SIGINT) once both workers print that their nap
    began (a fixed 1 s wait let a loaded machine send it earlier), one process for the two tests that read it (an
    interpreter, its imports and its two workers paid once).  Returns its stdout (every line), stderr, the
    workers' pids when ``/proc`` lists a process's children (else None), and whether each worker is gone within
    60 s of the interrupt.  Bounds: 180 s for the first map, 60 s for both naps to start, 60 s for the script to
    exit after the interrupt (a hang, or workers finishing their 60 s naps, would take longer)."""
    import selectors

    script = tmp_path_factory.mktemp("noguard") / "noguard.py"
    script.write_text(_NO_GUARD.format(root=ROOT))
    can_list = os.path.exists(f"/proc/{os.getpid()}/task/{os.getpid()}/children")
    proc = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, start_new_session=True, cwd=script.parent)
    lines: list[str] = []
    try:
        sel = selectors.DefaultSelector()
        sel.register(proc.stdout, selectors.EVENT_READ)
        for expected, timeout in ((["ready"], 180.0), (["napping", "napping"], 60.0)):
            left, t0 = list(expected), time.monotonic()
            while left:
                assert time.monotonic() - t0 < timeout, f"still waiting for {left} from the script: {lines}"
                if sel.select(timeout=1.0):
                    line = proc.stdout.readline().strip()
                    assert line, f"the script closed its stdout: {lines}\n{proc.stderr.read()[-3000:]}"
                    lines.append(line)
                    if line in left:
                        left.remove(line)
        workers = _children(proc.pid) if can_list else None
        proc.send_signal(signal.SIGINT)
        t0 = time.monotonic()
        rest, err = proc.communicate(timeout=60)
        lines += rest.splitlines()
        gone = None
        if workers is not None:
            while any(_alive(w) for w in workers) and time.monotonic() - t0 < 60:
                time.sleep(0.2)
            gone = [not _alive(w) for w in workers]
        return dict(stdout="\n".join(lines), stderr=err, workers=workers, gone=gone)
    finally:
        try:
            os.killpg(proc.pid, signal.SIGKILL)
        except (ProcessLookupError, PermissionError):
            pass


def test_script_without_main_guard_runs_on_processes(no_guard_script):
    """Hypothesis: a script with no ``if __name__ == "__main__":`` guard maps a function it defines itself on
    the process pool: the values are right (x*x + 1 for x < 6: exact integers) and no worker re-runs the
    script (its top-level line is printed once)."""
    out = no_guard_script["stdout"]
    assert out.count("top level") == 1, out
    assert "[(0, 1), (1, 2), (2, 5), (3, 10), (4, 17), (5, 26)] []" in out


def test_keyboard_interrupt_stops_workers(no_guard_script):
    """Hypothesis: Ctrl-C (SIGINT to the process) during a process-pool map ends the script with
    KeyboardInterrupt and kills its workers, which were running 60 s tasks.  Bound: 60 s for the script to exit
    and its workers to go (a hang, or workers finishing their tasks, would take longer); the interrupt is sent
    once both workers are inside a task, and the script restores Python's SIGINT handler (:data:`_NO_GUARD`)."""
    if no_guard_script["workers"] is None:
        pytest.skip("needs Linux's /proc/<pid>/task/<pid>/children")
    assert no_guard_script["workers"]
    assert "KeyboardInterrupt" in no_guard_script["stderr"]
    assert all(no_guard_script["gone"]), f"workers still running: {no_guard_script}"


def test_diagram_and_attractors_identical_on_every_pool_kind():
    """Hypothesis: an orbit diagram over V (breakdowns, aperiodic, periodic and steady values) and the
    attractors of two parameter points are the same, bit for bit, in this process, on threads and on loky
    processes: each value or start is one independent run, put back in order.  Exact equality (module
    docstring): the return maps' bytes and the Attractor records' reprs (floats as round-trip reprs)."""
    import exact
    from peelapprox import PeelParams

    def diagram(kind):
        d = exact.orbit_diagram(PeelParams(V=1.0, I=1e-4), "V", [0.3, 1.5, 4.0, 6.0], t_transient=5.0, window=5.0,
                                executor=kind, max_workers=None if kind == "serial" else 2)
        return d.labels, [r.tobytes() for r in d.returns]

    def atts(kind):
        return repr(exact.attractors(PeelParams(V=1.0, I=1e-5), (-0.3, 0.0, 0.3), t_transient=5.0, window=5.0,
                                     executor=kind, max_workers=None if kind == "serial" else 2))

    ref = diagram("serial")
    assert len(set(ref[0])) >= 3
    assert diagram("threads") == ref and diagram("processes") == ref
    ref = atts("serial")
    assert "Attractor(" in ref and atts("threads") == ref and atts("processes") == ref


def test_scaling_benchmark_writes_its_table(tmp_path, capsys):
    """The scaling benchmark's smallest run (2 points, threads with 1 and 2 workers, one repeat): one row per
    worker count in the printed table and in the CSV, the records equal across them, the ratios consistent
    (the speed-up is the throughput over the 1-worker throughput: equal to 1e-12 relative, float division)."""
    import csv

    from comparisons.benchmark.scaling import main

    out = tmp_path / "scaling.csv"
    assert main(["--grid", "sweep", "--I", "1e-3:1e-2:1:log", "--V", "1:2:2", "--workers", "1,2", "--kinds",
                 "threads", "--t-transient", "1", "--window", "1", "--repeat", "1", "--out", str(out)]) == 0
    assert capsys.readouterr().out.count("| threads |") == 2
    rows = list(csv.DictReader(out.open()))
    assert [int(r["workers"]) for r in rows] == [1, 2] and all(r["records_equal"] == "True" for r in rows)
    r1, r2 = (float(r["points_per_s"]) for r in rows)
    assert abs(float(rows[1]["speedup"]) - r2 / r1) <= 1e-12 * r2 / r1

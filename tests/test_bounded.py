"""Every call bounded in wall time, every grid size and start checked before the work starts.

Each test replays a call that used to run for minutes (or to fail late, or with the wrong exception) and
asserts that it now returns, or raises what it should, quickly.  The wall-clock bound asserted is
:data:`BOUND` = 30 s against budgets of 0.5 s: the machine running the tests is shared and noisy, and what is
tested is that the call is bounded (minutes before), not how fast it is.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import re
import time

import numpy as np
import pytest

import exact
from exact import Bifurcation, State
from peelapprox import PeelForce, PeelParams, SolverBudgetExceeded

#: Seconds a bounded call may take here, whatever its budget (module docstring: boundedness, not speed).
BOUND = 30.0
#: The wall budget given to the calls under test [s].
BUDGET = 0.5
PAPER = PeelParams(V=1.0, I=1e-5)  # a stable period-3 orbit (docs/dynamics.md), Newton in well under a second


@pytest.fixture(scope="module")
def orbit():
    return exact.periodic_orbit(PAPER)


def _timed(fn, *args, **kwargs):
    t0 = time.perf_counter()
    out = fn(*args, **kwargs)
    return out, time.perf_counter() - t0


# ---------------------------------------------------------------------------------------------- continuation
def test_continue_orbit_ends_with_max_wall_and_the_points_so_far(orbit):
    """The continuation that ran over 330 s (steps of at most 1e-7 in V towards 1.1, up to 1e5 points) ends
    with ``stopped="max_wall"`` once its 0.5 s are spent, within :data:`BOUND`: its points are orbits of the
    branch (each closes to the default tol 1e-10, the corrector's own criterion), start at V = 1 and stay in
    [1, 1.1], and the message names the budget."""
    b, took = _timed(exact.continue_orbit, orbit, "V", stop=1.1, min_step=1e-9, max_step=1e-7, max_points=100_000,
                     max_wall=BUDGET)
    assert took < BOUND
    assert b.stopped == "max_wall" and "max_wall=0.5 s" in b.message
    assert 1 <= len(b.points) < 100_000
    assert b.points[0].value == 1.0
    assert all(1.0 <= p.value <= 1.1 for p in b.points)
    assert all(p.orbit.residual <= 1e-10 for p in b.points)
    assert b.end_value == b.points[-1].value


@pytest.mark.parametrize("parameter, stop, exc, match", [
    (None, 2.0, TypeError, r"parameter must be one of V, I, k .*got None"),
    ("q", 2.0, ValueError, r"parameter must be one of V, I, k .*got 'q'"),
    ("V", math.nan, ValueError, r"stop must be finite and in \(-inf, inf\), got nan"),
    ("V", math.inf, ValueError, r"stop must be finite"),
    ("V", -1.0, ValueError, r"stop must be a valid value of V, got -1.0: V must be finite and in \[1e-6, 100\]"),
    ("V", 1.0, ValueError, r"stop must differ from the start's V=1.0"),
])
def test_continue_orbit_checks_parameter_and_stop(orbit, parameter, stop, exc, match):
    """A bad ``parameter`` (None used to be an AttributeError) or ``stop`` (NaN used to read "stop must differ")
    is refused by name, with the valid values, before any step: categorical, the exception type and message."""
    with pytest.raises(exc, match=match):
        exact.continue_orbit(orbit, parameter, stop=stop)


def test_switch_branch_raises_max_wall(orbit):
    """switch_branch returns one orbit or nothing, so a spent budget is ``SolverBudgetExceeded`` naming max_wall
    (categorical), raised at the first check: a budget of 1 µs is spent before Newton's first iteration, so the
    call returns within :data:`BOUND` whatever the bifurcation (here a stand-in at the period-3 orbit)."""
    bif = Bifurcation("period_doubling", 1.0, orbit, "V")
    t0 = time.perf_counter()
    with pytest.raises(SolverBudgetExceeded, match=r"switch_branch: more than 1e-06 s of wall time") as info:
        exact.switch_branch(bif, max_wall=1e-6)
    assert time.perf_counter() - t0 < BOUND
    assert info.value.budget == "max_wall" and info.value.limit == 1e-6


# ---------------------------------------------------------------------------------------------- periodic orbits
_S0 = State(t=0.0, alpha=0.0, omega=0.0, F=250.0, v=1.0, branch="AB")


@pytest.mark.parametrize("change, match", [
    (dict(t=math.nan), r"start\.t must be finite and in \[0, 1e6\], got nan"),
    (dict(v=math.nan), r"start\.v must be finite and in \(1e-150, 1000\], got nan"),
    (dict(v=-1.0), r"start\.v must be finite and in \(1e-150, 1000\], got -1.0"),
    (dict(Vp=1.0), r"start\.Vp must be None for the massless tape under velocity control"),
    (dict(alpha=4.0), r"start\.alpha must be finite and in \[-3\.14159, 3\.14159\], got 4.0"),
    (dict(branch="XY"), r"start\.branch must be one of \('AB', 'CD'\)"),
])
def test_periodic_orbit_checks_a_start_state(change, match):
    """A start State with a field out of its range used to be run (NaN t, NaN or negative v, a pull speed under
    velocity control silently ignored): now a ValueError naming ``start.<field>`` and its range (categorical)."""
    with pytest.raises(ValueError, match=match):
        exact.periodic_orbit(PAPER, start=dataclasses.replace(_S0, **change))


@pytest.mark.parametrize("other, match", [
    (PAPER.replace(I=2e-5), r"start\.params must be params .*I=2e-05 \(params: 1e-05\)"),
    (PAPER.replace(force=PeelForce.cubic()), r"start\.params\.force must be params\.force"),
])
def test_periodic_orbit_checks_a_start_trajectory(other, match):
    """A start Trajectory run with other parameters or another law used to seed Newton with another model's
    orbit: now a ValueError naming ``start.params`` (or its ``force``) and the fields that differ."""
    tr = exact.simulate(other, 0.1, save="jumps")
    with pytest.raises(ValueError, match=match):
        exact.periodic_orbit(PAPER, start=tr)


def test_periodic_orbit_raises_max_wall():
    """A seed run of 1e5 s (hours) under a 0.5 s budget raises ``SolverBudgetExceeded`` naming max_wall within
    :data:`BOUND` (categorical)."""
    t0 = time.perf_counter()
    with pytest.raises(SolverBudgetExceeded, match=r"more than 0.5 s of wall time \(max_wall\)") as info:
        exact.periodic_orbit(PAPER, t_transient=1e5, max_wall=BUDGET)
    assert time.perf_counter() - t0 < BOUND
    assert info.value.budget == "max_wall"


@pytest.mark.parametrize("bad, exc", [(0.0, ValueError), (-1.0, ValueError), (math.nan, ValueError),
                                      (math.inf, ValueError), ("1", TypeError)])
def test_max_wall_is_checked(orbit, bad, exc):
    """max_wall must be a positive finite number or None, refused by name before any work (categorical)."""
    for call in (lambda: exact.continue_orbit(orbit, "V", stop=1.1, max_wall=bad),
                 lambda: exact.switch_branch(Bifurcation("period_doubling", 1.0, orbit, "V"), max_wall=bad),
                 lambda: exact.periodic_orbit(PAPER, max_wall=bad)):
        with pytest.raises(exc, match=r"max_wall must be"):
            call()


# ---------------------------------------------------------------------------------------------- orbit diagram
def test_orbit_diagram_refuses_a_grid_too_large_at_once():
    """The diagram of 1e6 values (the CLI's ``--range 0.9:1.1:1000000``, over 300 s) is refused before any run,
    naming ``values`` and the limit :data:`exact.MAX_DIAGRAM_VALUES` (1e5), within :data:`BOUND`; a value the
    parameter cannot take is refused up front too (it used to fail at its turn)."""
    big = np.linspace(0.9, 1.1, 1_000_000)
    t0 = time.perf_counter()
    with pytest.raises(ValueError, match=r"values must hold at most MAX_DIAGRAM_VALUES = 100000 values.*got 1000000"):
        exact.orbit_diagram(PAPER, "V", big)
    assert time.perf_counter() - t0 < BOUND
    assert exact.MAX_DIAGRAM_VALUES == 100_000
    with pytest.raises(ValueError, match=r"values must be valid values of V, got -1.0"):
        exact.orbit_diagram(PAPER, "V", [1.0, -1.0])


@pytest.mark.parametrize("executor", ["serial", None])
def test_orbit_diagram_returns_what_it_has_when_max_wall_is_spent(executor):
    """200 values of 50 s runs (minutes) under a 0.5 s budget: the diagram comes back within :data:`BOUND` with
    all 200 values in order, the ones not run labelled ``budget:max_wall`` with no returns (at least the last:
    a run takes far more than 0.5 s / 200), the others labelled as usual.  Run serially, the values cut are a
    tail (once the budget is spent no later value runs).  On the default pool (two workers here) they need not
    be: a run beside other jobs saw value 0 cut on a worker still loading its kernels while value 1 finished on the
    other (29 Nov), so there the cut values' empty returns and the cut last value are asserted."""
    vals = np.linspace(0.9, 1.1, 200)
    d, took = _timed(exact.orbit_diagram, PAPER, "V", vals, max_wall=BUDGET, executor=executor)
    assert took < BOUND
    assert np.array_equal(d.values, vals) and len(d.labels) == len(d.returns) == 200
    cut = [i for i, lab in enumerate(d.labels) if lab == "budget:max_wall"]
    assert cut and cut[-1] == 199
    assert all(d.returns[i].size == 0 for i in cut)
    if executor == "serial":
        assert cut == list(range(cut[0], 200))


# ---------------------------------------------------------------------------------------------- basins
def test_basins_refuses_a_grid_too_large_at_once():
    """A 2000 x 1000 grid (2e6 starts) is refused before any run, naming both axes and the limit
    :data:`exact.MAX_BASIN_STARTS` (1e6), within :data:`BOUND` (the axes' lengths are read before they are
    converted)."""
    t0 = time.perf_counter()
    with pytest.raises(ValueError, match=r"alpha0 x F0: the grid must hold at most MAX_BASIN_STARTS = 1000000 "
                                         r"starts .*got 2000 x 1000 = 2000000"):
        exact.basins(PAPER, alpha0=np.linspace(-0.3, 0.3, 2000), F0=np.linspace(200, 280, 1000))
    assert time.perf_counter() - t0 < BOUND
    assert exact.MAX_BASIN_STARTS == 10**6


@pytest.mark.parametrize("workers", [0, 2], ids=["serial", "pool"])
def test_basins_returns_every_start_when_max_wall_is_spent(workers):
    """100 starts of 50 s runs (~0.2 s each) under a 0.5 s budget, in this process and on a pool of 2 spawned
    workers: the result comes back within :data:`BOUND` with all 100 starts, those the budget left out or cut
    labelled FAILURE with the text ``failure:max_wall`` (at least the last half: 0.5 s cannot run 50), the others
    as usual; an attractor's orbit is found, or its ``orbit_error`` names max_wall (the budget is spent before
    or during its search)."""
    r, took = _timed(exact.basins, PAPER, alpha0=np.linspace(-0.3, 0.3, 10), F0=np.linspace(200.0, 280.0, 10),
                     max_wall=BUDGET, max_workers=workers, progress=False, orbits=True)
    assert took < BOUND
    assert r.labels.shape == (10, 10)
    cut = r.texts == "failure:max_wall"
    assert cut.sum() >= 50 and np.all(r.labels[cut] == exact.dynamics._basins.FAILURE)
    assert all(a.orbit is not None or "max_wall" in (a.orbit_error or "") for a in r.attractors)


# ---------------------------------------------------------------------------------------------- sweep
def test_sweep_refuses_a_grid_too_large_at_once(tmp_path):
    """``--I 1e-5:1e-3:100000000`` (over 200 s without even writing the manifest) is refused by parse_grid
    before the values are made, and a 1e7-value axis given to the library before it is converted, naming the
    option or axes and :data:`comparisons.sweep.MAX_SWEEP_POINTS` (1e6), within :data:`BOUND`; nothing is
    written."""
    from comparisons.sweep import MAX_SWEEP_POINTS, parse_grid, sweep

    assert MAX_SWEEP_POINTS == 10**6
    t0 = time.perf_counter()
    with pytest.raises(ValueError, match=r"--I: num must be at most MAX_SWEEP_POINTS = 1000000 .*got 100000000"):
        parse_grid("1e-5:1e-3:100000000", name="--I")
    big = np.ones(10**7)  # the size check comes first: the values are not even looked at
    with pytest.raises(ValueError, match=r"I_values x V_values: a sweep must hold at most MAX_SWEEP_POINTS = "
                                         r"1000000 points .*got 10000000 x 2 = 20000000"):
        sweep(big, [1.0, 2.0], out=tmp_path / "s")
    with pytest.raises(ValueError, match=r"I_values x V_values x coef values: .*got 1000 x 1000 x 2 = 2000000"):
        sweep(np.geomspace(1e-5, 1e-3, 1000), np.linspace(1.0, 2.0, 1000), "period", out=tmp_path / "s",
              force=PeelForce.cubic(), coef=("c", [290.0, 300.0]))
    assert time.perf_counter() - t0 < BOUND
    assert not (tmp_path / "s").exists()


@pytest.mark.parametrize("workers", [pytest.param(0, marks=pytest.mark.slow), 2], ids=["serial", "pool"])
def test_sweep_writes_its_manifest_first_and_stops_at_max_wall(tmp_path, workers):
    """10 points of the period measure (a 50 s run each, ~0.2 s) under a 0.5 s budget, in this process and on a
    pool of 2 spawned workers: the manifest exists before the first point is reported; the call raises
    ``SolverBudgetExceeded`` naming max_wall within :data:`BOUND`, with the points done recorded (fewer than 10:
    0.5 s cannot run them, ~2 s of runs, and spawning the pool's workers alone takes longer) and none of the
    points it cut; the same call without a budget then completes the sweep, recording each point once
    (categorical counts).  10 points, not 20 as before: the completion's cost halves (~2 s of CPU less) and
    the budget still cuts the sweep at a point count the checks see.

    The serial case is slow (its completion, ~2.5 s CPU, is the pool case's); covered in the default tier
    by the pool case (the same checks, the budget cut across processes) and by
    ``test_cli_max_wall_bounds_each_command``'s sweep case (a serial sweep stopped by a 0.5 s budget, leaving
    its manifest)."""
    from comparisons.sweep import sweep

    out = tmp_path / "s"
    seen: list[bool] = []
    args = (np.geomspace(1e-5, 1e-3, 5), [1.0, 2.0], "period")
    t0 = time.perf_counter()
    with pytest.raises(SolverBudgetExceeded, match=r"sweep: the wall-clock budget max_wall=0.5 s was spent") as info:
        sweep(*args, out=out, max_workers=workers, max_wall=BUDGET,
              progress=lambda done, total, rec: seen.append((out / "sweep.json").exists()))
    assert time.perf_counter() - t0 < BOUND
    assert info.value.budget == "max_wall" and all(seen) and (out / "sweep.json").exists()
    done = len(info.value.partial.records)
    assert done < 10 and len((out / "results.jsonl").read_text().splitlines()) == done
    res = sweep(*args, out=out, max_workers=0, max_wall=None, progress=False)
    assert len(res.records) == 10 and len((out / "results.jsonl").read_text().splitlines()) == 10
    assert all(r["status"] == "ok" for r in res.records)


# ---------------------------------------------------------------------------------------------- the command line
def _cli(argv: list[str]) -> tuple[int, float]:
    """``peelapprox ARGV``: the exit status (``SystemExit`` taken as its code) and the seconds it took."""
    from peelapprox.cli import main

    t0 = time.perf_counter()
    try:
        rc = main(argv)
    except SystemExit as exc:
        rc = int(exc.code or 0)
    return rc, time.perf_counter() - t0


@pytest.mark.parametrize("argv, match", [
    (["bifurcation", "--V", "1", "--I", "1e-5", "--range", "0.9:1.1:1000000"],
     r"--range: N must be at most 100000 .*got 1000000"),
    (["sweep", "--I", "1e-5:1e-3:100000000", "--V", "1"], r"--I: num must be at most MAX_SWEEP_POINTS = 1000000"),
    (["sweep", "--I", "1e-5:1e-3:1000:log", "--V", "1:2:2000"],
     r"--I x --V: a sweep must hold at most MAX_SWEEP_POINTS = 1000000 points .*got 1000 x 2000 = 2000000"),
    (["basins", "--V", "1", "--I", "1e-5", "--alpha0", "0:0.3:2000", "--F0", "200:280:1000"],
     r"--alpha0 x --F0: the grid must hold at most 1000000 starts .*got 2000 x 1000 = 2000000"),
])
def test_cli_refuses_a_grid_too_large_at_once(tmp_path, capsys, argv, match):
    """The command lines that ran for minutes (``bifurcation --range 0.9:1.1:1000000``, ``sweep --I
    1e-5:1e-3:100000000``) and their kin exit with status 2 (a bad argument) within :data:`BOUND`, the message
    naming the option and the limit; the sweep's directory is not even created (categorical)."""
    out = tmp_path / "s"
    rc, took = _cli(argv + (["--out", str(out)] if argv[0] == "sweep" else []))
    assert rc == 2 and took < BOUND
    assert re.search(match, capsys.readouterr().err)
    assert not out.exists()


@pytest.mark.parametrize("argv, after", [
    (["orbit", "--V", "1", "--I", "1e-5", "--t-transient", "100000"],
     "error: more than 0.5 s of wall time (--max-wall)"),
    (["bifurcation", "--V", "1", "--I", "1e-5", "--range", "0.9:1.1:100"], "stopped: the --max-wall budget"),
    (["basins", "--V", "1", "--I", "1e-5", "--alpha0", "0:0.3:10", "--F0", "200:280:10", "--workers", "0"],
     "stopped: the --max-wall budget"),
    (["sweep", "--I", "1e-5:1e-3:10:log", "--V", "1:2:2", "--measure", "period", "--workers", "0", "--quiet"],
     "error: sweep: the wall-clock budget max_wall=0.5 s was spent"),
    (["compare"], "error: more than 0.01 s of wall time (--max-wall)"),
    (["figures", "--out", "FIGS"], "error: more than 0.01 s of wall time (--max-wall)"),
])
# the command timer's first firing may land in a weakref or gc callback, which prints it and drops it; it repeats
@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")
def test_cli_max_wall_bounds_each_command(tmp_path, capsys, argv, after):
    """Each of orbit, bifurcation, basins and sweep, given work for minutes and ``--max-wall 0.5``, ends within
    :data:`BOUND` with exit status 3 (a solver stop) and says why on stderr; the sweep leaves its manifest in its
    directory for the same command to resume; compare and figures, whose library calls have no budget of their
    own, are stopped by the command's timer (categorical).  Those two get ``--max-wall 0.01``, a budget their work
    cannot fit in on any machine (compare's statistics alone take seconds with its runs cached in the process;
    the timer also checks when the body returns), so the outcome does not depend on the machine's speed: with
    0.5 s it did.  Not smaller: a timer firing within microseconds can land before ``time_limit`` has entered
    its ``try`` and then stays armed."""
    out = tmp_path / "s"
    argv = [str(tmp_path / "figs") if a == "FIGS" else a for a in argv]
    budget = 0.01 if argv[0] in ("compare", "figures") else BUDGET
    rc, took = _cli(argv + ["--max-wall", str(budget)] + (["--out", str(out)] if argv[0] == "sweep" else []))
    assert rc == 3 and took < BOUND
    assert after in capsys.readouterr().err
    if argv[0] == "sweep":
        assert (out / "sweep.json").exists()


@pytest.mark.parametrize("command", ["orbit", "bifurcation", "basins", "sweep", "simulate", "dynamics", "folds",
                                     "estimate", "segment", "compare", "benchmark", "figures"])
def test_every_cli_max_wall_defaults_to_600_seconds(command):
    """``--max-wall`` of every subcommand defaults to 600 s and says so in its help (exact value and text)."""
    from peelapprox.cli import build_parser

    sub = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction)).choices[command]
    action = next(a for a in sub._actions if "--max-wall" in a.option_strings)
    assert action.default == 600.0
    assert "(default: 600)" in " ".join(sub.format_help().split())


# ---------------------------------------------------------------------------------------------- CSV headers
def _header_file(tmp_path, size: int) -> str:
    """The probe's header ``'v,f,a' + ' ' * n + '[' + ' ' * n + 'x'`` (``size`` bytes with its newline) and one
    row: a backtracking pattern took minutes on its 1,018-byte form."""
    n = (size - 8) // 2
    path = tmp_path / f"h{size}.csv"
    path.write_text("v,f,a" + " " * n + "[" + " " * n + "x\n1,2,3\n")
    return str(path)


def _parse_events(fn, *args, **kwargs) -> int:
    """Python line events executed in peelapprox's CSV modules during ``fn(*args, **kwargs)`` (its error
    swallowed): a count of the work done there, the same on any machine."""
    import sys

    count = 0

    def tracer(frame, event, arg):
        nonlocal count
        if "_csvread" in frame.f_code.co_filename or "_tablefile" in frame.f_code.co_filename:
            if event == "line":
                count += 1
            return tracer
        return None

    sys.settrace(tracer)
    try:
        fn(*args, **kwargs)
    except ValueError:
        pass
    finally:
        sys.settrace(None)
    return count


@pytest.mark.parametrize("size", [1018, 2048, 100_000])
def test_a_long_header_is_parsed_and_refused_at_once(tmp_path, size):
    """The ReDoS reproducer (1,018 bytes: past 120 s; 2 kB: 20 s in from_csv) and a 100 kB header are refused as
    a header without the columns (categorical: the class and the message naming the header), within
    :data:`BOUND`: whether the parse ends at all is what is tested, not its speed (it takes milliseconds)."""
    from peelapprox import ForceSeries

    path = _header_file(tmp_path, size)
    t0 = time.perf_counter()
    with pytest.raises(ValueError, match=r"header .*expected the columns v,f"):
        PeelForce.from_csv(path)
    with pytest.raises(ValueError, match=r"expected the columns t,F"):
        ForceSeries.from_csv(path)
    assert time.perf_counter() - t0 < BOUND


def test_header_parsing_work_is_linear_in_its_length(tmp_path):
    """The work of parsing a header grows linearly with its length, counted, not timed (a count does not depend
    on the machine's speed or load): Python line events in the CSV reader for the 100 kB header are at most
    1.2 x 100 times those for the 1 kB one (a scan per character, ~1 event each, plus a constant; the old
    pattern was cubic).  No regular expression reads a header cell, and the reader's one pattern (newlines) has
    no quantifier (the count cannot see work inside ``re``, so that is asserted on the module's source)."""
    import inspect

    from peelapprox import _csvread

    small = _parse_events(PeelForce.from_csv, _header_file(tmp_path, 1000))
    large = _parse_events(PeelForce.from_csv, _header_file(tmp_path, 100_000))
    assert small > 0
    assert large <= 1.2 * 100 * small, (small, large)
    assert "re." not in inspect.getsource(_csvread.header_cell)
    patterns = re.findall(r"re\.compile\(r?\"([^\"]*)\"\)", inspect.getsource(_csvread))
    assert patterns == ["\\r\\n|\\r|\\n"]  # the newline: no quantifier, so no backtracking


def test_column_specs_with_units_still_read(tmp_path):
    """The linear header scan reads what the pattern read: units in brackets or parentheses, in the file's header
    or in a ``columns`` spec, converted: compared exactly, each value being one product by a factor of
    :data:`UNITS` (1e-3, 1e3) whose float equals the literal asserted."""
    from peelapprox.law._tablefile import read_points

    path = tmp_path / "u.csv"
    path.write_text("v [mm/s],f (kN)\n1,0.2\n2,0.1\n")
    [(V, v, f, _)] = read_points(str(path))
    assert V is None and v.tolist() == [1e-3, 2e-3] and f.tolist() == [200.0, 100.0]
    path.write_text("speed,force\n1,200\n2,100\n")
    [(V, v, f, _)] = read_points(str(path), columns={"v": "speed (mm/s)", "f": "force [N]"})
    assert v.tolist() == [1e-3, 2e-3] and f.tolist() == [200.0, 100.0]


# ---------------------------------------------------------------------------------------------- memory
def _trace(n: int) -> tuple[np.ndarray, np.ndarray]:
    """A sawtooth stick-slip trace of n samples at 10 kHz (7.3 slips a second), noise 0.05 N (seeded)."""
    t = np.arange(n) * 1e-4
    F = 200.0 + 50.0 * ((t * 7.3) % 1.0) + np.random.default_rng(0).normal(0.0, 0.05, n)
    return t, F


def _peak_bytes(fn, *args, **kwargs) -> int:
    """The peak of memory allocated during ``fn(*args, **kwargs)`` (tracemalloc: Python objects and numpy's
    arrays, which numpy reports to it): a count of bytes, the same on any machine."""
    import tracemalloc

    tracemalloc.start()
    try:
        fn(*args, **kwargs)
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


@pytest.mark.parametrize("n", [10_000, 40_000])
def test_reading_a_trace_file_takes_a_few_bytes_per_byte(tmp_path, n):
    """``ForceSeries.from_csv`` of a 241 MB file peaked at 6.8 GB (a 256 MiB read buffer whatever the file's size,
    then a list of lines and of cells: ~65 bytes a byte).  Now at most 4 bytes per byte of the file, at two
    sizes 4x apart (so the bound is per byte, not a constant): the bytes (1), their text (1, ASCII), 8 bytes per
    value and line number (~1.2 at ~20 bytes a row), the trace's own copy (~0.8); measured 2.5."""
    from peelapprox import ForceSeries

    t, F = _trace(n)
    path = tmp_path / "trace.csv"
    path.write_text("t,F\n" + "\n".join(f"{a:.6f},{b:.6f}" for a, b in zip(t, F)) + "\n")
    peak = _peak_bytes(ForceSeries.from_csv, str(path))
    assert peak <= 4.0 * path.stat().st_size, peak / path.stat().st_size


@pytest.mark.parametrize("n", [10_000, 40_000])
def test_observables_take_a_bounded_memory_per_sample(n):
    """``observables()`` took 7.8 GB on 1e8 samples (a trace is now refused beyond MAX_SAMPLES, 1e7); its memory
    is linear in the samples: at most 64 bytes a sample (eight float64 arrays of the trace's length) at two
    sizes 4x apart; measured 40 (five)."""
    from peelapprox import ForceSeries

    s = ForceSeries(*_trace(n), V=1.0)
    assert _peak_bytes(s.observables) <= 64 * n


# ---------------------------------------------------------------------------------------------- law size
def _product(n: int) -> str:
    return "*".join(f"(v-{0.1 * (i + 1):.1f})" for i in range(n)) + " + 200"


@pytest.mark.parametrize("n", [30, 65])
def test_a_law_whose_derivatives_compile_for_minutes_is_refused_at_once(n):
    """A product of 60-65 linear factors built for 33 s and compiled for 54 s under ``--max-wall 10`` (numba's
    LLVM passes, which no timer interrupts).  Its derivative f' is counted before f'' is formed and refused past
    MAX_DERIVATIVE_NODES (categorical: the message names the limit), within :data:`BOUND`: boundedness, not
    speed (it takes about a second: one derivative of the product)."""
    t0 = time.perf_counter()
    with pytest.raises(ValueError, match=r"derivative f' has more than 1000 terms and factors \(MAX_DERIVATIVE"):
        PeelForce.expression(_product(n))
    assert time.perf_counter() - t0 < BOUND


def test_the_size_limit_leaves_ordinary_laws_alone():
    """The paper's law written out, a product of 12 factors and a degree-12 polynomial are built (their f'' has
    at most ~2,050 nodes, under the limit of 2,500)."""
    PeelForce.expression(_product(12))
    PeelForce.expression(" + ".join(f"{k + 1}*v**{k}" for k in range(13)))


# ---------------------------------------------------------------------------------------------- atlas cost
def test_atlas_cost_sample_has_a_range(capsys):
    """``--cost 1000000`` was accepted (a cost projection running for days): the sample is 1 to MAX_SAMPLE
    (400), refused by name before any run, in the library and on the command line (categorical)."""
    from comparisons.atlas import atlas_cost

    with pytest.raises(ValueError, match=r"sample must be .*400"):
        atlas_cost([1e-5], [1.0], sample=1_000_000)
    rc, took = _cli(["atlas", "--V", "0.2:5:10", "--I", "1e-6:1e-1:10:log", "--cost", "1000000", "--quiet"])
    assert rc == 2 and "--cost must be an integer in [1, 400]" in capsys.readouterr().err


def test_atlas_cost_keeps_its_wall_budget(capsys):
    """``atlas --cost 30 --max-wall 5`` ran 64.8 s (its budget was never handed to the cost): now each exact run
    gets what is left and no part starts once it is spent.  With 0.5 s, SolverBudgetExceeded naming max_wall and
    the points timed, within :data:`BOUND` (one exact run of the sample and the parts under way overrun the
    budget by at most seconds; boundedness is what is tested), and exit status 3 on the command line.  The
    kernels are compiled (or loaded) first by a one-point call without a budget: numba's compilation is not
    interruptible, and from an empty kernel cache on a loaded machine it alone took 36 s of the timed call
    (~0.2 s warm)."""
    from comparisons.atlas import atlas_cost

    atlas_cost([1e-5], [1.0], sample=1, max_wall=None)
    t0 = time.perf_counter()
    with pytest.raises(SolverBudgetExceeded, match=r"atlas_cost: more than 0.5 s .*sample points timed") as info:
        atlas_cost(np.geomspace(1e-6, 1e-1, 10), np.linspace(0.2, 5.0, 10), sample=30, max_wall=BUDGET)
    assert time.perf_counter() - t0 < BOUND and info.value.budget == "max_wall"
    rc, took = _cli(["atlas", "--V", "0.2:5:10", "--I", "1e-6:1e-1:10:log", "--cost", "30", "--max-wall", "0.5",
                     "--quiet"])
    assert rc == 3 and took < BOUND
    assert "more than 0.5 s of wall time (--max-wall)" in capsys.readouterr().err


@pytest.mark.parametrize("argv, n", [
    (["simulate", "--V", "1", "--I", "1e-5", "--t-end", "0.01", "--max-wall", "10", "--quiet"], 65),
    (["sweep", "--I", "1e-5", "--V", "1:2:2", "--max-wall", "10", "--workers", "2", "--quiet"], 55),
])
def test_cli_refuses_a_law_too_large_to_compile_in_its_budget(tmp_path, capsys, argv, n):
    """``simulate --max-wall 10`` with a 65-factor law ran 54 s (its kernel compiled past the budget), ``sweep
    --max-wall 10 --workers 2`` with a 55-factor law 176 s (compiled in the worker threads, which no timer
    interrupts): the law is now refused when read, exit status 2 naming MAX_DERIVATIVE_NODES, within
    :data:`BOUND` (about a second: one derivative)."""
    extra = ["--out", str(tmp_path / "sw")] if argv[0] == "sweep" else []
    rc, took = _cli([*argv, *extra, "--force", _product(n)])
    assert rc == 2 and took < BOUND
    assert "MAX_DERIVATIVE_NODES" in capsys.readouterr().err


def test_a_file_with_more_rows_than_allowed_is_refused_at_the_first_row_beyond(tmp_path):
    """read_columns' ``max_rows`` (a trace file: MAX_SAMPLES rows) stops at the first row beyond, naming its line
    and the limit (categorical), so a file of many short rows is not parsed whole before the trace refuses it."""
    from peelapprox._csvread import read_columns

    path = tmp_path / "rows.csv"
    path.write_text("t,F\n" + "".join(f"{i},{200 + i}\n" for i in range(5)))
    assert read_columns(str(path), {"t": "s", "F": "N"}, where="f", max_rows=5)["t"].tolist() == [0, 1, 2, 3, 4]
    with pytest.raises(ValueError, match=r"f line 5: more than the 3 data rows"):
        read_columns(str(path), {"t": "s", "F": "N"}, where="f", max_rows=3)


def test_cli_force_table_with_the_redos_header_is_a_usage_error(tmp_path, capsys):
    """``simulate --force-table f.csv --max-wall 5`` on the probe's 1,018-byte header ran past 120 s: now exit
    status 2 naming the header, within :data:`BOUND` (boundedness; it takes a second of start-up)."""
    rc, took = _cli(["simulate", "--V", "1", "--I", "1e-5", "--t-end", "0.01", "--max-wall", "5", "--quiet",
                     "--force-table", _header_file(tmp_path, 1018)])
    assert rc == 2 and took < BOUND
    assert "expected the columns" in capsys.readouterr().err


def test_sweep_compiles_an_expression_law_in_the_calling_thread_under_its_budget(tmp_path, monkeypatch):
    """A sweep's worker threads compiled the law where no timer interrupts (a 55-factor law: 176 s under
    ``max_wall=10``): the law is now compiled first in the calling thread, under the sweep's budget.  A stand-in
    compilation that would run for minutes (sleeping in short steps, as sympy's Python does) inside the real
    ``time_limit`` is interrupted at the 0.5 s budget in the main thread; the sweep then stops by its budget
    (``SolverBudgetExceeded``, no point recorded) within :data:`BOUND`."""
    import threading

    from comparisons.sweep import sweep
    from peelapprox import kernels
    from peelapprox._deadline import time_limit

    threads = []

    def slow_compile(source):
        threads.append(threading.current_thread() is threading.main_thread())
        with time_limit(600.0):
            for _ in range(60_000):
                time.sleep(0.01)

    monkeypatch.setattr(kernels, "expression_kernel", slow_compile)
    t0 = time.perf_counter()
    with pytest.raises(SolverBudgetExceeded, match=r"max_wall=0.5 s was spent with 0/4 points done"):
        sweep([1e-5, 1e-4], [1.0, 2.0], "period", out=tmp_path / "s", max_workers=2, max_wall=BUDGET,
              force=PeelForce.expression("153 + 300*v - 300*v**2 + 80*v**3"), progress=False)
    assert time.perf_counter() - t0 < BOUND
    assert threads == [True]


# ---------------------------------------------------------------------------------------------- table files
def _split_by_passes(Vs, v, f, lines, sd):
    """The grouping as it was (one pass over the rows per distinct V, in order of first appearance): the oracle of
    the grouping's definition, kept here to compare the sort-based one with."""
    return [(float(V), v[Vs == V], f[Vs == V], lines[Vs == V], sd[Vs == V]) for V in dict.fromkeys(Vs.tolist())]


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_table_file_split_is_the_per_value_split(tmp_path, seed):
    """The sort-based split of a file's rows by V gives the tables of the old one-pass-per-V split exactly
    (numpy.array_equal of V, v, f, sigma and file lines, same order of tables): seeded files of 1-40 pull speeds,
    rows shuffled (so the tables interleave), V repeated in different spellings (``1``, ``1.000000``), a comment
    line."""
    from peelapprox.law._tablefile import read_points

    rng = np.random.default_rng(seed)
    nV = int(rng.integers(1, 41))
    speeds = (rng.choice([0.5, 1.0, 2.0, 2.5, 3.0, 10.0], size=nV, replace=False) if nV <= 6 else
              np.round(rng.uniform(0.1, 5.0, nV), 3)).tolist()
    rows = [(V, float(rng.uniform(1e-3, 1.0)), float(rng.uniform(100, 300)), float(rng.uniform(0.1, 1)))
            for V in speeds for _ in range(int(rng.integers(1, 30)))]
    order = rng.permutation(len(rows))
    spell = ["{:g}", "{:.6f}", "{!r}"]  # each reads back to the same float (3 decimals)
    text = "V,v,f,sigma\n# measured\n" + "".join(
        f"{spell[i % 3].format(rows[i][0])},{rows[i][1]!r},{rows[i][2]!r},{rows[i][3]!r}\n" for i in order)
    path = tmp_path / "t.csv"
    path.write_text(text)
    got = read_points(str(path), sigma=True)
    Vs = np.array([rows[i][0] for i in order])
    cols = [np.array([rows[i][j] for i in order]) for j in (1, 2, 3)]
    want = _split_by_passes(Vs, cols[0], cols[1], np.arange(3, 3 + len(order)), cols[2])
    assert len(got) == len(want) == len(set(speeds))
    for (V, v, f, lines, sd), (V0, v0, f0, lines0, sd0) in zip(got, want):
        assert V == V0
        for a, b in ((v, v0), (f, f0), (lines, lines0), (sd, sd0)):
            assert np.array_equal(a, b)


def test_table_split_costs_one_sort_whatever_the_number_of_pull_speeds():
    """Splitting 1,000,000 rows costs one sort whether they hold MAX_TABLES = 1000 pull speeds (split) or 1,000,000
    (refused, before any table is built): the split made one pass over all rows per distinct V (500 s for the
    reproducer, 300,000 rows each at its own V; 1e12 comparisons here).  Asserted as a ratio of the best of three
    CPU timings of this process, at most 10 (measured ~1.0 on a loaded machine): a ratio, so the machine's speed
    cancels, CPU time, which other jobs' load does not stretch, and hundreds of times below the pass per V's."""
    from peelapprox.law._tablefile import MAX_TABLES, _split

    rng = np.random.default_rng(0)
    tables = 1.0 + rng.integers(0, MAX_TABLES, 1_000_000) * 1e-3
    distinct = rng.uniform(1.0, 2.0, 1_000_000)

    def best(Vs):
        times, out = [], None
        for _ in range(3):
            t0 = time.process_time()
            try:
                out = _split(Vs, "file x")
            except ValueError as exc:
                out = str(exc)
            times.append(time.process_time() - t0)
        return out, min(times)

    (split, t_split), (refused, t_refused) = best(tables), best(distinct)
    assert len(split) == MAX_TABLES and sum(len(rows) for _, rows in split) == tables.size
    assert refused == "file x (V): at most MAX_TABLES = 1000 distinct pull speeds V (one table each), got 1000000"
    assert t_refused < 10 * t_split, (t_refused, t_split)


def test_a_file_of_too_many_tables_is_refused_before_building_them(tmp_path):
    """A file of MAX_TABLES + 1 distinct pull speeds is refused, naming the file, the limit and the count (the
    reproducer, 300,000 rows each at its own V, ran 500 s); one of MAX_TABLES is split into its 1000 tables
    (and then refused by ``tabulated`` for tables of one point: a table needs 5)."""
    from peelapprox.law._tablefile import MAX_TABLES, read_points

    path = tmp_path / "many.csv"
    path.write_text("V,v,f\n" + "".join(f"{1 + i * 1e-3:.4f},0.01,100\n" for i in range(MAX_TABLES + 1)))
    with pytest.raises(ValueError, match=r"many.csv.* \(V\): at most MAX_TABLES = 1000 distinct pull speeds V "
                                         r"\(one table each\), got 1001"):
        PeelForce.from_csv(str(path))
    path.write_text("V,v,f\n" + "".join(f"{1 + i * 1e-3:.4f},0.01,100\n" for i in range(MAX_TABLES)))
    assert len(read_points(str(path))) == MAX_TABLES
    with pytest.raises(ValueError, match="needs at least 5 points"):
        PeelForce.from_csv(str(path))


def test_simulate_force_build_is_bounded_by_max_wall(monkeypatch, capsys):
    """``simulate --force '<39-term sum of 1/(v+i)>' --max-wall 5`` ran 69 s: the law's build (sympy's
    derivatives) honoured only LAW_BUILD_SECONDS (60 s).  A stand-in build that would run for minutes (sleeping in
    short steps, as sympy's Python does) under ``--max-wall 0.5`` now stops at that budget: exit status 3 within
    :data:`BOUND`, the message naming --force and --max-wall; with no budget nearer, the law's own limit is still
    the ValueError it was (checked with the limit lowered to 0.3 s: exit status 2, 'took more than 0.3 s')."""
    from peelapprox.law import _expression

    def slow(*args, **kwargs):
        for _ in range(60_000):
            time.sleep(0.01)

    monkeypatch.setattr(_expression, "_checked_text", slow)
    argv = ["simulate", "--V", "1", "--I", "1e-5", "--t-end", "0.01", "--force", "300 + 2*v"]
    rc, took = _cli([*argv, "--max-wall", str(BUDGET)])
    err = capsys.readouterr().err
    assert rc == 3 and took < BOUND, (rc, took, err)
    assert "--force: more than 0.5 s of wall time (--max-wall) building the peel-force law" in err, err
    monkeypatch.setattr(_expression, "LAW_BUILD_SECONDS", 0.3)
    rc, took = _cli([*argv, "--max-wall", "600"])
    err = capsys.readouterr().err
    assert rc == 2 and took < BOUND, (rc, took, err)
    assert "took more than 0.3 s" in err, err


def test_a_timer_that_fires_at_once_is_always_disarmed():
    """A limit of a microsecond expires before or just after the timer is armed: in 3000 such bodies every
    one must end in the named ``Expired``, and afterwards no timer may be left armed nor a handler installed
    (armed before its ``try``, the timer once escaped the clean-up after ~1600 bodies and killed the process
    with SIGALRM 0.05 s later).  Exact counts: nothing here is a tolerance."""
    import signal

    from peelapprox._deadline import Expired, time_limit

    before = signal.getsignal(signal.SIGALRM)
    expired = 0
    for _ in range(3000):
        try:
            with time_limit(1e-6):
                sum(range(50))
        except Expired:
            expired += 1
    assert expired == 3000
    assert signal.getitimer(signal.ITIMER_REAL) == (0.0, 0.0)
    assert signal.getsignal(signal.SIGALRM) == before


def test_an_import_the_limit_interrupts_can_be_imported_again(tmp_path, monkeypatch):
    """A limit that lands inside an import leaves the process able to import that package again: a package
    whose ``__init__`` imports a submodule, then sleeps past the 0.2 s limit, is interrupted (``Expired``); the
    next import (no sleep) gives a package whose submodule sees the new package (exact: the name it reads).
    Before, the submodule stayed in ``sys.modules`` bound to the interrupted package, and the next import failed
    with an ``AttributeError`` (in-process CLI calls: ``peelapprox figures --max-wall 0.01`` broke the next
    ``import matplotlib`` of the process)."""
    import sys

    from peelapprox._deadline import Expired, time_limit

    pkg = tmp_path / "interrupted_pkg"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("import os, time\nfrom . import sub\n"
                                     "time.sleep(float(os.environ.get('INTERRUPTED_PKG_SLEEP', '0')))\n"
                                     "NAME = 'whole'\n")
    (pkg / "sub.py").write_text("import interrupted_pkg\n\ndef name():\n    return interrupted_pkg.NAME\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setenv("INTERRUPTED_PKG_SLEEP", "5")
    with pytest.raises(Expired):
        with time_limit(0.2):
            import interrupted_pkg  # noqa: F401
    assert "interrupted_pkg" not in sys.modules and "interrupted_pkg.sub" not in sys.modules
    monkeypatch.setenv("INTERRUPTED_PKG_SLEEP", "0")
    try:
        import interrupted_pkg

        assert interrupted_pkg.sub.name() == "whole"
    finally:
        for name in ("interrupted_pkg", "interrupted_pkg.sub"):
            sys.modules.pop(name, None)

"""Basins of attraction: exact.basins labels a grid of starts by the attractor each reaches.

The scene: the cubic law at V = 1.2 m/s, I = 2.2e-5 kg m², where two stable period-1 orbits coexist
(docs/orbits.md: F at the jump 240.06 N, |μ| = 0.29, and 238.47 N, |μ| = 0.66).  From α0 = 0, ω0 = 18 rad/s
the run ends on the second, from ω0 = 12 and 24 rad/s on the first; at α0 = -0.4 the default F0 has no root of
CONSTR (an invalid start).
"""

from __future__ import annotations

import json
import math
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

import exact
import peelapprox
from peelapprox import PeelForce, PeelParams, periodicity, return_map

CUBIC = PeelParams(V=1.2, I=2.2e-5, force=PeelForce.cubic())
GRID = dict(alpha0=[-0.4, 0.0, 0.1], omega0=[12.0, 18.0, 24.0], t_transient=10.0, window=5.0)


@pytest.fixture(scope="module")
def cubic_basins():
    return exact.basins(CUBIC, **GRID, max_workers=0, progress=False, orbits=True)


def _direct_cycle(params, t_transient, window, **start):
    """The sorted return-map cycle of a direct exact.simulate run from ``start`` (the oracle)."""
    tr = exact.simulate(params, t_transient + window, save="jumps", t_transient=t_transient, rtol=1e-10, **start)
    x = return_map(tr)
    n = periodicity(x).period
    assert n is not None
    return n, np.sort(x[-n:])


def test_two_coexisting_attractors_from_different_starts(cubic_basins):
    """Two period-1 attractors are found, and every labelled start's attractor cycle equals a direct
    exact.simulate run from that start to 1e-6 relative (the matching tolerance MATCH_RTOL: starts on one orbit
    agree to ~1e-12 at rtol 1e-10, the two orbits differ by 7e-3 relative).  The invalid row is labelled -1."""
    r = cubic_basins
    assert r.axis == "omega0" and r.labels.shape == (3, 3)
    assert [a.n for a in r.attractors] == [1, 1]
    assert r.labels.tolist() == [[-1, -1, -1], [0, 1, 0], [0, 0, 0]]
    assert [a.count for a in r.attractors] == [5, 1]
    assert r.attractors[0].cycle[0] == pytest.approx(240.0602, abs=1e-3)
    assert r.attractors[1].cycle[0] == pytest.approx(238.4664, abs=1e-3)
    for i, a0 in enumerate(GRID["alpha0"]):
        for j, w0 in enumerate(GRID["omega0"]):
            lab = int(r.labels[i, j])
            if lab < 0:
                continue
            n, cyc = _direct_cycle(CUBIC, GRID["t_transient"], GRID["window"], alpha0=a0, omega0=w0)
            assert n == r.attractors[lab].n
            np.testing.assert_allclose(r.attractors[lab].cycle, cyc, rtol=1e-6, atol=0)
            assert r.texts[i, j] == f"period-{n}"


def test_orbits_close_on_the_attractors_cycles(cubic_basins):
    """orbits=True: Newton's periodic orbit (an independent method: a fixed point of the section map, closed to
    1e-10) has the attractor's return-map value to 1e-8 relative (the agreement asked of basins) and is stable, with
    the multiplier moduli of docs/orbits.md's two branches at this I (0.29 and 0.66, to 0.01)."""
    mods = []
    for a in cubic_basins.attractors:
        assert a.orbit is not None and a.orbit_error is None
        assert a.orbit.stable
        np.testing.assert_allclose(a.orbit.return_map_values, a.cycle, rtol=1e-8)
        mods.append(float(np.abs(a.orbit.multipliers[0])))
    assert mods == pytest.approx([0.286, 0.660], abs=0.01)


def test_invalid_start_and_breakdown_are_labels_not_exceptions():
    """An (α0, F0) grid: at α0 = -0.3, F0 = 200 N the level F0 (1 + sin α0) = 141 N is below f(0+) = 150 N
    (exact.initial_state raises ValueError: the oracle), labelled "invalid start" (-1); at α0 = 0.3, F0 = 200
    N the run breaks down at t = 2.8 ms (ModelBreakdown, reason no_root): -3; F0 = 230 N reaches the period-1
    orbit of 240.06 N from both (to 1e-6, as above)."""
    with pytest.raises(ValueError):
        exact.initial_state(CUBIC, alpha0=-0.3, F0=200.0)
    r = exact.basins(CUBIC, alpha0=[-0.3, 0.3], F0=[200.0, 230.0], t_transient=10.0, window=5.0, max_workers=0,
                     progress=False)
    assert r.axis == "F0"
    assert r.labels.tolist() == [[exact.dynamics._basins.INVALID, 0], [exact.dynamics._basins.BREAKDOWN, 0]]
    assert r.texts[0, 0] == "invalid start" and r.texts[1, 0] == "breakdown:no_root"
    assert "no stable root of CONSTR" in r.messages[0]
    assert r.attractors[0].cycle[0] == pytest.approx(240.0602, abs=1e-3)
    assert r.counts() == {"A0 period-1": 2, "invalid start": 1, "breakdown": 1}


def test_undetermined_windows():
    """A window too short to decide is "undetermined" (-4), not a guess: the cubic's first 0.1 s hold one AB->CD
    jump ("no stick-slip": fewer than 2 returns); fvV's first second at I = 1e-5 holds 13 returns of the
    transient, not periodic, and too few (< 3 max_period = 96) to call aperiodic ("too short")."""
    r = exact.basins(CUBIC, alpha0=[0.0], omega0=[12.0], t_transient=0.0, window=0.1, max_workers=0,
                     progress=False)
    assert r.labels.tolist() == [[exact.dynamics._basins.UNDETERMINED]]
    assert r.texts[0, 0] == "undetermined:no stick-slip"
    assert r.n_returns[0, 0] == 1 and r.attractors == ()
    r = exact.basins(PeelParams(V=1.0, I=1e-5), alpha0=[-0.2], F0=[283.5], t_transient=0.0, window=1.0,
                     max_workers=0, progress=False)
    assert r.texts[0, 0] == "undetermined:too short" and r.n_returns[0, 0] == 13


def test_process_pool_and_executor_give_identical_results(cubic_basins):
    """Determinism: the default 2-thread pool, a spawned process pool and a thread executor give the in-process
    labels, texts and cycles bit for bit (each start is the same deterministic run; outcomes are put in grid
    order before grouping)."""
    import multiprocessing as mp
    from concurrent.futures import ProcessPoolExecutor

    pool = exact.basins(CUBIC, **GRID, max_workers=2, progress=False)
    with ProcessPoolExecutor(2, mp_context=mp.get_context("spawn")) as ex:
        procs = exact.basins(CUBIC, **GRID, executor=ex, progress=False)
    with ThreadPoolExecutor(2) as ex:
        threads = exact.basins(CUBIC, **GRID, executor=ex, progress=False)
    for r in (pool, procs, threads):
        assert np.array_equal(r.labels, cubic_basins.labels)
        assert r.texts.tolist() == cubic_basins.texts.tolist()
        assert r.cycles == cubic_basins.cycles
        assert [(a.n, a.cycle, a.count) for a in r.attractors] == \
            [(a.n, a.cycle, a.count) for a in cubic_basins.attractors]


def test_progress_rows_json_and_plot(cubic_basins, capsys):
    """progress: a callable sees every start once (done = 1 .. 9 of 9), True writes one stderr line per
    ~5 % (here 9 lines, each start 11 %); rows() has one row per start with its outcome; to_json is strict
    JSON with the counts; plot() draws one legend entry per outcome."""
    seen = []
    exact.basins(CUBIC, alpha0=[-0.4], omega0=[12.0, 18.0, 24.0], t_transient=1.0, window=1.0, max_workers=0,
                 progress=lambda done, total, rec: seen.append((done, total, rec["text"])))
    assert [s[:2] for s in seen] == [(1, 3), (2, 3), (3, 3)] and {s[2] for s in seen} == {"invalid start"}
    exact.basins(CUBIC, alpha0=[-0.4], omega0=[12.0, 18.0, 24.0], t_transient=1.0, window=1.0, max_workers=0)
    assert capsys.readouterr().err.count("basins [") == 3
    rows = cubic_basins.rows()
    assert len(rows) == 9 and rows[4]["omega0"] == 18.0 and rows[4]["label"] == 1 and rows[4]["n"] == 1
    assert float(rows[4]["cycle"]) == pytest.approx(238.4664, abs=1e-3)
    doc = json.loads(cubic_basins.to_json())
    assert doc["counts"] == {"A0 period-1": 5, "A1 period-1": 1, "invalid start": 3}
    assert doc["attractors"][1]["orbit"]["stable"] is True
    ax = cubic_basins.plot().axes[0]  # a figure made without pyplot: nothing to close
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert labels == ["period-1: F = 240.0602 N (5)", "period-1: F = 238.4664 N (1)", "invalid start (3)"]


def test_peelapprox_reexports():
    """The lazy re-exports are exact's objects."""
    assert peelapprox.basins is exact.basins and peelapprox.BasinResult is exact.BasinResult


@pytest.mark.parametrize("kw, name", [
    (dict(alpha0=[0.0], F0=[230.0], omega0=[12.0]), "F0"),
    (dict(alpha0=[0.0]), "omega0"),
    (dict(alpha0=[0.1, 0.0], F0=[230.0]), "alpha0"),
    (dict(alpha0=[[0.0]], F0=[230.0]), "alpha0"),
    (dict(alpha0=[], F0=[230.0]), "alpha0"),
    (dict(alpha0=[math.nan], F0=[230.0]), "alpha0"),
    (dict(alpha0=[0.0], F0=[-1.0]), "F0"),
    (dict(alpha0=[0.0], omega0=[12.0, 12.0]), "omega0"),
    (dict(alpha0=[0.0], F0=[230.0], window=0.0), "window"),
    (dict(alpha0=[0.0], F0=[230.0], t_transient=-1.0), "t_transient"),
    (dict(alpha0=[0.0], F0=[230.0], rtol=0.5), "rtol"),
    (dict(alpha0=[0.0], F0=[230.0], max_period=0), "max_period"),
    (dict(alpha0=[0.0], F0=[230.0], max_workers=-1), "max_workers"),
    (dict(alpha0=[0.0], F0=[230.0], max_workers=1.0), "max_workers"),
    (dict(alpha0=[0.0], F0=[230.0], executor="spawn"), "executor"),
    (dict(alpha0=[0.0], F0=[230.0], executor=ThreadPoolExecutor(1), max_workers=1), "max_workers"),
    (dict(alpha0=[0.0], F0=[230.0], orbits=1), "orbits"),
    (dict(alpha0=[0.0], F0=[230.0], progress="yes"), "progress"),
])
def test_bad_arguments_name_the_argument(kw, name):
    """Each bad argument raises ValueError (or ArgumentTypeError, a ValueError) naming it, before any run."""
    kw = {"max_workers": 0 if "executor" not in kw else None, "progress": False, **kw}
    with pytest.raises(ValueError, match=name):
        exact.basins(CUBIC, **kw)


def test_bad_params():
    """params must be a PeelParams (ArgumentTypeError, a TypeError, naming it)."""
    with pytest.raises(TypeError, match="params"):
        exact.basins("params", alpha0=[0.0], F0=[230.0])


def test_fvV_low_inertia_three_coexisting_periods():
    """fvV at V = 1, I = 1e-5 (docs/dynamics.md: periods 1, 3 and 15 coexist over α0, 40 s transient, the
    ``attractors`` table: period 1 from -0.3, 15 from -0.2, 3 from 0): the grid (F0 the default 1.01 f(V, V))
    finds periods 1, 15 and 3 in that order, each cycle equal to a direct exact.simulate run to 1e-6 relative
    (the matching tolerance).  About 2 s."""
    p = PeelParams(V=1.0, I=1e-5)
    F0 = 1.01 * float(peelapprox.peel_force(1.0, 1.0))
    r = exact.basins(p, alpha0=[-0.3, -0.2, 0.0], F0=[F0], t_transient=40.0, window=20.0, max_workers=0,
                     progress=False)
    assert [a.n for a in r.attractors] == [1, 15, 3] and r.labels.ravel().tolist() == [0, 1, 2]
    for i, a0 in enumerate([-0.3, -0.2, 0.0]):
        lab = int(r.labels[i, 0])
        n, cyc = _direct_cycle(p, 40.0, 20.0, alpha0=a0, F0=F0)
        assert n == r.attractors[lab].n
        np.testing.assert_allclose(r.attractors[lab].cycle, cyc, rtol=1e-6, atol=0)


@pytest.mark.slow
def test_fvV_larger_grid_on_a_pool():
    """A 9 x 7 (α0, F0) grid at fvV, V = 1, I = 1e-5 on a 2-worker pool (about 30 s): a start is labelled
    "invalid start" exactly where exact.initial_state raises ValueError (the oracle: no root of CONSTR); the
    attractors are periods 15, 3 and 1 (docs/orbits.md, Basins), each with a stable periodic orbit found by Newton
    whose return-map values equal the attractor's cycle to 1e-8 relative (the agreement asked of basins)."""
    p = PeelParams(V=1.0, I=1e-5)
    a0, F0 = np.linspace(-0.4, 0.4, 9), np.linspace(150.0, 330.0, 7)
    r = exact.basins(p, alpha0=a0, F0=F0, t_transient=40.0, window=20.0, max_workers=2, progress=False,
                     orbits=True)
    for i, a in enumerate(a0):
        for j, F in enumerate(F0):
            try:
                exact.initial_state(p, alpha0=float(a), F0=float(F))
                feasible = True
            except ValueError:
                feasible = False
            assert (r.labels[i, j] == exact.dynamics._basins.INVALID) == (not feasible)
    assert sorted(a.n for a in r.attractors) == [1, 3, 15]
    for att in r.attractors:
        assert att.orbit is not None and att.orbit.stable
        np.testing.assert_allclose(np.sort(att.orbit.return_map_values), att.cycle, rtol=1e-8)

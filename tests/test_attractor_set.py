"""The set of coexisting attractors, :func:`exact.attractor_set`, and the escape law behind its transients.

Oracles: the periods and multipliers docs/dynamics.md and docs/orbits.md state (V = 1, I = 1e-5: periods 3 and 1
coexist, |μ| 0.486, 0.178 and 0.920; V = 2, I = 1e-3: period 7 from the default start; V = 2, I = 1e-4: chaos
at 4.2-5.5 bits/s; V = 6: steady; V = 0.5, I = 1e-4: breakdown), a linear map iterated by hand (the amplitude
law's closed form), the escape seen when the exact run is continued, and the set's own invariance to where its
starts run.
"""

from __future__ import annotations

import json
import math
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

import exact
from exact import attractor_set
from peelapprox import PeelParams, return_map

# ---------------------------------------------------------------------------------------------- coexistence


@pytest.fixture(scope="module")
def v1_set():
    """V = 1, I = 1e-5 from α0 = 0 (period 3) and α0 = -0.3 (period 1), docs/dynamics.md's table."""
    return attractor_set(PeelParams(V=1.0, I=1e-5), starts=[0.0, -0.3], t_transient=15.0, t_window=5.0)


def test_coexisting_periods_and_their_multipliers(v1_set):
    """docs/dynamics.md: from α0 = 0 period 3, from α0 = -0.3 period 1; docs/orbits.md: |μ| = 0.486, 0.178
    (period 3) and 0.920 (period 1).  Newton closes the orbits to 1e-9, so the moduli agree to the 3 digits the
    docs quote (tolerance 1e-3)."""
    s = v1_set
    assert s.status == "ok", s.message
    assert [a.label for a in s.attractors] == ["period-3", "period-1"]
    assert s.primary is s.attractors[0]
    assert [a.share for a in s.attractors] == [0.5, 0.5]
    p3, p1 = s.attractors
    assert sorted(abs(m) for m in p3.multipliers) == pytest.approx([0.178, 0.486], abs=1e-3)
    assert p1.max_multiplier == pytest.approx(0.920, abs=1e-3)
    assert p3.stable and p1.stable
    # the observables are the window's: period 3's slip interval is docs/dynamics.md's 0.08023 s
    assert p3.observables.slip_interval == pytest.approx(0.08023, rel=1e-4)
    assert s.counters["runs"] == 2 and s.counters["orbits"] == 2 and s.wall_time > 0


def test_closest_names_the_attractor_of_given_observables(v1_set):
    """An attractor's own observables are at distance 0 from it (to rounding, 1e-12) and farther from the other
    (their slip intervals differ by 11 %)."""
    p3, p1 = v1_set.attractors
    a, d = v1_set.closest(p1.observables)
    assert a is p1 and d < 1e-12
    a, d = v1_set.closest({"slip_interval": p3.observables.slip_interval * 1.02,
                           "force_drop": p3.observables.force_drop})
    assert a is p3 and d == pytest.approx(0.02, rel=1e-9)
    assert v1_set.closest({"slip_interval": None, "force_drop": 1.0}) is None
    with pytest.raises(ValueError, match="min_share"):
        v1_set.closest(p1.observables, min_share=2)


def test_table_json_repr_plot(v1_set):
    """The outputs: a row per attractor, strict JSON, a one-line repr, a figure with one line per attractor."""
    pd = pytest.importorskip("pandas")
    df = v1_set.to_dataframe()
    assert isinstance(df, pd.DataFrame) and list(df["label"]) == ["period-3", "period-1"]
    assert df.loc[0, "period"] == 3 and df.loc[1, "n_starts"] == 1
    doc = json.loads(v1_set.to_json())
    assert doc["status"] == "ok" and len(doc["outcomes"]) == 2
    r = repr(v1_set)
    assert r.startswith("AttractorSet(ok, V=1, I=1e-05: period-3 50 %; period-1 50 %") and "\n" not in r
    pytest.importorskip("matplotlib")
    fig = v1_set.plot()
    assert len(fig.axes[0].lines) == 2


def test_period_seven_at_v2():
    """docs/dynamics.md: V = 2, I = 1e-3 is period 7 from the default start (stable, Newton-closed)."""
    s = attractor_set(PeelParams(V=2.0, I=1e-3), starts=[0.0], t_transient=10.0, t_window=5.0)
    assert s.primary.label == "period-7" and s.primary.kind == "periodic" and s.primary.stable


def test_chaos_has_a_positive_exponent():
    """docs/dynamics.md: V = 2, I = 1e-4 is chaotic, 4.2-5.5 bits/s by four methods over 200 s.  A 10 s tangent
    estimate scatters by ~1 bit/s, hence the band [2.5, 8]."""
    s = attractor_set(PeelParams(V=2.0, I=1e-4), starts=[0.0], t_transient=5.0, t_window=5.0, lyapunov_T=10.0)
    a = s.primary
    assert a.kind == "chaotic" and 2.5 < a.lyapunov < 8.0 and a.period is None
    assert s.counters["lyapunov"] == 1


def test_steady_and_breakdown_are_statuses():
    """docs/dynamics.md: V = 6 (no folds) is steady peeling; V = 0.5, I = 1e-4 breaks down (no root of CONSTR at
    t = 0.018 s) -- statuses, not exceptions."""
    s = attractor_set(PeelParams(V=6.0, I=1e-5), t_transient=1.0, t_window=1.0)
    assert s.status == "ok" and [a.kind for a in s.attractors] == ["steady"] and s.attractors[0].share == 1.0
    b = attractor_set(PeelParams(V=0.5, I=1e-4), starts=[0.0], t_transient=1.0, t_window=1.0)
    assert b.status == "breakdown only" and b.attractors[0].kind == "breakdown"
    assert b.outcomes[0].outcome == "breakdown" and "breakdown" in b.attractors[0].label


# ---------------------------------------------------------------------------------------------- transients


def test_escape_law_on_a_linear_map():
    """Closed form: iterate ``d_{k+1} = M d_k`` with M a rotation by 0.1 rad scaled by 1.002 (a complex pair of
    modulus 1.002) near a section point; the escape return is where ``|x_k - x*|`` first exceeds 1 % of x*,
    computed here from the iterates.  The amplitude law is exact for a linear map, so the prediction lands within
    half a rotation (31 returns) of it."""
    from exact.dynamics._escape import ESCAPE_DEVIATION, predict_escape

    p = PeelParams(V=2.0, I=1e-3)
    s = np.array([1.0, p.V / p.R])
    r, th = 1.002, 0.1
    Ms = r * np.array([[math.cos(th), -math.sin(th)], [math.sin(th), math.cos(th)]])
    M = Ms * s[:, None] / s[None, :]  # in (α, ω)
    z_star = np.array([0.05, 25.0])
    F = lambda a: 300.0 / (1.0 + float(p.closure(a)[0]))  # noqa: E731 - the section force, f_max = 300 N
    d = np.array([1e-5, 0.0])
    alphas, omegas, xs = [], [], []
    for _ in range(6000):
        alphas.append(z_star[0] + d[0])
        omegas.append(z_star[1] + d[1] * s[1])
        xs.append(F(alphas[-1]))
        d = Ms @ d
    alphas, omegas, xs = map(np.array, (alphas, omegas, xs))
    x_star = F(z_star[0])
    k_true = int(np.flatnonzero(np.abs(xs - x_star) > ESCAPE_DEVIATION * x_star)[0])
    window = slice(0, 200)
    e = predict_escape(p, M, z_star, x_star, alphas[window], omegas[window], np.arange(200) * 0.01, 0.01, 1, 0)
    assert abs(e.multiplier) == pytest.approx(1.002, rel=1e-12)
    assert abs(e.return_index - k_true) <= 31, (e.return_index, k_true)
    assert e.growth == pytest.approx(1.002, rel=1e-3)


@pytest.mark.parametrize("t_transient", [0.6, 1.0])
def test_weakly_unstable_small_mode_is_a_transient_with_its_escape(t_transient):
    """V = 4.31, I = 7.2e-4 (the issue's small mode): from the default start the run sits on a period-1 orbit
    with a complex pair |μ| = 1.0018 for ~1700 returns.  At the end of a 0.6 or 1 s transient it is a transient,
    not an attractor, and the escape it predicts (the return at which F departs from the orbit's by 1 %) lies
    within 20 % (the issue's target) of the escape seen when the same run is continued to 4 s, counted in
    returns from the window's start."""
    p = PeelParams(V=4.31, I=7.2e-4)
    s = attractor_set(p, starts=[0.0], t_transient=t_transient, t_window=0.4)
    assert s.status == "transient only" and not s.attractors
    o = s.outcomes[0]
    assert o.outcome == "transient" and o.escape is not None
    mu = abs(o.escape.multiplier)
    assert 1.0001 < mu < 1.01 and abs(o.escape.multiplier.imag) > 0
    assert "weakly unstable period-1" in o.message and "predicted escape" in o.message
    from exact.dynamics._escape import escape_index

    full = exact.simulate(p, 4.0, save="jumps", rtol=1e-10)
    t, x = return_map(full, with_times=True)
    k_window = int(np.searchsorted(t, t_transient))
    orbit = exact.periodic_orbit(p, start=exact.simulate(p, t_transient + 0.4, save="jumps", t_transient=t_transient),
                                 n=1)
    k_seen = escape_index(x, orbit.return_map_values, start=k_window)
    assert k_seen is not None
    assert (o.escape.return_index - k_window) == pytest.approx(k_seen - k_window, rel=0.2)
    assert o.escape.time == pytest.approx(t[k_seen], rel=0.2)


# ---------------------------------------------------------------------------------------------- input, budget


def test_bad_starts_are_named_errors():
    """An empty set, a start out of its range, a start without a consistent state, an unknown key: ValueError
    or TypeError naming the argument, before any run."""
    p = PeelParams(V=1.0, I=1e-5)
    with pytest.raises(ValueError, match="at least one start"):
        attractor_set(p, starts=[])
    with pytest.raises(ValueError, match=r"starts\[0\]"):
        attractor_set(p, starts=[5.0])
    with pytest.raises(ValueError, match=r"starts\[1\]"):
        attractor_set(p, starts=[0.0, {"alpha0": 0.0, "F0": 1e4, "branch0": "AB"}])
    with pytest.raises(ValueError, match="unknown keys"):
        attractor_set(p, starts=[{"alpha": 0.1}])
    with pytest.raises(TypeError, match=r"starts\[0\]"):
        attractor_set(p, starts=["x"])
    with pytest.raises(ValueError, match="starts must be 'default'"):
        attractor_set(p, starts="all")
    with pytest.raises(ValueError, match="t_window"):
        attractor_set(p, t_window=0.0)


def test_default_design_and_where_it_runs():
    """The default design is 8 starts where f has folds (the solver's first, the rest foot second); the set is
    the same serially, on a thread pool and on a given executor (the windows are read in the starts' order)."""
    p = PeelParams(V=2.0, I=1e-3)
    from exact.dynamics._attractor_set_runs import default_starts

    names = [s.name for s in default_starts(p)]
    assert len(names) == 8 and names[:2] == ["solver", "rest"]
    kw = dict(t_transient=2.0, t_window=1.0, stability=False)
    a = attractor_set(p, workers=0, **kw)
    b = attractor_set(p, workers=2, **kw)
    with ThreadPoolExecutor(3) as ex:
        c = attractor_set(p, executor=ex, **kw)
    for other in (b, c):
        assert [x.row() for x in other.attractors] == [x.row() for x in a.attractors]
        assert [o.attractor for o in other.outcomes] == [o.attractor for o in a.outcomes]
    calls = []
    attractor_set(p, starts=[0.0, 0.1], progress=lambda d, t, m: calls.append((d, t)), **kw)
    assert calls[-1] == (2, 2)


def test_a_lost_start_is_an_outcome():
    """An executor whose workers die: every start an outcome "failure" naming the cause, the set's status "no
    attractor", no exception."""
    from concurrent.futures import Executor, Future

    class Dying(Executor):
        def submit(self, fn, /, *args, **kwargs):
            f: Future = Future()
            f.set_exception(RuntimeError("worker died"))
            return f

    s = attractor_set(PeelParams(V=2.0, I=1e-3), starts=[0.0, 0.1], executor=Dying())
    assert s.status == "no attractor" and not s.attractors
    assert [o.outcome for o in s.outcomes] == ["failure", "failure"]
    assert "worker died" in s.outcomes[0].message


def test_max_wall_is_a_status():
    """A budget too small for any run: every start an outcome "max_wall", the set's status "max_wall", no
    exception, and the call returns within the budget plus the overhead of reading: under a second of this
    process's CPU time (serial; CPU, not wall time, which other jobs' load stretches)."""
    import time

    t0 = time.process_time()
    s = attractor_set(PeelParams(V=2.0, I=1e-3), max_wall=1e-3, workers=0)
    assert s.status == "max_wall" and not s.attractors
    assert all(o.outcome == "max_wall" for o in s.outcomes)
    assert time.process_time() - t0 < 1.0


@pytest.mark.slow
def test_primary_agrees_with_attractor_observables_on_random_points():
    """On 6 seeded random points (V in [0.3, 4.8] m/s, I log-uniform in [2e-6, 8e-2]): the first start's window is
    attractor_observables' own run (identical observables), and where it is periodic the cycle Newton closes agrees
    with the window's sorted last n returns to 1e-5 (a window settled to period_rtol 1e-6 lies within ~1e-7 of its
    orbit; Newton is an independent computation from one seed), and the orbit is stable (an attractor)."""
    rng = np.random.default_rng(3535)
    checked = 0
    for V, lgI in zip(rng.uniform(0.3, 4.8, 6), rng.uniform(math.log10(2e-6), math.log10(8e-2), 6), strict=True):
        p = PeelParams(V=float(V), I=float(10 ** lgI))
        s = attractor_set(p, starts=[0.0], max_exponents=0)
        try:
            obs = exact.attractor_observables(p)
        except exact.ModelBreakdown:
            assert s.status == "breakdown only"
            continue
        o = s.outcomes[0]
        if o.outcome == "transient":
            continue
        a = s.primary
        for name in ("slip_interval", "force_drop", "F_max", "n_slips", "period"):
            assert getattr(a.observables, name) == getattr(obs, name)
        if a.kind == "periodic" and obs.period is not None:
            tr = exact.window_run(p)
            x = return_map(tr)
            assert np.allclose(a.cycle, np.sort(x[-a.period:]), rtol=1e-5, atol=0)
            assert a.stable
            checked += 1
    assert checked >= 2


@pytest.mark.slow
def test_escape_predictions_on_random_points_of_the_small_mode_band():
    """The issue's target on 8 seeded random points of the band where the solver's start lands on the small
    period-1 mode (V in [3.3, 4.8] m/s, I log-uniform in [2.5e-4, 1.5e-3]): wherever the run is reported as a
    transient after 0.5 s with |μ| - 1 in [1e-4, 1e-2], its predicted escape (returns after the window's start)
    is within 20 % of the escape seen in the same run continued to 12 s.  Half the points at least must be such
    transients (on seed 7 of this band 10 of 14 were, predictions within 2.5 %)."""
    from exact.dynamics._escape import escape_index

    rng = np.random.default_rng(35)
    tested = 0
    for V, lgI in zip(rng.uniform(3.3, 4.8, 8), rng.uniform(math.log10(2.5e-4), math.log10(1.5e-3), 8), strict=True):
        p = PeelParams(V=float(V), I=float(10 ** lgI))
        s = attractor_set(p, starts=[0.0], t_transient=0.5, t_window=0.3)
        e = s.outcomes[0].escape
        if s.outcomes[0].outcome != "transient" or e is None or not 1e-4 <= abs(e.multiplier) - 1 <= 1e-2:
            continue
        t, x = return_map(exact.simulate(p, 12.0, save="jumps", rtol=1e-10), with_times=True)
        k_window = int(np.searchsorted(t, 0.5))
        orbit = exact.periodic_orbit(p, start=exact.simulate(p, 0.8, save="jumps", t_transient=0.5), n=1)
        k_seen = escape_index(x, orbit.return_map_values, start=k_window)
        assert k_seen is not None, (V, 10 ** lgI)
        assert (e.return_index - k_window) == pytest.approx(k_seen - k_window, rel=0.2), (V, 10 ** lgI)
        tested += 1
    assert tested >= 4

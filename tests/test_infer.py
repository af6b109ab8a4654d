"""Parameters from data: :func:`peelapprox.infer` recovers the parameters of a synthetic experiment.

The oracle is the truth the synthetic trace was made with: the exact model at known parameters, sampled at
10 kHz with 0.5 N of white noise and a 5 N drift (``Trajectory.as_series``), the way a tensile machine records.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import exact
from peelapprox import ForceSeries, PeelParams, infer


def _trace(V: float, I: float, k: float = 1000.0, seconds: float = 20.0) -> ForceSeries:
    tr = exact.simulate(PeelParams(V=V, I=I, k=k), 30.0 + seconds, t_eval=30.0 + np.arange(int(seconds * 1e4)) / 1e4)
    return tr.as_series(1e4, noise=0.5, drift=5.0, seed=1)


@pytest.fixture(scope="module")
def high_inertia() -> ForceSeries:
    return _trace(1.0, 1e-2)


def _infer_stats():
    import exact.dynamics._infer_stats as stats

    return stats


def _read_once(monkeypatch) -> None:
    """Within one test, each exact run and each model reading of ``exact.dynamics._infer_stats`` made once: the
    module's ``simulate`` and ``_readings`` memoised on their arguments (the run's parameters, end time, sampling
    times, tolerance, budget and start, with the solver's start ``alpha0=0.0`` spelled out; the reading's series,
    threshold, noise level and seeds).  Both are deterministic (the same inputs give the same run, bitwise, and
    the noise has fixed seeds), so a test sees the values it would see without: fewer runs, the same checks."""
    stats = _infer_stats()
    runs: dict = {}
    reads: dict = {}
    simulate, readings = stats.simulate, stats._readings

    def start_key(kw: dict) -> tuple:
        return tuple(sorted({"alpha0": 0.0, **kw}.items()))

    def simulate_once(p, t_end, *, t_eval=None, **kw):
        key = (repr(p), t_end, None if t_eval is None else np.asarray(t_eval).tobytes(),
               kw.pop("rtol", 1e-8), kw.pop("max_wall", None), start_key(kw))
        if key not in runs:
            runs[key] = simulate(p, t_end, t_eval=t_eval, rtol=key[3], max_wall=key[4], **kw)
        return runs[key]

    def readings_once(p, series, threshold, noise, t_transient, rtol, max_wall, start, seeds):
        key = (repr(p), id(series), threshold, noise, t_transient, rtol, max_wall, start_key(start), seeds)
        if key not in reads:
            reads[key] = readings(p, series, threshold, noise, t_transient, rtol, max_wall, start, seeds)
        return reads[key]

    monkeypatch.setattr(stats, "simulate", simulate_once)
    monkeypatch.setattr(stats, "_readings", readings_once)


def test_k_alone_is_recovered():
    """Hypothesis: with I known, the stiffness k of a periodic high-inertia trace (V = 1, I = 1e-2, k = 1000 N/m;
    5 s of it, 20 cycles of the period-8 orbit, to keep the test short) is recovered from a start at 900 N/m
    within 5 % (the goal; measured 0.2 % from 20 s with I free too), identified, its 95 % interval covering the
    truth."""
    res = infer(_trace(1.0, 1e-2, seconds=5.0), PeelParams(V=1.0, I=1e-2, k=900.0), ("k",), search=1.5,
                max_wall=300)
    assert res.status == "converged" and res.identified["k"]
    assert abs(res.values["k"] / 1000.0 - 1) < 0.05
    lo, hi = res.intervals["k"]
    assert lo <= 1000.0 <= hi
    assert res.params.k == res.values["k"] and res.params.V == 1.0
    assert "identified" in res.report() and len(res.residuals) == 7


@pytest.mark.slow
def test_a_start_a_third_of_the_truth_extends_the_box():
    """Hypothesis (inference over attractor sets): with I a factor 3 below the truth (V = 1, I = 1e-2, k known, 5 s
    of the period-8 trace) the truth lies on the initial box's edge (params0 · search); the search extends the box
    instead of calling I "not identified: ... the edge of the search", and recovers I within 10 % (the issue's
    goal), identified, its 95 % interval inside the extended box and covering the truth (about 30 exact runs,
    1-2 min)."""
    res = infer(_trace(1.0, 1e-2, seconds=5.0), PeelParams(V=1.0, I=1e-2 / 3, k=1000.0), ("I",), max_wall=600)
    assert "extended" in res.message, res.message
    assert res.identified["I"], res.verdicts["I"]
    assert abs(res.values["I"] / 1e-2 - 1) < 0.10
    lo, hi = res.intervals["I"]
    assert lo <= 1e-2 <= hi and hi > 1e-2 * 1.01


def test_the_box_stops_at_the_parameter_range():
    """The extension stays within PARAM_RANGES: a side at the range's limit does not move, an interior side
    moves out by the initial half-width at the node spacing (a closed-form check of the helper)."""
    from exact.dynamics._infer_search import extend as _extend
    from peelapprox import PARAM_RANGES

    lo = np.array([np.log(PARAM_RANGES["I"][0])])
    hi = np.array([np.log(PARAM_RANGES["I"][1])])
    axes = [np.linspace(hi[0] - 2 * np.log(3.0), hi[0], 9)]
    new, blo, bhi = _extend(["I"], axes, axes[0][:1].copy(), axes[0][-1:].copy(), [(0, 1), (0, -1)], (lo, hi), 3.0)
    assert bhi[0] == hi[0]  # already at the limit: unchanged
    assert np.isclose(blo[0], axes[0][0] - np.log(3.0))  # 4 nodes of spacing ln 3 / 4 below the old edge
    assert new[0].size == 13 and np.allclose(np.diff(new[0]), np.log(3.0) / 4)


def test_the_refined_grid_covers_the_best_cells():
    """After the first grid, a finer grid around its best nodes (``refine``, REFINE_TOP of them) at a quarter of
    the node spacing: closed-form checks on a 9 x 9 grid with two best nodes side by side: 24 new points around
    the best one, 20 more around its neighbour (the 5 x 5 patches overlap in a column), none outside the box (a
    best node on the box's edge loses the points beyond it), each point once, the best node's first."""
    from exact.dynamics._infer_search import Point, refine

    axes = [np.linspace(0.0, 2.0, 9), np.linspace(10.0, 12.0, 9)]  # spacing 0.25
    box = (np.array([0.0, 10.0]), np.array([2.0, 12.0]))
    pts = [Point(np.array([a, b]), 100.0, [], []) for a in axes[0] for b in axes[1]]
    pts[4 * 9 + 4] = Point(np.array([1.0, 11.0]), 1.0, [], [])  # the best
    pts[5 * 9 + 4] = Point(np.array([1.25, 11.0]), 2.0, [], [])  # its neighbour along the first axis
    out = np.array(refine(axes, pts, box, 2))
    assert len(out) == 25 + 20  # 5 x 5 patches, centres included, one shared column of 5
    assert np.allclose(out[0], [0.875, 10.875]) and np.allclose(out[12], [1.0, 11.0])
    assert len({tuple(np.round(x, 9)) for x in out}) == len(out)
    assert np.allclose(np.unique(np.round(np.diff(np.unique(out[:, 0])), 9)), 0.0625)
    edge = [Point(np.array([0.0, 10.0]), 0.5, [], [])]
    assert len(refine(axes, edge, box, 1)) == 9  # a corner: 3 x 3 of the patch inside the box


def test_the_closest_attractor_of_the_set_is_read():
    """Hypothesis (inference over attractor sets): at V = 1, I = 1e-5 the solver's start and the rest start reach
    the period-3 orbit, alpha0 = -0.3 the period-1 (exact.attractor_set). Given a trace of the period-1 attractor, the
    set's reading over the first three starts picks alpha0 = -0.3, labels it period-1, and its statistics equal the
    data's within 3 sigma (the same orbit; the data carry another noise draw and a drift); from the solver's start
    alone the reading is period-3, off by more than 3 sigma (slip interval 0.080 vs 0.071 s: 6 sigma)."""
    from exact.dynamics._infer_stats import data_statistics, set_statistics

    p = PeelParams(V=1.0, I=1e-5)
    tr = exact.simulate(p, 35.0, alpha0=-0.3, t_eval=30.0 + np.arange(50000) / 1e4)
    s = tr.as_series(1e4, noise=0.5, drift=5.0, seed=1)
    d = data_statistics(s)
    vals, sig, threshold, noise, used = d.values, d.sigma, d.threshold, d.noise, d.used
    r = set_statistics(p, s, threshold, noise, 30.0, 1e-10, 120.0, (vals, sig, used), 3)
    assert r.start == "alpha0=-0.3" and r.label == "period-1" and r.n_runs == 3
    assert r.values is not None and np.all(np.abs((r.values - vals) / sig)[used] <= 3.0)
    one = set_statistics(p, s, threshold, noise, 30.0, 1e-10, 120.0, (vals, sig, used), 1)
    assert one.start == "solver" and one.label == "period-3" and one.n_runs == 1
    assert one.values is not None and abs(one.values[0] - vals[0]) > 3.0 * sig[0]


def test_the_replicate_spread_of_a_chaotic_trace():
    """Hypothesis (inference over attractor sets, synthetic likelihood): at the chaotic point V = 2.5, I = 1e-4 (5 s
    windows) the model's spread over replicates (three starts of the attractor set's design, each another phase of the
    attractor) of the window means of the slip interval, drop, stick and slip times matches the standard error
    of the mean the data's own slips give (spread / sqrt(n - 1)) within a factor 4: the sd of three replicates
    lies within [0.16, 1.92] of its true value at 95 % (chi-squared, 2 dof) and the slips' correlation makes the
    standard error itself approximate (measured ratios 0.5-1.3).  The cycle line of a chaotic trace is not
    stable across the replicates."""
    from exact.dynamics._attractor_set_runs import default_starts
    from exact.dynamics._infer_stats import STATISTICS, data_statistics, replicate_spread

    p = PeelParams(V=2.5, I=1e-4)
    s = exact.simulate(p, 35.0, t_eval=30.0 + np.arange(50000) / 1e4).as_series(1e4, noise=0.5, drift=5.0, seed=1)
    o = s.observables()
    assert o.period is None
    d = data_statistics(s)
    threshold, noise = d.threshold, d.noise
    sd, stable, n, start = replicate_spread(p, s, threshold, noise, 30.0, 1e-10, 120.0, 3)
    assert sd is not None and n == 3 and not stable
    assert start == default_starts(p)[0].kwargs()  # without a target, the first replicate: the solver's start
    for j, name in enumerate(STATISTICS[:4]):
        sem = getattr(o, f"{name}_spread") / np.sqrt(o.n_slips - 1)
        assert 0.25 <= sd[j] / sem <= 4.0, (name, sd[j], sem)


@pytest.mark.slow
def test_I_and_k_at_high_inertia(high_inertia):
    """Hypothesis (the stated goal): at V = 1, I = 1e-2 (period 8) I is recovered within 10 % and k within 5 %
    from a start at I = 1.3e-2, k = 900, both identified with 95 % intervals covering the truth (measured: I
    0.4 % off, k 0.03 %; ~110 exact runs, 0.5-3 min)."""
    res = infer(high_inertia, PeelParams(V=1.0, I=1.3e-2, k=900.0), ("I", "k"), max_wall=900)
    assert res.identified == {"I": True, "k": True}
    assert abs(res.values["I"] / 1e-2 - 1) < 0.10 and abs(res.values["k"] / 1000.0 - 1) < 0.05
    assert res.intervals["I"][0] <= 1e-2 <= res.intervals["I"][1]
    assert res.intervals["k"][0] <= 1000.0 <= res.intervals["k"][1]


@pytest.mark.slow
def test_I_and_k_at_low_inertia():
    """Hypothesis (the stated goal at low inertia): at V = 3.95 m/s, I = 1.43e-5 (period 1 over k from 900 to
    1100 N/m: a robust attractor, unlike V = 1, I = 1e-5 where periods 1, 3 and 15 coexist) k is recovered
    within 5 % from a start at I = 1.86e-5, k = 900, identified with a 95 % interval covering the truth; I too
    (measured: I +0.2 %, k -0.04 %; ~120 exact runs, about 2 min)."""
    res = infer(_trace(3.95, 1.43e-5), PeelParams(V=3.95, I=1.3 * 1.43e-5, k=900.0), ("I", "k"), max_wall=900)
    assert res.identified == {"I": True, "k": True}
    assert abs(res.values["k"] / 1000.0 - 1) < 0.05 and abs(res.values["I"] / 1.43e-5 - 1) < 0.10
    assert res.intervals["k"][0] <= 1000.0 <= res.intervals["k"][1]
    assert res.intervals["I"][0] <= 1.43e-5 <= res.intervals["I"][1]
    assert "f_cycle" not in {r["observable"] for r in res.residuals}  # period 1: no line below f_slip / 2


@pytest.mark.slow
def test_a_multistable_point_is_not_called_identified():
    """Hypothesis: at V = 1, I = 1e-5 periods 1, 3 and 15 coexist (docs/dynamics.md), so neighbouring parameter
    points land on other attractors and no point of the search fits the period-3 trace (chi2 probability
    below 1e-3): the verdict is "not identified" for both parameters, not a number with a narrow interval."""
    res = infer(_trace(1.0, 1e-5), PeelParams(V=1.0, I=1.3e-5, k=900.0), ("I", "k"), max_wall=900)
    assert res.identified == {"I": False, "k": False}
    assert all("fits poorly" in v for v in res.verdicts.values())


def test_bad_input_is_named(high_inertia):
    p0 = PeelParams(V=1.0, I=1e-2)
    t = np.arange(1000) / 1000.0
    cases = [
        (dict(series=high_inertia, params0=p0, free=("m",)), ValueError, "free"),
        (dict(series=high_inertia, params0=p0, free=("force.a1",)), ValueError, "not a coefficient"),
        (dict(series=high_inertia, params0=p0, free=("k", "k")), ValueError, "twice"),
        (dict(series=high_inertia, params0=p0, free="k"), TypeError, "free"),
        (dict(series=high_inertia, params0={"V": 1}, free=("k",)), TypeError, "params0"),
        (dict(series=ForceSeries(t, t), params0=p0, free=("k",)), ValueError, "no pull speed"),
        (dict(series=ForceSeries(t, t, V=1.0), params0=p0, free=("k",)), ValueError, "does not stick-slip"),
        (dict(series=high_inertia, params0=p0, free=("k",), search=1.0), ValueError, "search"),
        (dict(series=high_inertia, params0=p0, free=("k",), statistics=("period",)), ValueError, "statistics"),
        (dict(series=high_inertia, params0=p0, free=("k",), max_wall=0.0), ValueError, "max_wall"),
        (dict(series=high_inertia, params0=p0, free=("k",), attractors=0), ValueError, "attractors"),
        (dict(series=high_inertia, params0=p0, free=("k",), attractors=9), ValueError, "attractors"),
        (dict(series=high_inertia, params0=p0, free=("k",), replicates=0), ValueError, "replicates"),
        (dict(series=high_inertia, params0=p0, free=("k",), replicates=2.0), ValueError, "replicates"),
    ]
    for kwargs, error, match in cases:
        with pytest.raises(error, match=match):
            infer(**kwargs)


def test_a_statistic_the_trace_does_not_carry_is_named():
    """A period-1 trace (V = 3.95 m/s, I = 1.43e-5) has no cycle line below half its slip frequency, so
    ``statistics=("f_cycle",)`` leaves nothing to fit: a ValueError naming ``statistics`` and why, before any
    model run, not a "converged" fit of an empty residual; with every statistic the report notes what was left
    out."""
    p = PeelParams(V=3.95, I=1.43e-5)
    s = exact.simulate(p, 32.0, t_eval=30.0 + np.arange(20000) / 1e4).as_series(1e4, noise=0.5, drift=5.0, seed=1)
    with pytest.raises(ValueError, match=r"statistics: 0 fitted statistic\(s\) for 1 free.*f_cycle is not fitted"):
        infer(s, p, ("k",), statistics=("f_cycle",))
    with pytest.raises(ValueError, match=r"statistics: 1 fitted statistic\(s\) for 2 free"):
        infer(s, p, ("I", "k"), statistics=("rise", "f_cycle"))


def test_an_aperiodic_fit_needs_a_probable_chi2():
    """The verdict's threshold: chi2 = 13 on 5 dof has probability 0.0233 (scipy.stats.chi2.sf; tables: 0.023),
    above POOR_FIT (1e-3) and below GOOD_FIT (0.05).  With a tight interval inside the box the parameter is
    identified for a periodic series (threshold POOR_FIT) and not for an aperiodic one (threshold GOOD_FIT: its
    sigma rests on a few model replicates), and the verdict quotes the probability."""
    from exact.dynamics._infer import GOOD_FIT, POOR_FIT
    from exact.dynamics._infer_result import Outcome, assemble
    from exact.dynamics._infer_search import Point, Problem, SeriesFit
    from exact.dynamics._infer_stats import SeriesData

    x = np.log(1000.0)
    model = np.ones(7)
    evaluated = [Point(np.array([x + d]), c, [model], []) for d, c in ((0.0, 13.0), (0.01, 20.0), (-0.01, 20.0))]
    fits = [SeriesFit(None, 1.0, SeriesData(np.ones(7), np.full(7, 0.1), 1.0, 0.5, np.ones(7, dtype=bool)))]
    box = (np.array([x - 1.0]), np.array([x + 1.0]))
    problem = Problem(PeelParams(V=1.0, I=1e-2), ("k",), np.arange(7), 30.0, 1e-10, 1)
    outcome = Outcome(evaluated, None, box, 6, "converged", "", 1.0)
    assert outcome.poor_fit == POOR_FIT and assemble(problem, fits, outcome).identified["k"]
    strict = assemble(problem, fits, dataclasses.replace(outcome, poor_fit=GOOD_FIT))
    assert not strict.identified["k"] and "probability 0.023" in strict.verdicts["k"]


def test_a_lucky_window_is_not_called_identified():
    """For an aperiodic series the best of many trial points is biased low (each read from one window, a draw);
    the verdict also reads the χ² of the best point's neighbours 0.3 % away (``replicate_check``: draws the
    statistics cannot tell from it).  Closed-form thresholds
    (scipy.stats.chi2.sf): the best window's χ² = 2.5 on 5 dof (probability 0.78) with replicates' χ² = 40 on 24
    (probability 0.021, below GOOD_FIT = 0.05): not identified, the verdict says why; replicates' χ² = 24 on 24
    (probability 0.46): identified as without the check.  (Measured on ``infer_targets`` seed 3, trace 1, with a
    finer grid: I 39 % low at χ² 2.55 on 4 dof, called identified without this check.)"""
    from exact.dynamics._infer import GOOD_FIT
    from exact.dynamics._infer_result import Outcome, assemble
    from exact.dynamics._infer_search import Point, Problem, SeriesFit
    from exact.dynamics._infer_stats import SeriesData

    x = np.log(1000.0)
    model = np.ones(7)
    evaluated = [Point(np.array([x + d]), c, [model], []) for d, c in ((0.0, 2.5), (0.01, 20.0), (-0.01, 20.0))]
    fits = [SeriesFit(None, 1.0, SeriesData(np.ones(7), np.full(7, 0.1), 1.0, 0.5, np.ones(7, dtype=bool)), True)]
    box = (np.array([x - 1.0]), np.array([x + 1.0]))
    problem = Problem(PeelParams(V=1.0, I=1e-2), ("k",), np.arange(7), 30.0, 1e-8, 1)
    outcome = Outcome(evaluated, None, box, 6, "converged", "", 1.0, poor_fit=GOOD_FIT)
    assert assemble(problem, fits, outcome).identified["k"]
    lucky = assemble(problem, fits, dataclasses.replace(outcome, replicate=(40.0, 24)))
    assert not lucky.identified["k"] and "lucky draw" in lucky.verdicts["k"] and "probability 0.021" in \
        lucky.verdicts["k"]
    assert assemble(problem, fits, dataclasses.replace(outcome, replicate=(24.0, 24))).identified["k"]


def test_the_profile_widens_by_the_window_scatter():
    """For an aperiodic series each trial point's χ² is a draw (one window of its attractor); the profile's
    threshold χ²_min + 3.84 s widens by twice χ²'s standard deviation over the best point's neighbours.
    Closed form: χ² 1 (best), 6 and 12 at ln k offsets 0, +0.2, -0.5 on 6 statistics (dof 5, s = 1): the
    threshold 4.84 keeps the best alone; with a scatter of 1 (threshold 6.84) the +0.2 point joins; with 4
    (12.84) all three, and the interval [-0.5, +0.2] spans a factor e^0.7 > 2: not identified."""
    from exact.dynamics._infer_result import Outcome, assemble
    from exact.dynamics._infer_search import Point, Problem, SeriesFit, spans
    from exact.dynamics._infer_stats import SeriesData

    x = np.log(1000.0)
    evaluated = [Point(np.array([x + d]), c, [np.ones(7)], []) for d, c in ((0.0, 1.0), (0.2, 6.0), (-0.5, 12.0))]
    for noise, lo, hi in ((0.0, 0.0, 0.0), (1.0, 0.0, 0.2), (4.0, -0.5, 0.2)):
        _, _, _, lo_, hi_, _ = spans(["k"], evaluated, None, 6, noise)
        assert np.isclose(lo_[0] - x, lo) and np.isclose(hi_[0] - x, hi)
    fits = [SeriesFit(None, 1.0, SeriesData(np.ones(7), np.full(7, 0.1), 1.0, 0.5, np.ones(7, dtype=bool)), True)]
    box = (np.array([x - 1.0]), np.array([x + 1.0]))
    problem = Problem(PeelParams(V=1.0, I=1e-2), ("k",), np.arange(7), 30.0, 1e-8, 1)
    outcome = Outcome(evaluated, None, box, 6, "converged", "", 1.0, poor_fit=0.05)
    assert assemble(problem, fits, outcome).identified["k"]
    wide = assemble(problem, fits, dataclasses.replace(outcome, chi2_noise=4.0))
    assert not wide.identified["k"] and "factor 2" in wide.verdicts["k"]


def test_the_replicate_mean_of_a_chaotic_trace():
    """Hypothesis (synthetic likelihood's mean, Wood 2010): at the chaotic point V = 2.5, I = 1e-4 the model's
    statistics over two replicates (the attractor set's first two starts) are the mean of the two starts' own
    readings (model_statistics from each start: the same runs, so equal to round-off, 1e-12 relative), and that
    mean lies strictly between them wherever they differ."""
    from exact.dynamics._attractor_set_runs import default_starts
    from exact.dynamics._infer_stats import data_statistics, model_statistics, replicate_mean

    p = PeelParams(V=2.5, I=1e-4)
    s = exact.simulate(p, 33.0, t_eval=30.0 + np.arange(30000) / 1e4).as_series(1e4, noise=0.5, drift=5.0, seed=1)
    d = data_statistics(s)
    r = replicate_mean(p, s, d.threshold, d.noise, 30.0, 1e-10, 120.0, (d.values, d.sigma, d.used), 2)
    each = [model_statistics(p, s, d.threshold, d.noise, 30.0, 1e-10, 120.0, **st.kwargs())
            for st in default_starts(p)[:2]]
    assert all(e is not None for e in each) and r.values is not None
    assert r.start == "mean of 2 aperiodic replicates" and r.label == "aperiodic" and r.n_runs == 2
    np.testing.assert_allclose(r.values, (each[0] + each[1]) / 2, rtol=1e-12)
    differ = each[0] != each[1]
    assert differ.any()
    assert np.all(np.minimum(each[0], each[1])[differ] < r.values[differ])
    assert np.all(r.values[differ] < np.maximum(each[0], each[1])[differ])


@pytest.mark.slow
def test_the_statistics_along_k_at_a_chaotic_point():
    """Hypothesis (why ``replicates`` stays 1, docs/your-data.md): at the chaotic point V = 2.5, I = 1e-4 (5 s
    windows, k over 9 steps spanning ±10 %) the model's statistics (slip interval, drop, stick, slip time, rise,
    F_start) deviate from a line in ln k by less than one data sigma (rms), with one reading and with the mean of
    3 replicates alike (measured 0.05-0.81 and 0.06-0.90); and the mean of 3 does not smooth them by the sqrt(3)
    independent replicates would give (its rms over the six statistics is above 1/sqrt(3) = 0.58 of one
    reading's; measured 1.08): the roughness is not replicate noise.  36 runs, 1.5-5 min."""
    from exact.dynamics._infer_stats import data_statistics, replicate_mean, set_statistics

    p = PeelParams(V=2.5, I=1e-4)
    s = exact.simulate(p, 35.0, t_eval=30.0 + np.arange(50000) / 1e4).as_series(1e4, noise=0.5, drift=5.0, seed=1)
    d = data_statistics(s)
    tgt = (d.values, d.sigma, d.used)
    ks = 1000.0 * np.exp(np.linspace(-0.1, 0.1, 9))
    x = np.log(ks)
    rough = []
    for read in (lambda q: set_statistics(q, s, d.threshold, d.noise, 30.0, 1e-10, 300.0, tgt, 1),
                 lambda q: replicate_mean(q, s, d.threshold, d.noise, 30.0, 1e-10, 300.0, tgt, 3)):
        y = np.array([read(p.replace(k=float(k))).values for k in ks])[:, :6]
        fit = np.array([np.polyval(np.polyfit(x, y[:, j], 1), x) for j in range(6)]).T
        rough.append(np.sqrt(np.mean((y - fit) ** 2, axis=0)) / d.sigma[:6])
    assert np.all(rough[0] < 1.0) and np.all(rough[1] < 1.0), rough
    assert np.sqrt(np.mean(rough[1] ** 2)) > np.sqrt(np.mean(rough[0] ** 2)) / np.sqrt(3.0), rough


def test_the_knee_detectors_fast_pieces_agree_with_numpy():
    """The knee detector infer reads traces with (``peelapprox/_slips_knee.py``) fits its lines in closed form
    and takes its gradient without ``np.gradient``'s N-d bookkeeping (2.5x cheaper: the detector was over half a
    trial run's cost).  Oracles: ``np.polyfit`` (an SVD) and ``np.gradient`` on seeded random segments (2-60
    samples, uniform and jittered times, slopes over 8 decades).  The gradient is bitwise numpy's; the line's
    slope and intercept within 1e-9 relative of the segment's scale (rounding: polyfit's own conditioning at
    t ~ 30 s is ~1e-12)."""
    from peelapprox._slips_knee import _gradient, _line

    rng = np.random.default_rng(7)
    for trial in range(400):
        n = int(rng.integers(2, 61))
        t = 30.0 + np.arange(n) / 1e4 + (rng.normal(0.0, 1e-9, n) if trial % 2 else 0.0)
        F = 250.0 + 10.0 ** rng.uniform(-3, 5) * (t - t[0]) + rng.normal(0.0, 0.5, n)
        assert np.array_equal(_gradient(F, t), np.gradient(F, t))
        got = _line(t, F, 0, n, 2)
        assert got is not None
        slope, icept = np.polyfit(t - t[0], F, 1)
        scale = max(abs(slope), float(np.ptp(F)) / max(float(t[-1] - t[0]), 1e-12))
        assert abs(got[0] - slope) <= 1e-9 * scale and abs(got[1] - icept) <= 1e-9 * max(abs(icept), 1.0)
    assert _line(t, F, 0, 2, 3) is None


def test_the_default_rtol_moves_the_statistics_by_far_less_than_sigma():
    """infer's trial runs use rtol = 1e-8 (was 1e-10: 28 % more simulation CPU).  Oracle: the same statistics
    at rtol = 1e-10, on the first three seeded points of ``comparisons.benchmark.infer_targets``' seed 4 (one
    periodic, two aperiodic but not chaotic traces; 5 s windows to keep the test short), a trial point 3 % off
    in I and 2 % in k.  Measured: at most 0.008 σ on 10 s windows (docs/your-data.md); the tolerance 0.1 σ
    leaves room for the shorter window, and is still far below the fit's resolution (a χ² change of 0.01 per
    statistic)."""
    from comparisons.benchmark.infer_targets import draw
    from exact.dynamics._infer_stats import data_statistics, model_statistics

    for t in draw(3, 4):
        p = PeelParams(V=t["V"], I=t["I"], k=t["k"])
        series = _trace(t["V"], t["I"], t["k"], seconds=5.0)
        d = data_statistics(series)
        q = p.replace(I=t["I"] * 1.03, k=t["k"] * 0.98)
        m8, m10 = (model_statistics(q, series, d.threshold, d.noise, 30.0, rtol, 60.0) for rtol in (1e-8, 1e-10))
        assert m8 is not None and m10 is not None
        assert np.max((np.abs(m8 - m10) / d.sigma)[d.used]) < 0.1, (t, (m8 - m10) / d.sigma)


@pytest.mark.slow
def test_an_island_in_a_chaotic_band_is_not_called_identified():
    """Hypothesis (calibration: never a confident wrong number): on the chaotic trace of
    ``comparisons.benchmark.infer_targets``' seed 3, trace 1 (V = 2.249 m/s, I = 3.204e-4, k = 701.8; 10 s,
    started at I x 1.38, k x 0.84) the search's best point is I 39 % low at χ² 2.55 on 4 dof, an island whose
    neighbours 0.3 % away do not fit with the statistics' σ (χ² 87 on 24); with σ from the neighbours' spread the
    points as good as the best reach the box's edge.  I is not called identified, and its 95 % interval covers
    the truth.  Measured 147 runs, 92-212 s on 2 loaded cores."""
    from comparisons.benchmark.infer_targets import draw

    t = draw(2, 3)[1]
    tr = exact.simulate(PeelParams(V=t["V"], I=t["I"], k=t["k"]), 40.0, t_eval=30.0 + np.arange(100000) / 1e4)
    series = tr.as_series(1e4, noise=0.5, drift=5.0, seed=3 * 1000 + 1)
    res = infer(series, PeelParams(V=t["V"], I=t["I0"], k=t["k0"]), ("I", "k"), max_wall=600, progress=False,
                executor="serial")
    assert not res.identified["I"], res.verdicts["I"]
    lo, hi = res.intervals["I"]
    assert lo <= t["I"] <= hi
    assert any("neighbours" in n for n in res.notes)


def test_the_neighbours_set_an_aperiodic_sigma(monkeypatch):
    """For an aperiodic series, σ of each statistic is joined by its spread over the best point and its 2 x (free
    parameters) neighbours ±JITTER away (a diagonal synthetic likelihood's covariance at the best point), every
    evaluated χ² recomputed with it.  Closed form with the model runs replaced: one free parameter, the best
    point's statistics all 1.0, its two neighbours' 1.0 ± 0.3 (sample sd over the three draws 0.3), σ 0.4: the
    new σ is hypot(0.4, 0.3) = 0.5, the best point's χ² 0, each neighbour's 7 · (0.3/0.5)² = 2.52."""
    import exact.dynamics._infer_search as search
    from exact.dynamics._infer_search import Point, Problem, SeriesFit, replicate_check
    from exact.dynamics._infer_stats import SeriesData, SetReading

    data = SeriesData(np.ones(7), np.full(7, 0.4), 1.0, 0.5, np.ones(7, dtype=bool))
    fits = [SeriesFit(None, 1.0, data, True)]
    problem = Problem(PeelParams(V=1.0, I=1e-2), ("k",), np.arange(7), 30.0, 1e-8, 1)
    x = np.array([np.log(1000.0)])
    evaluated = [Point(x, 0.0, [np.ones(7)], [SetReading(np.ones(7), "solver", None, 1)]),
                 Point(x + 0.1, 7 * (0.6 / 0.4) ** 2, [np.full(7, 1.6)], [SetReading(np.ones(7), "solver", None, 1)])]

    def fake(problem, fits, xn, left):
        assert problem.attractors == search.CHECK_STARTS  # each neighbour: the closest of the set's first starts
        m = np.full(7, 1.0 + (0.3 if xn[0] > x[0] else -0.3))
        return (m - 1.0) / fits[0].data.sigma, [m], [SetReading(m, "solver", None, 1)]

    monkeypatch.setattr(search, "residuals", fake)
    total, dof, runs, spread, new = replicate_check(problem, evaluated, fits, 100.0)
    assert np.allclose(new[0].data.sigma, 0.5) and dof == 14 and runs == 2
    assert np.isclose(total, 2 * 2.52) and np.isclose(spread, 0.0)
    assert evaluated[0].chi2 == 0.0 and np.isclose(evaluated[1].chi2, 7 * (0.6 / 0.5) ** 2)


def test_same_attractor_compares_three_statistics():
    """Hypothesis: two readings are of one attractor exactly where the slip interval, force drop and slip-start
    force agree within ``SAME_ATTRACTOR`` (10 %, relative to the second); the other statistics do not enter.
    Seeded random readings around a base, each of the three moved by 0.95 or 1.05 of the tolerance (the oracle is
    the definition, evaluated here by hand)."""
    from exact.dynamics._infer_stats import SAME_ATTRACTOR, STATISTICS, same_attractor

    rng = np.random.default_rng(7)
    checked = [STATISTICS.index(n) for n in ("slip_interval", "force_drop", "F_start")]
    for _ in range(30):
        base = rng.uniform(0.5, 300.0, len(STATISTICS))
        other = base * rng.uniform(0.3, 3.0, len(STATISTICS))  # the unchecked statistics anywhere
        other[checked] = base[checked]
        assert same_attractor(other, base)
        j = int(rng.choice(checked))
        for f, same in ((0.95, True), (1.05, False)):
            moved = other.copy()
            moved[j] = base[j] * (1 + rng.choice([-1.0, 1.0]) * f * SAME_ATTRACTOR)
            assert same_attractor(moved, base) is same


def test_a_quasi_periodic_replicate_spread_keeps_the_datas_torus(monkeypatch):
    """Hypothesis (the quasi-periodic point V = 3.149 m/s, I = 0.05665, k = 1173 of ``infer_targets``' seed 2,
    5 s): of the first 4 starts the one at rest reaches another torus (slip interval over 50 % longer: measured
    70 %); the replicate spread keeps the other three, so the cycle frequency's spread over them stays within its
    3 % repeatability and the line is kept (before, the other torus made every σ a multiple of the data's spread
    and I free within a factor 4).  The cycle frequency (the torus' modulation, an α oscillation) goes as
    I^-1/2 at this inertia: the model's at 0.75 I over its value at I is (0.75)^-1/2 = 1.1547 within 1 %
    (measured 1.1544).  Each model reading is made once (:func:`_read_once`: the rest start's and the solver's are
    asked twice, by the test and by ``replicate_spread``; a reading is deterministic): 5 readings instead of 7."""
    from exact.dynamics._attractor_set_runs import default_starts
    from exact.dynamics._infer_stats import STATISTICS, _reading, data_statistics, model_statistics, replicate_spread

    _read_once(monkeypatch)
    p = PeelParams(V=3.149, I=0.05665, k=1173.0)
    s = exact.simulate(p, 35.0, t_eval=30.0 + np.arange(50000) / 1e4).as_series(1e4, noise=0.5, drift=5.0, seed=1)
    d = data_statistics(s)
    j = STATISTICS.index("f_cycle")
    assert s.observables().period is None and d.used[j]
    rest = default_starts(p)[1]
    assert rest.name == "rest"
    m_rest = _reading(p, s, d.threshold, d.noise, 30.0, 1e-8, 120.0, rest.kwargs())[0]
    assert m_rest is not None and m_rest[0] > 1.5 * d.values[0]
    sd, stable, n, _ = replicate_spread(p, s, d.threshold, d.noise, 30.0, 1e-8, 120.0, 4,
                                        target=(d.values, d.sigma, d.used))
    assert sd is not None and n == 3 and stable
    at = model_statistics(p, s, d.threshold, d.noise, 30.0, 1e-8, 120.0)
    low = model_statistics(p.replace(I=0.75 * p.I), s, d.threshold, d.noise, 30.0, 1e-8, 120.0)
    assert at is not None and low is not None
    assert low[j] / at[j] == pytest.approx(0.75 ** -0.5, rel=0.01)


def test_a_chaotic_neighbour_is_read_from_the_datas_attractor():
    """Hypothesis (``replicate_check`` reads each neighbour from the closest of ``CHECK_STARTS`` starts): at the
    chaotic truth V = 0.6854 m/s, I = 2.459e-5, k = 1317 (``infer_targets`` seed 3, trace 0, 10 s), the neighbour
    at I +0.3 % from the solver's start alone falls into a periodic window (measured period 6, χ² 149 on 6: over
    50), while among the first 4 starts one reaches the chaotic attractor, aperiodic, every residual within the
    3 σ at which ``set_statistics`` stops (measured χ² 2.1)."""
    from exact.dynamics._infer_search import CHECK_STARTS
    from exact.dynamics._infer_stats import data_statistics, set_statistics

    p = PeelParams(V=0.6854, I=2.459e-05, k=1317.0)
    s = exact.simulate(p, 40.0, t_eval=30.0 + np.arange(100000) / 1e4).as_series(1e4, noise=0.5, drift=5.0,
                                                                                  seed=3000)
    d = data_statistics(s)
    assert s.observables().period is None
    tgt = d.target(np.arange(7))
    q = p.replace(I=p.I * np.exp(3e-3))
    one = set_statistics(q, s, d.threshold, d.noise, 30.0, 1e-8, 120.0, tgt, 1)
    assert one.values is not None and one.period is not None
    z1 = ((one.values - d.values) / d.sigma)[d.used]
    assert z1 @ z1 > 50.0
    wide = set_statistics(q, s, d.threshold, d.noise, 30.0, 1e-8, 120.0, tgt, CHECK_STARTS)
    assert wide.values is not None and wide.period is None
    assert np.all(np.abs((wide.values - d.values) / d.sigma)[d.used] <= 3.0)


def test_an_aperiodic_interval_is_no_finer_than_the_search():
    """An aperiodic fit's 95 % interval is at least ± the search's finest spacing (``Outcome.resolution``).
    Closed form: best point χ² 1 at ln k = ln 1000, neighbours ±0.01 at χ² 20 (outside the threshold 4.84: the
    profile alone is the point), resolution 0.07: the interval is [1000 e^-0.07, 1000 e^0.07] = [932.4, 1072.5]
    (to 1e-9), still identified (a factor 1.15 < 2), and the verdict quotes the factor e^0.07 = 1.07 (3 digits); with no
    resolution the interval is the point."""
    from exact.dynamics._infer_result import Outcome, assemble
    from exact.dynamics._infer_search import Point, Problem, SeriesFit
    from exact.dynamics._infer_stats import SeriesData

    x = np.log(1000.0)
    evaluated = [Point(np.array([x + d]), c, [np.ones(7)], []) for d, c in ((0.0, 1.0), (0.01, 20.0), (-0.01, 20.0))]
    fits = [SeriesFit(None, 1.0, SeriesData(np.ones(7), np.full(7, 0.1), 1.0, 0.5, np.ones(7, dtype=bool)), True)]
    box = (np.array([x - 1.0]), np.array([x + 1.0]))
    problem = Problem(PeelParams(V=1.0, I=1e-2), ("k",), np.arange(7), 30.0, 1e-8, 1)
    outcome = Outcome(evaluated, None, box, 6, "converged", "", 1.0, poor_fit=0.05)
    bare = assemble(problem, fits, outcome)
    assert bare.intervals["k"] == pytest.approx((1000.0, 1000.0), rel=1e-12)
    res = assemble(problem, fits, dataclasses.replace(outcome, resolution=np.array([0.07])))
    assert res.intervals["k"] == pytest.approx((1000.0 * np.exp(-0.07), 1000.0 * np.exp(0.07)), rel=1e-9)
    assert res.identified["k"] and "factor 1.07 " in res.verdicts["k"]


@pytest.mark.slow
def test_I_and_k_of_a_quasi_periodic_trace():
    """Hypothesis (the inference goal on a quasi-periodic trace: I and k within 10 %, identified):
    ``infer_targets``' seed 2 trace 3 (V = 3.149 m/s,
    I = 0.05665, k = 1173, quasi-periodic; 10 s, the benchmark's noise, drift and seed), from its start I0 = 0.04875,
    k0 = 1020: I and k recovered within 10 % and both identified (measured with ``run_trace`` at the last commit
    I -1.3 %, k -0.2 %, χ² 0.078 on 5, 379 s on 2 loaded cores; before the replicate spread kept to the data's
    torus: I -25 %, not identified)."""
    p = PeelParams(V=3.149, I=0.05665, k=1173.0)
    tr = exact.simulate(p, 40.0, t_eval=(30.0 + np.arange(100000) / 1e4).tolist())
    s = tr.as_series(1e4, noise=0.5, drift=5.0, seed=2003)
    assert s.observables().period is None
    res = infer(s, PeelParams(V=3.149, I=0.04874741179683219, k=1020.1905516150418), ("I", "k"), max_wall=600,
                progress=False, executor="serial")
    assert res.identified["I"] and res.identified["k"]
    assert abs(res.values["I"] / 0.05665 - 1) < 0.10 and abs(res.values["k"] / 1173.0 - 1) < 0.10


def test_the_detectors_spread_under_noise(monkeypatch):
    """Hypothesis (``noise_spread``): at the quasi-periodic V = 3.923 m/s, I = 0.01045, k = 994.6
    (``infer_targets`` seed 5, trace 0; 1.5 ms sticks, 15 samples each) the mean stick slope of one model run read
    with 4 draws of 0.5 N noise spreads by 1-4 % (measured 2.2 % on 10 s, here 5 s: about √2 more), more than its
    2 % repeatability's half, while the slip interval spreads by under 1.5 % (measured 0.8 %); without noise every
    draw reads the same trace: the spread is exactly 0 (2 draws: the least a spread has; 4 as with noise read the
    same trace twice more).  The quiet reading's model run is the noisy one's (the same call of ``exact.simulate``):
    :func:`_read_once` runs it once."""
    from exact.dynamics._infer_stats import STATISTICS, data_statistics, noise_spread

    _read_once(monkeypatch)
    p = PeelParams(V=3.923, I=0.01045, k=994.6)
    s = exact.simulate(p, 35.0, t_eval=30.0 + np.arange(50000) / 1e4).as_series(1e4, noise=0.5, drift=5.0, seed=1)
    d = data_statistics(s)
    nsd = noise_spread(p, s, d.threshold, d.noise, 30.0, 1e-8, 120.0, {})
    assert nsd is not None
    rise = STATISTICS.index("rise")
    assert 0.01 <= nsd[rise] / d.values[rise] <= 0.04
    assert nsd[0] / d.values[0] < 0.015
    quiet = noise_spread(p, s, d.threshold, 0.0, 30.0, 1e-8, 120.0, {}, n=2)
    assert quiet is not None and np.all(quiet == 0.0)


def test_an_aperiodic_sigma_joins_both_spreads(monkeypatch):
    """``replicated`` for an aperiodic series, closed form with the model runs replaced: data σ 0.4 for every
    statistic, the replicate spread 0.3 (over 3 replicates, ``replicates`` 1) and the noise spread 0.1 give
    σ = hypot(0.4, 0.3, √2 · 0.1) = 0.5196 for each statistic but the cycle line, whose 0.4 is first replaced by
    half a periodogram bin, 0.5 / (10 s) = 0.05: hypot(0.05, 0.3, √2 · 0.1) = 0.3358; a periodic series is left as
    it was."""
    import exact.dynamics._infer_search as search
    from exact.dynamics._infer_search import Point, Problem, SeriesFit, replicated
    from exact.dynamics._infer_stats import STATISTICS, SeriesData, Spread

    t = np.arange(100001) / 1e4  # 10 s
    s = ForceSeries(t, np.sin(t), V=1.0)
    data = SeriesData(np.ones(7), np.full(7, 0.4), 1.0, 0.5, np.ones(7, dtype=bool))
    fits = [SeriesFit(s, 1.0, data, True), SeriesFit(s, 1.0, data, False)]
    problem = Problem(PeelParams(V=1.0, I=1e-2), ("k",), np.arange(7), 30.0, 1e-8, 1)
    evaluated = [Point(np.array([np.log(1000.0)]), 0.0, [np.ones(7), np.ones(7)], [])]
    monkeypatch.setattr(search, "replicate_spread", lambda *a, **k: Spread(np.full(7, 0.3), True, 3, {}))
    monkeypatch.setattr(search, "noise_spread", lambda *a, **k: np.full(7, 0.1))
    out, n_obs, notes = replicated(problem, evaluated, fits, 100.0)
    j = STATISTICS.index("f_cycle")
    want = np.full(7, np.sqrt(0.4 ** 2 + 0.3 ** 2 + 2 * 0.1 ** 2))
    want[j] = np.sqrt(0.05 ** 2 + 0.3 ** 2 + 2 * 0.1 ** 2)
    assert np.allclose(out[0].data.sigma, want, rtol=1e-12) and out[1] is fits[1] and n_obs == 14
    assert len(notes) == 2

"""A force trace in, the model's statistics out: :class:`peelapprox.ForceSeries` and ``Trajectory.as_series``.

The oracle is the exact solver's own jump record: a trace sampled from a run (at 10 kHz, with noise and drift
added) must give back the run's slips and observables.
"""

from __future__ import annotations

import csv
import math

import numpy as np
import pytest

import exact
from peelapprox import ForceSeries, PeelParams, Slips, StickSlipObservables

RATE = 10_000.0
T0, T1 = 30.0, 50.0  # 30 s of transient (the period-8 orbit settles to 1e-6), 20 s of trace


def _run(V: float, I: float) -> exact.Trajectory:
    return exact.simulate(PeelParams(V=V, I=I), T1, t_eval=T0 + np.arange(int((T1 - T0) * RATE)) / RATE)


@pytest.fixture(scope="module", params=[(1.0, 1e-2), (1.0, 1e-5)], ids=["high-inertia-period-8",
                                                                        "low-inertia-period-3"])
def run(request):
    return _run(*request.param)


def _exact_slips(tr) -> np.ndarray:
    """Times of the run's AB→CD jumps inside the trace, away from its ends by more than a slip."""
    jt = np.asarray(tr.jumps.t)
    ab = np.asarray(tr.jumps.from_branch) == 0
    return jt[ab & (jt > T0 + 0.01) & (jt < T1 - 0.01)]


def test_noisy_drifting_trace_gives_back_every_slip_and_the_observables(run):
    """Hypothesis: 20 s at 10 kHz with 0.5 N of white noise and a 5 N drift, at a periodic high-inertia point
    (V = 1, I = 1e-2, period 8: drops of 20 N, slips of 2 ms) and a periodic low-inertia one (V = 1, I = 1e-5,
    period 3): every exact slip is found within 0.5 ms (5 samples) of its jump and nothing else (0 missed, 0
    false); the mean slip interval is within 1 % and the mean force drop within 2 % of the noiseless run's
    exact ones (the detector's stated goals; measured 2e-6 and 0.3 %), and the period is the exact one."""
    exact_obs = StickSlipObservables.from_trajectory(run, T0)
    series = run.as_series(RATE, noise=0.5, drift=5.0, seed=7)
    assert "the solver's values on the grid" in series.source
    slips = series.slips()
    assert slips.noise == pytest.approx(0.5, rel=0.05)  # the MAD estimate of 2e5 samples: ~1 % scatter
    jt = _exact_slips(run)
    inside = slips.t_start[(slips.t_start > T0 + 0.01) & (slips.t_start < T1 - 0.01)]
    dist = np.abs(inside[:, None] - jt[None, :])
    assert inside.size == jt.size, "missed or false slips"
    assert float(dist.min(axis=1).max()) < 5e-4 and float(dist.min(axis=0).max()) < 5e-4
    o = series.observables()
    assert o.status == "stick-slip" and o.period == exact_obs.period
    assert abs(o.slip_interval / exact_obs.slip_interval - 1) < 0.01
    assert abs(o.force_drop / exact_obs.force_drop - 1) < 0.02


def test_a_fast_low_inertia_trace_gives_back_every_slip():
    """Hypothesis: at V = 3.95 m/s, I = 1.43e-5 (low inertia, period 1, sticks and slips of ~40 samples, drops of
    15 N), 10 s at 10 kHz with 0.5 N of noise and a 5 N drift give back every exact slip and nothing else, the
    slip interval within 1 % and the mean drop within 2 % of the noiseless run's (the detector's goals).  With
    the stick's end taken where the gradient first flattens, noise put the knee 3.5 samples late and the drop
    8 % low; the split of least squares measures 4e-6 and 0.3 % on 20 s."""
    t1 = T0 + 10.0
    tr = exact.simulate(PeelParams(V=3.95, I=1.43e-5), t1, t_eval=T0 + np.arange(int(10.0 * RATE)) / RATE)
    exact_obs = StickSlipObservables.from_trajectory(tr, T0)
    slips = tr.as_series(RATE, noise=0.5, drift=5.0, seed=7).slips()
    jt = np.asarray(tr.jumps.t)[np.asarray(tr.jumps.from_branch) == 0]
    jt = jt[(jt > T0 + 0.01) & (jt < t1 - 0.01)]
    inside = slips.t_start[(slips.t_start > T0 + 0.01) & (slips.t_start < t1 - 0.01)]
    assert inside.size == jt.size, "missed or false slips"
    assert float(np.abs(inside - jt).max()) < 5e-4
    interval = float(np.mean(np.diff(slips.t_start)))
    assert abs(interval / exact_obs.slip_interval - 1) < 0.01
    assert abs(float(np.mean(slips.drop)) / exact_obs.force_drop - 1) < 0.02


def test_noiseless_trace_reads_the_jumps(run):
    """Hypothesis: without noise the corners (the sticks' lines meeting the fall's first and last thirds) sit
    within 0.15 ms of the jumps and F there within 0.3 N of the jump's F (the sampling grid is 0.1 ms; measured
    on 10 s: 0.1 ms at most at V = 1, I = 1e-5, 0.04 ms at I = 1e-2; the stick's curvature near the fold is what
    the straight line misses: 0.22 N at most)."""
    s = run.as_series(RATE).slips()
    jt, jF = np.asarray(run.jumps.t), np.asarray(run.jumps.F)
    ab = np.asarray(run.jumps.from_branch) == 0
    for times, forces, mask in ((s.t_start, s.F_before, ab), (s.t_end, s.F_after, ~ab)):
        k = np.searchsorted(jt[mask], times)
        k = np.clip(k, 1, mask.sum() - 1)
        near = np.where(np.abs(jt[mask][k] - times) < np.abs(jt[mask][k - 1] - times), k, k - 1)
        assert float(np.max(np.abs(jt[mask][near] - times))) < 1.5e-4
        assert float(np.max(np.abs(jF[mask][near] - forces))) < 0.3


def test_a_steady_trace_has_no_slip():
    """Hypothesis: a rising ramp with 0.5 N of noise (2e5 samples) holds no fall of 12 times the averaged
    force's noise (its running maximum and a later minimum lie at most ~10 of its sigma apart in a million
    samples), so no slip: status "steady", never NaN."""
    t = np.arange(200_000) / RATE
    F = 200 + 3 * t + np.random.default_rng(3).normal(0, 0.5, t.size)
    o = ForceSeries(t, F, V=1.0).observables()
    assert o.status == "steady" and o.n_slips == 0 and o.slip_interval is None
    assert all(not (isinstance(v, float) and math.isnan(v)) for v in o.as_dict().values())


def test_a_sawtooth_with_known_drops():
    """Hypothesis: an ideal sawtooth (rise 100 N/s for 0.9 s, fall of 90 N in 0.1 s, 1 kHz, no noise) gives its
    slips exactly: interval 1 s, drop 90 N, slip time 0.1 s, stick time 0.9 s (1e-9: straight lines are fitted
    exactly; the corners fall between samples only by rounding)."""
    t = np.arange(10_000) / 1000.0
    phase = t % 1.0
    F = np.where(phase < 0.9, 100 * phase, 90 - 900 * (phase - 0.9)) + 100
    s = ForceSeries(t, F).slips()
    assert len(s) == 9
    assert np.allclose(s.drop, 90.0, rtol=1e-9) and np.allclose(s.slip_time, 0.1, rtol=1e-9)
    assert np.allclose(s.stick_time, 0.9, rtol=1e-9)
    o = ForceSeries(t, F).observables()
    assert o.period == 1 and o.slip_interval == pytest.approx(1.0, rel=1e-9)


def test_slips_table_writes_csv(tmp_path):
    """The per-slip table as CSV: one row per slip, the first stick None (written empty)."""
    t = np.arange(5000) / 1000.0
    F = 100 + 100 * (t % 1.0) - np.where(t % 1.0 > 0.9, 900 * (t % 1.0 - 0.9) + 10 * 0, 0)
    s = ForceSeries(t, F).slips()
    assert isinstance(s, Slips) and len(s) >= 3
    path = tmp_path / "slips.csv"
    s.write(str(path))
    rows = list(csv.DictReader(path.open()))
    assert len(rows) == len(s) and rows[0]["stick_before"] in ("", "None")
    assert float(rows[1]["drop"]) == pytest.approx(float(s.drop[1]), rel=1e-12)


def test_spectrum_finds_a_sinusoid():
    """Hypothesis: the Welch spectrum of a 37 Hz sinusoid (10 s at 10 kHz, 1.25 s segments: 0.8 Hz bins)
    peaks within one bin of 37 Hz."""
    t = np.arange(100_000) / RATE
    sp = ForceSeries(t, 250 + 5 * np.sin(2 * np.pi * 37 * t)).spectrum()
    assert abs(sp.peak - 37.0) <= float(sp.frequency[1] - sp.frequency[0])


def test_interpolated_sampling_says_so():
    """A run stored at its steps is sampled by linear interpolation, and ``source`` says so with its gap."""
    tr = exact.simulate(PeelParams(V=1.0, I=1e-5), 0.5)
    s = tr.as_series(2000.0)
    assert "interpolated linearly" in s.source and len(s) == 1001 and s.V == 1.0


@pytest.mark.parametrize("t, F, kwargs, error, match", [
    (np.arange(20.0), np.r_[np.ones(19), np.nan], {}, ValueError, r"F"),
    (np.r_[np.arange(10.0), np.arange(10.0)], np.ones(20), {}, ValueError, r"t must increase: t\[10\]"),
    (np.arange(5.0), np.ones(5), {}, ValueError, "at least 16 samples"),
    (np.arange(20.0), np.ones(19), {}, ValueError, "one length"),
    (np.arange(20.0), np.ones(20), {"V": -1.0}, ValueError, "V"),
    (np.arange(20.0).reshape(4, 5), np.ones(20), {}, ValueError, "1-D"),
    ("abc", np.ones(20), {}, TypeError, "t"),
])
def test_bad_traces_are_named(t, F, kwargs, error, match):
    """Bad input names the argument (and the first bad sample)."""
    with pytest.raises(error, match=match):
        ForceSeries(t, F, **kwargs)


def test_bad_options_are_named():
    t = np.arange(100) / 100.0
    s = ForceSeries(t, t)
    for kwargs, match in (({"threshold": -1.0}, "threshold"), ({"smooth": 4}, "smooth"), ({"fit": 1}, "fit")):
        with pytest.raises(ValueError, match=match):
            s.slips(**kwargs)
    tr = exact.simulate(PeelParams(V=1.0, I=1e-5), 0.1)
    for kwargs, match in (({"rate": 0.0}, "rate"), ({"rate": 1e3, "noise": -1.0}, "noise"),
                          ({"rate": 1e3, "drift": math.inf}, "drift")):
        with pytest.raises(ValueError, match=match):
            tr.as_series(**kwargs)


def test_from_csv_reads_units_and_names_bad_rows(tmp_path):
    """A trace in ms and kN is read back in s and N to rounding (1e-12 relative: the decimal text of savetxt);
    a time that does not increase is named with its file line; a cell that is not a number with its line and
    column; an unknown unit by name."""
    t = np.arange(200) / 1000.0
    F = 100.0 + 50.0 * np.sin(7 * t)
    np.savetxt(tmp_path / "a.csv", np.c_[t * 1e3, F / 1e3], delimiter=",", header="t [ms],F [kN]", comments="",
               fmt="%.17g")
    s = ForceSeries.from_csv(str(tmp_path / "a.csv"), V=1.0)
    assert np.allclose(s.t, t, rtol=1e-12, atol=1e-15) and np.allclose(s.F, F, rtol=1e-12) and s.V == 1.0
    np.savetxt(tmp_path / "b.csv", np.c_[np.r_[t[:100], t[:100]], F], delimiter=",", header="t,F", comments="")
    with pytest.raises(ValueError, match=r"t must increase: t\[100\].*file line 102"):
        ForceSeries.from_csv(str(tmp_path / "b.csv"))
    (tmp_path / "c.csv").write_text("t,F\n0,1\n0.1,x\n")
    with pytest.raises(ValueError, match="line 3 column 2"):
        ForceSeries.from_csv(str(tmp_path / "c.csv"))
    (tmp_path / "d.csv").write_text("t [h],F\n0,1\n")
    with pytest.raises(ValueError, match="unknown unit"):
        ForceSeries.from_csv(str(tmp_path / "d.csv"))


def test_slips_are_found_once_per_trace_and_arguments():
    """Hypothesis: ``slips()`` is memoised per trace and arguments (observables, spectrum and lyapunov each read
    it): the same call returns the very same read-only table, other arguments a new one with the values a fresh
    trace gives (categorical; exact equality, the same computation)."""
    t = np.arange(4000) / 1000.0
    F = 100.0 + 10.0 * ((t * 7.0) % 1.0)
    s = ForceSeries(t, F)
    a = s.slips()
    assert s.slips() is a and not a.F_before.flags.writeable
    with pytest.raises(ValueError):
        a.F_before[0] = 0.0
    b = s.slips(method="knee")
    assert b is not a and b is s.slips(method="knee")
    fresh = ForceSeries(t, F).slips(method="knee")
    assert np.array_equal(fresh.F_before, b.F_before) and np.array_equal(fresh.t_start, b.t_start)

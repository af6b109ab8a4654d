"""The observables of a stick-slip attractor: :class:`peelapprox.StickSlipObservables`.

Oracles: hand-computed jump sequences (exact arithmetic, spreads by :func:`statistics.stdev`).
"""

from __future__ import annotations

import json
import statistics
from types import SimpleNamespace

import numpy as np
import pytest

from peelapprox import PeelParams, StickSlipObservables

AB, CD = 0, 1  # from_branch codes (peelapprox.BRANCHES)
MEANS = ("slip_interval", "force_drop", "slip_time", "stick_time")


def _fake(times, forces, from_branch, *, t_transient=0.0, t_end=10.0, params=None):
    """A trajectory-like object: the HasJumps protocol plus the window and params an exact.Trajectory has."""
    jumps = SimpleNamespace(t=np.array(times, float), F=np.array(forces, float),
                            from_branch=np.array(from_branch, np.int8))
    return SimpleNamespace(jumps=jumps, t_transient=t_transient, t_end=t_end, params=params)


# three slips in [0, 10] s: AB→CD at 1, 3, 6 s; CD→AB at 1.25, 3.5, 6.25 s; an open AB stay of 3.75 s at the end
HAND = _fake([1.0, 1.25, 3.0, 3.5, 6.0, 6.25], [300, 200, 310, 190, 290, 210], [AB, CD] * 3,
             params=PeelParams(V=1.0, I=1e-5))


def test_hand_computed_jump_sequence():
    """Exact oracle: slip intervals 2 and 3 s; drops 100, 120, 80 N; CD stays 0.25, 0.5, 0.25 s; AB stays 1.75
    and 2.5 s (the stays cut by the window's edges, [0, 1] and [6.25, 10], are not counted); F from 190 to
    310 N.  Three returns are too few to try a period, so the means are over all values.  Spreads are the
    sample standard deviations of :func:`statistics.stdev`.  The values are dyadic or short sums, so 1e-12
    relative only allows for the summation order."""
    o = StickSlipObservables.from_trajectory(HAND)
    want = {"slip_interval": [2.0, 3.0], "force_drop": [100.0, 120.0, 80.0], "slip_time": [0.25, 0.5, 0.25],
            "stick_time": [1.75, 2.5]}
    for name, values in want.items():
        assert getattr(o, name) == pytest.approx(statistics.fmean(values), rel=1e-12), name
        assert getattr(o, f"{name}_spread") == pytest.approx(statistics.stdev(values), rel=1e-12), name
    assert (o.status, o.n_slips, o.period, o.period_label) == ("stick-slip", 3, None, "too short")
    assert (o.F_max, o.F_min, o.t_start, o.t_end, o.V, o.I) == (310.0, 190.0, 0.0, 10.0, 1.0, 1e-5)
    assert o.method == "trajectory: window [0, 10] s, period_rtol 1e-06"


def test_transient_cut_and_single_sample_spread():
    """Exact oracle: ``t_transient = 2`` drops the first slip and its return; one interval (3 s) is left, whose
    spread is 0 by definition (one sample); ``t_transient = 1.1`` starts on a CD→AB jump, and the CD stay
    it ends (cut by the window) is not counted: CD stays 0.5 and 0.25 s, AB stays 1.75 and 2.5 s."""
    o = StickSlipObservables.from_trajectory(HAND, 2.0)
    assert (o.n_slips, o.slip_interval, o.slip_interval_spread, o.t_start) == (2, 3.0, 0.0, 2.0)
    assert o.force_drop == pytest.approx(100.0, rel=1e-12) and o.stick_time == 2.5
    o = StickSlipObservables.from_trajectory(HAND, 1.1)
    assert o.slip_time == pytest.approx(0.375, rel=1e-12) and o.stick_time == pytest.approx(2.125, rel=1e-12)
    assert o.n_slips == 2 and o.F_max == 310.0 and o.F_min == 190.0


def test_periodic_means_are_over_whole_cycles():
    """Exact oracle: a period-2 orbit (returns 300, 280; intervals 1 and 2 s) seen over 7 slips (six intervals,
    three cycles) plus one more slip (a seventh interval, 1 s).  The orbit's mean interval is 1.5 s; the mean
    over all seven intervals would be 10/7 s.  The means are taken over the last whole cycles (six values),
    so they give 1.5 exactly (1e-12: summation order)."""
    t_slip = np.cumsum([0.5, 1, 2, 1, 2, 1, 2, 1])  # 8 slips, intervals 1, 2, 1, 2, 1, 2, 1
    times, forces, fb = [], [], []
    for k, ts in enumerate(t_slip):
        times += [ts, ts + 0.1]
        forces += [300.0 if k % 2 == 0 else 280.0, 200.0]
        fb += [AB, CD]
    o = StickSlipObservables.from_trajectory(_fake(times, forces, fb, t_end=t_slip[-1] + 1.0))
    assert (o.period, o.period_label) == (2, "period-2")
    assert o.slip_interval == pytest.approx(1.5, rel=1e-12)
    assert o.slip_interval_spread == pytest.approx(statistics.stdev([2, 1, 2, 1, 2, 1]), rel=1e-12)
    assert o.force_drop == pytest.approx(90.0, rel=1e-12)  # drops 100 and 80 over whole cycles
    assert o.stick_time == pytest.approx(1.4, rel=1e-12)  # AB stays 0.9 and 1.9


def test_statuses_without_a_stick_slip_attractor():
    """Categorical: no jump is "steady" with every mean, spread, extreme and the period None (never NaN), and
    its dict is strict JSON; one slip is "too few slips" (no interval, but its complete CD stay counts);
    jumps that stop (an open stay of 6.5 s after complete stays of 0.5 s: over 10 times) are
    "transient"."""
    steady = StickSlipObservables.from_trajectory(_fake([], [], []))
    assert steady.status == "steady" and steady.n_slips == 0 and steady.period_label == "no stick-slip"
    for name in (*MEANS, *(f"{m}_spread" for m in MEANS), "F_max", "F_min", "period"):
        assert getattr(steady, name) is None, name
    assert json.loads(json.dumps(steady.as_dict(), allow_nan=False)) == steady.as_dict()
    assert "no slip" in repr(steady) and "no jump in the window [0, 10] s" in steady.reason
    one = StickSlipObservables.from_trajectory(_fake([1.0, 1.2], [300, 200], [AB, CD]))
    assert (one.status, one.slip_interval, one.force_drop, one.period_label) == ("too few slips", None, 100.0,
                                                                                 "too short")
    assert one.slip_time == pytest.approx(0.2, rel=1e-12)
    stop = StickSlipObservables.from_trajectory(_fake([1.0, 1.5, 2.0, 2.5, 3.0, 3.5], [300, 200] * 3,
                                                      [AB, CD] * 3))
    assert stop.status == "transient" and "jumps stop at t = 3.5 s" in stop.reason


def test_bad_input_is_named():
    """Categorical: jumps that do not alternate, a t_transient past the window's end, and an object without
    jumps are refused with the argument named."""
    with pytest.raises(ValueError, match="alternate"):
        StickSlipObservables.from_trajectory(_fake([1.0, 2.0], [300, 310], [AB, AB]))
    with pytest.raises(ValueError, match="t_transient"):
        StickSlipObservables.from_trajectory(HAND, 10.0)
    with pytest.raises(TypeError, match="tr must be an exact.Trajectory"):
        StickSlipObservables.from_trajectory(object())
    with pytest.raises(ValueError, match="max_period"):
        StickSlipObservables.from_trajectory(HAND, max_period=0)


def test_dataframe_row():
    """One row whose columns are the dict's keys, with units (categorical)."""
    pytest.importorskip("pandas")
    o = StickSlipObservables.from_trajectory(HAND)
    df = o.to_dataframe()
    assert df.shape == (1, len(o.as_dict())) and df.loc[0, "force_drop"] == pytest.approx(100.0, rel=1e-12)
    assert df.attrs["units"]["slip_interval"] == "s"

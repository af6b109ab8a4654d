"""The slip detector's mean drop on short noisy cycles (issue 36, item 4): within 2 % at >= 25 samples a cycle
and drop/noise >= 10, on sawtooth traces with a known drop (``comparisons.benchmark.detector_bias.sawtooth``:
cycle lengths drawn from 1 +- 10 %, so the jumps fall at every phase of the sampling grid)."""

from __future__ import annotations

import numpy as np
import pytest

from comparisons.benchmark.detector_bias import DROP, sawtooth
from peelapprox import ForceSeries


@pytest.mark.parametrize("samples, ratio", [(25, 10.0), (28, 11.2), (40, 10.0)])
@pytest.mark.parametrize("slip_fraction", [0.01, 0.1])
def test_mean_drop_within_two_percent(samples, ratio, slip_fraction):
    """Mean drop within 2 % of 5.6 N (the goal), every slip found (198 or 199 of 200 cycles: the first and last
    are dropped).  Why 2 %: the goal; the benchmark measures at most 1.2 % over its grid (2 seeds of 200
    cycles), and the old detector read 9-11 % low at 25-28 samples a cycle (the issue's 9.4 %: 5.05 N for
    5.6 N at 28 samples, 0.5 N of noise)."""
    t, F = sawtooth(samples, ratio, slip_fraction, cycles=200, seed=11)
    s = ForceSeries(t, F).slips()
    assert 197 <= len(s) <= 199
    assert abs(float(np.mean(s.drop)) / DROP - 1) <= 0.02


def test_noiseless_unresolved_jump_reads_the_drop():
    """A fall shorter than a sample (slip fraction 0.01 at 40 samples a cycle), no noise: each drop within 5 %
    of 5.6 N and the mean within 1 % (the jump's time within its sample interval is unknown, so each drop is off
    by up to the sticks' rise over a sample, 2.5 % of the drop for each line: measured 3.8 % at most, the mean
    0.16 %: the errors average out over the phases)."""
    t, F = sawtooth(40, float("inf"), 0.01, cycles=100, seed=3)
    s = ForceSeries(t, F).slips()
    assert np.max(np.abs(s.drop / DROP - 1)) <= 0.05
    assert abs(float(np.mean(s.drop)) / DROP - 1) <= 0.01


def test_knee_method_kept_for_infer():
    """``method="knee"`` is the earlier detector (what exact.infer reads traces with, its statistics calibrated
    on it): on the issue's short noisy cycles (28 samples, drop/noise 11.2) it reads the drop more than 4 % low
    where the default is within 2 % (measured -9 to -11 % and within 1.4 %), the same slips found; a bad method
    is named."""
    t, F = sawtooth(28, 11.2, 0.1, cycles=200, seed=11)
    s = ForceSeries(t, F)
    knee, lines = s.slips(method="knee"), s.slips()
    assert len(knee) == len(lines)
    assert float(np.mean(knee.drop)) / DROP - 1 < -0.04 and abs(float(np.mean(lines.drop)) / DROP - 1) <= 0.02
    assert "knee method" in knee.method and "three-piece" in lines.method
    with pytest.raises(ValueError, match="method must be"):
        s.slips(method="gradient")

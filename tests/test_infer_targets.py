"""The benchmark of infer's targets (comparisons/benchmark/infer_targets.py): its draw, classes and summary.

The recovery figures themselves are measured by running the benchmark (docs/your-data.md); these tests check the
bookkeeping on hand-made inputs whose answers are counted by hand.
"""

from __future__ import annotations

import math
from types import SimpleNamespace

from comparisons.benchmark.infer_targets import classify, draw, summarise


def test_the_draw_is_seeded_and_in_its_ranges():
    """The same seed draws the same truths and starts; every value lies in the documented ranges (V in
    [0.3, 4.8], I in [2e-6, 8e-2] and k in [600, 1600] up to their 4-digit rounding, the start's factors within
    2 for I and 1.25 for k)."""
    a, b = draw(30, 7), draw(30, 7)
    assert a == b and a != draw(30, 8)
    for t in a:
        assert 0.3 <= t["V"] <= 4.8 and 2e-6 * (1 - 5e-4) <= t["I"] <= 8e-2 * (1 + 5e-4)
        assert 600 * (1 - 5e-4) <= t["k"] <= 1600 * (1 + 5e-4)
        assert abs(math.log(t["I0"] / t["I"])) <= math.log(2.0) + 1e-12
        assert abs(math.log(t["k0"] / t["k"])) <= math.log(1.25) + 1e-12


def _att(kind, share, starts=()):
    return SimpleNamespace(kind=kind, share=share, starts=starts,
                           is_stick_slip=kind in ("periodic", "quasi-periodic", "chaotic", "aperiodic"))


def test_classes():
    """Two stick-slip attractors of >= 10 % each, one periodic: multistable (a 5 % second one does not count, nor
    two aperiodic groups alone); otherwise the
    solver's attractor's kind, periodic split at I = 1e-4; steady at the solver's start: no stick-slip."""
    two = SimpleNamespace(attractors=[_att("periodic", 0.75, ("solver",)), _att("chaotic", 0.25)])
    assert classify(two, 1e-3) == "multistable"
    small = SimpleNamespace(attractors=[_att("chaotic", 0.95, ("solver",)), _att("periodic", 0.05)])
    assert classify(small, 1e-3) == "chaotic"
    split = SimpleNamespace(attractors=[_att("chaotic", 0.5, ("solver",)), _att("aperiodic", 0.5)])
    assert classify(split, 1e-3) == "chaotic"
    per = SimpleNamespace(attractors=[_att("periodic", 1.0, ("solver", "rest"))])
    assert classify(per, 1e-4) == "periodic-low" and classify(per, 1.1e-4) == "periodic"
    assert classify(SimpleNamespace(attractors=[_att("quasi-periodic", 1.0, ("solver",))]), 1.0) == "quasi-periodic"
    assert classify(SimpleNamespace(attractors=[_att("steady", 1.0, ("solver",))]), 1.0) == "no-stick-slip"


def test_the_summary_counts():
    """Three fitted chaotic rows (one hit, one recovered but not identified, one identified but wrong) and a
    skipped row: hit 1/3, recovered 2/3, identified 2/3, recovered among identified 1/2, identified among
    recovered 1/2; the skipped row is counted apart."""
    rows = [{"class": "chaotic", "recovered": True, "identified": True, "hit": True, "infer_s": 1.0, "runs": 10},
            {"class": "chaotic", "recovered": True, "identified": False, "hit": False, "infer_s": 3.0, "runs": 30},
            {"class": "chaotic", "recovered": False, "identified": True, "hit": False, "infer_s": 2.0, "runs": 20},
            {"class": "no-stick-slip"}]
    text = summarise(rows)
    line = next(s for s in text.splitlines() if s.startswith("chaotic"))
    assert "1/3 (33 %)" in line and line.count("2/3 (67 %)") == 2 and line.count("1/2 (50 %)") == 2
    assert "skipped (no stick-slip at the truth): 1" in text and "median 2 s" in text and "runs median 20" in text

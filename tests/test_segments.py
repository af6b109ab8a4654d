"""Segment extraction from exact trajectories (comparisons.segments)."""

from __future__ import annotations

import numpy as np
import pytest

from comparisons import segments
from exact import simulate
from peelapprox import PeelParams, inertial_period

P5 = PeelParams(V=1.0, I=1e-5)


@pytest.fixture(scope="module")
def low():
    return simulate(P5, 0.45, rtol=1e-10)


def test_segments_follow_the_jumps(low):
    """One complete segment between each pair of jumps, alternating branches; Δt, ΔF and the entry state
    are the jump records themselves (exact equality), and α̇_in = ω - v_in/R (FLOW1)."""
    segs = segments(low)
    J = low.jumps
    assert len(segs) == len(J) - 1
    for s, a, b in zip(segs, list(J)[:-1], list(J)[1:]):
        assert s.branch == a.to_branch == b.from_branch
        assert s.dt == b.t - a.t and s.dF == b.F - a.F
        assert s.alphadot_in == a.omega - a.v_after / P5.R
    assert {s.branch for s in segs[::2]} != {s.branch for s in segs[1::2]}


def test_ab_periods_are_the_inertial_period(low):
    """Case I a: on AB at I=1e-5 the α oscillation's local period is 2π sqrt(I/(F R)) at the local mean F
    (approxalpha).  Tolerance 1e-3: the neglected v̇/R term is O(v/(R Ω)) ~ 1e-3 on AB (measured <= 1.7e-4)."""
    ab = [s for s in segments(low) if s.branch == "AB"]
    assert sum(len(s.periods) for s in ab) >= 40
    for s in ab:
        rel = s.periods / inertial_period(P5, s.F_at_periods) - 1
        assert np.max(np.abs(rel)) <= 1e-3


def test_hermite_crossings_match_dense_output(low):
    """Zero crossings from the step output (cubic Hermite in α, α̇) agree with crossings of a 20 000-point
    dense-output sampling of the same segment to 1e-8 s (measured 3e-10 s)."""
    seg = max(segments(low), key=lambda s: len(s.crossings))
    te = np.linspace(seg.t_in, seg.t_out, 20001)[1:-1]
    d = simulate(P5, 0.45, rtol=1e-10, t_eval=te)
    a, t = d.alpha, d.t
    i = np.nonzero((a[:-1] < 0) & (a[1:] >= 0))[0]
    cr = t[i] - a[i] * (t[i + 1] - t[i]) / (a[i + 1] - a[i])
    assert len(cr) == len(seg.crossings)
    assert np.max(np.abs(cr - seg.crossings)) <= 1e-8


def test_jumps_only_trajectory_gives_entries_without_periods():
    """With save="jumps" the segments still carry entry/exit states and Δt (same as with steps), but no periods."""
    a = segments(simulate(P5, 0.2, rtol=1e-10, save="jumps"))
    b = segments(simulate(P5, 0.2, rtol=1e-10))
    assert [s.dt for s in a] == [s.dt for s in b]
    assert all(len(s.periods) == 0 for s in a)
    assert a[1].entry()["v_f"] == b[1].v_out


def test_compare_rows(low):
    """compare() gives one row per (segment, model of its branch); genalpha + fullvdot, the full model linearised
    in α, matches every segment's Δt and ΔF to 1e-3 (O(α²), α <= 0.07) and the AB α period to 1e-3."""
    from comparisons import DEFAULT_MODELS, compare

    segs = segments(low)
    rows = compare(low, segs=segs[:4])
    assert len(rows) == sum(len(DEFAULT_MODELS[s.branch]) for s in segs[:4])
    assert all(r.status == "ok" for r in rows)
    gen = [r for r in rows if (r.alpha_model, r.v_equation) == ("genalpha", "fullvdot")]
    assert len(gen) == 4
    for r in gen:
        assert abs(r.dt_rel_error) <= 1e-3 and abs(r.dF_rel_error) <= 1e-3
        assert r.dt_abs_error == pytest.approx(r.dt_approx - r.dt_exact, abs=0)
        if r.branch == "AB":
            assert abs(r.period_rel_error) <= 1e-3


def test_last_segments_are_the_tail_of_all(low):
    """``segments(tr, last=k)`` is the last k of ``segments(tr)``, each the same segment (index, entry, exit,
    crossings, periods, extrema equal exactly: each stay is computed from its own two jumps), k beyond the
    count gives all, 0 none; a negative or non-integer ``last`` is refused by name."""
    full = segments(low)
    for k in (0, 1, 4, len(full), len(full) + 7):
        tail = segments(low, last=k)
        assert len(tail) == min(k, len(full))
        for s, r in zip(tail, full[len(full) - len(tail):]):
            assert s.index == r.index and s.dt == r.dt and s.dF == r.dF and s.v_in == r.v_in
            for f in ("crossings", "periods", "F_at_periods", "extrema"):
                assert np.array_equal(getattr(s, f), getattr(r, f))
    for bad in (-1, 1.5, "2"):
        with pytest.raises((ValueError, TypeError), match="last"):
            segments(low, last=bad)


def test_stacked_roots_equal_numpy_roots_per_interval():
    """The crossings and extrema found with one stacked eigenvalue call equal, bitwise, those of the
    per-interval ``numpy.roots`` path (``_hermite_roots``, ``_extremum``: the code before the stacking, kept for
    the cubics with a zero end coefficient) on 200 seeded random sample sets with repeated times and exact
    zeros of α and α̇: the same companion matrices go to the same LAPACK routine, so no tolerance."""
    from comparisons._segments import _crossings, _extrema, _extremum, _hermite_roots

    rng = np.random.default_rng(37)
    found = 0
    for _ in range(200):
        m = int(rng.integers(2, 60))
        t = np.cumsum(rng.random(m) * rng.choice([0, 1, 1, 1], m))
        a = np.sin(rng.random() * 20 * t + rng.random()) + rng.normal(0, 0.1, m)
        d = np.cos(rng.random() * 20 * t) * rng.choice([1, 0, -1], m, p=[.45, .1, .45])
        a[rng.random(m) < 0.05] = 0.0
        ref = []
        for i in np.nonzero((a[:-1] < 0) & (a[1:] >= 0))[0]:
            if t[i + 1] > t[i]:
                ref.extend(_hermite_roots(t[i], t[i + 1], a[i], a[i + 1], d[i], d[i + 1]))
        got = _crossings(t, a, d)
        assert got.tobytes() == np.array(sorted(set(ref))).tobytes()
        ext = [_extremum(t[i], t[i + 1] - t[i], a[i], a[i + 1], d[i], d[i + 1])
               for i in np.nonzero(np.sign(d[:-1]) * np.sign(d[1:]) < 0)[0] if t[i + 1] > t[i]]
        assert _extrema(t, a, d).tobytes() == np.array(ext, dtype=float).tobytes()
        found += len(got) + len(ext)
    assert found > 1000
    # intervals whose cubic term is exactly zero (the numpy.roots fallback) beside ordinary ones
    t = np.array([0.0, 1.0, 2.0, 3.0, 4.0])
    a, d = np.array([-1.0, 0.5, 0.0, 0.0, -0.3]), np.array([1.0, 2.0, 1.0, -1.0, 0.7])
    # on [0, 1] a(s) = -1 + s + s^2/2: the root sqrt(3) - 1 (to rounding: 2 ulp); on [2, 3] a(s) = s - s^2, the
    # stationary point 1/2 exactly (a linear root), and the ordinary interval [3, 4] on the stacked path
    cross = _crossings(t, a, d)
    assert len(cross) == 1 and abs(cross[0] - (np.sqrt(3.0) - 1.0)) <= 4.5e-16
    ext = _extrema(t, a, d)
    assert len(ext) == 2 and ext[0] == 2.5 and 3.0 < ext[1] < 4.0


def test_compare_without_periods_gives_the_same_rows(low):
    """``compare(..., periods=False)`` (the atlas's call: the reduced solves store no steps) gives every row's
    status, Δt and ΔF exactly as with periods (the driver's steps do not depend on what it stores: no
    tolerance), and None for the approximate period columns; a non-bool ``periods`` is refused by name."""
    from comparisons import compare

    segs = segments(low, last=4)
    full, lean = compare(low, segs=segs), compare(low, segs=segs, periods=False)
    assert len(full) == len(lean) >= 16
    for a, b in zip(full, lean):
        da, db = a.as_dict(), b.as_dict()
        assert db.pop("period_approx") is None and db.pop("period_rel_error") is None
        da.pop("period_approx"), da.pop("period_rel_error")
        assert da == db
    assert any(r.period_approx is not None for r in full)
    with pytest.raises(TypeError, match="periods"):
        compare(low, segs=segs, periods="no")

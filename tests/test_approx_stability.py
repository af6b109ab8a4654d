"""The stability-aware reduced map of :func:`peelapprox.approximate_attractor`: Newton and the multipliers against
independent oracles, the confidence flag and its one warning, and the breakdown flag (issue 34).

Oracles: the Hénon map, whose fixed point, period-2 orbit and their multipliers are closed forms; the exact
model's periodic orbit (:func:`exact.periodic_orbit`, its own Newton on the full DAE's section); the exact
solver's breakdown.  Accuracy over random points is measured by ``python -m comparisons.benchmark.approx_targets``,
not here.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import exact
from peelapprox import (
    ApproximateAttractor,
    ApproximationWarning,
    PeelParams,
    StickSlipObservables,
    approximate_attractor,
)
from peelapprox._reduced._reducedmap import newton


class Henon:
    """The Hénon map ``(x, y) -> (1 - a x² + y, b x)``: a map of the plane with closed-form orbits."""

    def __init__(self, a: float, b: float) -> None:
        self.a, self.b = a, b

    def power(self, z: np.ndarray, n: int) -> np.ndarray:
        for _ in range(n):
            z = np.array([1.0 - self.a * z[0] ** 2 + z[1], self.b * z[0]])
        return z

    def scale(self, z: np.ndarray) -> np.ndarray:
        return np.array([1.0, 1.0])

    def J(self, z: np.ndarray) -> np.ndarray:
        return np.array([[-2.0 * self.a * z[0], 1.0], [self.b, 0.0]])


@pytest.mark.parametrize("a, b", [(0.2, 0.3), (1.4, 0.3), (0.9, -0.4)])
def test_newton_finds_the_henon_fixed_point_and_its_multipliers(a, b):
    """Closed form: the fixed point ``x* = (b - 1 + sqrt((1 - b)² + 4a))/(2a)``, ``y* = b x*``, its multipliers the
    eigenvalues of ``[[-2a x*, 1], [b, 0]]``.  Newton starts 5 % off.  It stops when its step is below 1e-8 of the
    scale (1 here); the chord iteration converges linearly, so the point is within a few 1e-9 (measured 1.7e-9 on
    the period-2 orbit): 1e-8.  The multipliers come from central differences of step 3e-5 at that point, whose
    truncation error is O(h²) ~ 1e-9, plus the point's error times the map's second derivative: 1e-7 with a
    margin."""
    m = Henon(a, b)
    x = (b - 1.0 + math.sqrt((1.0 - b) ** 2 + 4.0 * a)) / (2.0 * a)
    star = np.array([x, b * x])
    res = newton(m, star * 1.05, 1)
    assert res is not None
    z, J = res
    np.testing.assert_allclose(z, star, rtol=0, atol=1e-8)
    mu = np.sort_complex(np.linalg.eigvals(J))
    np.testing.assert_allclose(mu, np.sort_complex(np.linalg.eigvals(m.J(star))), rtol=0, atol=1e-7)


def test_newton_finds_the_henon_period_two_orbit():
    """Closed form: at a = 1.4, b = 0.3 the period-2 points are ``x = (1 - b ± sqrt(4a - 3(1 - b)²))/(2a)``,
    ``y = b x_other``; the multipliers of P² are the eigenvalues of ``J(z2) J(z1)`` (both outside the unit
    circle's stable side: the orbit is a saddle).  Tolerances as for the fixed point."""
    a, b = 1.4, 0.3
    m = Henon(a, b)
    r = math.sqrt(4.0 * a - 3.0 * (1.0 - b) ** 2)
    x1, x2 = (1.0 - b + r) / (2.0 * a), (1.0 - b - r) / (2.0 * a)
    z1, z2 = np.array([x1, b * x2]), np.array([x2, b * x1])
    res = newton(m, z1 + np.array([0.02, -0.01]), 2)
    assert res is not None
    z, J = res
    np.testing.assert_allclose(z, z1, rtol=0, atol=1e-8)
    mu = np.sort(np.abs(np.linalg.eigvals(J)))
    np.testing.assert_allclose(mu, np.sort(np.abs(np.linalg.eigvals(m.J(z2) @ m.J(z1)))), rtol=0, atol=1e-7)


def test_newton_gives_up_on_a_map_without_the_orbit():
    """The Hénon map at a = -0.5, b = 0.3 has no real fixed point ((1 - b)² + 4a < 0): Newton returns None (a step
    over half the scale, or no convergence in its iterations), never a wrong point."""
    assert newton(Henon(-0.5, 0.3), np.array([0.5, 0.1]), 1) is None


def test_multipliers_agree_with_the_exact_periodic_orbit():
    """Independent oracle: :func:`exact.periodic_orbit`, Newton on the full DAE's section with its own monodromy,
    at V = 2, I = 1e-3 where both find a stable period-7 orbit (the issue's example: the old map called it
    aperiodic).  The reduced map's period label is the exact one, and its largest |μ| is within the reduction's
    measured multiplier error, :data:`peelapprox._reduced._approx_result.MULTIPLIER_ERROR` = 0.07, of the exact one
    (measured: 0.847 against 0.899)."""
    from peelapprox._reduced._approx_result import MULTIPLIER_ERROR

    p = PeelParams(V=2.0, I=1e-3)
    o = approximate_attractor(p, warn=False)
    assert (o.status, o.period_label) == ("stick-slip", "period-7")
    assert o.multipliers is not None and len(o.multipliers) == 2
    orbit = exact.periodic_orbit(p, n=7)
    assert orbit.stable and o.stable
    assert abs(max(abs(m) for m in o.multipliers) - max(abs(m) for m in orbit.multipliers)) < MULTIPLIER_ERROR


def test_the_result_is_still_stick_slip_observables():
    """Every caller of the observables reads the new result unchanged: it is a StickSlipObservables, its
    ``as_dict`` is JSON data (multipliers as [re, im] pairs), and ``set`` is the primary then the alternatives."""
    o = approximate_attractor(PeelParams(V=1.0, I=1e-5), warn=False)
    assert isinstance(o, StickSlipObservables) and isinstance(o, ApproximateAttractor)
    assert o.set[0] is o and o.set[1:] == o.alternatives
    d = o.as_dict()
    assert d["confidence"] in ("high", "low") and isinstance(d["confidence_reason"], str)
    assert all(isinstance(pair, list) and len(pair) == 2 for pair in d["multipliers"])
    assert "confidence" in repr(o) and "confidence" in o.summary()


def test_low_confidence_warns_once_and_high_does_not():
    """V = 4.5, I = 0.1 (the issue's example, where the old map put F in 570-622 N against the exact 306-308 N):
    the map's period-1 orbit has |μ| within 1e-3 of 1 (1.00001 with the default chain, which leaves it and samples
    500 returns around it), inside the reduction's multiplier error, so the answer is low confidence and says why,
    with exactly one ApproximationWarning.  Stored oracle: ``exact.attractor_observables(PeelParams(V=4.5, I=0.1))``
    (slip interval 1.25517e-3 s, force drop 1.76414 N, F 305.9-308.4 N); the prediction's means within 1 %
    (measured -0.31 % and -0.59 %) and its forces within 5 % of that range (measured 294.5-320.0 N: the sample
    wanders around the weakly unstable orbit, where Airy1 + approxvdot's weakly stable one had 306.3-308.0 N).
    ``warn=False`` is silent.  V = 1, I = 1e-5 (a stable period-3 orbit, |μ| 0.23 and 0.28, low inertia) is high
    confidence and silent."""
    p = PeelParams(V=4.5, I=0.1)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        o = approximate_attractor(p)
    flagged = [w for w in caught if issubclass(w.category, ApproximationWarning)]
    assert len(flagged) == 1 and "low confidence" in str(flagged[0].message)
    assert o.confidence == "low" and "multiplier" in o.confidence_reason
    assert o.slip_interval == pytest.approx(1.2551746602333178e-3, rel=0.01)
    assert o.force_drop == pytest.approx(1.764138221973517, rel=0.01)
    assert o.F_min >= 0.95 * 305.9449825738739 and o.F_max <= 1.05 * 308.3878124009863
    with warnings.catch_warnings():
        warnings.simplefilter("error", ApproximationWarning)
        approximate_attractor(p, warn=False)
        high = approximate_attractor(PeelParams(V=1.0, I=1e-5))
    assert high.confidence == "high" and high.period_label == "period-3"


def test_breakdown_of_the_exact_run_is_flagged():
    """Issue 34: at V = 0.903, I = 1.08e-4 the exact run breaks down from the solver's start (F(1 + sin α) falls to
    f(0+, V) on AB at t = 0.021 s: :class:`peelapprox.ModelBreakdown`), and so does the full branch dynamics
    linearised in α (genalpha + fullvdot) from the same start, the default chain at this intermediate inertia: the
    default answer is that breakdown (low confidence).  Airy1 + approxvdot (the default at high inertia before)
    predicts stick-slip: an artefact of its O(α) terms (its first CD stay lasts 2.6 ms against the exact 11.2 ms), which
    the answer flags: low confidence, the reason naming the full chain's breakdown."""
    p = PeelParams(V=0.903, I=1.08e-4)
    with pytest.raises(exact.ModelBreakdown):
        exact.simulate(p, 0.1)
    full = approximate_attractor(p, alpha_model="genalpha", v_equation="fullvdot", cd_alpha_model="genalpha",
                                 cd_v_equation="fullvdot", start="solver", warn=False)
    assert full.status == "breakdown" and "v -> 0" in full.reason
    o = approximate_attractor(p, warn=False)
    assert o.status == "breakdown" and o.confidence == "low" and "v -> 0" in o.reason
    airy = approximate_attractor(p, alpha_model="airy1", v_equation="approxvdot", cd_alpha_model="airy1",
                                 cd_v_equation="approxvdot", warn=False)
    assert airy.status == "stick-slip" and airy.confidence == "low" and "breaks down" in airy.confidence_reason


def test_benchmark_points_and_cached_reference():
    """The benchmark's points are the seeded draw it documents (V in [0.3, 4.8], I log-uniform in [2e-6, 8e-2],
    the same for the same seed, others for another), and its cached reference is read, not recomputed: the file
    holds five starts per point, α0 = 0 first (the strict reference)."""
    from comparisons.benchmark import approx_targets as bench

    pts = bench.points(100, 1)
    assert pts == bench.points(100, 1) and pts != bench.points(100, 2)
    assert all(0.3 <= V <= 4.8 and 2e-6 <= I <= 8e-2 for V, I in pts)
    ref = bench.reference(100, 1)
    assert [(r["V"], r["I"]) for r in ref] == pts
    assert all([s["alpha0"] for s in r["starts"]] == list(bench.ALPHA0S) for r in ref)


@pytest.mark.slow
def test_validation_seed_meets_the_accuracy_targets():
    """The issue's targets on the validation points (seed 2, never used to choose a confidence rule or constant;
    the chain per inertia label was chosen on both seeds), against their cached exact multi-start reference: the
    primary prediction matches an exact attractor of the set at >= 90 % of the stick-slip points (measured 97.9 %;
    92.8 % with Airy1 + approxvdot everywhere), the default start's at >= 85 % (96.9 %); of the predictions not
    flagged low >= 95 % match (100 %), and at least half are unflagged (62.9 %).  Deterministic: the same numbers
    on every run (the map has no randomness), so the margins are the measured ones."""
    from comparisons.benchmark import approx_targets as bench

    s = bench.score(bench.reference(100, 2))
    assert s["n"] == 97
    assert s["set"] >= 0.90 and s["strict"] >= 0.85
    assert s["high_share"] >= 0.5 and s["high_match"] >= 0.95


def test_period_label_is_the_maps_own_long_run_period():
    """The period label of a periodic primary prediction is the period the reduced map itself settles on, not an
    artefact of the period detection (Newton on ``P^n`` proposed by returns that repeat to 20 %): from the same
    start the map iterated 1500 returns (the first 1300 discarded) repeats with that period, classified by
    :func:`peelapprox.periodicity` at 1e-4 (the map's own sample tolerance, ``PERIOD_RTOL``; its returns at rtol
    1e-6 repeat to ~1e-7 once converged).  On 30 seeded random points of the benchmark's plane (seed 3, never used
    to choose a rule), every periodic primary that needs no escape to reach and contracts well is checked: largest
    |μ| below 0.9, so over 1300 returns a deviation shrinks by 0.9^(1300/12) ~ 1e-5 at period 12 (far more at
    shorter periods), below the tolerance.  At the 27 points of seeds 1 and 2 whose label differs from the exact
    run's, the same check (3000 returns, the last 400 at 1e-6 and 1e-4) gave the prediction's period at 25 (the two
    others: a weakly stable orbit, |μ| 0.9945, reached after ~2600 returns, and one reached past an escape): they
    are the reduction's orbits, not its period detection (docs/theory.md, "Period labels")."""
    from comparisons.benchmark import approx_targets as bench
    from peelapprox import periodicity
    from peelapprox._reduced._approximate import _chain, _rest, _solver_start
    from peelapprox._reduced._reducedmap import ReturnMap
    from peelapprox.law._compiled import compiled_law

    checked = 0
    for V, I in bench.points(30, 3):
        p = PeelParams(V=V, I=I)
        o = approximate_attractor(p, warn=False, max_wall=None)
        if o.status != "stick-slip" or o.multipliers is None or o.escape_multiplier is not None \
                or max(abs(m) for m in o.multipliers) >= 0.9 or "Newton" not in o.method:
            continue
        if any(a.start == o.start and a.multipliers is not None and max(abs(m) for m in a.multipliers) > 1.0
               for a in o.alternatives):
            continue  # reached past an unstable orbit the map left (pushed along its deviation), not by iteration
        law = compiled_law(p.force, p.V)
        _, _, models, _ = _chain(p, law, [None] * 4)
        m = ReturnMap(p, law, models, 1e-6)
        x, recs = m.run(m.enter(_solver_start(p, law) if o.start == "solver" else _rest(law)), 1500)
        got = periodicity(np.ascontiguousarray(recs[1300:, 0]), rtol=1e-4, max_period=32)
        assert got.period == o.period, (V, I, o.period_label, got.label)
        checked += 1
    assert checked >= 10, checked  # measured: 14 of the 30 points qualify


def test_label_measure_against_the_matched_attractor():
    """The benchmark's label measures on a hand-made point (closed-form expectations): the prediction (slip interval
    1.0, force drop 10, period 11) matches the exact starts with period 12 (distance 0.09) and 11 (0.02), not the one
    20 % off; ``matched_start`` is the closest, so the strict label (against the first start, period 12) differs and
    the matched one (period 11) agrees; an aperiodic prediction or exact attractor gives no label comparison."""
    from types import SimpleNamespace

    from comparisons.benchmark import approx_targets as bench

    def start(T: float, dF: float, n: int | None, status: str = "stick-slip") -> dict:
        return {"status": status, "slip_interval": T, "force_drop": dF, "period": n}

    starts = [start(1.09, 10.0, 12), start(1.2, 10.0, 5), start(1.02, 10.0, 11), start(1.0, 10.0, 3, "steady")]
    pred = SimpleNamespace(status="stick-slip", slip_interval=1.0, force_drop=10.0, period=11)
    assert bench.matched_start(pred, starts) is starts[2]
    assert bench._labels(pred, starts[0]) is False and bench._labels(pred, starts[2]) is True
    assert bench.matched_start(SimpleNamespace(**{**vars(pred), "slip_interval": 2.0}), starts) is None
    assert bench._labels(SimpleNamespace(**{**vars(pred), "period": None}), starts[2]) is None
    assert bench._labels(pred, start(1.0, 10.0, None)) is None


@pytest.mark.slow
def test_period_labels_at_every_inertia():
    """Issue 35's label target, the full branch dynamics linearised in α being the default at every inertia: on
    both seeds' cached references, wherever the primary prediction matches an exact attractor of the set and both
    are periodic, its period equals that attractor's (the measure the issue's sentence asks for: docs/theory.md,
    "Period labels") at >= 95 % of the points (measured 49 of 51 and 57 of 58; the exceptions: V = 1.533, I =
    1.25e-4, the rest start's period-3 where the exact orbit is period-28, a miss; V = 0.667, I = 4.8e-3, period-5
    as the default start but nearest another start's attractor; V = 2.97, I = 1.5e-5 on seed 2).  With Airy1 +
    approxvdot at high inertia (the default before) the same measure was 43 of 51 and 50 of 58, with it everywhere
    40 of 51 and 41 of 56; at low and intermediate inertia alone the full chain gives 36 of 37 and 43 of 44.  The
    default tier's cover: the label is the map's own long-run period
    (``test_period_label_is_the_maps_own_long_run_period``) and the measure's definition
    (``test_label_measure_against_the_matched_attractor``)."""
    from comparisons.benchmark import approx_targets as bench

    for seed in (1, 2):
        rows = [r for r in bench.score(bench.reference(100, seed))["rows"]
                if r["strict_ss"] and r["labels_matched"] is not None]
        assert len(rows) >= 50 and sum(r["labels_matched"] for r in rows) >= 0.95 * len(rows), seed


def test_the_solver_start_is_not_followed_where_the_rest_start_ranks_first():
    """Hypothesis: at this high-inertia point of the benchmark (seed 1's second) the solver's start reaches the small
    mode, a period-1 orbit the map finds weakly unstable (|μ| 1.0066, within the multiplier error of 1), while the rest
    start's answer is stick-slip inside the physical range with its stability decided; so the rest start's answer
    ranks first whatever the solver's start reaches after the small mode, and that start is not followed past it.
    Checked: the primary prediction is the rest start's own, every field but the alternatives equal (identity, not a
    tolerance: the same computation); the alternatives are the small mode alone, with its escape return; and the
    attractor the solver's start reaches when followed (``start="solver"``, an aperiodic sample 3.5 % below in slip
    interval, so not the same attractor by the 1 % rule) is not among them.  The rule's cost: 709 against 979 returns
    a call at high inertia (docs/theory.md, "Which chain where")."""
    p = PeelParams(V=4.577086633466709, I=0.00019300180177724523)
    o = approximate_attractor(p, warn=False)
    rest = approximate_attractor(p, start="rest", warn=False)
    solver = approximate_attractor(p, start="solver", warn=False)
    primary, alone = o.as_dict(), rest.as_dict()
    primary.pop("alternatives"), alone.pop("alternatives")
    assert o.start == "rest" and primary == alone
    assert len(o.alternatives) == 1
    small = o.alternatives[0]
    assert small.start == "solver" and small.period == 1 and small.escape_returns is not None
    assert small.multipliers is not None and 1.0 < max(abs(m) for m in small.multipliers) < 1.07
    assert solver.status == "stick-slip" and abs(solver.slip_interval / o.slip_interval - 1.0) > 0.01
    assert all(a.start != "solver" or a.escape_returns is not None for a in o.alternatives)

"""The attractor sets' public surface under hostile input: :func:`peelapprox.approximate_attractor` and
:func:`exact.attractor_set` on seeded random points of the plane and on laws and starts at the edge of the model.

Found by a fuzz of a few hundred random calls (V 0.05-6 m/s, I 1e-7-0.2 kg m^2, k 200-5000 N/m, R, the law
families, every chain): a law whose lower fold force is negative raised an internal ``F must be finite`` error; a
closed-form α model whose force ramp crosses 0 raised numba's ZeroDivisionError; an answer without a return map (no
AB landing, no folds) carried confidence ``"high"`` with an empty reason, whatever its status; a set whose stability
steps the budget cut said ``"ok"`` while a near-periodic window, left without its Newton orbit, was called aperiodic;
breakdown and steady attractors were numbered before the first start's.  Oracles: the cubic law's folds in closed
form, the sinusoid's linear force ramp, the documented rules (confidence, statuses, numbering) and strict JSON.
"""

from __future__ import annotations

import dataclasses
import json
import math
import time
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from exact import attractor_set
from peelapprox import (
    ApproximationWarning,
    PeelParams,
    StickSlipObservables,
    approximate_attractor,
    estimate,
    reduced_segment,
)
from peelapprox.errors import ModelBreakdown
from peelapprox.law import PeelForce

#: A cubic ``a + b v - c v^2 + d v^3`` whose lower fold (CD's minimum) lies below 0 N (module docstring).
DIP = dict(a=100.0, b=400.0, c=450.0, d=60.0)


def _cubic_folds(a: float, b: float, c: float, d: float) -> tuple[float, float]:
    """The cubic's fold velocities, the roots of ``b - 2 c v + 3 d v^2`` (closed form)."""
    r = math.sqrt(4 * c * c - 12 * b * d)
    return (2 * c - r) / (6 * d), (2 * c + r) / (6 * d)


def _calls(fn, *args, **kwargs):
    """``fn(...)`` and the ApproximationWarnings it gave."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        out = fn(*args, **kwargs)
    return out, [w for w in caught if issubclass(w.category, ApproximationWarning)]


def _finite_json(d: dict) -> dict:
    """``d`` through strict JSON (no NaN, no inf) and back."""
    return json.loads(json.dumps(d, allow_nan=False))


# ---------------------------------------------------------------------------------------------- approximate_attractor


def test_a_law_with_a_negative_lower_fold_force_is_a_breakdown_not_a_traceback():
    """The cubic of :data:`DIP` has its CD minimum at v = (2c + sqrt(4c^2 - 12bd))/(6d) = 4.507 m/s, where f =
    -1745 N (closed form): no cycle closes (the exact runs from α0 = ±0.15, ±0.3 break down), while the fixed point
    v = V = 0.36 m/s, below the AB fold, is stable (f' = b - 2cV + 3dV^2 = 99 N s/m), where the exact solver's
    start settles.  From rest approximate_attractor says so as a low-confidence breakdown (one warning); from both
    starts the solver's steady peeling is the primary, that breakdown its alternative; estimate raises a ValueError
    naming params.force.  Before, all three raised the internal "F must be finite" of the inertial period at f_min."""
    a, b, c, d = DIP.values()
    v_max, v_min = _cubic_folds(a, b, c, d)
    assert a + b * v_min - c * v_min**2 + d * v_min**3 < 0  # the oracle: the law's own dip
    assert 0.36 < v_max and b - 2 * c * 0.36 + 3 * d * 0.36**2 > 0  # ... and its stable fixed point on AB
    p = PeelParams(V=0.36, I=1.5e-4, k=326.0, force=PeelForce.cubic(**DIP))
    o, caught = _calls(approximate_attractor, p, start="rest")
    assert o.status == "breakdown" and "f_min" in o.reason
    assert o.confidence == "low" and o.reason in o.confidence_reason
    assert len(caught) == 1
    both, caught = _calls(approximate_attractor, p)
    assert (both.status, both.start, len(caught)) == ("steady", "solver", 0)
    assert [x.reason for x in both.alternatives] == [o.reason]
    with pytest.raises(ValueError, match="params.force"):
        estimate(p)


@pytest.mark.parametrize("V, start, status, confidence, warned", [
    (0.01, "rest", "breakdown", "low", 1), (6.0, "auto", "steady", "high", 0)])
def test_an_answer_without_a_return_map_is_rated_like_any_other(V, start, status, confidence, warned):
    """Without a map to iterate (V = 0.01 from rest: f_min below f(0+, V), no AB landing; V = 6: no folds) the
    answer is rated by the rules every other answer gets: a breakdown is low confidence with its reason and warns
    once, steady peeling high with its reason; before, both were "high" with an empty reason."""
    o, caught = _calls(approximate_attractor, PeelParams(V=V, I=1e-4), start=start)
    assert (o.status, o.confidence, len(caught)) == (status, confidence, warned)
    assert o.confidence_reason


def test_without_an_ab_landing_the_solver_start_rests_on_the_stable_fixed_point():
    """V = 0.1 m/s (paper's law): f_min = 117.8 N lies below f(0+, V), so no stick-slip cycle closes, and f'(V, V) =
    126 N s/m > 0 with V below the AB fold (0.31 m/s): the exact solver's start settles on the fixed point (steady;
    30 of 30 random such points, the docstring of ``_at_fixed_point`` in peelapprox/_reduced/_approximate.py), the
    α0 = -0.3 start breaks down without a landing.  The primary prediction is that steady answer (it was a breakdown:
    the solver start's fate was never looked at), the breakdown its alternative."""
    p = PeelParams(V=0.1, I=1e-4)
    s = attractor_set(p, starts=[0.0, -0.3], t_transient=2.0, t_window=1.0, workers=0, stability=False)
    assert [a.label for a in s.attractors] == ["steady", "breakdown:no_landing"]
    o, caught = _calls(approximate_attractor, p)
    assert (o.status, o.confidence, o.start, len(caught)) == ("steady", "high", "solver", 0)
    assert [(x.status, x.confidence) for x in o.alternatives] == [("breakdown", "low")]


def test_a_closed_form_force_ramp_through_zero_is_a_breakdown():
    """The sinusoid's force ramp on AB is ``F_in + k (V - v_in) t``: from the rest start of the cubic of this test
    (F_in = f_min = 244.54 N, v_in = v_land_ab = 0.4399 m/s > V) it reaches 0 at ``t = f_min / (k (v_in - V))`` =
    3.808 s, where numba's F_in/F divided by zero.  Now the segment stops there as a non-finite state: the map's
    answer is a breakdown, reduced_segment's a ModelBreakdown, both at that t (to 1e-3 relative: the step that
    stops lands within the last accepted step of the singular time)."""
    law = PeelForce.cubic(a=82.02466743307578, b=482.2516595818645, c=276.0749539774449, d=44.52066544430903)
    p = PeelParams(V=0.1930888643456089, I=4.179427299254265e-06, k=260.1555301613499, R=0.05448238387195528,
                   force=law)
    bs = law.folds(p.V)
    t_zero = bs.f_min / (p.k * (bs.v_land_ab - p.V))
    o = approximate_attractor(p, alpha_model="sinusoid", v_equation="approxvdot", start="rest", warn=False)
    assert o.status == "breakdown" and "non-finite" in o.reason
    assert float(o.reason.split(" s after its entry")[0].rsplit(", ", 1)[1]) == pytest.approx(t_zero, rel=1e-3)
    with pytest.raises(ModelBreakdown) as info:
        reduced_segment(p, "AB", F_in=bs.f_min, alpha_model="sinusoid", alpha_in=0.0, alphadot_in=0.0)
    assert info.value.t == pytest.approx(t_zero, rel=1e-3)


def test_a_multiplier_near_one_is_printed_apart_from_one():
    """V = 4.5, I = 0.1 (the issue's miss): the map leaves a period-1 orbit with |mu| = 1 + 1.2e-5, which the
    confidence reason printed as "|mu| = 1" (five digits).  The printed value now reads back within 1e-6 of that
    orbit's largest |mu| and apart from 1."""
    import re

    o = approximate_attractor(PeelParams(V=4.5, I=0.1), warn=False)
    rho = max(max(abs(m) for m in x.multipliers) for x in o.set if x.multipliers)
    printed = float(re.search(r"\|mu\| = ([0-9.]+)", o.confidence_reason).group(1))
    assert printed != 1.0 and printed == pytest.approx(rho, rel=1e-6)


_V = st.floats(math.log(0.05), math.log(6.0)).map(math.exp)
_I = st.floats(math.log(1e-7), math.log(0.2)).map(math.exp)
_K = st.floats(math.log(200.0), math.log(5000.0)).map(math.exp)


def _check_answer(o) -> None:
    """The documented consistency of one answer (module docstring of :mod:`peelapprox._reduced._approx_result`)."""
    for x in o.set:
        assert x.confidence in ("high", "low") and x.confidence_reason
        if x.confidence == "high" and x.status == "stick-slip":
            assert x.confidence_reason == "no rule of low confidence applies"
        for mu in x.multipliers or ():
            assert math.isfinite(mu.real) and math.isfinite(mu.imag)
        assert x.escape_returns is None or (math.isfinite(x.escape_returns) and x.escape_returns >= 0)
    if o.status != "stick-slip":  # the primary is an attractor of the set's first rank: only left orbits rank lower
        assert all(x.status != "stick-slip" or "unstable" in x.method for x in o.alternatives)
    d = o.as_dict()
    assert _finite_json(d) == d
    assert "nan" not in repr(o).lower()


@settings(max_examples=10, deadline=None, derandomize=True)
@given(V=_V, I=_I, k=_K, start=st.sampled_from(("auto", "solver", "rest")))
def test_random_points_give_consistent_answers(V, I, k, start):
    """Seeded points over the plane (V 0.05-6 m/s, I 1e-7-0.2 kg m^2, k 200-5000 N/m, log-uniform): every answer is
    rated (high or low, with its reason; high stick-slip only where no rule applies), warns exactly once where its
    confidence is low, carries finite multipliers and escape returns, goes through strict JSON unchanged and is the
    same, field for field, when asked twice.  10 examples (a few seconds); 100 over every family are
    the slow sweep's."""
    p = PeelParams(V=V, I=I, k=k)
    o, caught = _calls(approximate_attractor, p, start=start, max_wall=None)
    assert len(caught) == (o.confidence == "low")
    _check_answer(o)
    assert approximate_attractor(p, start=start, max_wall=None, warn=False).as_dict() == o.as_dict()


@pytest.mark.slow
@settings(max_examples=100, deadline=None, derandomize=True)
@given(V=_V, I=_I, k=_K, R=st.floats(0.01, 0.5), law=st.sampled_from(("paper", "cubic", "power_branches", "dip")),
       chain=st.sampled_from((None, ("airy1", "approxvdot"), ("sinusoid", "approxvdot"), ("exponential", "fullvdot"),
                              ("airy2_frozen", "fullvdot"), ("static", "approxvdot"))))
def test_random_points_every_family_and_chain(V, I, k, R, law, chain):
    """The default-tier property (:func:`test_random_points_give_consistent_answers`) over the law families, a
    negative-dip cubic (:data:`DIP`), the roller radius and the α models of both kinds: no exception but a named
    ValueError, every answer consistent."""
    force = PeelForce.cubic(**DIP) if law == "dip" else getattr(PeelForce, law)()
    p = PeelParams(V=V, I=I, k=k, R=R, l=max(1.0, 2 * R), force=force)
    kw = {} if chain is None else dict(alpha_model=chain[0], v_equation=chain[1])
    o, caught = _calls(approximate_attractor, p, max_wall=10.0, **kw)
    assert len(caught) == (o.confidence == "low")
    _check_answer(o)


@pytest.mark.slow
def test_the_same_answers_in_two_processes(tmp_path):
    """40 seeded points (V 0.05-6, I 1e-7-0.2, k 200-5000, log-uniform; no wall budget, which alone could cut one
    run and not the other): the answers' JSON is byte for byte the same from two fresh processes."""
    import subprocess
    import sys

    code = ("import json, math, warnings, numpy as np\nwarnings.simplefilter('ignore')\n"
            "from peelapprox import PeelParams, approximate_attractor\nrng = np.random.default_rng(7)\nout = []\n"
            "for _ in range(40):\n"
            "    V, I, k = (float(math.exp(rng.uniform(math.log(a), math.log(b)))) for a, b in "
            "((0.05, 6.0), (1e-7, 0.2), (200.0, 5000.0)))\n"
            "    out.append(approximate_attractor(PeelParams(V=V, I=I, k=k), max_wall=None).as_dict())\n"
            "print(json.dumps(out))\n")
    runs = [subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, timeout=600)
            for _ in range(2)]
    assert runs[0].stdout == runs[1].stdout and len(json.loads(runs[0].stdout)) == 40


# ---------------------------------------------------------------------------------------------- attractor_set


def test_a_stability_step_cut_by_max_wall_is_a_status():
    """V = 1, I = 1e-5 from α0 = 0 over a 1 s window: Newton closes its period-3 orbit (docs/dynamics.md) where
    the budget allows.  A progress callback that waits out the budget just before the stability steps leaves them
    uncomputed: the window, near-periodic but not settled, is then read as aperiodic, and the set says so with
    status "max_wall" (it said "ok").  The wait is about 2 s of wall time and no CPU."""
    p = PeelParams(V=1.0, I=1e-5)
    kw = dict(starts=[0.0], t_transient=1.0, t_window=1.0, workers=0, lyapunov_T=1.0)
    full = attractor_set(p, **kw)
    assert full.status == "ok" and [a.label for a in full.attractors] == ["period-3"]
    t0 = time.perf_counter()

    def wait(done, total, message):
        if "Newton" in message or "Lyapunov" in message:
            time.sleep(max(0.0, t0 + 2.05 - time.perf_counter()))

    cut = attractor_set(p, max_wall=2.0, progress=wait, **kw)
    assert cut.status == "max_wall" and "stability" in cut.message
    assert "max_wall" in cut.attractors[0].note


def test_attractors_are_numbered_by_the_start_that_first_reaches_them():
    """V = 0.7, I = 3e-4: from α0 = 0 a period-1 orbit, from α0 = -0.3 a breakdown (CONSTR loses its root on AB).
    The attractors are numbered in the order of the starts (the documented order), so the first start's, the
    primary, is ``attractors[0]``; before, the breakdown, grouped in a first pass, came first.  (Newton closes the
    period-1 orbit: about a second.)"""
    s = attractor_set(PeelParams(V=0.7, I=3e-4), starts=[0.0, -0.3], t_transient=2.0, t_window=1.0, workers=0)
    assert [a.label for a in s.attractors] == ["period-1", "breakdown:no_root"]
    assert [a.id for a in s.attractors] == [0, 1] and [o.attractor for o in s.outcomes] == [0, 1]
    assert s.primary is s.attractors[0]
    pd = pytest.importorskip("pandas")
    df = s.to_dataframe()
    assert isinstance(df, pd.DataFrame) and list(df["label"]) == ["period-1", "breakdown:no_root"]
    documented = ["id", "kind", "label", "period", "share", "n_starts", "starts", "stable", "max_multiplier",
                  "multipliers", "lyapunov_bits_per_s", "lyapunov_stderr", "cycle", "note"]
    observed = ["window_period" if f.name == "period" else f.name for f in dataclasses.fields(StickSlipObservables)
                if f.name not in ("status", "reason", "method", "V", "I")]
    assert list(df.columns) == documented + observed  # SetAttractor.row's docstring
    # the attractor's period is Newton's (the window, 1 s after 2 s, had not settled: its own is None); the window's
    # None overwrote it in the table before
    assert s.attractors[0].period == 1 and s.attractors[0].observables.period is None
    assert df["period"].iloc[0] == 1 and df["window_period"].isna().iloc[0]


def test_starts_as_an_array_and_bad_start_values_are_named():
    """A 1-D array of α0 (as np.linspace gives) and numpy integers are starts like a list of floats (the same set);
    a mapping's non-numeric alpha0 is a TypeError naming ``starts[0]['alpha0']`` (it was float()'s bare "could not
    convert string to float")."""
    p = PeelParams(V=1.0, I=1e-5)
    kw = dict(t_transient=0.2, t_window=0.2, workers=0, stability=False)
    ref = attractor_set(p, starts=[0.0, 0.1], **kw)
    for starts in (np.array([0.0, 0.1]), [np.int64(0), np.float64(0.1)]):
        s = attractor_set(p, starts=starts, **kw)
        assert [a.row() for a in s.attractors] == [a.row() for a in ref.attractors]
    with pytest.raises(TypeError, match=r"starts\[0\]\['alpha0'\]"):
        attractor_set(p, starts=[{"alpha0": "x"}], **kw)
    with pytest.raises(TypeError, match="starts"):
        attractor_set(p, starts=np.zeros((1, 1)), **kw)


def test_a_law_not_defined_at_the_pull_speed_is_named_before_any_start():
    """A table measured at V = 1 m/s only, asked at V = 2 m/s: a ValueError naming params.force, as simulate's,
    whatever the starts (it was the status "no attractor" with every default start an "invalid start", and a given
    start blamed as ``starts[0]``)."""
    v = np.geomspace(1e-3, 50.0, 60)
    p = PeelParams(V=2.0, I=1e-4, force=PeelForce.tabulated(v, PeelForce.paper().f(v, 1.0), V=1.0))
    for starts in ("default", [0.0]):
        with pytest.raises(ValueError, match=r"params\.force: V=2\.0 m/s: this tabulated law was measured at V=1\.0"):
            attractor_set(p, starts=starts, t_transient=0.1, t_window=0.1, workers=0)


def test_a_set_without_return_maps_plots_without_a_warning():
    """V = 0.5, I = 1e-4 (every start breaks down, docs/dynamics.md) and a budget spent before any run: the plot
    names the breakdown, or the status, in its legend, without matplotlib's "No artists with labels" warning (its
    legend was empty)."""
    pytest.importorskip("matplotlib")
    for kw in ({}, {"max_wall": 1e-6}):
        s = attractor_set(PeelParams(V=0.5, I=1e-4), starts=[0.0], t_transient=0.2, t_window=0.2, workers=0, **kw)
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            fig = s.plot()
        texts = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
        assert len(texts) == 1 and texts[0].startswith("A0 breakdown" if not kw else "max_wall")


def test_an_exponent_that_decides_nothing_leaves_the_class_open():
    """V = 2, I = 1e-4 is chaotic (docs/dynamics.md: 4.2-5.5 bits/s by four methods over 200 s).  A 1 s tangent
    estimate measures 7.9 ± 9.3 bits/s there: above the chaos threshold yet within three standard errors of 0.  The
    attractor was then "quasi-periodic" (an exponent zero within its error, by the rule's else); it is now
    "aperiodic", its note saying the exponent decides neither, and the exponent is still reported."""
    s = attractor_set(PeelParams(V=2.0, I=1e-4), starts=[0.0], t_transient=0.5, t_window=0.5, workers=0,
                      lyapunov_T=1.0)
    a = s.attractors[0]
    assert a.lyapunov is not None and a.lyapunov >= 1.0 and a.lyapunov <= 3 * a.lyapunov_stderr  # the premise
    assert a.kind == a.label == "aperiodic" and "decides neither" in a.note


def test_closest_names_its_bad_arguments():
    """closest() with a min_share that is no number, fields that are no observables (a bare string, an empty tuple,
    an unknown name) or a NaN observable: a ValueError/TypeError naming the argument (they were float()'s bare
    message, AttributeError, max()'s "empty sequence" and a NaN distance).  The set is one 1 s window."""
    s = attractor_set(PeelParams(V=1.0, I=1e-5), starts=[0.0], t_transient=1.0, t_window=1.0, workers=0,
                      stability=False)
    obs = {"slip_interval": 0.08, "force_drop": 70.0}
    mine = s.attractors[0].observables
    expected = max(abs(mine.slip_interval - 0.08) / mine.slip_interval, abs(mine.force_drop - 70.0) / mine.force_drop)
    assert s.closest(obs)[1] == pytest.approx(expected, rel=1e-12)  # the documented distance, the same arithmetic
    bad = [({"min_share": "x"}, TypeError), ({"min_share": None}, TypeError), ({"fields": "slip_interval"}, TypeError),
           ({"fields": ()}, TypeError), ({"fields": ("bogus",)}, ValueError),
           ({"fields": ("period_label",)}, ValueError)]
    for kw, error in bad:
        with pytest.raises(error, match=next(iter(kw))):
            s.closest(obs, **kw)
    with pytest.raises(ValueError, match=r"observables\['slip_interval'\]"):
        s.closest({"slip_interval": float("nan"), "force_drop": 70.0})
    with pytest.raises(TypeError, match=r"observables\['force_drop'\]"):
        s.closest({"slip_interval": 0.08, "force_drop": "70"})


@settings(max_examples=8, deadline=None, derandomize=True)
@given(V=_V, I=_I, starts=st.lists(st.floats(-0.3, 0.3), min_size=1, max_size=3),
       t_transient=st.floats(0.0, 1.0), t_window=st.floats(0.1, 0.5))
def test_random_small_sets_are_consistent(V, I, starts, t_transient, t_window):
    """Seeded small sets over the plane (the windows' stability off: the cheapest set): a documented status;
    attractors numbered 0, 1, ... in the order of their first starts, the primary first; shares of the starts that
    ran summing to 1 where every run is read as an attractor or a breakdown; strict JSON; a finite table.  8
    examples, a few seconds."""
    s = attractor_set(PeelParams(V=V, I=I), starts=starts, t_transient=t_transient, t_window=t_window, workers=0,
                      stability=False, max_wall=30.0)
    assert s.status in ("ok", "transient only", "breakdown only", "max_wall", "no attractor"), s.message
    assert [a.id for a in s.attractors] == list(range(len(s.attractors)))
    first = [min(i for i, o in enumerate(s.outcomes) if o.attractor == a.id) for a in s.attractors]
    assert first == sorted(first)
    if s.outcomes[0].attractor is not None:
        assert s.primary is s.attractors[0]
    if all(o.outcome in ("attractor", "breakdown") for o in s.outcomes):
        assert sum(a.share for a in s.attractors) == pytest.approx(1.0, abs=1e-12)
    doc = json.loads(s.to_json())
    assert doc["status"] == s.status and len(doc["attractors"]) == len(s.attractors)
    for row in s.rows():
        assert all(not isinstance(v, float) or math.isfinite(v) for v in row.values())


@pytest.mark.slow
@settings(max_examples=25, deadline=None, derandomize=True)
@given(V=_V, I=_I, k=_K, law=st.sampled_from(("paper", "cubic", "power_branches")),
       starts=st.one_of(st.just("default"), st.lists(st.floats(-0.3, 0.3), min_size=1, max_size=3)),
       t_transient=st.floats(0.0, 2.0), t_window=st.floats(0.1, 1.0))
def test_random_sets_with_stability_within_their_budget(V, I, k, law, starts, t_transient, t_window):
    """The default-tier property (:func:`test_random_small_sets_are_consistent`) with the stability steps on
    (Newton orbits, exponents over 1 s), over the families and k, under a 5 s budget: the call returns within the
    budget and 5 s (a run checks the deadline between steps, Newton between iterations, an exponent between its
    renormalisations; a first compile is not interruptible, which the default tier's tests have done by then);
    multipliers and exponents finite; transients' escapes finite and after the transient.  A given α0 without a
    consistent state for the law (the cubic's f(0+) is higher) is the documented ValueError naming ``starts[i]``."""
    p = PeelParams(V=V, I=I, k=k, force=getattr(PeelForce, law)())
    t0 = time.perf_counter()
    try:
        s = attractor_set(p, starts=starts, t_transient=t_transient, t_window=t_window, workers=0, lyapunov_T=1.0,
                          max_wall=5.0)
    except ValueError as exc:  # a given start without a consistent state for this law: documented, named
        assert starts != "default" and str(exc).startswith("starts[")
        return
    assert time.perf_counter() - t0 < 10.0
    assert [a.id for a in s.attractors] == list(range(len(s.attractors)))
    for a in s.attractors:
        assert all(math.isfinite(abs(m)) for m in a.multipliers or ())
        assert a.lyapunov is None or math.isfinite(a.lyapunov)
    for o in s.transients:
        if o.escape is not None:
            assert math.isfinite(o.escape.returns) and o.escape.time >= s.t_transient
    json.loads(s.to_json())

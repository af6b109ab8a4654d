"""The option objects of ``exact.simulate``: Hybrid, Regularized, SaveAt, Budget.

Each is a frozen, keyword-only dataclass validated in ``__post_init__`` by the same named validators as the
``simulate`` keyword of the same name, so a bad field raises the same exception with the same message; a run
given the objects is the run given the keywords, bit for bit.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

import exact
from exact import Budget, Hybrid, Regularized, SaveAt, simulate
from peelapprox import PeelParams
from peelapprox.validate import ArgumentTypeError

P = PeelParams(V=1, I=1e-5)
NAN = math.nan

#: (object factory, simulate keyword arguments with the same bad value): the messages must be equal.
SAME_MESSAGE = [
    (lambda: Hybrid(rtol=NAN), dict(rtol=NAN)),
    (lambda: Hybrid(rtol=1.0), dict(rtol=1.0)),
    (lambda: Hybrid(rtol="1e-3"), dict(rtol="1e-3")),
    (lambda: Hybrid(rtol=True), dict(rtol=True)),
    (lambda: Hybrid(atol=-1), dict(atol=-1)),
    (lambda: Hybrid(atol=[1e-3] * 3), dict(atol=[1e-3] * 3)),
    (lambda: Hybrid(atol="x"), dict(atol="x")),
    (lambda: Hybrid(v_floor=0), dict(v_floor=0)),
    (lambda: Hybrid(v_floor="x"), dict(v_floor="x")),
    (lambda: Regularized(eps=1.0), dict(method="regularized", eps=1.0)),
    (lambda: Regularized(eps=NAN), dict(method="regularized", eps=NAN)),
    (lambda: Regularized(eps="x"), dict(method="regularized", eps="x")),
    (lambda: Regularized(solver="RK45"), dict(method="regularized", solver="RK45")),
    (lambda: Regularized(solver=3), dict(method="regularized", solver=3)),
    (lambda: Regularized(rtol=0), dict(method="regularized", rtol=0)),
    (lambda: Regularized(atol=2.0), dict(method="regularized", atol=2.0)),
    (lambda: Budget(max_points=0), dict(max_points=0)),
    (lambda: Budget(max_points=1.0), dict(max_points=1.0)),
    (lambda: Budget(max_jumps=10**16), dict(max_jumps=10**16)),
    (lambda: Budget(max_steps=0), dict(max_steps=0)),
    (lambda: Budget(max_steps=2.0), dict(max_steps=2.0)),
    (lambda: Budget(max_wall=0), dict(max_wall=0)),
    (lambda: Budget(max_wall=NAN), dict(max_wall=NAN)),
    (lambda: SaveAt(steps=True, t_transient=NAN), dict(t_transient=NAN)),
    (lambda: SaveAt(steps=True, t_transient="x"), dict(t_transient="x")),
]


def _raised(call):
    with pytest.raises((ValueError, TypeError)) as info:
        call()
    return info.value


@pytest.mark.parametrize("case", range(len(SAME_MESSAGE)))
def test_bad_field_raises_as_the_keyword(case):
    """Hypothesis: a bad field raises the exception of the ``simulate`` keyword of that name (same class);
    the message is the keyword's, word for word, except for the horizon-dependent ranges (t_transient's upper
    bound is TIME_MAX for the object, t_end for simulate): then the name and ``must be`` still match."""
    make, kw = SAME_MESSAGE[case]
    obj_exc, kw_exc = _raised(make), _raised(lambda: simulate(P, 0.01, **kw))
    assert type(obj_exc) is type(kw_exc)
    name = next(k for k in kw if k != "method")
    if name == "t_transient":
        assert str(obj_exc).startswith(f"{name} must be") and "[0, 1e6]" in str(obj_exc), str(obj_exc)
        assert str(kw_exc).startswith(f"{name} must be") and "[0, 0.01]" in str(kw_exc), str(kw_exc)
    else:
        assert str(obj_exc) == str(kw_exc)
        assert name in str(obj_exc)


def test_saveat_times_checked_like_t_eval():
    """Hypothesis: ``SaveAt(ts=...)`` refuses what ``t_eval=`` refuses (empty, unsorted, non-finite, before
    t_transient, a string), with the same exception class and its own field name; times beyond ``t_end``
    are refused by ``simulate`` naming ``t_transient``/``ts`` and the range ``[t_transient, t_end]``."""
    for bad in ([], [0.02, 0.01], [NAN], [-1.0], "x"):
        obj_exc, kw_exc = _raised(lambda b=bad: SaveAt(ts=b)), _raised(lambda b=bad: simulate(P, 0.03, t_eval=b))
        assert type(obj_exc) is type(kw_exc), (bad, obj_exc, kw_exc)
        assert str(obj_exc).startswith("ts must be") and str(kw_exc).startswith("t_eval must be")
    exc = _raised(lambda: SaveAt(ts=[0.1, 0.2], t_transient=0.15))
    assert "ts must be finite and in [0.15, 1e6]" in str(exc)
    exc = _raised(lambda: simulate(P, 0.01, saveat=SaveAt(ts=[0.005, 0.02])))
    assert isinstance(exc, ValueError) and "ts must be finite and in [0, 0.01]" in str(exc)
    exc = _raised(lambda: simulate(P, 0.01, saveat=SaveAt(jumps_only=True, t_transient=0.5)))
    assert isinstance(exc, ValueError) and "t_transient must be finite and in [0, 0.01], got 0.5" in str(exc)
    exc = _raised(lambda: simulate(P, 0.01, saveat=SaveAt(ts=np.linspace(0, 0.01, 11)), budget=Budget(max_points=10)))
    assert str(exc) == "saveat.ts has 11 points, more than max_points=10"


def test_saveat_needs_exactly_one_choice():
    """Hypothesis: a SaveAt stores steps, times or jumps only, never none or two (ValueError naming the
    three); flags are bools (``steps=1`` is an ArgumentTypeError naming ``steps``)."""
    for kw in ({}, dict(steps=True, jumps_only=True), dict(steps=True, ts=[0.0]), dict(ts=[0.0], jumps_only=True)):
        with pytest.raises(ValueError, match="exactly one of steps=True, ts=.* or jumps_only=True"):
            SaveAt(**kw)
    with pytest.raises(ArgumentTypeError, match="steps must be True or False, got 1"):
        SaveAt(steps=1)


@pytest.mark.parametrize("make", [
    lambda: Hybrid(rtol=1e-6, atol=1e-9, v_floor=1e-3),
    lambda: Regularized(eps=1e-4, solver="BDF", atol=[1e-6, 1e-5, 1e-4, 1e-8]),
    lambda: SaveAt(ts=[0.0, 0.5, 1.0], t_transient=0.0),
    lambda: SaveAt(jumps_only=True, t_transient=2.0),
    lambda: Budget(max_steps=10, max_jumps=3, max_points=7, max_wall=1.5),
])
def test_frozen_hashable_equal_by_value(make):
    """Hypothesis: two objects built from equal fields are equal with equal hashes (exact equality: the
    fields are normalised floats, ints, strings, tuples and a read-only float array), every field is read-only,
    keyword-only construction is enforced, and the repr names the class."""
    a, b = make(), make()
    assert a == b and hash(a) == hash(b) and len({a, b}) == 1
    field = dataclasses.fields(a)[0].name
    with pytest.raises(dataclasses.FrozenInstanceError):
        setattr(a, field, getattr(a, field))
    with pytest.raises(TypeError):
        type(a)(getattr(a, field))  # positional
    assert repr(a).startswith(type(a).__name__ + "(")
    if isinstance(a, SaveAt) and a.ts is not None:
        with pytest.raises(ValueError):
            a.ts[0] = 1.0


def test_normalised_fields():
    """Hypothesis: fields are stored in one canonical form (rtol a float, atol a 4-tuple of floats), so
    equivalent spellings are equal (exact comparisons), and the default atol is rtol * ATOL_SCALE[method]."""
    assert Hybrid(rtol=np.float64(1e-6)) == Hybrid(rtol=1e-6)
    assert Hybrid(atol=1e-9) == Hybrid(atol=[1e-9] * 4) and Hybrid(atol=1e-9).atol == (1e-9,) * 4
    assert Hybrid() != Regularized()
    np.testing.assert_array_equal(Regularized(rtol=1e-6).atol_vector(),
                                  1e-6 * np.asarray(exact.ATOL_SCALE["regularized"]))
    assert SaveAt(ts=(0, 1)) == SaveAt(ts=np.array([0.0, 1.0]))
    assert SaveAt(ts=(0, 1)) != SaveAt(ts=(0, 2)) and SaveAt(steps=True) != SaveAt(steps=True, t_transient=1.0)


def test_budget_resolved():
    """Hypothesis: ``resolved`` fills only ``max_steps=None``, with default_max_steps (exact integers)."""
    assert Budget().resolved("hybrid", 3.0).max_steps == 3_000_000
    assert Budget().resolved("regularized", 1e6).max_steps == 500_000
    b = Budget(max_steps=17)
    assert b.resolved("hybrid", 3.0) is b


def _same_run(a, b):
    for k in ("t", "alpha", "omega", "F", "v", "branch", "atol"):
        assert np.array_equal(getattr(a, k), getattr(b, k)), k
    for k in ("t", "from_branch", "to_branch", "alpha", "omega", "F", "v_before", "v_after"):
        assert np.array_equal(getattr(a.jumps, k), getattr(b.jumps, k)), k
    assert (a.method, a.solver, a.rtol, a.eps, a.t_transient, a.final_state) == \
           (b.method, b.solver, b.rtol, b.eps, b.t_transient, b.final_state)
    assert (a.stats.n_steps, a.stats.n_rhs, a.stats.n_jumps) == (b.stats.n_steps, b.stats.n_rhs, b.stats.n_jumps)


def test_regularized_object_is_the_keywords_bitwise():
    """Hypothesis: ``method=Regularized(eps=1e-4)`` is ``method="regularized", eps=1e-4`` -- the same
    arguments reach the same driver, so every array is equal bit for bit (numpy.array_equal, tolerance 0)."""
    _same_run(simulate(P, 0.02, method=Regularized(eps=1e-4)), simulate(P, 0.02, method="regularized", eps=1e-4))


def test_hybrid_objects_are_the_keywords_bitwise():
    """Hypothesis: Hybrid/SaveAt/Budget objects give the runs of the keywords they stand for, bit for bit
    (tolerance 0), for each of the three save modes, a transient, a non-default atol and a v_floor."""
    p = PeelParams(V=1, I=1e-2)
    _same_run(simulate(p, 1.0, method=Hybrid(rtol=1e-6, atol=1e-9, v_floor=1e-30)),
              simulate(p, 1.0, rtol=1e-6, atol=1e-9, v_floor=1e-30))
    ts = np.linspace(0.5, 1.0, 11)
    _same_run(simulate(p, 1.0, saveat=SaveAt(ts=ts, t_transient=0.5), budget=Budget(max_points=11)),
              simulate(p, 1.0, t_eval=ts, t_transient=0.5, max_points=11))
    _same_run(simulate(p, 1.0, saveat=SaveAt(jumps_only=True, t_transient=0.3)),
              simulate(p, 1.0, save="jumps", t_transient=0.3))
    _same_run(simulate(p, 1.0, saveat=SaveAt(steps=True), budget=Budget(max_wall=100.0)),
              simulate(p, 1.0, max_wall=100.0))


def test_budget_object_raises_as_the_keyword():
    """Hypothesis: a Budget's limit stops the run as the keyword does (SolverBudgetExceeded naming it, the
    same partial trajectory: exact equality of the step count)."""
    with pytest.raises(exact.SolverBudgetExceeded) as a:
        simulate(P, 0.01, budget=Budget(max_steps=5))
    with pytest.raises(exact.SolverBudgetExceeded) as b:
        simulate(P, 0.01, max_steps=5)
    assert a.value.budget == b.value.budget == "max_steps"
    assert a.value.partial.stats.n_steps == b.value.partial.stats.n_steps


@pytest.mark.parametrize("kw, names", [
    (dict(method=Regularized(), eps=1e-4), ("eps", "method")),
    (dict(method=Regularized(), solver="BDF"), ("solver", "method")),
    (dict(method=Hybrid(), rtol=1e-6), ("rtol", "method")),
    (dict(method=Hybrid(), atol=1e-9), ("atol", "method")),
    (dict(method=Hybrid(), v_floor=1e-3), ("v_floor", "method")),
    (dict(method=Hybrid(), solver="Radau"), ("solver", "method")),
    (dict(saveat=SaveAt(steps=True), t_eval=[0.0]), ("t_eval", "saveat")),
    (dict(saveat=SaveAt(steps=True), save="jumps"), ("save", "saveat")),
    (dict(saveat=SaveAt(steps=True), t_transient=0.001), ("t_transient", "saveat")),
    (dict(budget=Budget(), max_steps=10), ("max_steps", "budget")),
    (dict(budget=Budget(), max_points=10), ("max_points", "budget")),
    (dict(budget=Budget(), max_jumps=10), ("max_jumps", "budget")),
    (dict(budget=Budget(), max_wall=1.0), ("max_wall", "budget")),
])
def test_mixing_an_object_and_its_keywords_is_refused(kw, names):
    """Hypothesis: a keyword that an option object also holds, given at a non-default value together with
    the object, is a ValueError naming both (nothing is silently overridden)."""
    with pytest.raises(ValueError) as info:
        simulate(P, 0.01, **kw)
    assert all(n in str(info.value) for n in names), str(info.value)


def test_keywords_at_their_defaults_mix_freely():
    """Hypothesis: keywords left at (or spelled as) their defaults do not conflict with an object: the run is
    the object's (exact equality of the stored times)."""
    a = simulate(P, 0.01, method=Hybrid(rtol=1e-6), rtol=1e-8, save="steps", t_transient=0,
                 saveat=SaveAt(jumps_only=True), budget=Budget(max_wall=50.0), max_points=5_000_000)
    assert a.rtol == 1e-6 and a.t.size == 0


def test_signature_defaults_are_the_field_defaults():
    """Hypothesis: each simulate keyword an object stands for has the object's field default (exact
    equality), except those whose simulate default is None and filled in later (solver, eps) and ``save``, so
    that "a keyword at its default counts as not given" means the same run either way."""
    import inspect

    sig = inspect.signature(simulate).parameters
    for cls in (Hybrid, Regularized, SaveAt, Budget):
        for f in dataclasses.fields(cls):
            if f.name in sig:
                expected = None if f.name in ("solver", "eps") else f.default
                assert sig[f.name].default == expected, (cls.__name__, f.name)
    assert sig["save"].default == "steps" and sig["t_eval"].default is None


def test_wrong_object_types():
    """Hypothesis: ``saveat``/``budget`` of another type is a TypeError naming the keyword; a method that is
    neither a string nor a method object keeps the ``method`` keyword's error."""
    with pytest.raises(TypeError, match="saveat must be a SaveAt or None, got str"):
        simulate(P, 0.01, saveat="steps")
    with pytest.raises(TypeError, match="budget must be a Budget or None, got dict"):
        simulate(P, 0.01, budget={})
    with pytest.raises(ArgumentTypeError, match=r"method must be one of \('hybrid', 'regularized', 'smooth'\)"):
        simulate(P, 0.01, method=SaveAt(steps=True))

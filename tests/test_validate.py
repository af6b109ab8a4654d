"""The named argument validators (peelapprox.validate) and reproducers of bad arguments once accepted.

Every bad argument must end in a ``ValueError`` or ``TypeError`` whose message names the argument, never in
ZeroDivisionError, OverflowError, AttributeError, a numba error or a NaN result.
"""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import peelapprox as pa
from peelapprox import PARAM_RANGES, PeelParams
from peelapprox import validate as v

NOT_NUMBERS = [None, "abc", "1.0", True, False, np.bool_(True), [1.0], np.array([1.0, 2.0]), 1 + 2j, object()]


# ---------------------------------------------------------------------------------------------- validators
@pytest.mark.parametrize("x", NOT_NUMBERS)
def test_not_a_number_is_a_type_error_naming_the_argument(x):
    """Hypothesis: None, strings, bools, sequences and complex numbers are not real numbers: every scalar
    validator raises ArgumentTypeError (a TypeError and a ValueError) with the argument's name and range."""
    for check in (v.finite, v.positive, v.nonnegative, lambda n, y: v.in_range(n, y, 0.0, 1.0)):
        with pytest.raises(TypeError, match=r"^alpha0 must be a real number in ") as exc:
            check("alpha0", x)
        assert isinstance(exc.value, ValueError)


@pytest.mark.parametrize(
    "args, kw, text",
    [
        (("rtol", math.nan, 1e-14, 1e-2), {}, "rtol must be finite and in [1e-14, 0.01], got nan"),
        (("rtol", 0.5, 1e-14, 1e-2), {}, "rtol must be finite and in [1e-14, 0.01], got 0.5"),
        (("x", 0.0, 0.0, 1.0), dict(lo_open=True), "x must be finite and in (0, 1], got 0.0"),
        (("x", 1.0, 0.0, 1.0), dict(hi_open=True), "x must be finite and in [0, 1), got 1.0"),
        (("x", math.inf), {}, "x must be finite and in (-inf, inf), got inf"),
        (("x", 10**400), {}, "x must be finite and in (-inf, inf), got 1000"),
    ],
)
def test_in_range_rejects_with_the_range_in_the_message(args, kw, text):
    """Hypothesis: a real number outside its range (NaN, inf, an excluded bound) is a ValueError reading
    "<name> must be finite and in <range>, got <value>", the bracket showing open or closed ends."""
    with pytest.raises(ValueError) as exc:
        v.in_range(*args, **kw)
    assert not isinstance(exc.value, TypeError)
    assert str(exc.value).startswith(text)


def test_in_range_accepts_numpy_scalars_and_bounds():
    """Hypothesis: numpy and 0-d real values and the closed bounds themselves are accepted, as floats."""
    assert v.in_range("x", np.float32(0.5), 0.0, 1.0) == 0.5
    assert v.in_range("x", np.array(1.0), 0.0, 1.0) == 1.0
    assert v.in_range("x", np.int64(0), 0.0, 1.0) == 0.0
    assert type(v.positive("x", 3)) is float and v.positive("x", 3) == 3.0


@pytest.mark.parametrize("x, kind", [(100.0, TypeError), (1.5, TypeError), (math.inf, TypeError), (True, TypeError),
                                     ("7", TypeError), (None, TypeError), (0, ValueError), (-3, ValueError),
                                     (10**16, ValueError)])
def test_integer_rejects_floats_bools_and_out_of_range(x, kind):
    """Hypothesis: counts are ints (floats — integral ones too — bools and strings are TypeErrors) in
    [lo, MAX_COUNT]; the message names the argument and the range."""
    with pytest.raises(kind, match=r"^max_points must be an integer in \[1, 1e15\], got "):
        v.integer("max_points", x)


def test_integer_accepts_ints_and_numpy_ints():
    """Hypothesis: Python and numpy integers inside the range come back as int."""
    assert v.integer("n", np.int32(5)) == 5 and type(v.integer("n", np.int64(5))) is int
    assert v.integer("n", 0, lo=0) == 0 and v.integer("n", v.MAX_COUNT) == v.MAX_COUNT


def test_integral_float_hint():
    """Hypothesis: an integral float is refused with the integer to write instead."""
    with pytest.raises(TypeError, match="write 100 for a whole number"):
        v.integer("max_points", 100.0)


def test_choice():
    """Hypothesis: a choice returns the matching element; a wrong value is a ValueError and a wrong kind
    (None, a number for a string, a bool or float for an integer) an ArgumentTypeError, both listing the
    choices."""
    assert v.choice("branch", "CD", ("AB", "CD")) == "CD"
    assert v.choice("order", np.int64(2), (0, 1, 2)) == 2
    with pytest.raises(ValueError, match=r"branch must be one of \('AB', 'CD'\), got 'XY'") as exc:
        v.choice("branch", "XY", ("AB", "CD"))
    assert not isinstance(exc.value, TypeError)
    for bad in (None, 1, True):
        with pytest.raises(TypeError, match="branch must be one of"):
            v.choice("branch", bad, ("AB", "CD"))
    for bad in (True, 1.0):
        with pytest.raises(TypeError, match="order must be one of"):
            v.choice("order", bad, (0, 1, 2))


def test_flag_function_params():
    """Hypothesis: flags are bools only, functions are callables, params are PeelParams: anything else is an
    ArgumentTypeError naming the argument."""
    assert v.flag("linear", np.bool_(True)) is True
    for bad in (0, 1, "yes", None):
        with pytest.raises(TypeError, match="^linear must be True or False"):
            v.flag("linear", bad)
    assert v.function("fprime", abs) is abs
    with pytest.raises(TypeError, match="^fprime must be callable"):
        v.function("fprime", 3.0)
    p = PeelParams(V=1.0, I=1e-5)
    assert v.params("params", p) is p
    for bad in (None, {"V": 1.0, "I": 1e-5}, "p"):
        with pytest.raises(TypeError, match="^params must be a PeelParams"):
            v.params("params", bad)


def test_reals_and_times():
    """Hypothesis: arrays are checked element by element (the first offender shown); times are non-empty,
    1-D, in range and strictly increasing (the first non-increasing pair named)."""
    np.testing.assert_array_equal(v.reals("F", [1, 2]), [1.0, 2.0])
    with pytest.raises(ValueError, match=r"^F must be finite and in \(0, inf\) \(every element\), got -1.0"):
        v.reals("F", [1.0, -1.0, math.nan], 0.0, lo_open=True)
    for bad in (["a"], [True, False], None, "1,2"):
        with pytest.raises(TypeError, match="^F must be an array of real numbers"):
            v.reals("F", bad)
    np.testing.assert_array_equal(v.times("t_eval", (0.0, 0.5, 2.0)), [0.0, 0.5, 2.0])
    with pytest.raises(ValueError, match=r"t_eval must be strictly increasing, got t_eval\[1\] = 2.0 >= t_eval\[2\]"):
        v.times("t_eval", [0.0, 2.0, 1.0])
    with pytest.raises(ValueError, match="t_eval must be a non-empty array"):
        v.times("t_eval", [])
    with pytest.raises(ValueError, match=r"t_eval must be a 1-D array"):
        v.times("t_eval", [[0.0, 1.0]])
    with pytest.raises(ValueError, match=r"t_eval must be finite and in \[0, inf\)"):
        v.times("t_eval", [-1.0, 0.0])


def test_state_and_duration_ranges():
    """Hypothesis: state variables use STATE_RANGES (v open at 0) and durations (0, TIME_MAX]."""
    assert v.state("F0", 250, "F") == 250.0
    with pytest.raises(ValueError, match=r"^F0 must be finite and in \[0.001, 1e7\], got 1e\+300"):
        v.state("F0", 1e300, "F")
    with pytest.raises(ValueError, match=r"^v_in must be finite and in \(1e-150, 1000\], got 0.0"):
        v.state("v_in", 0.0, "v")
    assert v.duration("t_transient", 0, zero=True) == 0.0
    with pytest.raises(ValueError, match=r"^window must be finite and in \(0, 1e6\], got 1e\+300"):
        v.duration("window", 1e300)


# ---------------------------------------------------------------------------------------------- PeelParams
def test_param_ranges_edges_are_usable():
    """Hypothesis: every corner of PARAM_RANGES is accepted and gives a finite regime estimate (no overflow
    at the bounds chosen; measurements behind them in the PeelParams docstring)."""
    for name, (lo, hi) in PARAM_RANGES.items():
        for x in (lo, hi):
            kw = dict(V=2.0, I=1e-4)
            kw[name] = x
            if name == "l":
                kw["R"] = min(0.1, x / 1.001)
            if name == "R":
                kw["l"] = max(1.0, 1.01 * x)
            e = pa.estimate(PeelParams(**kw))
            assert math.isfinite(e.fixed_point_F) and e.fixed_point_F > 0


def test_l_must_clear_R_by_the_margin():
    """Hypothesis: l < 1.001 R is refused (the exact closure degenerates), naming l and R."""
    with pytest.raises(ValueError, match=r"l must be greater than R.*\[1.001 R, 1000\]"):
        PeelParams(V=1.0, I=1e-5, R=0.1, l=0.1 * (1 + 1e-6))
    assert PeelParams(V=1.0, I=1e-5, R=0.1, l=0.1001).l == 0.1001


# ---------------------------------------------------------------------------------------------- reproducers
P = PeelParams(V=1.0, I=1e-5)
SEG = dict(F_in=250.0, alpha_in=0.01, alphadot_in=0.0)

#: (label, call, argument name, exception type): the item-6 reproducers (except exact.simulate's) and
#: the further cases found by trying each public function with None, 'abc', True, nan, inf, -1, 0,
#: 1e300, 1e-300 (integers also 100.0 and inf).  Before: the error in the label.
REPRODUCERS = [
    ("PeelParams V=1e300 (accepted, then OverflowError)", lambda: PeelParams(V=1e300, I=1e-5), "V", ValueError),
    ("PeelParams k=1e300 (ZeroDivisionError in simulate)", lambda: PeelParams(V=1, I=1e-5, k=1e300), "k", ValueError),
    ("PeelParams R=1e-300 (ZeroDivisionError in simulate)", lambda: PeelParams(V=1, I=1e-5, R=1e-300), "R",
     ValueError),
    ("PeelParams V='abc'", lambda: PeelParams(V="abc", I=1e-5), "V", TypeError),
    ("PeelParams I=True (accepted as 1)", lambda: PeelParams(V=1, I=True), "I", TypeError),
    ("PeelParams geometry=None", lambda: PeelParams(V=1, I=1e-5, geometry=None), "geometry", TypeError),
    ("branch_structure V=1e300 (OverflowError)", lambda: pa.branch_structure(1e300), "V", ValueError),
    ("branch_structure V=None (TypeError without name)", lambda: pa.branch_structure(None), "V", TypeError),
    ("peel_force V='abc'", lambda: pa.peel_force(0.5, "abc"), "V", TypeError),
    ("peel_force_derivative order=0.0 (tuple index TypeError)", lambda: pa.peel_force_derivative(0.5, 1.0, 0.0),
     "order", TypeError),
    ("fixed_point R=0 (ZeroDivisionError)", lambda: pa.fixed_point(1.0, 0.0), "R", ValueError),
    ("fixed_point R=nan (NaN omega)", lambda: pa.fixed_point(1.0, math.nan), "R", ValueError),
    ("branch_inverse G='abc'", lambda: pa.branch_inverse("abc", 1.0, "AB"), "G", TypeError),
    ("estimate params=None", lambda: pa.estimate(None), "params", TypeError),
    ("estimate alpha_min='abc'", lambda: pa.estimate(P, alpha_min="abc", alpha_max=0.1), "alpha_min", TypeError),
    ("crude_branch_time params=None (AttributeError)", lambda: pa.crude_branch_time(None), "params", TypeError),
    ("quasi_static_branch_time fprime=1.0", lambda: pa.quasi_static_branch_time(P, fprime=1.0), "fprime",
     TypeError),
    ("force_bounds alpha_min=None", lambda: pa.force_bounds(P, None, 0.1), "alpha_min", TypeError),
    ("force_bounds linear=1", lambda: pa.force_bounds(P, -0.1, 0.1, linear=1), "linear", TypeError),
    ("slope_criterion F_in=-1 (message named F)", lambda: pa.slope_criterion(P, F_in=-1.0, alphadot_in=5.0,
                                                                             alpha0=0.1), "F_in", ValueError),
    ("slope_criterion alphadot_in=nan (NaN ratio)", lambda: pa.slope_criterion(P, F_in=200.0, alphadot_in=math.nan,
                                                                               alpha0=0.1), "alphadot_in",
     ValueError),
    ("inertial_frequency params=None (AttributeError)", lambda: pa.inertial_frequency(None, 200.0), "params",
     TypeError),
    ("inertial_frequency F='abc'", lambda: pa.inertial_frequency(P, "abc"), "F", TypeError),
    ("harmonic_alpha params=1.0", lambda: pa.harmonic_alpha(1.0, [0.0], F=200.0, alpha_in=0.1, alphadot_in=0.0),
     "params", TypeError),
    ("airy_alpha F_rate=1e-300 (NaN)", lambda: pa.airy_alpha(P, [0.0, 0.01], F_in=200.0, alpha_in=0.1,
                                                             alphadot_in=0.0, F_rate=1e-300), "F_rate", ValueError),
    ("airy_alpha t=1e300 (NaN)", lambda: pa.airy_alpha(P, 1e300, F_in=200.0, alpha_in=0.1, alphadot_in=0.0), "t",
     ValueError),
    ("wkb_error_bound F_in=1e-300 (OverflowError)", lambda: pa.wkb_error_bound(P, [0.01], F_in=1e-300, alpha_in=0.1,
                                                                               alphadot_in=0.0), "F_in", ValueError),
    ("alpha_numerical atol=0 (hung)", lambda: pa.alpha_numerical(P, [0.01], F_in=200.0, alpha_in=0.1,
                                                                 alphadot_in=0.0, atol=0.0), "atol", ValueError),
    ("alpha_numerical rtol=None", lambda: pa.alpha_numerical(P, [0.01], F_in=200.0, alpha_in=0.1, alphadot_in=0.0,
                                                             rtol=None), "rtol", TypeError),
    ("cd_damping_time F=None (blamed v)", lambda: pa.cd_damping_time(P, None, 20.0), "F", TypeError),
    ("cd_decay_alpha alpha_in='abc' (blamed v)", lambda: pa.cd_decay_alpha(P, [0.0], F_in=200.0, alpha_in="abc",
                                                                           v_in=20.0), "alpha_in", TypeError),
    ("reduced_segment F_in=1e300 (ZeroDivisionError)", lambda: pa.reduced_segment(P, "AB", **{**SEG, "F_in": 1e300}),
     "F_in", ValueError),
    ("reduced_segment F_in=1e-300 (ZeroDivisionError)",
     lambda: pa.reduced_segment(P, "AB", **{**SEG, "F_in": 1e-300}), "F_in", ValueError),
    ("reduced_segment alphadot_in=1e300 (ZeroDivisionError)",
     lambda: pa.reduced_segment(P, "AB", **{**SEG, "alphadot_in": 1e300}), "alphadot_in", ValueError),
    ("reduced_segment atol=1e-300 (ZeroDivisionError)", lambda: pa.reduced_segment(P, "AB", **SEG, atol=1e-300),
     "atol", ValueError),
    ("reduced_segment max_steps=inf (OverflowError)", lambda: pa.reduced_segment(P, "AB", **SEG, max_steps=math.inf),
     "max_steps", TypeError),
    ("reduced_segment max_steps=10**30 (OverflowError)",
     lambda: pa.reduced_segment(P, "AB", **SEG, max_steps=10**30), "max_steps", ValueError),
    ("reduced_segment max_steps=100.0", lambda: pa.reduced_segment(P, "AB", **SEG, max_steps=100.0), "max_steps",
     TypeError),
    ("reduced_segment rtol=None", lambda: pa.reduced_segment(P, "AB", **SEG, rtol=None), "rtol", TypeError),
    ("reduced_segment params=None", lambda: pa.reduced_segment(None, "AB", **SEG), "params", TypeError),
    ("reduced_segment t_eval='abc'", lambda: pa.reduced_segment(P, "AB", **SEG, t_eval="abc"), "t_eval", TypeError),
    ("periodicity x='abc'", lambda: pa.periodicity("abc"), "x", TypeError),
    ("periodicity max_period=32.0", lambda: pa.periodicity([1.0, 2.0] * 40, max_period=32.0), "max_period",
     TypeError),
    ("return_map trajectory=None (AttributeError)", lambda: pa.return_map(None), "trajectory", TypeError),
    ("force_drops trajectory=1.0 (AttributeError)", lambda: pa.force_drops(1.0), "trajectory", TypeError),
    ("lyapunov params=None (AttributeError)", lambda: pa.lyapunov(None), "params", TypeError),
    ("lyapunov tau=1e300 (unbounded)", lambda: pa.lyapunov(P, tau=1e300), "tau", ValueError),
    ("lyapunov t_transient=-1", lambda: pa.lyapunov(P, t_transient=-1.0), "t_transient", ValueError),
    ("lyapunov n=inf", lambda: pa.lyapunov(P, n=math.inf), "n", TypeError),
    ("lyapunov_tangent T=1e300 (numba TypingError)", lambda: pa.lyapunov_tangent(P, T=1e300), "T", ValueError),
    ("lyapunov_tangent max_steps=1e6", lambda: pa.lyapunov_tangent(P, max_steps=1e6), "max_steps", TypeError),
    ("lyapunov_return_map n_returns=True", lambda: pa.lyapunov_return_map(P, n_returns=True), "n_returns",
     TypeError),
    ("attractors window=1e300 (unbounded)", lambda: pa.attractors(P, window=1e300), "window", ValueError),
    ("attractors alpha0s=['abc'] (taken for an infeasible start)", lambda: pa.attractors(P, alpha0s=["abc"]),
     "alpha0s", TypeError),
    ("attractors progress=3", lambda: pa.attractors(P, progress=3), "progress", TypeError),
    ("benettin n=2.5", lambda: pa.benettin(lambda a, b: (a, b, 1.0), 0.0, 1.0, lambda a, b: 1.0,
                                           lambda a, b, f: b, 2.5), "n", TypeError),
]


@pytest.mark.parametrize("label, call, name, kind", REPRODUCERS, ids=[r[0] for r in REPRODUCERS])
def test_reproducer_raises_an_error_naming_the_argument(label, call, name, kind):
    """Hypothesis: each reproducer (its former failure in the label) now raises the stated kind of error,
    before any integration, with the argument's name at the start of the message."""
    with pytest.raises(kind) as exc:
        call()
    assert isinstance(exc.value, ValueError)  # ArgumentTypeError is both
    assert str(exc.value).startswith(name + " "), str(exc.value)


def test_lyapunov_variational_eps_1e_300_names_eps():
    """Hypothesis: eps=1e-300 (the regularised rates overflow) is refused by lyapunov_variational with a
    message naming eps and EPS_RANGE, before pydiffsol is needed."""
    from exact import lyapunov_variational

    with pytest.raises(ValueError, match=r"^eps must be finite and in \[1e-15, 0.01\], got 1e-300"):
        lyapunov_variational(P, eps=1e-300)
    with pytest.raises(TypeError, match="^params must be a PeelParams"):
        lyapunov_variational(None)


# ---------------------------------------------------------------------------------------------- fuzz
ANY = st.one_of(
    st.none(), st.booleans(), st.text(max_size=3),
    st.floats(allow_nan=True, allow_infinity=True),
    st.floats(min_value=-1e3, max_value=1e3),
    st.sampled_from([0.0, -1.0, 1e-300, 1e300, 1e-3, 1e7, 0.5]),
)
FIELDS = ("V", "I", "k", "R", "l")


def _finite_numbers(obj) -> bool:
    """All float fields and arrays of a result are finite (None and strings allowed)."""
    vals = obj.__dict__.values() if hasattr(obj, "__dict__") else [obj]
    for x in vals:
        if isinstance(x, (float, np.floating, np.ndarray)) and not np.all(np.isfinite(x)):
            return False
    return True


def _ok_or_named(fn, names):
    """Run fn; a result must be all finite, an exception a ValueError/TypeError naming one of ``names``
    (or a documented model exception)."""
    try:
        res = fn()
    except (pa.ModelBreakdown, pa.SolverBudgetExceeded, pa.SolverFailure) as exc:
        assert exc.t is None or math.isfinite(exc.t)
        return None
    except (ValueError, TypeError) as exc:
        msg = str(exc)
        assert any(n in msg for n in names), msg
        return None
    assert _finite_numbers(res)
    return res


@settings(max_examples=120, deadline=None, derandomize=True)
@given(field=st.sampled_from(FIELDS), value=ANY, V=st.floats(0.05, 8.0), logI=st.floats(-8, 0))
def test_fuzz_peelparams_and_estimate(field, value, V, logI):
    """Hypothesis: PeelParams with one field set to anything either builds (then estimate returns, with every
    number finite: the ranges leave nothing to overflow) or raises ValueError/TypeError naming that field."""
    kw = dict(V=V, I=10.0**logI)
    kw[field] = value
    try:
        p = PeelParams(**kw)
    except (ValueError, TypeError) as exc:
        assert str(exc).startswith(field + " "), str(exc)
        return
    e = pa.estimate(p)
    assert _finite_numbers(e) and math.isfinite(e.fixed_point_F)


SEG_ARGS = ("F_in", "alpha_in", "alphadot_in", "v_in", "v_f", "F_rate", "rtol", "atol", "t_max", "max_steps")


@settings(max_examples=80, deadline=None, derandomize=True)
@given(arg=st.sampled_from(SEG_ARGS), value=ANY, branch=st.sampled_from(["AB", "CD"]),
       model=st.sampled_from(["approxalpha", "sinusoid", "static", "exponential"]))
def test_fuzz_reduced_segment(arg, value, branch, model):
    """Hypothesis: reduced_segment with one argument set to anything returns a segment with finite Δt and
    state, raises a documented model exception with a finite time, or raises ValueError/TypeError naming that
    argument (or, for a value that is valid by itself, another argument it conflicts with: the branch's
    velocity range, the alpha inputs)."""
    kw = dict(F_in=250.0, alpha_in=0.01, alphadot_in=0.0, alpha_model=model, max_steps=20000)
    kw[arg] = value
    res = _ok_or_named(lambda: pa.reduced_segment(P, branch, **kw), (arg, "v_in", "v_f", "F = F_in"))
    if res is not None:
        assert math.isfinite(res.dt) and res.dt >= 0 and math.isfinite(res.F_exit)


def test_interval_text_is_remembered_per_sign_and_type():
    """The range text of the validators' messages is cached (peelapprox/_checks.py): a cached ``0.0`` must not
    serve ``-0.0``, nor an int bound a float one, and an open/closed end must stay as asked (exact strings)."""
    from peelapprox._checks import interval

    assert interval(0.0, 1.0) == "[0, 1]" and interval(0.0, 1.0) == "[0, 1]"
    assert interval(-0.0, 1.0) == "[-0, 1]"
    assert interval(0.0, 1.0, lo_open=True) == "(0, 1]"
    assert interval(1, 2) == "[1, 2]" and interval(1.5, 2) == "[1.5, 2]"
    assert interval(0.0, math.inf) == "[0, inf)"

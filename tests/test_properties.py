"""Property-based tests (hypothesis): the peel force's branch inverses and folds.

Each property is a statement of the model that must hold for every input in the stated range; hypothesis
searches for a counterexample (examples are capped so the default tier stays fast; the searches are
deterministic: ``derandomize=True``).
"""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

from peelapprox import branch_inverse, branch_structure, peel_force, peel_force_derivative

Vs = st.floats(0.1, 5.0)
FAST = settings(max_examples=60, deadline=None, derandomize=True)


@FAST
@given(V=Vs, u=st.floats(1e-4, 1 - 1e-6))
def test_ab_inverse_round_trips(V, u):
    """For any v on AB, ``branch_inverse(f(v, V), V, "AB")`` returns v.  Tolerance 1e-9 relative in v: the
    inverse is solved to rounding in f, and dv = df/f' with f' bounded away from 0 at u <= 1 - 1e-6."""
    bs = branch_structure(V)
    v = u * bs.v_max
    back = float(branch_inverse(float(peel_force(v, V)), V, "AB"))
    assert abs(back - v) <= 1e-9 * v + 1e-12


@FAST
@given(V=Vs, w=st.floats(1e-6, 5.0))
def test_cd_inverse_round_trips(V, w):
    """For any v on CD (v = v_min (1 + w)), the CD inverse returns v to 1e-9 relative (same argument)."""
    bs = branch_structure(V)
    v = bs.v_min * (1 + w)
    back = float(branch_inverse(float(peel_force(v, V)), V, "CD"))
    assert abs(back - v) <= 1e-9 * v


@FAST
@given(V=Vs)
def test_folds_are_sign_changes_of_the_slope(V):
    """The folds are where f' changes sign: f' > 0 just below v_max, < 0 just above it, < 0 just below v_min
    and > 0 just above it (at ±1e-6 relative: the folds are located to 4 ulp, far inside that)."""
    bs = branch_structure(V)
    d = lambda v: float(peel_force_derivative(v, V))  # noqa: E731
    assert d(bs.v_max * (1 - 1e-6)) > 0 > d(bs.v_max * (1 + 1e-6))
    assert d(bs.v_min * (1 - 1e-6)) < 0 < d(bs.v_min * (1 + 1e-6))

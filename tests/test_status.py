"""The one status table of the compiled drivers (each status code defined once)."""

from __future__ import annotations

import pytest

from peelapprox import _status as S
from peelapprox.errors import ModelBreakdown, SolverBudgetExceeded, SolverFailure


def test_drivers_use_the_table_codes():
    """Hypothesis: the hybrid, segment and tangent drivers share the table's integer codes (identity of the
    values each driver module imported; two numberings existed before)."""
    import exact._hybrid as H
    import exact._tangent as T
    import peelapprox._reduced._segment_kernel as G

    for mod, names in ((H, ("DONE", "OUT_FULL", "JUMPS_FULL", "PAUSE", "NO_ROOT", "NO_LANDING", "GEOMETRY",
                            "V_CEILING", "STEP_FAIL")),
                       (G, ("DONE", "OUT_FULL", "T_MAX", "MAX_STEPS", "V_FLOOR", "V_CEILING", "F_NONPOSITIVE",
                            "NONFINITE", "STEP_FAIL")),
                       (T, ("DONE", "FOLD", "MAX_STEPS", "NO_ROOT", "NO_LANDING", "STEP_FAIL"))):
        for name in names:
            assert getattr(mod, name) == getattr(S, name), (mod.__name__, name)
    codes = [s.code for s in S.STATUS.values()]
    assert len(codes) == len(set(codes))


@pytest.mark.parametrize("code, exc, reason", [
    (S.NO_ROOT, ModelBreakdown, "no_root"), (S.NO_LANDING, ModelBreakdown, "no_landing"),
    (S.GEOMETRY, ModelBreakdown, "geometry"), (S.V_CEILING, ModelBreakdown, "v_ceiling"),
    (S.V_FLOOR, ModelBreakdown, "v_floor"), (S.F_NONPOSITIVE, ModelBreakdown, "F_nonpositive"),
    (S.NONFINITE, ModelBreakdown, "nonfinite"), (S.STEP_FAIL, SolverFailure, None),
    (S.MAX_STEPS, SolverBudgetExceeded, "max_steps"), (S.T_MAX, SolverBudgetExceeded, "t_max"),
])
def test_status_error_builds_the_documented_exception(code, exc, reason):
    """Each error code gives its exception with the table's reason (breakdowns) or budget name (budgets),
    the time and state passed in, and a message from the template (exact checks)."""
    fields = dict(f_zero=128.0, f_min=199.4, level=1e-10, v=1e-70, v_ceiling=1e3, v_floor=1e-9, why="test",
                  limit=7, v_f=0.5)
    e = S.status_error(code, t=0.25, state={"t": 0.25}, prefix="p: ", where="here", **fields)
    assert type(e) is exc and e.t == 0.25 and e.state == {"t": 0.25}
    assert str(e).startswith("p: ") and str(e).endswith(" here")
    if exc is ModelBreakdown:
        assert e.reason == reason
    if exc is SolverBudgetExceeded:
        assert e.budget == reason and e.limit == 7


def test_non_error_codes_are_refused():
    """A driver asking for the exception of DONE/PAUSE (or an unknown code) is a bug: ValueError."""
    for code in (S.DONE, S.OUT_FULL, S.PAUSE, 99):
        with pytest.raises(ValueError, match="not an error"):
            S.status_error(code, t=0.0, state={})

"""One table of the compiled drivers' status codes: code, reason, exception, message.

The hybrid DAE driver (``exact._hybrid``), the reduced-segment driver (``peelapprox._reduced._segment_kernel``) and the
saltation-tangent driver (``exact._tangent``) return one of these integer codes (plain module constants:
numba freezes them into the kernels); :func:`status_error` turns a code into the documented exception, in
the style of scipy's ``MESSAGES`` and diffrax's ``RESULTS``.  Codes below 10 are not errors (the run ended
or paused); 10-19 are physical breakdowns of the model (:class:`ModelBreakdown`, whose ``reason`` is the
table's), 20-29 numerical failures and exhausted budgets.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from .errors import ModelBreakdown, SolverBudgetExceeded, SolverFailure

__all__ = ["Status", "STATUS", "status_error"]

# ------------------------------------------------------------------ codes
DONE = 0  # reached the end: t_end (hybrid), the exit velocity (segment), the fold or t_max (tangent)
OUT_FULL = 1  # the output buffer is full: the caller empties it and calls again
JUMPS_FULL = 2  # the jump buffer is full (hybrid)
PAUSE = 3  # the per-call step quota is used: budgets and progress are checked between calls
FOLD = 4  # the tangent driver reached a fold (it stops there for the saltation)
NO_ROOT = 10  # on AB the level F(1 + c) fell to f(0+, V): CONSTR has no root
NO_LANDING = 11  # CD fold reached but f_min <= f(0+, V): no AB root to land on
GEOMETRY = 12  # 1 + c(alpha) reached 0: the peel geometry degenerates
V_CEILING = 13  # v ran away on CD
V_FLOOR = 14  # v fell to a floor (the caller's, or the reduced equations' e^-60 fall)
F_NONPOSITIVE = 15  # the pull force reached 0 (reduced equations)
NONFINITE = 16  # the state became non-finite (reduced equations)
LAW_DOMAIN = 17  # v left the peel-force law's domain (a table's range, an expression's probed range)
STEP_FAIL = 20  # step-size underflow or repeated rejection
MAX_STEPS = 21  # the step budget is used up
T_MAX = 22  # the reduced segment did not reach its exit velocity before t_max


@dataclass(frozen=True)
class Status:
    """One row of :data:`STATUS`: the code, its short ``reason``, the exception it raises (None: not an
    error) and the message template (``str.format`` fields given by the driver)."""

    code: int
    reason: str
    exception: type | None
    message: str


#: code -> :class:`Status`.
STATUS: dict[int, Status] = {s.code: s for s in (
    Status(DONE, "done", None, "reached the end"),
    Status(OUT_FULL, "out_full", None, "output buffer full"),
    Status(JUMPS_FULL, "jumps_full", None, "jump buffer full"),
    Status(PAUSE, "pause", None, "step quota of one call used"),
    Status(FOLD, "fold", None, "reached a fold"),
    Status(NO_ROOT, "no_root", ModelBreakdown,
           "F(1 - cos theta) fell to f(0+, V)={f_zero:.6g} N on AB (within {level:g}, v = {v:.3g} m/s): CONSTR has "
           "no root left, the peel front would have to stop"),
    Status(NO_LANDING, "no_landing", ModelBreakdown,
           "CD fold reached but f_min={f_min} <= f(0+, V)={f_zero:.6g}: no AB root to land on"),
    Status(GEOMETRY, "geometry", ModelBreakdown,
           "1 - cos(theta) reached 0: the peel geometry degenerates (alpha -> -pi/2)"),
    Status(V_CEILING, "v_ceiling", ModelBreakdown, "v ran away on CD (above {v_ceiling:g} m/s)"),
    Status(V_FLOOR, "v_floor", ModelBreakdown, "v fell to {v_floor:.3g} m/s on AB ({why})"),
    Status(F_NONPOSITIVE, "F_nonpositive", ModelBreakdown, "the pull force reached 0"),
    Status(NONFINITE, "nonfinite", ModelBreakdown, "the state became non-finite"),
    Status(LAW_DOMAIN, "law_domain", ModelBreakdown,
           "{what}: the peel-force law {law} is defined on [{lo:.6g}, {hi:.6g}] m/s only and is not extrapolated "
           "(extend the table or the law's range)"),
    Status(STEP_FAIL, "step_fail", SolverFailure, "step size collapsed"),
    Status(MAX_STEPS, "max_steps", SolverBudgetExceeded, "max_steps={limit} steps used"),
    Status(T_MAX, "t_max", SolverBudgetExceeded, "v did not reach v_f={v_f} before t_max={limit} s"),
)}


def status_error(code: int, *, t: float, state: dict, partial: Any = None, prefix: str = "", where: str = "",
                 **fields: Any) -> Exception:
    """The exception for an error ``code`` (raise it): ``"<prefix><message> <where>"`` with the template's
    ``fields``; ModelBreakdown carries the table's ``reason``, SolverBudgetExceeded the ``budget`` name and
    ``fields["limit"]``.

    Raises
    ------
    ValueError
        If ``code`` is not an error code of :data:`STATUS` (a driver bug).
    """
    st = STATUS.get(code)
    if st is None or st.exception is None:
        raise ValueError(f"status code {code} is not an error of the status table")
    text = prefix + st.message.format(**fields) + (f" {where}" if where else "")
    if st.exception is ModelBreakdown:
        return ModelBreakdown(text, t=t, state=state, reason=st.reason, partial=partial)
    if st.exception is SolverBudgetExceeded:
        return SolverBudgetExceeded(text, budget=st.reason, limit=fields["limit"], t=t, state=state, partial=partial)
    return SolverFailure(text, t=t, state=state, partial=partial)

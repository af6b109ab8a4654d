"""The named argument validators shared by every public function.

One rule for every public argument, so that a bad argument is reported as what it is, by name, before
any computation:

* a value of the wrong *kind* — ``None``, a string, a bool, a sequence where a number is expected, a
  float where an integer count is expected, anything but a :class:`PeelParams` where parameters are
  expected — raises :class:`ArgumentTypeError` (a ``TypeError``);
* a value of the right kind outside its valid range — NaN, ±inf, a negative time, an unknown choice —
  raises ``ValueError``.

Both messages name the argument and the valid range, in the one pattern
``"<name> must be <kind> in <range>, got <value>"``, e.g.
``"rtol must be finite and in (0, 1), got nan"`` or ``"alpha0 must be a real number in (-inf, inf), got 'abc'
(str)"``.

:class:`ArgumentTypeError` subclasses both ``TypeError`` and ``ValueError`` (as numpy's ``AxisError``
subclasses ``ValueError`` and ``IndexError``), so callers written against the earlier rule "bad arguments
raise ValueError" (the CLI's error report, ``except ValueError`` around a run) still catch it.

Decisions recorded here once:

* **bool and str are not numbers**: ``True`` is not 1.0 and ``"1e-3"`` is not 1e-3.
* **integer counts are integers**: :func:`integer` accepts ``int`` and numpy integers and rejects every
  float, integral or not (``max_points=100.0`` is refused rather than rounded: a float count is usually
  a unit mix-up, and numpy refuses ``np.zeros(3.0)`` for the same reason).  Counts are bounded above by
  :data:`MAX_COUNT` so that no budget overflows numba's int64 or means "forever".
* ranges are closed unless stated open; bounds are printed with ``[``/``]`` or ``(``/``)`` accordingly.
* **what the user passed is shown, shortened**: a message echoes a value through :func:`shown`, its ``repr``
  cut after 200 characters with ``... (N characters)`` appended, so that a 700 KB expression or path gives a
  one-line message that still says what was passed.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ._checks import (
    MAX_COUNT,
    ArgumentTypeError,
    _got,
    choice,
    finite,
    flag,
    function,
    in_range,
    integer,
    interval,
    nonnegative,
    optional,
    optional_finite,
    path,
    positive,
    real,
    reals,
    shown,
    times,
)
from ._params import PeelParams
from ._ranges import EPS_RANGE, RTOL_RANGE, STATE_RANGES, TIME_MAX
from .law import ALL_LAWS, require_law

__all__ = [
    "ArgumentTypeError",
    "MAX_COUNT",
    "real",
    "in_range",
    "finite",
    "positive",
    "nonnegative",
    "optional",
    "optional_finite",
    "integer",
    "choice",
    "flag",
    "function",
    "params",
    "paper_model",
    "reals",
    "times",
    "interval",
    "state",
    "states",
    "duration",
    "rtol",
    "eps",
    "path",
    "shown",
]


def params(name: str, x: Any, *, laws: tuple[str, ...] = ALL_LAWS, where: str | None = None,
           variants: bool = True):
    """x if it is a :class:`peelapprox.PeelParams` (validated when it was built), else ArgumentTypeError.

    A ValueError if ``x.force`` is not one of ``laws``, the laws the calling function runs (by their names:
    ``"paper"``, ``"cubic"``, ``"tabulated"``, ... as in ``peelapprox.law.law_label``; default every law);
    the message names ``where``, the calling function (every caller in the package names itself; default
    ``"this function"``).  With ``variants=False`` (the paper's reduced equations), also a ValueError for a model
    variant (:func:`paper_model`).
    """
    if not isinstance(x, PeelParams):
        raise ArgumentTypeError(f"{name} must be a PeelParams, got {_got(x)}")
    require_law(x, where, laws)
    if not variants:
        paper_model(name, x, where=where or "this function")
    return x


def paper_model(name: str, x: PeelParams, *, where: str) -> PeelParams:
    """``x`` if it is the paper's model (massless tape, constant pull speed: ``x.variant is None``), else a
    ValueError naming ``<name>.tape_mass`` / ``<name>.loading``: the one check of every entry point of the
    paper's reduced equations (``where``: estimate, reduced_segment, the alpha forms, the comparison harness).

    Those equations (approxalpha, approxvdot, fullvdot, the Airy and WKB forms, the branch-time estimates) are
    derived branch-wise from the massless DAE (CONSTR: F (1 + sin α) = f(v, V)) under velocity control; a tape
    mass replaces CONSTR by an equation of motion for v, and a load makes the pull speed a state, so neither
    has those branches.  The full model runs both: ``exact.simulate`` (docs/tape-mass.md, docs/constant-load.md).
    """
    if x.variant is None:
        return x
    got = ", ".join(f"{n}={v!r}" for n, v in (("tape_mass", x.tape_mass), ("loading", x.loading),
                                                ("load_mass", x.load_mass), ("load", x.load)) if v is not None)
    raise ValueError(
        f"{name}.tape_mass / {name}.loading: {where} solves the paper's reduced branch-wise equations "
        f"(approxalpha, approxvdot, Airy), derived for the massless DAE under velocity control (tape_mass=None, "
        f"loading='velocity'); got {got} (variant {x.variant!r}). Run the full model instead: exact.simulate")


def state(name: str, x: Any, quantity: str) -> float:
    """A scalar state variable in its range :data:`peelapprox.STATE_RANGES` [quantity].

    ``quantity`` is ``"alpha"`` (rad), ``"omega"`` (rad/s, also for α̇), ``"F"`` (N), ``"v"`` (m/s, open at
    0) or ``"F_rate"`` (N/s); e.g. ``state("F0", F0, "F")``.
    """
    lo, hi = STATE_RANGES[quantity]
    return in_range(name, x, lo, hi, lo_open=quantity == "v")


def states(name: str, x: Any, quantity: str) -> np.ndarray:
    """:func:`state` for an array (any shape, scalars as 0-d), every element checked (:func:`reals`)."""
    lo, hi = STATE_RANGES[quantity]
    return reals(name, x, lo, hi, lo_open=quantity == "v")


def duration(name: str, x: Any, *, zero: bool = False) -> float:
    """A time span [s] in ``(0, TIME_MAX]`` (``[0, TIME_MAX]`` with ``zero``), TIME_MAX = 1e6 s."""
    return in_range(name, x, 0.0, TIME_MAX, lo_open=not zero)


def rtol(name: str, x: Any) -> float:
    """A relative tolerance of the package's solvers, in :data:`peelapprox.RTOL_RANGE` = [1e-14, 1e-2]."""
    return in_range(name, x, *RTOL_RANGE)


def eps(name: str, x: Any) -> float:
    """A regularisation ε of the ε-regularised scheme, in :data:`peelapprox.EPS_RANGE` = [1e-15, 1e-2]."""
    return in_range(name, x, *EPS_RANGE)

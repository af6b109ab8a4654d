"""The option objects of :func:`exact.simulate`: the method, what to save, the budgets.

In the style of diffrax (``diffeqsolve(solver=Dopri5(), saveat=SaveAt(ts=...), ...)``), each group of
``simulate``'s keywords has a frozen, keyword-only, self-validating dataclass:

* the method — :class:`Hybrid` (the ε → 0 limit) or :class:`Regularized` (the paper's ε-scheme, with its
  ``eps`` and scipy ``solver``) — with the local error control (``rtol``, ``atol``: the default ``atol``
  depends on the method, :data:`ATOL_SCALE`) and the caller's stopping velocity ``v_floor``;
* :class:`SaveAt` — what is stored: every step, the states at given times, or the jumps only, after
  ``t_transient``;
* :class:`Budget` — stored points, accepted steps, stored jumps, wall time.

``simulate`` builds them from its keywords (or takes them as given) and hands them to the drivers, which
read their fields and validate nothing again.  Each object checks its fields in ``__post_init__`` with the
named validators of :mod:`peelapprox.validate`, so a bad field raises the same ``ValueError`` /
``TypeError`` (naming the field and its valid range) as the ``simulate`` keyword of the same name.  What
depends on the horizon ``t_end`` (``t_transient <= t_end``, the save times within it, the default step
budget) is checked or resolved by ``simulate``, which knows it (:meth:`SaveAt.within`,
:meth:`Budget.resolved`).
"""

from __future__ import annotations

import numbers
from collections.abc import Sequence
from dataclasses import dataclass, fields, replace
from typing import Any, ClassVar

import numpy as np

from peelapprox import EPS_DEFAULT, TIME_MAX
from peelapprox.validate import ArgumentTypeError, choice, flag, in_range, integer, interval, optional, positive, reals
from peelapprox.validate import eps as _eps
from peelapprox.validate import rtol as _rtol

__all__ = ["Hybrid", "Regularized", "Smooth", "SaveAt", "Budget", "ATOL_SCALE", "ATOL_RANGE", "STEP_BUDGET",
           "default_max_steps", "default_atol", "method_option", "output_options"]

METHODS = ("hybrid", "regularized", "smooth")
SOLVERS = ("Radau", "BDF", "LSODA")
#: Solvers of the model variants' smooth ODE (``method="smooth"``): the stiff ones and two explicit ones.
SMOOTH_SOLVERS = ("Radau", "BDF", "LSODA", "DOP853", "RK45")
#: The default solver of ``method="smooth"`` (measured: docs/tape-mass.md, "Which integrator").
SMOOTH_DEFAULT = "LSODA"
SAVES = ("steps", "jumps")

#: Default absolute tolerances are ``rtol * ATOL_SCALE`` for the integrated
#: components.  Hybrid: (τ [s], α [rad], ω [rad/s], ln v [-]); regularised:
#: (α, ω, F [N], v [m/s]).  The scales are the smallest magnitudes that matter on
#: the orbits of the paper: α oscillates with amplitude ≥ ~1e-3 rad, segment
#: durations are ≥ ~1e-4 s; ln v is controlled to ``rtol (1 + |ln v|)``, a
#: relative accuracy of v at every speed (the regularised v ≥ ~1e-3 m/s on AB).
ATOL_SCALE = {"hybrid": (1e-6, 1e-4, 1e-3, 1.0), "regularized": (1e-4, 1e-3, 1e-2, 1e-6),
              "smooth": (1e-4, 1e-3, 1e-2, 1e-6)}

#: Valid absolute tolerances, every component: 0 is excluded (τ starts every branch segment at 0, so pure
#: relative control has no scale there), above 1 (1 s, 1 rad, 1 rad/s, a factor e in v (hybrid, ln v),
#: 1 m/s or 1 N (regularised)) no error is controlled at all; below 1e-100 the scaled field overflows the
#: error norm.
ATOL_RANGE = (1e-100, 1.0)

#: Default step budget per simulated second, floor and cap, by method (``max_steps=None``).  The
#: physical grid of the stress suite needs at most ~1.5e4 hybrid steps per simulated second (I = 1e-6,
#: rtol 1e-8; 1.3-1.8 us each) and the regularised scheme ~1e3 (~150 us each), so the rate leaves a
#: margin of ~50x, while the cap bounds a default call: hybrid <= 2e7 steps (~35 s measured on
#: t_end = 1e300), regularised <= 5e5 (~80 s).  The tape-mass model (``"smooth"``, default LSODA at
#: rtol 1e-8) needs 1.8e4-1.3e5 steps per simulated second over m = 1e-9 ... 1e-1 kg (V = 1, I = 1e-5 and V = 2,
#: I = 1e-4; 9-19 us each; ``python -m comparisons.benchmark.tape_mass``), so its rate leaves a margin of ~8x
#: (rtol 1e-10 needs ~2.5x more steps) and its cap ~60 s of LSODA (Radau and BDF take 10-20x longer per step:
#: give them ``max_wall``).  A run that needs more raises SolverBudgetExceeded naming max_steps.
STEP_BUDGET = {"hybrid": (1e6, 1e6, 2e7), "regularized": (1e5, 1e5, 5e5), "smooth": (1e6, 1e5, 5e6)}


def default_max_steps(method: str, t_end: float) -> int:
    """The step budget ``simulate`` uses when ``max_steps=None``: ``clip(rate * t_end, floor, cap)``."""
    rate, lo, hi = STEP_BUDGET[method]
    return int(min(hi, max(lo, rate * t_end)))


def _atol_vector(method: str, rtol: float, atol) -> np.ndarray:
    if atol is None:
        return rtol * np.asarray(ATOL_SCALE[method], dtype=float)
    a = reals("atol", atol, *ATOL_RANGE)
    if a.ndim == 0:
        a = np.full(4, float(a))
    if a.shape != (4,):
        raise ValueError(f"atol must be a scalar or 4 values (one per integrated component), got shape {a.shape}")
    return a


class _Method:
    """What the two method objects share: the local error control (``rtol``, ``atol``) and ``v_floor``."""

    name: ClassVar[str]
    rtol: float
    atol: float | Sequence[float] | None
    v_floor: float | None

    def _check_shared(self) -> None:
        """Validate and normalise ``rtol`` (a float), ``atol`` (None or 4 floats) and ``v_floor``."""
        rtol = _rtol("rtol", self.rtol)
        atol = None if self.atol is None else tuple(float(a) for a in _atol_vector(self.name, rtol, self.atol))
        object.__setattr__(self, "rtol", rtol)
        object.__setattr__(self, "atol", atol)
        object.__setattr__(self, "v_floor", optional(positive, "v_floor", self.v_floor))

    def atol_vector(self) -> np.ndarray:
        """The 4 absolute tolerances the integrator uses (a new array)."""
        return _atol_vector(self.name, self.rtol, self.atol)


@dataclass(frozen=True, kw_only=True)
class Hybrid(_Method):
    """The ε → 0 limit (``method="hybrid"``): compiled DOP853 on the branch dynamics, exact fold jumps.

    Parameters
    ----------
    rtol : float
        Relative tolerance, in ``RTOL_RANGE`` = [1e-14, 1e-2].
    atol : None, float or 4 floats
        Absolute tolerance of ``(τ, α, ω, ln v)``, each in :data:`ATOL_RANGE` = [1e-100, 1]; a scalar is
        used for every component and stored as 4 values; ``None``: ``rtol * ATOL_SCALE["hybrid"]``.
    v_floor : float, optional
        Stop with ``ModelBreakdown(reason="v_floor")`` when v falls to this velocity [m/s], in (0, inf);
        None: the model's own criterion only (see :func:`exact.simulate`).

    Raises
    ------
    ValueError, TypeError
        A field outside its range or of the wrong kind, named as the ``simulate`` keyword of that name.
    """

    name: ClassVar[str] = "hybrid"
    rtol: float = 1e-8
    atol: float | Sequence[float] | None = None
    v_floor: float | None = None

    def __post_init__(self) -> None:
        self._check_shared()


@dataclass(frozen=True, kw_only=True)
class Regularized(_Method):
    """The paper's ε-regularised scheme (``method="regularized"``): mass matrix ``diag(1, 1, 1, ε)`` on a
    scipy stiff solver with the analytic Jacobian.

    Parameters
    ----------
    eps : float
        Regularisation ε, in ``EPS_RANGE`` = [1e-15, 1e-2]; default 1e-7 as in the paper.
    solver : {"Radau", "BDF", "LSODA"}
        The scipy solver.
    rtol, atol, v_floor
        As for :class:`Hybrid`; the components are ``(α, ω, F, v)`` and ``atol=None`` means
        ``rtol * ATOL_SCALE["regularized"]``.  Bad fields raise as for :class:`Hybrid`.
    """

    name: ClassVar[str] = "regularized"
    eps: float = EPS_DEFAULT
    solver: str = "Radau"
    rtol: float = 1e-8
    atol: float | Sequence[float] | None = None
    v_floor: float | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "solver", choice("solver", self.solver, SOLVERS))
        object.__setattr__(self, "eps", _eps("eps", self.eps))
        self._check_shared()


@dataclass(frozen=True, kw_only=True)
class Smooth(_Method):
    """The model variants' smooth ODE (``method="smooth"``): the tape-mass model (``PeelParams(tape_mass=m)``,
    with or without a load) on a scipy solver, the stiff ones with the analytic Jacobian.

    Parameters
    ----------
    solver : {"LSODA", "Radau", "BDF", "DOP853", "RK45"}
        The scipy solver; default "LSODA", the fastest at every tape mass measured (1e-9 … 1e-1 kg): it switches
        itself between Adams (non-stiff, large m) and BDF (stiff, small m) by its stiffness estimate
        (docs/tape-mass.md, "Which integrator").
    rtol, atol, v_floor
        As for :class:`Hybrid`; the components are ``(α, ω, F, v)`` (and ``V_p`` under a load, with the
        tolerance of v) and ``atol=None`` means ``rtol * ATOL_SCALE["smooth"]``.
    """

    name: ClassVar[str] = "smooth"
    solver: str = "LSODA"
    rtol: float = 1e-8
    atol: float | Sequence[float] | None = None
    v_floor: float | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "solver", choice("solver", self.solver, SMOOTH_SOLVERS))
        self._check_shared()


def _sorted_times(name: str, ts: Any, lo: float, hi: float, range_text: str) -> np.ndarray:
    """``ts`` as a flat float array, non-empty, sorted, every time in ``[lo, hi]`` (the message shows
    ``range_text = [lo, hi]``)."""
    te = reals(name, ts, lo, hi).ravel()
    if te.size == 0 or np.any(np.diff(te) < 0):
        shown = interval(lo, hi) if range_text.endswith("TIME_MAX]") else f"[{lo:g}, {hi:g}]"  # t_eval: as ever
        raise ValueError(f"{name} must be a non-empty, sorted sequence of times in {range_text} = {shown}")
    return te


@dataclass(frozen=True, kw_only=True, eq=False)
class SaveAt:
    """What a run stores (``simulate``'s ``save``, ``t_eval``, ``t_transient``).  Give exactly one of:

    Parameters
    ----------
    steps : bool
        Every accepted step, plus the states just before and after each jump (``save="steps"``).
    ts : array_like of float
        The states exactly at these times (``t_eval``): sorted, non-empty, in ``[t_transient, TIME_MAX]``
        (and within ``[t_transient, t_end]``, checked by ``simulate``); stored as a read-only float array.
    jumps_only : bool
        No points, only the jumps (``save="jumps"``): memory proportional to the number of jumps.
    t_transient : float
        Integrate from 0 but store no point or jump before this time [s], in [0, TIME_MAX] = [0, 1e6]
        (and at most ``t_end``).

    The jumps after ``t_transient`` are stored in every case.  Equal by value (``ts`` elementwise) and
    hashable.

    Raises
    ------
    ValueError, TypeError
        A field outside its range or of the wrong kind (named), or not exactly one of the three choices.
    """

    steps: bool = False
    ts: np.ndarray | None = None
    jumps_only: bool = False
    t_transient: float = 0.0

    def __post_init__(self) -> None:
        steps, jumps_only = flag("steps", self.steps), flag("jumps_only", self.jumps_only)
        t_transient = in_range("t_transient", self.t_transient, 0.0, TIME_MAX)
        ts = None
        if self.ts is not None:
            ts = _sorted_times("ts", self.ts, t_transient, TIME_MAX, "[t_transient, TIME_MAX]")
            ts.flags.writeable = False
        if steps + jumps_only + (ts is not None) != 1:
            raise ValueError(f"SaveAt needs exactly one of steps=True, ts=[...] or jumps_only=True, got "
                             f"steps={steps}, ts={'None' if ts is None else f'<{ts.size} times>'}, "
                             f"jumps_only={jumps_only}")
        for name, value in (("steps", steps), ("ts", ts), ("jumps_only", jumps_only), ("t_transient", t_transient)):
            object.__setattr__(self, name, value)

    def _key(self) -> tuple:
        ts = None if self.ts is None else (self.ts.shape, self.ts.tobytes())
        return (self.steps, ts, self.jumps_only, self.t_transient)

    def __eq__(self, other: object) -> bool:
        return self._key() == other._key() if isinstance(other, SaveAt) else NotImplemented

    def __hash__(self) -> int:
        return hash(self._key())

    def within(self, t_end: float) -> SaveAt:
        """``self`` if ``t_transient`` and every time of ``ts`` lie within ``[0, t_end]``; else ValueError
        naming the field and the range the horizon allows."""
        in_range("t_transient", self.t_transient, 0.0, t_end)
        if self.ts is not None:
            _sorted_times("ts", self.ts, self.t_transient, t_end, "[t_transient, t_end]")
        return self


@dataclass(frozen=True, kw_only=True)
class Budget:
    """The limits of one run; needing more than one raises ``SolverBudgetExceeded`` naming it.

    Parameters
    ----------
    max_steps : int, optional
        Accepted steps, all of them (from t = 0), in [1, MAX_COUNT = 1e15]; None: scaled with the horizon
        by :func:`default_max_steps` (resolved by :meth:`resolved`).
    max_jumps : int
        Stored jumps (those at ``t >= t_transient``: a memory budget), in [1, 1e15].
    max_points : int
        Stored points, in [1, 1e15].
    max_wall : float, optional
        Wall-clock seconds of the integration, in (0, inf); None: bounded by ``max_steps`` only.

    Raises
    ------
    ValueError, TypeError
        A field outside its range or of the wrong kind (a float count included), named.
    """

    max_steps: int | None = None
    max_jumps: int = 20_000_000
    max_points: int = 5_000_000
    max_wall: float | None = None

    def __post_init__(self) -> None:
        # the order of simulate's checks: points, jumps, steps, wall
        object.__setattr__(self, "max_points", integer("max_points", self.max_points))
        object.__setattr__(self, "max_jumps", integer("max_jumps", self.max_jumps))
        object.__setattr__(self, "max_steps", optional(integer, "max_steps", self.max_steps))
        object.__setattr__(self, "max_wall", optional(positive, "max_wall", self.max_wall))

    def resolved(self, method: str, t_end: float) -> Budget:
        """This budget with ``max_steps=None`` replaced by ``default_max_steps(method, t_end)``."""
        if self.max_steps is not None:
            return self
        return replace(self, max_steps=default_max_steps(method, t_end))


def _given(value: Any, default: Any) -> bool:
    """A keyword differs from its default (a keyword at its default value counts as not given)."""
    if default is None:
        return value is not None
    plain = isinstance(value, (numbers.Real, str)) and not isinstance(value, (bool, np.bool_))
    return not (plain and value == default)


#: ``simulate``'s defaults of the keywords an option object stands for, where they are not the object's field
#: defaults (the others are: tests/test_options.py compares the signature with the fields).
_KEYWORD_DEFAULTS = {"solver": None, "eps": None, "save": "steps", "t_eval": None}


def _refuse(kind: str, obj: Any, pairs: Sequence[tuple[str, Any]], holds: str) -> None:
    """ValueError naming both if a keyword that the object ``obj`` stands for is given (not at its default)."""
    defaults = {f.name: f.default for f in fields(obj)} | _KEYWORD_DEFAULTS
    for name, value in pairs:
        if _given(value, defaults.get(name)):
            raise ValueError(f"{name} and {kind} both given ({name}={value!r:.60}, {kind}={obj!r:.80}): "
                             f"{holds}; give one of them")


def method_option(method: Any, *, solver: Any, eps: Any, rtol: Any, atol: Any, v_floor: Any,
                  params: Any = None) -> Hybrid | Regularized | Smooth:
    """The method object of a ``simulate`` call: ``method`` itself if it is one (then the keywords it holds
    must be left at their defaults), else the object built from the string and the keywords.  ``method=None``
    picks the model's method (``params``: :func:`default_method`); a method the model cannot use is refused.
    """
    if isinstance(method, (Hybrid, Regularized, Smooth)):
        _refuse("method", method, [("solver", solver), ("eps", eps), ("rtol", rtol), ("atol", atol),
                                   ("v_floor", v_floor)],
                f"a method object holds rtol, atol, v_floor (and a Regularized eps, solver): e.g. "
                f"{type(method).__name__}(rtol=...)")
        opts: Hybrid | Regularized | Smooth = method
    else:
        name = default_method(params) if method is None else choice("method", method, METHODS)
        if name in ("hybrid", "smooth") and eps is not None:
            raise ValueError(f"eps applies only to method='regularized' (the paper's eps-scheme), got eps={eps!r} "
                             f"with method={name!r}")
        if name == "hybrid":
            if solver is not None:
                raise ValueError(f"solver applies only to method='regularized' or 'smooth' (the hybrid method is "
                                 f"the eps -> 0 limit, integrated by its own DOP853), got solver={solver!r} with "
                                 "method='hybrid'")
            opts = Hybrid(rtol=rtol, atol=atol, v_floor=v_floor)
        elif name == "smooth":
            opts = Smooth(solver=SMOOTH_DEFAULT if solver is None else solver, rtol=rtol, atol=atol, v_floor=v_floor)
        else:
            opts = Regularized(solver="Radau" if solver is None else solver, eps=EPS_DEFAULT if eps is None else eps,
                               rtol=rtol, atol=atol, v_floor=v_floor)
    if params is not None:
        _check_method_model(opts.name, params)
    return opts


def default_method(params: Any) -> str:
    """The method ``simulate`` uses for ``params`` when none is given: ``"hybrid"`` for the paper's massless model
    under velocity control, ``"smooth"`` for the tape-mass model (``tape_mass``), ``"regularized"`` for the
    massless tape under a load (the hybrid solver runs velocity control only)."""
    if params is None or getattr(params, "variant", None) is None:
        return "hybrid"
    return "smooth" if params.tape_mass is not None else "regularized"


def _check_method_model(name: str, params: Any) -> None:
    """ValueError if the method ``name`` cannot solve the model of ``params`` (its variant)."""
    if params.tape_mass is not None and name != "smooth":
        raise ValueError(f"method={name!r} solves the massless model; with tape_mass={params.tape_mass!r} kg the "
                         "model is a smooth ODE (its jumps arise from the ribbon's inertia): use method='smooth' "
                         "(the default for a tape mass)")
    if params.tape_mass is None and name == "smooth":
        raise ValueError("method='smooth' solves the tape-mass model: give params.tape_mass (kg), or use "
                         "method='hybrid' (velocity control) or 'regularized' for the massless tape")
    if params.loading == "load" and name == "hybrid":
        raise ValueError("method='hybrid' runs velocity control only; under loading='load' the massless tape is "
                         "solved by method='regularized' (the paper's eps-scheme with the pull speed a state), "
                         "a tape mass by method='smooth'")


def output_options(method: str, t_end: float, saveat: Any, budget: Any, *, save: Any, t_eval: Any,
                   t_transient: Any, max_points: Any, max_steps: Any, max_jumps: Any,
                   max_wall: Any) -> tuple[SaveAt, Budget]:
    """The :class:`SaveAt` and the resolved :class:`Budget` of a ``simulate`` call with horizon ``t_end``.

    ``saveat`` / ``budget`` (objects or None) replace the keywords they hold, which must then be left at
    their defaults; the keyword path checks in ``simulate``'s documented order and messages (``t_eval``
    named as such, within ``[t_transient, t_end]``, at most ``max_points`` times).
    """
    if saveat is not None:
        if not isinstance(saveat, SaveAt):
            raise ArgumentTypeError(f"saveat must be a SaveAt or None, got {type(saveat).__name__}")
        _refuse("saveat", saveat, [("save", save), ("t_eval", t_eval), ("t_transient", t_transient)],
                "saveat=SaveAt(...) holds save, t_eval and t_transient")
        saveat.within(t_end)
    else:
        t_transient = in_range("t_transient", t_transient, 0.0, t_end)
        save = choice("save", save, SAVES)
    if budget is not None:
        if not isinstance(budget, Budget):
            raise ArgumentTypeError(f"budget must be a Budget or None, got {type(budget).__name__}")
        _refuse("budget", budget, [("max_points", max_points), ("max_steps", max_steps), ("max_jumps", max_jumps),
                                   ("max_wall", max_wall)],
                "budget=Budget(...) holds max_points, max_steps, max_jumps and max_wall")
    else:
        budget = Budget(max_points=max_points, max_jumps=max_jumps, max_steps=max_steps, max_wall=max_wall)
    if saveat is None:
        if t_eval is not None:
            te = _sorted_times("t_eval", t_eval, t_transient, t_end, "[t_transient, t_end]")
            saveat = SaveAt(ts=te, t_transient=t_transient)
        else:
            saveat = SaveAt(steps=save == "steps", jumps_only=save == "jumps", t_transient=t_transient)
        name = "t_eval"
    else:
        name = "saveat.ts"
    if saveat.ts is not None and saveat.ts.size > budget.max_points:
        raise ValueError(f"{name} has {saveat.ts.size} points, more than max_points={budget.max_points}")
    return saveat, budget.resolved(method, t_end)


def default_atol(method: str, rtol: float, atol: None | float | Sequence[float] = None) -> np.ndarray:
    """The absolute tolerances ``simulate(method=method, rtol=rtol, atol=atol)`` uses, one per integrated component.

    Parameters
    ----------
    method : {"hybrid", "regularized"}
        The solver; its integrated components are (τ, α, ω, ln v) for ``"hybrid"`` and (α, ω, F, v) for
        ``"regularized"``.
    rtol : float
        The relative tolerance (not checked here; :func:`simulate` checks it against ``RTOL_RANGE``).
    atol : None, float or sequence of 4 floats
        None: ``rtol * ATOL_SCALE[method]``, the default rule.  Else checked (every component in
        ``[1e-100, 1]``) and a scalar broadcast to 4 values.

    Returns
    -------
    ndarray, shape (4,)
        A new array.

    Raises
    ------
    ValueError
        Naming ``atol``, if it is out of range or neither a scalar nor 4 values.
    """
    return _atol_vector(method, rtol, atol)

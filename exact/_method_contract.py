"""The solver-method contract of :func:`exact.simulate`: the base class :class:`Method` and the table
:data:`METHODS` of the methods by name.

A method is a frozen, keyword-only dataclass deriving from :class:`Method`, like scipy's ``OdeSolver``
subclasses: its class attributes say what it is (name, default tolerances, step budget, the models it solves,
its scipy solvers), its fields are the caller's settings (validated in ``__post_init__``), and :meth:`Method.run`
integrates one consistent start.  ``simulate`` checks its arguments, builds the start and calls ``run``.  The
built-in methods (:mod:`exact._methods`) enter the table when ``exact`` is imported; adding one is one class and
one entry (CONTRIBUTING.md, "Adding a solver method").
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import fields
from typing import TYPE_CHECKING, Any, ClassVar, cast

import numpy as np

from peelapprox.validate import choice, optional, positive, reals
from peelapprox.validate import rtol as _rtol

from ._model import Model, model_of
from ._models import solving
from ._options import METHODS, _refuse, method_class

if TYPE_CHECKING:
    from peelapprox import PeelParams

    from ._options import Budget, SaveAt
    from ._trajectory import State, Trajectory

__all__ = ["Method", "ATOL_RANGE", "default_atol", "default_method", "method_option"]

#: Valid absolute tolerances, every component: 0 is excluded (τ starts every branch segment at 0, so pure
#: relative control has no scale there), above 1 (1 s, 1 rad, 1 rad/s, a factor e in v (hybrid, ln v),
#: 1 m/s or 1 N (regularised)) no error is controlled at all; below 1e-100 the scaled field overflows the
#: error norm.
ATOL_RANGE = (1e-100, 1.0)

def _atol_vector(scale: Sequence[float], rtol: float, atol: Any) -> np.ndarray:
    """``rtol * scale`` for ``atol=None``, else ``atol`` checked (:data:`ATOL_RANGE`) and broadcast to 4 values."""
    if atol is None:
        return rtol * np.asarray(scale, dtype=float)
    a = reals("atol", atol, *ATOL_RANGE)
    if a.ndim == 0:
        a = np.full(4, float(a))
    if a.shape != (4,):
        raise ValueError(f"atol must be a scalar or 4 values (one per integrated component), got shape {a.shape}")
    return a


def _field_names(method: type[Method]) -> set[str]:
    """The fields of a method class (a dataclass, by the contract, which the type of Method does not say)."""
    return {f.name for f in fields(cast(Any, method))}


class Method:
    """A solver method of :func:`exact.simulate` (subclass it as a frozen, keyword-only dataclass).

    Class attributes
    ----------------
    name : str
        The ``method=`` string, the key in :data:`METHODS`.
    about : str
        What it solves and how, a few words for messages ("the eps -> 0 limit ...").
    atol_scale : tuple of 4 floats
        The default absolute tolerances are ``rtol * atol_scale``, one per integrated component.
    step_budget : (rate, floor, cap)
        The default step budget, ``clip(rate * t_end, floor, cap)`` (:func:`default_max_steps`).
    models : frozenset of str
        Models (names in ``exact.MODELS``) it solves besides those that list it in their own ``methods``
        (:class:`exact.Model`); the first method of :data:`METHODS` that solves a model is that model's
        default.
    solvers : tuple of str
        The scipy solvers its ``solver`` field takes (empty: it has no ``solver``).

    Every method has the fields ``rtol``, ``atol`` and ``v_floor`` (:class:`Hybrid`); ``simulate``'s keywords
    ``solver`` and ``eps`` fill the fields of those names, and are refused by a method without them.
    """

    name: ClassVar[str]
    about: ClassVar[str]
    atol_scale: ClassVar[tuple[float, ...]]
    step_budget: ClassVar[tuple[float, float, float]]
    models: ClassVar[frozenset[str]] = frozenset()
    solvers: ClassVar[tuple[str, ...]] = ()
    rtol: float
    atol: float | Sequence[float] | None
    v_floor: float | None
    #: The scipy solver and the regularisation, for a method with such fields (None: it has none).
    solver: str | None = None
    eps: float | None = None

    def __post_init__(self) -> None:
        """Validate the fields, in ``simulate``'s order: ``solver`` (among ``solvers``, for a method with one), the
        method's own (:meth:`_check_own`), then ``rtol``, ``atol`` (normalised to None or 4 floats) and
        ``v_floor``."""
        if self.solvers:
            object.__setattr__(self, "solver", choice("solver", self.solver, self.solvers))
        self._check_own()
        rtol = _rtol("rtol", self.rtol)
        atol = None if self.atol is None else tuple(float(a) for a in _atol_vector(self.atol_scale, rtol, self.atol))
        object.__setattr__(self, "rtol", rtol)
        object.__setattr__(self, "atol", atol)
        object.__setattr__(self, "v_floor", optional(positive, "v_floor", self.v_floor))

    def _check_own(self) -> None:
        """Validate the fields a method adds (set each with ``object.__setattr__``: the dataclass is frozen)."""

    def atol_vector(self) -> np.ndarray:
        """The 4 absolute tolerances the integrator uses (a new array)."""
        return _atol_vector(self.atol_scale, self.rtol, self.atol)

    @classmethod
    def from_keywords(cls, *, solver: Any, eps: Any, rtol: Any, atol: Any, v_floor: Any) -> Method:
        """The method built from ``simulate``'s keywords (``solver``, ``eps``: None for the field's default);
        ValueError naming the keyword if the method has no field of that name."""
        own = _field_names(cls)
        given = {}
        for key, value in (("eps", eps), ("solver", solver)):
            if value is None:
                continue
            if key not in own:
                takers = " or ".join(repr(n) for n, m in METHODS.items() if key in _field_names(m))
                raise ValueError(f"{key} applies only to method={takers} (method={cls.name!r} is {cls.about}), got "
                                 f"{key}={value!r} with method={cls.name!r}")
            given[key] = value
        return cast(Any, cls)(rtol=rtol, atol=atol, v_floor=v_floor, **given)

    @classmethod
    def check_model(cls, model: Model) -> None:
        """ValueError saying which methods solve ``model`` if this one does not."""
        fits = solving(model, METHODS)
        if cls.name not in fits:
            raise ValueError(f"method={cls.name!r} is {cls.about}; it does not solve {model.about}: use "
                             f"method={' or '.join(map(repr, fits))} (the default there: {fits[0]!r})")

    def run(self, model: Model, params: PeelParams, t_end: float, s0: State, saveat: SaveAt, budget: Budget,
            progress: Callable[[float, float], None] | None) -> Trajectory:
        """Integrate ``model`` (:class:`exact.Model`, one that this method solves) with the parameters ``params``
        from the consistent state ``s0`` to ``t_end``.

        ``saveat`` and ``budget`` are validated (``budget.max_steps`` resolved); ``progress``, if given, is called
        with ``(t, t_end)`` now and then.  Returns the :class:`Trajectory`; a stop of the model or the integrator
        raises its documented exception (ModelBreakdown, SolverFailure, SolverBudgetExceeded) with the partial
        trajectory.
        """
        raise NotImplementedError


def default_method(params: PeelParams | None, model: Model | None = None) -> str:
    """The method ``simulate`` uses when none is given: the first of :data:`METHODS` that solves ``model`` (default
    the model of ``params``, :func:`exact._model.model_of`): hybrid for the paper's model, regularized for a
    massless tape under a load, smooth with a tape mass."""
    if params is None and model is None:
        return next(iter(METHODS))
    return solving(model if model is not None else model_of(cast(Any, params)), METHODS)[0]


def default_atol(method: str, rtol: float, atol: None | float | Sequence[float] = None) -> np.ndarray:
    """The absolute tolerances ``simulate(method=method, rtol=rtol, atol=atol)`` uses, one per integrated component.

    Parameters
    ----------
    method : {"hybrid", "regularized", "smooth"}
        The solver; its integrated components are (τ, α, ω, ln v) for ``"hybrid"`` and (α, ω, F, v) for the
        others.
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
    return _atol_vector(method_class(method).atol_scale, rtol, atol)


def method_option(method: Any, *, solver: Any, eps: Any, rtol: Any, atol: Any, v_floor: Any,
                  params: Any = None, model: Model | None = None) -> Method:
    """The method object of a ``simulate`` call: ``method`` itself if it is one (then the keywords it holds
    must be left at their defaults), else the :data:`exact._methods.METHODS` entry of that name built from the
    keywords.  ``method=None`` picks the model's method (``model``, default that of ``params``:
    :func:`default_method`); a method that cannot solve the model is refused (ValueError naming the ones that
    can).
    """
    if isinstance(method, Method):
        _refuse("method", method, [("solver", solver), ("eps", eps), ("rtol", rtol), ("atol", atol),
                                   ("v_floor", v_floor)],
                f"a method object holds rtol, atol, v_floor (and a Regularized eps, solver): e.g. "
                f"{type(method).__name__}(rtol=...)")
        opts = method
    else:
        name = default_method(params, model) if method is None else choice("method", method, tuple(METHODS))
        opts = METHODS[name].from_keywords(solver=solver, eps=eps, rtol=rtol, atol=atol, v_floor=v_floor)
    if params is not None or model is not None:
        opts.check_model(model if model is not None else model_of(params))
    return opts

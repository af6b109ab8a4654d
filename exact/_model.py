"""What a model of :func:`exact.simulate` is: the base class :class:`Model` and the registry :data:`MODELS`.

In the style of diffrax's terms (``diffeqsolve(terms=ODETerm(f), solver=...)``: the equations are an object, the
solver another), a model is a frozen dataclass that carries everything a method needs to integrate it: its state
layout (``states``), its field and Jacobian (:meth:`Model.field`), the events that stop or mark a run
(``events``), its consistent initial state (:meth:`Model.initial_state`) and the methods that solve it
(``methods``, preferred first).  A method's ``run`` takes the model (:meth:`exact._method_contract.Method.run`);
nothing downstream asks the parameters which variant they are.

The built-in models (the paper's massless tape and its follow-ups: the tape mass, the constant load) live in
:mod:`exact._models`; adding one is one module with a subclass and one :func:`register_model` call
(CONTRIBUTING.md, "Adding a model").
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, cast

import numpy as np

from peelapprox.kernels import CompiledLaw, compiled_law

from . import _registry
from ._initial import initial_state

if TYPE_CHECKING:
    from peelapprox import PeelParams

    from ._trajectory import State

__all__ = ["Model", "MODELS", "EVENTS", "register_model", "model_of"]

#: The events a model may list, in the order the scipy driver checks them after every accepted step
#: (:mod:`exact._regularized`): the front's arrest (v -> 0 is physical), the tape going slack (F <= 0), v <= 0
#: leaving the domain of a massless front (numerical), v leaving the law's domain, the caller's ``v_floor``,
#: CONSTR losing its root on AB (a massless front), and the jump marker (v crossing the inflection velocity).
EVENTS = ("arrest", "slack", "v_positive", "law_domain", "v_floor", "no_root", "jump")


@dataclass(frozen=True, kw_only=True)
class Model:
    """A model of the peeling dynamics that :func:`exact.simulate` integrates (subclass it as a frozen,
    keyword-only dataclass and register an instance: :func:`register_model`).

    Parameters
    ----------
    name : str
        The key in :data:`MODELS` (``simulate(model=name)``).
    about : str
        What it is, a few words for messages ("the massless tape under velocity control (the paper's model)").
    states : tuple of str
        The layout of the state its :meth:`field` integrates: ``("alpha", "omega", "F", "v")``, then ``"Vp"``
        (the pull speed) under a load.
    methods : tuple of str
        The methods (names in ``exact.METHODS``) that solve it, the default first; a method may also claim a
        model in its own ``models`` (:class:`exact._method_contract.Method`).
    events : tuple of str
        Its events among :data:`EVENTS`, checked in that order after every accepted step of a scipy method.
    parameters : tuple of (str, str)
        The fields of :class:`peelapprox.PeelParams` that it reads beyond the paper's (V, I, k, R, l, geometry,
        force), each with its unit: a trajectory shows those that are set (its repr, its DataFrame's attrs), and
        those not in any model's ``selected_by`` are the numeric parameters that ``exact.with_parameter`` and
        ``exact.orbit_diagram`` take (:func:`model_parameters`).
    selected_by : tuple of (str, object)
        The field values that select it besides its parameters (``loading="load"``): ``exact.with_parameter`` sets
        them with a parameter of which this is the first model in :data:`MODELS` to list it.

    The base class's methods are those of the paper's massless tape under velocity control; a subclass overrides
    what differs (:meth:`accepts`, :meth:`field`, :meth:`initial_state`, :meth:`failure_hint`).
    """

    name: str
    about: str
    states: tuple[str, ...] = ("alpha", "omega", "F", "v")
    methods: tuple[str, ...] = ()
    events: tuple[str, ...] = ("slack", "v_positive", "law_domain", "v_floor", "no_root", "jump")
    parameters: tuple[tuple[str, str], ...] = ()
    selected_by: tuple[tuple[str, object], ...] = ()

    def __post_init__(self) -> None:
        unknown = [e for e in self.events if e not in EVENTS]
        if unknown:
            raise ValueError(f"events of model {self.name!r} must be among {EVENTS}, got {unknown}")

    @property
    def n_states(self) -> int:
        """The number of integrated states (the length of :attr:`states`)."""
        return len(self.states)

    @property
    def has_hybrid(self) -> bool:
        """Whether the hybrid method solves it: the tools built on that method's jumps (section returns, tangent
        dynamics, saltation matrices) apply, and no scipy ``solver`` is chosen for its default run."""
        return "hybrid" in self.methods

    @property
    def under_load(self) -> bool:
        """Whether the pull speed ``Vp`` is a state (a constant load), not the fixed ``params.V``."""
        return "Vp" in self.states

    def accepts(self, params: PeelParams) -> bool:
        """Whether ``params`` describe this model (the registry picks the first that does: :func:`model_of`)."""
        return params.variant is None

    def law(self, params: PeelParams) -> CompiledLaw:
        """The compiled peel-force law of ``params`` at ``params.V`` (:func:`peelapprox.kernels.compiled_law`)."""
        return compiled_law(params.force, params.V)

    def field(self, params: PeelParams, law: CompiledLaw, eps: float | None) -> tuple[Callable, Callable]:
        """The smooth field ``fun(t, y)`` and its Jacobian ``jac(t, y)`` of the state :attr:`states` (scipy's
        form), for the compiled law ``law`` and, where the model has one, the regularisation ``eps``."""
        raise NotImplementedError(f"model {self.name!r} has no smooth field")

    def y0(self, params: PeelParams, s0: State) -> np.ndarray:
        """The integrated state at the start ``s0`` (a new array in the layout :attr:`states`)."""
        extra = [params.V if s0.Vp is None else s0.Vp] if self.under_load else []
        return np.array([s0.alpha, s0.omega, s0.F, s0.v] + extra)

    def atol(self, atol: np.ndarray) -> np.ndarray:
        """A method's 4 absolute tolerances ``(α, ω, F, v)`` extended to :attr:`states` (``Vp`` on the scale of
        v)."""
        return np.append(atol, atol[3]) if self.under_load else atol

    def initial_state(self, params: PeelParams, *, alpha0: float = 0.0, omega0: float | None = None,
                      F0: float | None = None, branch0: str | None = None, Vp0: float | None = None) -> State:
        """The consistent start of a run (:func:`exact.initial_state`; ``Vp0`` is refused under velocity control,
        a ValueError naming it)."""
        st0 = initial_state(params, alpha0=alpha0, omega0=omega0, F0=F0, branch0=branch0)
        if Vp0 is not None:
            raise ValueError(f"Vp0 (the initial pull speed) applies only under loading='load'; got Vp0={Vp0!r} "
                             "with loading='velocity' (the pull speed is params.V)")
        return st0

    def failure_hint(self, params: PeelParams) -> str:
        """What to add to a scipy solver's failure message (empty: nothing)."""
        return ""


#: The models of :func:`exact.simulate` by name, in the order :func:`model_of` tries them (the built-in ones
#: entered by :mod:`exact._models`).
MODELS: dict[str, Model] = _registry.MODELS  # one dict: the registry's (exact/_registry.py), typed here


def register_model(model: Model) -> Model:
    """Enter ``model`` in :data:`MODELS` under its name (TypeError for a non-:class:`Model`, ValueError for a name
    taken by another model); returns it."""
    if not isinstance(model, Model):
        raise TypeError(f"model must be an exact.Model, got {type(model).__name__}")
    if MODELS.get(model.name, model) is not model:
        raise ValueError(f"a model named {model.name!r} is registered already: {MODELS[model.name]!r}")
    MODELS[model.name] = model
    return model


def model_of(params: PeelParams) -> Model:
    """The model ``params`` describe: the first of :data:`MODELS` that accepts them."""
    return cast(Model, _registry.model_of(params))


def model_parameters() -> dict[str, Model]:
    """The numeric parameters of the models (their ``parameters`` that no model's ``selected_by`` names: a tape mass,
    a load's mass and force), each with the first model of :data:`MODELS` that lists it, in the order of
    :class:`peelapprox.PeelParams`' fields."""
    from peelapprox import PeelParams

    selectors = {n for m in MODELS.values() for n, _ in m.selected_by}
    found: dict[str, Model] = {}
    for m in MODELS.values():
        for n, _ in m.parameters:
            if n not in selectors:
                found.setdefault(n, m)
    order = [f.name for f in dataclasses.fields(PeelParams)]
    return {n: found[n] for n in sorted(found, key=order.index)}

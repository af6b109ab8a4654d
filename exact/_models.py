"""The built-in models of :func:`exact.simulate` (the contract: :mod:`exact._model`), entered in ``MODELS``.

================  =========================================================  ===========================
name              the model                                                  methods (default first)
================  =========================================================  ===========================
``massless``      the paper's massless tape under velocity control (FLOW1,   hybrid, regularized
                  FLOW2, flow3, CONSTR; XDAE with ε for the scheme)
``massless_load`` the massless tape under a constant load (XDAE, ``V → V_p``) regularized
``tape_mass``     the tape-mass model under velocity control                 smooth
``tape_mass_load`` the tape-mass model under a constant load                 smooth
================  =========================================================  ===========================

The variants' fields are the compiled ones of :func:`peelapprox.kernels.bound_variant_field` (the law bound
in); the paper's massless model's is the ε-regularised XDAE field, with fvV inlined (the paper's law) or the law
as an argument.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, cast

from peelapprox.kernels import (
    ALL_LAWS,
    CompiledLaw,
    bound_variant_field,
    regularized_field,
    regularized_field_jacobian,
    regularized_law_field,
    regularized_parameters,
    variant_parameters,
)
from peelapprox.validate import in_range

from ._initial import initial_state
from ._model import Model, register_model

if TYPE_CHECKING:
    from peelapprox import PeelParams

    from ._trajectory import State

__all__ = ["Massless", "MasslessLoad", "TapeMass", "TapeMassLoad", "VP0_MAX"]

#: Largest initial pull speed ``Vp0`` [m/s] under a load: the model's velocities stay below 1e3 m/s (STATE_RANGES).
VP0_MAX = 1e3

_VARIANT_EVENTS = ("arrest", "slack", "v_positive", "law_domain", "v_floor")
#: The variants' fields of PeelParams and their units (a trajectory shows those set): the tape mass, the loading
#: (which selects velocity control or a load) and the load's mass and force.
_TAPE, _LOADING, _LOAD = (("tape_mass", "kg"),), (("loading", ""),), (("load_mass", "kg"), ("load", "N"))


@dataclass(frozen=True, kw_only=True)
class Massless(Model):
    """The paper's massless tape under velocity control: FLOW1, FLOW2, flow3 with the constraint CONSTR; its
    smooth field is the ε-regularised XDAE ``M Ẋ = φ(X)``, ``M = diag(1, 1, 1, ε)``, of the regularised method
    (the hybrid method integrates the ε → 0 limit with a field of its own, :func:`exact.hybrid_field`)."""

    name: str = "massless"
    about: str = "the massless tape under velocity control (the paper's model)"
    methods: tuple[str, ...] = ("hybrid", "regularized")

    def field(self, params: PeelParams, law: CompiledLaw, eps: float | None) -> tuple[Callable, Callable]:
        if law.inlined:  # the paper's law: fvV inlined in the field (the default)
            q = regularized_parameters(params, cast(float, eps), ("paper",))
            return (lambda t, y: regularized_field(y, q)), (lambda t, y: regularized_field_jacobian(y, q))
        q = regularized_parameters(params, cast(float, eps), ALL_LAWS)
        lfun, ljac = regularized_law_field()
        fn, coef = law.fn, law.coef
        return (lambda t, y: lfun(y, q, fn, coef)), (lambda t, y: ljac(y, q, fn, coef))


class _Variant(Model):
    """A model variant with a compiled field of :mod:`peelapprox.kernels` (``variant``, by name)."""

    variant: str = ""

    def accepts(self, params: PeelParams) -> bool:
        return params.variant == self.variant

    def _mass(self, params: PeelParams, eps: float | None) -> float:
        """The field's first parameter: the tape mass m [kg] (ε for the massless tape under a load)."""
        return eps if eps is not None else cast(float, params.tape_mass)

    def field(self, params: PeelParams, law: CompiledLaw, eps: float | None) -> tuple[Callable, Callable]:
        vfun, vjac = bound_variant_field(self.variant, law.fn)  # the law bound in: ~1 us a call, not ~65 us
        q = variant_parameters(params, self._mass(params, eps), params.load_mass or 1.0, params.load or 0.0)
        coef = law.coef
        return (lambda t, y: vfun(y, q, coef)), (lambda t, y: vjac(y, q, coef))


class _Loaded(_Variant):
    """A model under a constant load: the pull speed ``V_p`` is a state, starting at ``Vp0`` (default V)."""

    def initial_state(self, params: PeelParams, *, alpha0: float = 0.0, omega0: float | None = None,
                      F0: float | None = None, branch0: str | None = None, Vp0: float | None = None) -> State:
        st0 = initial_state(params, alpha0=alpha0, omega0=omega0, F0=F0, branch0=branch0)
        return st0 if Vp0 is None else dataclasses.replace(st0, Vp=in_range("Vp0", Vp0, 0.0, VP0_MAX))


@dataclass(frozen=True, kw_only=True)
class MasslessLoad(_Loaded):
    """The massless tape under a constant load (``loading="load"``): XDAE with ``V → V_p`` and
    ``M V̇_p = F_L - F``, regularised by ε (docs/constant-load.md)."""

    name: str = "massless_load"
    about: str = "the massless tape under a load (loading='load')"
    states: tuple[str, ...] = ("alpha", "omega", "F", "v", "Vp")
    methods: tuple[str, ...] = ("regularized",)
    events: tuple[str, ...] = _VARIANT_EVENTS + ("no_root", "jump")
    parameters: tuple[tuple[str, str], ...] = _LOADING + _LOAD
    selected_by: tuple[tuple[str, object], ...] = (("loading", "load"),)
    variant: str = "eps_load"


def _small_mass_hint(params: PeelParams) -> str:
    return ("; at so small a tape mass the model is the massless one to ~m^(2/3) (docs/tape-mass.md): use "
            "tape_mass=None" if cast(float, params.tape_mass) < 1e-9 else "")


@dataclass(frozen=True, kw_only=True)
class TapeMass(_Variant):
    """The tape-mass model under velocity control (``PeelParams(tape_mass=m)``): a smooth ODE whose jumps arise
    from the ribbon's inertia (docs/tape-mass.md)."""

    name: str = "tape_mass"
    about: str = "the tape-mass model (params.tape_mass) under velocity control"
    methods: tuple[str, ...] = ("smooth",)
    events: tuple[str, ...] = _VARIANT_EVENTS + ("jump",)
    parameters: tuple[tuple[str, str], ...] = _TAPE + _LOADING
    variant: str = "tape"

    def failure_hint(self, params: PeelParams) -> str:
        return _small_mass_hint(params)


@dataclass(frozen=True, kw_only=True)
class TapeMassLoad(_Loaded):
    """The tape-mass model under a constant load (``tape_mass=m, loading="load"``)."""

    name: str = "tape_mass_load"
    about: str = "the tape-mass model (params.tape_mass) under a load"
    states: tuple[str, ...] = ("alpha", "omega", "F", "v", "Vp")
    methods: tuple[str, ...] = ("smooth",)
    events: tuple[str, ...] = _VARIANT_EVENTS + ("jump",)
    parameters: tuple[tuple[str, str], ...] = _TAPE + _LOADING + _LOAD
    selected_by: tuple[tuple[str, object], ...] = (("loading", "load"),)
    variant: str = "tape_load"

    def failure_hint(self, params: PeelParams) -> str:
        return _small_mass_hint(params)


for _m in (Massless(), MasslessLoad(), TapeMass(), TapeMassLoad()):
    register_model(_m)


def solving(model: Model, methods: dict[str, Any]) -> list[str]:
    """The names of ``methods`` (the table ``METHODS``) that solve ``model``, in the table's order: those the model
    lists and those that claim it in their own ``models``."""
    return [n for n, m in methods.items() if n in model.methods or model.name in m.models]


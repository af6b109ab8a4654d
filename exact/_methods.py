"""The built-in solver methods of :func:`exact.simulate` (the contract: :mod:`exact._method_contract`): the hybrid
ε → 0 limit, the paper's ε-regularised scheme and the model variants' smooth ODE, entered in ``METHODS``."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, ClassVar

from peelapprox import EPS_DEFAULT
from peelapprox.validate import eps as _eps

from ._hybrid_driver import run_hybrid
from ._method_contract import METHODS, Method

if TYPE_CHECKING:
    from peelapprox import PeelParams

    from ._model import Model
    from ._options import Budget, SaveAt
    from ._trajectory import State, Trajectory

__all__ = ["Hybrid", "Regularized", "Smooth", "ATOL_SCALE", "STEP_BUDGET"]


@dataclass(frozen=True, kw_only=True)
class Hybrid(Method):
    """The ε → 0 limit (``method="hybrid"``): compiled DOP853 on the branch dynamics, exact fold jumps.

    Parameters
    ----------
    rtol : float
        Relative tolerance, in ``RTOL_RANGE`` = [1e-14, 1e-2].
    atol : None, float or 4 floats
        Absolute tolerance of ``(τ, α, ω, ln v)``, each in :data:`ATOL_RANGE` = [1e-100, 1]; a scalar is
        used for every component and stored as 4 values; ``None``: ``rtol * ATOL_SCALE["hybrid"]``.
    v_floor : float, optional
        Stop with ``ModelBreakdown(reason="v_floor")`` when v falls to this velocity [m/s], in (0, inf) (a
        threshold of the caller's, not of the model); None: the model's own criterion only.  On AB the level
        ``G = F(1 - cos θ)`` falling to ``f(0+, V)`` leaves CONSTR without a root (the peel front would have to
        stop): ``ModelBreakdown(reason="no_root")`` once ``G - f(0+) <= 1e-10 max(|f(0+)|, 1 N)``, i.e. v below
        ``BranchStructure.v_breakdown`` (~1e-67 m/s; this method integrates ln v, so it follows v that far).

    Raises
    ------
    ValueError, TypeError
        A field outside its range or of the wrong kind, named as the ``simulate`` keyword of that name.
    """

    name: ClassVar[str] = "hybrid"
    about: ClassVar[str] = ("the eps -> 0 limit of the massless tape under velocity control, integrated by its own "
                            "DOP853")
    #: (τ [s], α [rad], ω [rad/s], ln v [-]): the smallest magnitudes that matter on the paper's orbits (α
    #: oscillates with amplitude >= ~1e-3 rad, segments last >= ~1e-4 s); ln v is controlled to
    #: ``rtol (1 + |ln v|)``, a relative accuracy of v at every speed.
    atol_scale: ClassVar[tuple[float, ...]] = (1e-6, 1e-4, 1e-3, 1.0)
    #: The stress suite's grid needs <= ~1.5e4 steps per simulated second (I = 1e-6, rtol 1e-8; 1.3-1.8 us
    #: each): a margin of ~50x; the cap bounds a default call to ~35 s (t_end = 1e300).
    step_budget: ClassVar[tuple[float, float, float]] = (1e6, 1e6, 2e7)
    rtol: float = 1e-8
    atol: float | Sequence[float] | None = None
    v_floor: float | None = None

    def run(self, model: Model, params: PeelParams, t_end: float, s0: State, saveat: SaveAt, budget: Budget,
            progress: Callable[[float, float], None] | None) -> Trajectory:
        return run_hybrid(params, t_end, s0, self, saveat, budget, progress)  # the massless model's eps -> 0 limit


class _OnScipy(Method):
    """A method run on a scipy solver by :func:`exact._regularized.run_regularized`."""

    def run(self, model: Model, params: PeelParams, t_end: float, s0: State, saveat: SaveAt, budget: Budget,
            progress: Callable[[float, float], None] | None) -> Trajectory:
        # imported on first use: scipy's solvers are not on the hybrid method's path (docs/performance.md)
        from ._regularized import run_regularized

        return run_regularized(model, params, t_end, s0, self, saveat, budget, progress)


@dataclass(frozen=True, kw_only=True)
class Regularized(_OnScipy):
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
    about: ClassVar[str] = "the paper's eps-scheme for the massless tape (the pull speed a state under a load)"
    #: (α [rad], ω [rad/s], F [N], v [m/s]); the regularised v stays >= ~1e-3 m/s on AB.
    atol_scale: ClassVar[tuple[float, ...]] = (1e-4, 1e-3, 1e-2, 1e-6)
    #: ~1e3 steps per simulated second needed (~150 us each); the cap bounds a default call to ~80 s.
    step_budget: ClassVar[tuple[float, float, float]] = (1e5, 1e5, 5e5)
    solvers: ClassVar[tuple[str, ...]] = ("Radau", "BDF", "LSODA")
    eps: float = EPS_DEFAULT
    solver: str = "Radau"
    rtol: float = 1e-8
    atol: float | Sequence[float] | None = None
    v_floor: float | None = None

    def _check_own(self) -> None:
        object.__setattr__(self, "eps", _eps("eps", self.eps))


@dataclass(frozen=True, kw_only=True)
class Smooth(_OnScipy):
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
    about: ClassVar[str] = "the tape-mass model's smooth ODE (its jumps arise from the ribbon's inertia)"
    atol_scale: ClassVar[tuple[float, ...]] = (1e-4, 1e-3, 1e-2, 1e-6)
    #: LSODA at rtol 1e-8 needs 1.8e4-1.3e5 steps per simulated second over m = 1e-9 ... 1e-1 kg (9-19 us each;
    #: ``python -m comparisons.benchmark.tape_mass``): a margin of ~8x, and the cap ~60 s of LSODA (Radau and
    #: BDF take 10-20x longer per step: give them ``max_wall``).
    step_budget: ClassVar[tuple[float, float, float]] = (1e6, 1e5, 5e6)
    solvers: ClassVar[tuple[str, ...]] = ("Radau", "BDF", "LSODA", "DOP853", "RK45")
    solver: str = "LSODA"
    rtol: float = 1e-8
    atol: float | Sequence[float] | None = None
    v_floor: float | None = None



METHODS.update({m.name: m for m in (Hybrid, Regularized, Smooth)})

#: Default absolute tolerances per method, ``rtol * ATOL_SCALE[name]`` (each class's ``atol_scale``).
ATOL_SCALE = {name: m.atol_scale for name, m in METHODS.items()}
#: Default step budget per method, ``(rate per simulated second, floor, cap)`` (each class's ``step_budget``);
#: a run that needs more raises SolverBudgetExceeded naming max_steps.
STEP_BUDGET = {name: m.step_budget for name, m in METHODS.items()}

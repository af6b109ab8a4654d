"""The branch structure and the fixed point of any peel-force law at a pull speed: what the solvers read.

:func:`branch_structure` is the one function for every law (the paper's fvV by default): the
:class:`~peelapprox.law._folds.BranchStructure` that every solver uses for it, from its compiled form
(:func:`peelapprox.law._compiled.compiled_law`).  :func:`fixed_point` is the steady sliding ``v = V`` and its
stability.
"""

from __future__ import annotations

from dataclasses import dataclass

from .._checks import in_range
from .._ranges import PARAM_RANGES
from ._compiled import compiled_law
from ._folds import BranchStructure
from ._force import PeelForce
from ._paper import check_V

__all__ = ["FixedPoint", "branch_structure", "fixed_point"]


def branch_structure(V: float, force: PeelForce | None = None) -> BranchStructure:
    """Folds, inflection, landing and breakdown velocities of ``f(·, V)``; cached per law and V.

    For fvV the folds are the two roots of ``f'(v, V) = 0`` either side of the unique minimiser of ``f'``, each
    located by Brent's method to ``xtol = 4 ulp``, robust near the cusp where they merge (``V ≈ 5.2``).  For
    another law, its :meth:`PeelForce.folds` and, from its compiled kernel, ``f(0+)`` (or f at the start of its
    domain), the breakdown velocity and the minimiser of f'.

    Parameters
    ----------
    V : float
        Pull speed [m/s], in ``PARAM_RANGES["V"]``.
    force : PeelForce, optional
        The law (default: the paper's fvV).

    Returns
    -------
    BranchStructure

    Raises
    ------
    ValueError
        If V is outside ``PARAM_RANGES["V"]`` (TypeError if not a number), or the law's folds cannot be found
        (the message names ``params.force``).
    """
    return compiled_law(force or PeelForce.paper(), check_V(V)).structure


@dataclass(frozen=True)
class FixedPoint:
    """The steady state ``α = 0, ω = V/R, v = V, F = f(V, V)`` (Sec. II).

    ``stable`` is ``f'(V, V) > 0``: the paper's Hopf criterion.
    """

    alpha: float
    omega: float
    F: float
    v: float
    fprime: float
    stable: bool


def fixed_point(V: float, R: float = 0.1, *, force: PeelForce | None = None) -> FixedPoint:
    """Fixed point ``α = 0, ω = V/R, v = V, F = f(V, V)`` of FLOW1–flow3 with CONSTR and its stability
    (``f'(V, V) > 0``: the paper's Hopf criterion).

    ``V`` and ``R`` must lie in :data:`peelapprox.PARAM_RANGES`; ``force`` (a :class:`peelapprox.PeelForce`;
    None: fvV) is the law, evaluated at ``v = V`` (ValueError if V is outside its domain).
    """
    V = check_V(V)
    R = in_range("R", R, *PARAM_RANGES["R"])
    law = force or PeelForce.paper()
    f, fp = law.impl.value_slope(law, V)
    return FixedPoint(0.0, V / R, f, V, fp, fp > 0)

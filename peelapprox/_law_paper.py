"""Hands the built-in law fvV and the parameter ranges to :mod:`peelapprox._law` (run at ``import peelapprox``).

:mod:`peelapprox._law` cannot import :mod:`peelapprox._peelforce` or :mod:`peelapprox._params` (the latter
imports it for ``PeelParams.force``: an import circle), so ``PeelForce.paper()`` is evaluated by the
functions registered here: :func:`peelapprox.peel_force` and :func:`peelapprox.peel_force_derivative`
themselves (bitwise), its folds by :func:`peelapprox.branch_structure`, V checked against
``PARAM_RANGES["V"]`` and v against ``STATE_RANGES["v"]``.
"""

from __future__ import annotations

from ._law import register_paper
from ._params import PARAM_RANGES, STATE_RANGES
from ._peelforce import branch_structure, peel_force, peel_force_derivative

__all__: list[str] = []


def _evaluate(v, V, order: int):
    """The built-in law's f (order 0, :func:`peel_force`), f' or f'' (:func:`peel_force_derivative`)."""
    return peel_force(v, V) if order == 0 else peel_force_derivative(v, V, order)


register_paper(evaluate=_evaluate, branch_structure=branch_structure, V_range=PARAM_RANGES["V"],
               v_range=STATE_RANGES["v"])

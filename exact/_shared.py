"""What the solving room lends to both the orbits and the dynamics rooms (and to the tangent driver, which serves
both): the default wall budget of the calls made of many solver runs, the guard of the tools built on the hybrid
solver's jumps, and the natural sizes by which perturbations of a state are measured.

They live here, beside the solvers, so that :mod:`exact.orbits` needs nothing from :mod:`exact.dynamics`.
"""

from __future__ import annotations

import numpy as np

from peelapprox import PeelParams, branch_structure

from ._model import model_of

__all__ = ["DEFAULT_MAX_WALL", "natural_scales", "paper_model_only"]

#: Default wall-clock budget [s] of the calls made of many solver runs (lyapunov, lyapunov_return_map,
#: attractors, periodic_orbit, continue_orbit, ...): their work grows with counts (n, n_returns, starts, points)
#: that no step budget bounds.
DEFAULT_MAX_WALL = 3600.0


def paper_model_only(params: PeelParams, what: str, instead: str = "") -> None:
    """Refuse a model the hybrid method does not solve (a tape mass or a constant load) for ``what``, a tool built on
    the hybrid solver's jumps (its section returns, tangent dynamics and saltation matrices), with a ValueError
    naming ``params`` and the model it supports (``instead``: what to use for the variant)."""
    model = model_of(params)
    if not model.has_hybrid:
        raise ValueError(
            f"{what} supports the paper's massless, velocity-controlled model only (the hybrid method's jumps and "
            f"saltation matrices), got params of the model {model.name!r}, {model.about}"
            + (f"; {instead}" if instead else ""))


def natural_scales(params: PeelParams) -> np.ndarray:
    """The natural sizes ``(1 rad, V/R, f_max)`` of ``(α, ω, F)``: every Lyapunov estimate measures
    perturbations in ``(δα, δω, δF)`` divided by these (``f_max`` of the law ``params.force`` at V, its
    :func:`peelapprox.branch_structure`; 1 N when f has no folds)."""
    bs = branch_structure(params.V, force=params.force)
    return np.array([1.0, params.V / params.R, bs.f_max if bs.has_folds else 1.0])

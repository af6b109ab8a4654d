"""Linear stability of a uniform front against transverse modes (docs/peel-front.md, "Transverse modes")."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .._checks import in_range
from ._params import FrontParams

__all__ = ["TransverseModes", "transverse_growth_rates"]


@dataclass(frozen=True)
class TransverseModes:
    """The transverse modes of a uniform front at peel velocity ``v``.

    ``n`` the mode numbers 1 … N-1, ``q`` their wavenumbers (``2πn/N`` periodic, ``πn/N`` free), ``s = sin²(q/2)``,
    ``rates`` the two roots λ of each mode (shape (N-1, 2), complex, larger real part first), ``unstable`` which
    modes grow (Re λ > 0), ``f_slope`` = f'(v, V) [N s/m].
    """

    v: float
    f_slope: float
    n: np.ndarray
    q: np.ndarray
    s: np.ndarray
    rates: np.ndarray
    unstable: np.ndarray


def transverse_growth_rates(params: FrontParams, v: Any = None) -> TransverseModes:
    """The growth rates of the transverse modes of a uniform front at peel velocity ``v`` (frozen coefficients).

    A perturbation of the uniform front by a mode of the discrete Laplacian (eigenvalue ``-4 s_q``,
    ``s_q = sin²(q/2)``) leaves the mean (the roller, ū, v̄) unchanged to first order and obeys

    ``m λ² + (f'(v) + 4 N Γ s_q) λ + k + 4 N k_c s_q = 0``

    (the per-strip equation of docs/peel-front.md linearised).  A mode grows iff ``f'(v) + 4NΓ s_q < 0``: only on
    the unstable branch, and there only while ``γ s_q < |f'(v)|/|f'_u|``; hence ``γ = 4NΓ/|f'_u|`` decides.

    Parameters
    ----------
    params : FrontParams
    v : float, optional
        The uniform front's peel velocity [m/s], > 0; default the inflection velocity (the steepest slope).

    Returns
    -------
    TransverseModes
    """
    if not isinstance(params, FrontParams):
        raise TypeError(f"params must be a FrontParams, got {type(params).__name__}")
    from ..law import branch_structure

    base = params.base
    if v is None:
        v = branch_structure(base.V, force=base.force).v_inflection
    v = in_range("v", v, 0.0, 1e6, lo_open=True)
    fp = float(base.force.df(v, base.V))
    N = params.N
    n = np.arange(1, N, dtype=float)
    q = (2.0 if params.ends == "periodic" else 1.0) * np.pi * n / N
    s = np.sin(q / 2) ** 2
    b = fp + 4.0 * N * float(params.Gamma or 0.0) * s  # both set by FrontParams
    c = base.k + 4.0 * N * float(params.k_c or 0.0) * s
    disc = np.sqrt((b * b - 4.0 * params.m * c).astype(complex))
    lam = np.stack([(-b + disc) / (2 * params.m), (-b - disc) / (2 * params.m)], axis=1)
    return TransverseModes(float(v), fp, n.astype(int), q, s, lam, lam.real.max(axis=1) > 0.0)

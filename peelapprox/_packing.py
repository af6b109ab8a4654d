"""The model block: how every compiled driver receives :class:`~peelapprox.PeelParams` in its float vector.

A numba kernel takes the model as one float64 vector.  Every driver's vector starts with the same
**model block**, defined here once::

    index   constant  value
    0       M_V       V, pull speed of the motor [m/s] (fvV, flow3)
    1       M_I       I, moment of inertia of the roller tape [kg m²] (FLOW2)
    2       M_K       k, elastic constant of the tape [N/m] (flow3)
    3       M_R       R, roller radius [m] (FLOW1, FLOW2)
    4       M_L       l, distance O-O' between the roller axis and the motor [m] (full geometry only)
    5       M_B       b(V) = -2 V^1.5, coefficient of fvV (``peel_force_coefficients``)
    6       M_A       A(V) = 415 - 45 V^0.4 - 0.35 V^2.15, the prefactor of -v^0.5 in fvV
    7       M_GEOM    closure of cos θ: 0 = the paper's ``-sin α``, 1 = the full geometry ``-l sin α / L``

and a driver appends its own fields after it, numbering them from :data:`N_M` (the hybrid solver's fold and
landing velocities in ``exact._hybrid``, the reduced segment's α model and entry state in
:mod:`peelapprox._reduced._segment_kernel`).  The kernels read every entry by its named constant.  The constants are
frozen into the compiled kernels, so this file is one of :data:`peelapprox._compiled._jit.KERNEL_SOURCES`.
"""

from __future__ import annotations

import numpy as np

from ._params import PeelParams
from .law import require_law
from .law._paper import peel_force_coefficients

__all__ = ["MODEL_FIELDS", "M_V", "M_I", "M_K", "M_R", "M_L", "M_B", "M_A", "M_GEOM", "N_M", "model_block"]

#: The model block's entries, in order (module docstring).
MODEL_FIELDS = ("V", "I", "k", "R", "l", "b", "A", "geometry")
M_V, M_I, M_K, M_R, M_L, M_B, M_A, M_GEOM = range(len(MODEL_FIELDS))
#: Length of the model block: a driver's own fields start at this index.
N_M = len(MODEL_FIELDS)


def model_block(params: PeelParams, size: int = N_M, laws: tuple[str, ...] = ("paper",)) -> np.ndarray:
    """A driver's parameter vector of length ``size`` with the model block filled and the rest zero.

    Parameters
    ----------
    params : PeelParams
        Already validated.
    size : int, default N_M
        Length of the driver's vector, ``N_M`` plus its own fields (which the driver fills).
    laws : tuple of str, default ("paper",)
        The laws ``params.force`` may be (``peelapprox.law.law_label`` names): those the calling driver
        honours.  A driver that takes the law as an argument (the hybrid law driver: ``"cubic"``) passes it
        its own coefficients; for such a law the slots ``b, A`` of fvV are unused and hold 0.0 (not NaN, which
        the vector's checks would trip on).

    Returns
    -------
    ndarray
        ``(V, I, k, R, l, b, A, geometry, 0, ..., 0)``, float64.
    """
    require_law(params, "the compiled drivers (model_block)", laws)
    if size < N_M:
        raise ValueError(f"size must be at least the model block's length {N_M}, got {size}")
    b, A = peel_force_coefficients(params.V) if params.force.inlined else (0.0, 0.0)
    p = np.zeros(size)
    p[:N_M] = params.V, params.I, params.k, params.R, params.l, b, A, 0.0 if params.geometry == "paper" else 1.0
    return p

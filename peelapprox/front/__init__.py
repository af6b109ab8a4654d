"""The peel front as a line of N strips and its acoustic emission (docs/peel-front.md).

A reconstruction of the spatially extended model of De & Ananthakrishna (PRL 97, 165503 (2006)) and Kumar, De &
Ananthakrishna (PRE 78, 066119 (2008)) on top of the library's tape-mass model: :class:`FrontParams` (the
parameters), :func:`front_pattern` (the pattern classes of an orbit), :func:`transverse_growth_rates` (the
linear stability of a uniform front).  The solver is :func:`exact.simulate_front`.
"""

from ._observables import PATTERN_CLASSES, PATTERN_THRESHOLDS, FrontPattern, front_pattern
from ._params import (
    FRONT_DELTA0_RANGE,
    FRONT_ENDS,
    FRONT_GAMMA_RANGE,
    FRONT_KAPPA_RANGE,
    FRONT_N_RANGE,
    FrontParams,
)
from ._stability import TransverseModes, transverse_growth_rates

__all__ = ["FrontParams", "FrontPattern", "front_pattern", "transverse_growth_rates", "TransverseModes",
           "PATTERN_CLASSES", "PATTERN_THRESHOLDS", "FRONT_N_RANGE", "FRONT_ENDS", "FRONT_GAMMA_RANGE",
           "FRONT_KAPPA_RANGE", "FRONT_DELTA0_RANGE"]

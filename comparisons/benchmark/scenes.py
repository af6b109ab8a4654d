"""The benchmark's scenes and its error metric on the jump sequence (see :mod:`comparisons.benchmark`)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from peelapprox import PeelParams

__all__ = ["BenchScene", "BENCH_SCENES", "jump_errors"]


@dataclass(frozen=True)
class BenchScene:
    """One work-precision scene: parameters, start and horizon (all jumps in the horizon are compared)."""

    name: str
    V: float
    I: float
    horizon: float
    alpha0: float = 0.0

    @property
    def params(self) -> PeelParams:
        return PeelParams(V=self.V, I=self.I)


#: The three scenes of the work-precision benchmark (the paper's Cases I-III).  Horizons hold 8, 35 and 47
#: jumps: every part of a solver is exercised (folds, both branches, landings, the rapid-jump cascades of
#: Cases II-III), while scipy's Radau at ε = 1e-10 and rtol 1e-9 still finishes each in ~10 s.
BENCH_SCENES = (
    BenchScene("V1-I1e-5", 1.0, 1e-5, 0.3),
    BenchScene("V1-I1e-2", 1.0, 1e-2, 0.5),
    BenchScene("V4-I1e-2", 4.0, 1e-2, 0.05, alpha0=0.3),
)


def jump_errors(t: np.ndarray, F: np.ndarray, t_ref: np.ndarray, F_ref: np.ndarray) -> tuple[float, float]:
    """The benchmark's error metric: ``(max |Δt_j| / T̄_ref, max |ΔF_j| / F_j^ref)`` over the reference's jumps
    (all of them in the horizon; T̄_ref the reference's mean interval between jumps); the reported error is the
    larger of the two.  ``(inf, inf)`` if the run has a different number of jumps: it is on another orbit.  The
    regularised runs record a jump where v crosses the inflection velocity of f, the hybrid one at the fold."""
    if len(t_ref) < 2:
        raise ValueError(f"the reference needs at least 2 jumps in the horizon, got {len(t_ref)}")
    if len(t) != len(t_ref):
        return math.inf, math.inf
    T = (t_ref[-1] - t_ref[0]) / (len(t_ref) - 1)
    return float(np.max(np.abs(t - t_ref)) / T), float(np.max(np.abs(F - F_ref) / np.abs(F_ref)))

"""The peel front's solver (docs/peel-front.md): :func:`simulate_front` and its result :class:`FrontTrajectory`."""

from ._simulate import ATOL_SCALE_FRONT, simulate_front
from ._trajectory import FrontTrajectory, LocalSwitches

__all__ = ["simulate_front", "FrontTrajectory", "LocalSwitches", "ATOL_SCALE_FRONT"]

"""Periodic orbits of the hybrid DAE and their branches: the AB→CD section map and its saltation Jacobian
(``section_return``, ``monodromy_fd``), orbits by Newton (``periodic_orbit``, ``solve_orbit``), continuation in a
parameter with the bifurcations located (``continue_orbit``; their kinds in one table, ``_kinds``), the crest and
grazing ends of a branch (``crest_margin``) and the switch to the doubled branch (``switch_branch``).

Built on the solvers and the tangent driver of :mod:`exact`; never on :mod:`exact.dynamics`, which builds on it.
Every name here is also :mod:`exact`'s.
"""

from ._continuation import Bifurcation, BranchPoint, OrbitBranch, continue_orbit
from ._corrector import parameter_value, with_parameter
from ._crest import Crest, crest_margin
from ._periodic import PeriodicOrbit, periodic_orbit, solve_orbit
from ._section import SectionReturn, monodromy_fd, section_return
from ._switch import switch_branch

__all__ = [
    "periodic_orbit", "PeriodicOrbit", "solve_orbit", "section_return", "SectionReturn", "monodromy_fd",
    "continue_orbit", "OrbitBranch", "BranchPoint", "Bifurcation", "switch_branch", "crest_margin", "Crest",
    "with_parameter", "parameter_value",
]

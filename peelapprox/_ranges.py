"""The model's constant ranges and defaults: the valid range of each parameter and state variable, the tolerances.

Plain constants, importing nothing of the package, so that every module (the law's among them) can check its
arguments against them without an import circle through :class:`peelapprox.PeelParams`.
"""

from __future__ import annotations

import math
import types

__all__ = ["F0_FACTOR", "EPS_DEFAULT", "EPS_RANGE", "GRAVITY", "LOADINGS", "TAPE_MASS_RANGE", "LOAD_MASS_RANGE",
           "LOAD_RANGE", "LYAPUNOV_TAU", "RTOL_RANGE", "T_TRANSIENT", "WINDOW_DEFAULTS", "GEOMETRIES",
           "L_OVER_R_MIN", "PARAM_RANGES", "STATE_RANGES", "TIME_MAX", "default_load_masses"]

#: Closures of ``cos θ`` available to the model.  ``"paper"`` is the paper's
#: numerics, ``cos θ = -sin α`` (used in FLOW2, flow3 and CONSTR);  ``"exact"``
#: is the full geometry ``cos θ = -l sin α / L``, ``L² = l² + R² - 2 l R cos α``.
GEOMETRIES = ("paper", "exact")

#: Smallest ``l/R``: closer, the exact closure's ``L(α) = l - R + O(α²)`` cancels (see ``l`` below).
L_OVER_R_MIN = 1.001

#: Valid range ``(lo, hi)`` of each numeric field of :class:`PeelParams`, closed at both ends (``l`` also needs
#: ``l >= L_OVER_R_MIN * R``).  Chosen so that every function of the package returns or raises a
#: documented exception (no overflow, no division by zero, no bracket failure) with room to spare.
#:
#: The paper's values are V = 0.05-8 m/s, I = 1e-6-1e-1 kg m², k = 1000 N/m, R = 0.1 m.  Beyond the bounds
#: the runs fail with ZeroDivisionError, OverflowError or bracket
#: errors, or take unbounded time.  Measured with ``estimate``,
#: ``reduced_segment`` and a 0.2 s ``exact.simulate(..., save="jumps")``
#: in both geometries, around V = 2, I = 1e-4:
#:
#: * ``V`` in [1e-6, 100] m/s.  The law fvV is fitted to the paper's
#:   V <= 10; its ``f(0+, V) = 130 - 2 V^1.5`` is negative above 16 m/s.
#:   Numerically, the fixed point ``f(V, V) ~ 130 e^(V/11)`` overflows at
#:   V ~ 7800, and the solvers' root bracket (v <= 300 m/s) fails already
#:   at V = 300 (exact.simulate: "f(a) and f(b) must have different
#:   signs"); V = 100 and 200 work.  Below 1e-6 m/s nothing fails (V =
#:   1e-300 ends in a documented breakdown) but the stick phase lasts
#:   ``(f_max - f_min)/(k V)`` > 1e5 s: not a pull speed.
#: * ``I`` in [1e-12, 1e6] kg m².  The inertial period ``2π sqrt(I/(F R))``
#:   is 1.2e-6 s at I = 1e-12 (a 0.2 s run: 2 s of wall time); at 1e-15 it
#:   does not finish in 20 s.  1e6 kg m² (a 10 t flywheel) is used by the
#:   tests as the inertia-free limit; 1e9 also works.
#: * ``k`` in [1e-3, 1e7] N/m.  The stiff time ``sqrt(I/(k R²))`` sets the
#:   step: 0.2 s take 1.1 s at k = 1e7, 16 s at 1e8, over 20 s at 1e9;
#:   ``k = 1e300`` divides by zero (the default absolute tolerances).  Down to
#:   k = 1e-6 every run returns (the reduced segment then exhausts its step
#:   budget, a documented SolverBudgetExceeded).
#: * ``R`` in [1e-4, 10] m.  ``V/R`` and ``F R/I`` set the fast scales:
#:   R = 1e-4 takes 0.3 s, 1e-5 5 s, 1e-6 over 20 s; ``R = 1e-300`` divides
#:   by zero.  R = 100 (with l = 1000) still works; 10 m is a generous roller.
#: * ``l`` in [1.001 R, 1e3] m (``l`` is read only by ``geometry="exact"``).
#:   At ``l = R (1 + 1e-12)`` the closure is NaN at α = 0 and at
#:   ``R (1 + 1e-6)`` a 0.2 s run does not finish in 20 s; from 1.001 R
#:   (closure slope ``l/(l - R)`` <= 1001) runs are ordinary.  l = 1e6 works;
#:   beyond 1 km the exact geometry is the paper's to 1e-4.
PARAM_RANGES = {
    "V": (1e-6, 100.0),
    "I": (1e-12, 1e6),
    "k": (1e-3, 1e7),
    "R": (1e-4, 10.0),
    "l": (L_OVER_R_MIN * 1e-4, 1e3),
}
#: Valid range ``(lo, hi)`` of the state variables wherever they are given as arguments (initial and
#: entry states; forces, velocities and angles of the closed forms), closed unless noted:
#:
#: * ``"alpha"`` [rad], ``[-π, π]``: one turn (the closures are 2π-periodic; the reduced equations,
#:   linear in α, are meant for ``|α|`` of order 0.1).
#: * ``"omega"`` [rad/s], for ω and α̇: ``|ω| <= 1e9``, above every natural rate of the model within
#:   :data:`PARAM_RANGES` (``V/R <= 1e6``; the inertial frequency ``sqrt(F R/I)`` on the branches,
#:   F <= 1e3 N, is <= 1e8).  Measured: α̇_in = 1e9 still returns (or fails with a documented
#:   SolverFailure) in :func:`reduced_segment`; 1e300 divided by zero.
#: * ``"F"`` [N]: ``[1e-3, 1e7]``: the pull force; the peel force is 100-400 N in the stick-slip window and
#:   ``f(V, V) <= 1.3e6 N`` at the fastest V.  ``F_in = 1e-300`` divided by zero, ``1e300`` did not finish.
#: * ``"v"`` [m/s]: ``(1e-150, 1e3]``: every branch velocity the model reaches is below 30 m/s; f(1e3, V) ~ 4e41 N
#:   is still finite (its e^(v/11) overflows at v ~ 7800).  Below 1e-150, v² underflows in f'' (the reduced
#:   equations' fullvdot); the model's own breakdown velocity (``BranchStructure.v_breakdown``) is ~1e-67.
#: * ``"F_rate"`` [N/s], ``|dF/dt| <= 1e12``: ``k V <= 1e9``.
STATE_RANGES = {
    "alpha": (-math.pi, math.pi),
    "omega": (-1e9, 1e9),
    "F": (1e-3, 1e7),
    "v": (1e-150, 1e3),
    "F_rate": (-1e12, 1e12),
}
#: Largest time [s] accepted as a horizon or a time since a branch entry by the closed forms and the reduced
#: segment: 1e6 s (12 days of peeling) keeps ``F_in + F_rate t`` and the phases finite.
TIME_MAX = 1e6

#: Valid relative tolerance of every DOP853 run of the package (exact.simulate, the reduced segments, the
#: dynamics functions) and of the regularised scheme: below 1e-14 the error test asks for less than rounding,
#: above 1e-2 it controls nothing a user could mean.
RTOL_RANGE = (1e-14, 1e-2)

#: Default transient [s] discarded by the dynamics functions (windowed runs, attractors, the Lyapunov family,
#: the sweep measures): the paper's orbits settle within it (docs/dynamics.md, "Transients").
T_TRANSIENT = 30.0
#: Default renormalisation interval [s] of the two-trajectory Lyapunov exponent (docs/dynamics.md).
LYAPUNOV_TAU = 0.005
#: Defaults of the windowed run (``exact.window_run``) shared by the attractors, the sweep measures ``period``
#: and ``jumps`` and ``peelapprox dynamics``: 20 s of jumps after the transient, at rtol 1e-10, from α0 = 0.
#: Read-only (a ``types.MappingProxyType``): the one place these defaults are written.
#: The default start's pull force in units of f(V, V): ``F0 = 1.01 f(V, V)``, just above steady sliding
#: (:func:`exact.initial_state`; the reduced return map starts there too).
F0_FACTOR = 1.01
WINDOW_DEFAULTS = types.MappingProxyType(dict(t_transient=T_TRANSIENT, window=20.0, rtol=1e-10, alpha0=0.0))

#: Valid regularisation ε of the ε-regularised scheme (XDAE): the ε study (comparisons.benchmark.eps) goes
#: down to 1e-15, where double precision is exhausted (the fast transit time ~ ε/f' falls below the rounding
#: of t); at 1e-300 the rates (F(1 + c) - f)/ε overflow.  Above 1e-2 the "fast" transits last as long as
#: the slow dynamics (the paper uses 1e-7): no longer a regularisation of the jumps.
EPS_RANGE = (1e-15, 1e-2)
#: Default regularisation ε of the ε-regularised scheme and of the variational Lyapunov exponent: the paper's.
EPS_DEFAULT = 1e-7

#: Loading modes: ``"velocity"`` (the paper's: the end O' pulled at the constant speed V) or ``"load"`` (a
#: constant force F_L on a body of mass M at O': ``M V̇_p = F_L - F``, the pull speed ``V_p`` a state).
LOADINGS = ("velocity", "load")
#: Standard gravity [m/s²]: a hanging mass M is the load ``F_L = M g`` (the default of ``load``).
GRAVITY = 9.80665
#: Valid tape (ribbon) mass m [kg] of the tape-mass model (0 or None: the massless model).  Its fast time scale
#: is ~ m (1 + sin α)² / f' (the ε of XDAE, docs/tape-mass.md): from 1e-15 kg (EPS_RANGE's floor: the time
#: scale reaches the rounding of t) to 10 kg (a 10 m ribbon of heavy tape; far above the paper's I/R²).
TAPE_MASS_RANGE = (1e-15, 10.0)
#: Valid loading mass M [kg] under ``loading="load"``: 1 mg (the loading is then force control) to 1000 t
#: (then the pull speed hardly changes within a run: velocity control).
LOAD_MASS_RANGE = (1e-6, 1e6)
#: Valid load F_L [N]: the range of the pull force F (:data:`STATE_RANGES`).
LOAD_RANGE = (1e-3, 1e7)


def default_load_masses() -> tuple[float, float]:
    """The loading masses M [kg] (within :data:`LOAD_MASS_RANGE`) whose default load ``M g`` lies in
    :data:`LOAD_RANGE`: what a user who gives no load may pass."""
    return max(LOAD_MASS_RANGE[0], LOAD_RANGE[0] / GRAVITY), min(LOAD_MASS_RANGE[1], LOAD_RANGE[1] / GRAVITY)

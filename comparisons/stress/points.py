"""Stress points: what the suite runs.

:class:`StressPoint` (the arguments of one :func:`exact.simulate` run), the
grids and samples that make up the suite (``GRID_*``, ``QUICK_*``, ``TOL_*``,
``LOOSE_*``, ``LONG_*``, ``RANDOM_*``) and the functions that build the point
lists: :func:`grid_points`, :func:`random_points`, :func:`tolerance_points`,
:func:`loose_points`, :func:`budget_points`, :func:`variant_points`,
:func:`long_points` and :func:`all_points`.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from peelapprox import GEOMETRIES
from peelapprox.validate import finite, integer, nonnegative, positive
from peelapprox.validate import rtol as _rtol

__all__ = [
    "GRID_I", "GRID_V", "GRID_K", "GRID_ALPHA0", "RANDOM_BOX", "TOL_RTOLS", "TOL_POINTS", "LONG_RUNS",
    "LOOSE_V", "LOOSE_I", "LOOSE_ALPHA0", "LOOSE_TOLS",
    "StressPoint", "grid_points", "random_points", "tolerance_points", "loose_points", "budget_points",
    "variant_points",
    "long_points", "all_points",
]

# --------------------------------------------------------------------- grid
#: Moments of inertia [kg m²]: from far below the paper's low-inertia case
#: (1e-5) to far above its high-inertia case (1e-2).
GRID_I: tuple[float, ...] = (1e-6, 1e-5, 1e-4, 1e-3, 1e-2, 1e-1)
#: Pull speeds [m/s]: below, across and beyond the stick-slip window (the
#: folds of f exist for V up to ≈ 5.3).
GRID_V: tuple[float, ...] = (0.05, 0.2, 0.5, 1.0, 2.0, 4.0, 5.0, 6.0, 8.0)
#: Tape stiffnesses [N/m].
GRID_K: tuple[float, ...] = (100.0, 1000.0, 1e4)
#: Initial roller angles [rad] (α0 = -1 makes ``1 - cos θ = 1 + sin α0`` small).
GRID_ALPHA0: tuple[float, ...] = (-1.0, -0.5, 0.0, 0.5, 1.0)
#: Simulated horizon of a grid point [s].
GRID_T_END = 1.0
#: Budgets of a grid point: at ~4e5 steps/s the step budget ends a run after
#: ~10-20 s of wall time, well inside the default timeout, so a ``timeout``
#: can only be a loop that does not count steps (a real hang).
GRID_MAX_STEPS = 5_000_000
GRID_MAX_JUMPS = 1_000_000
GRID_MAX_POINTS = 6_000_000

QUICK_I: tuple[float, ...] = (1e-6, 1e-4, 1e-2, 1e-1)
QUICK_V: tuple[float, ...] = (0.05, 1.0, 4.0, 5.0, 8.0)
QUICK_K: tuple[float, ...] = (100.0, 1e4)
QUICK_ALPHA0: tuple[float, ...] = (-1.0, 0.0, 1.0)

#: Relative tolerances of the tolerance sweep: the whole range simulate
#: accepts, [1e-14, 1e-2]; the smallest is the reference of the error column.
TOL_RTOLS: tuple[float, ...] = tuple(10.0 ** -e for e in range(2, 15))
#: (label, V, I, k, α0) of the tolerance sweep: the paper's two cases, an
#: irregular high-jump-rate orbit, a stiff tape near the cusp of the folds.
TOL_POINTS: tuple[tuple[str, float, float, float, float], ...] = (
    ("paper low inertia", 1.0, 1e-5, 1000.0, 0.0),
    ("paper high inertia", 1.0, 1e-2, 1000.0, 0.0),
    ("irregular V=4", 4.0, 1e-2, 1000.0, 0.3),
    ("stiff near cusp", 5.0, 1e-3, 1e4, 0.5),
)
#: The loose-tolerance grid (a new user's tolerance scan): 6 V × 4 I × 3 α0 × 6 (rtol, atol) = 432 runs of 5 s,
#: ``save="jumps"``.
#: Before the kernel rejected steps whose dense output left the domain, 66 of 432 such runs ended with a NaN
#: state (a false "geometry" breakdown) or a "successful" trajectory with v < 0.
LOOSE_V: tuple[float, ...] = (0.5, 1.0, 2.0, 4.0, 6.0, 8.0)
LOOSE_I: tuple[float, ...] = (1e-6, 1e-4, 1e-2, 1e-1)
LOOSE_ALPHA0: tuple[float, ...] = (-0.5, 0.0, 0.5)
#: (rtol, atol); atol None means simulate's default ``rtol * ATOL_SCALE``.
LOOSE_TOLS: tuple[tuple[float, float | None], ...] = (
    (1e-2, None), (1e-2, 1e-3), (1e-2, 1.0), (1e-8, 1e-3), (1e-8, 1e-1), (1e-8, 1.0),
)
LOOSE_T_END = 5.0

#: (label, V, I, k, α0, t_end, rtol) of the long runs (t_eval sampling).
LONG_RUNS: tuple[tuple[str, float, float, float, float, float, float], ...] = (
    ("long V=4 I=1e-2", 4.0, 1e-2, 1000.0, 0.3, 300.0, 1e-8),
    ("long V=4 I=1e-3 k=1e4", 4.0, 1e-3, 1e4, 0.3, 100.0, 1e-8),
)
LONG_N_EVAL = 10_000

_METHODS = ("hybrid", "regularized")
_SAVES = ("steps", "jumps")


@dataclass(frozen=True)
class StressPoint:
    """One run of the stress suite: the arguments of :func:`exact.simulate`.

    Parameters
    ----------
    V, I, k : float
        Pull speed [m/s], roller inertia [kg m²], tape stiffness [N/m]; all
        finite and > 0 (``R = 0.1``, ``l = 1`` fixed).
    alpha0 : float
        Initial roller angle [rad], finite (default F0 and ω0 of
        :func:`exact.initial_state`).
    method : {"hybrid", "regularized"}
    geometry : {"paper", "exact"}
    rtol : float
        In [1e-14, 1e-2].
    atol : float, optional
        Scalar absolute tolerance (>= 0); None for simulate's default.
    t_end : float
        Simulated horizon [s], > 0.
    save : {"steps", "jumps"}
        ``"steps"`` (default) stores every step, so the constraint residual
        and time monotonicity are checked at every step; ``"jumps"`` stores
        no points (only jumps).
    n_eval : int
        If > 0, store the state at ``n_eval`` equispaced times in
        ``[0, t_end]`` (``t_eval``) instead; 0 (default) for ``save``.
    max_steps, max_jumps, max_points : int
        Budgets (>= 1).
    group, label : str
        Which part of the suite ("grid", "tol", "budget", "variant", "long")
        and a free-form label.
    expect : str
        Expected outcome class, or "" (any allowed outcome).
    """

    V: float
    I: float
    k: float = 1000.0
    alpha0: float = 0.0
    method: str = "hybrid"
    geometry: str = "paper"
    rtol: float = 1e-8
    atol: float | None = None
    t_end: float = GRID_T_END
    save: str = "steps"
    n_eval: int = 0
    max_steps: int = GRID_MAX_STEPS
    max_jumps: int = GRID_MAX_JUMPS
    max_points: int = GRID_MAX_POINTS
    group: str = "grid"
    label: str = ""
    expect: str = ""

    def __post_init__(self) -> None:
        for name in ("V", "I", "k", "t_end"):
            object.__setattr__(self, name, positive(name, getattr(self, name)))
        object.__setattr__(self, "alpha0", finite("alpha0", self.alpha0))
        object.__setattr__(self, "rtol", _rtol("rtol", self.rtol))
        if self.atol is not None:
            object.__setattr__(self, "atol", nonnegative("atol", self.atol))
        if self.method not in _METHODS:
            raise ValueError(f"method must be one of {_METHODS}, got {self.method!r}")
        if self.geometry not in GEOMETRIES:
            raise ValueError(f"geometry must be one of {GEOMETRIES}, got {self.geometry!r}")
        if self.save not in _SAVES:
            raise ValueError(f"save must be one of {_SAVES}, got {self.save!r}")
        object.__setattr__(self, "n_eval", integer("n_eval", self.n_eval, lo=0))  # 0: no t_eval
        for name in ("max_steps", "max_jumps", "max_points"):
            object.__setattr__(self, name, integer(name, getattr(self, name)))
        if self.n_eval > self.max_points:
            raise ValueError(f"n_eval must be in [0, max_points] = [0, {self.max_points}], got {self.n_eval}")

    def as_dict(self) -> dict:
        """The fields as a plain dict."""
        return dataclasses.asdict(self)


# ------------------------------------------------------------ point lists
def grid_points(quick: bool = False, t_end: float = GRID_T_END) -> list[StressPoint]:
    """The main grid: I × V × k × α0, ``save="steps"``, rtol 1e-8.

    Parameters
    ----------
    quick : bool
        A corner subset (4 I × 5 V × 2 k × 3 α0 = 120 points) instead of the
        full grid (6 × 9 × 3 × 5 = 810 points).
    t_end : float
        Simulated horizon per point [s], > 0 (default 1 s).
    """
    t_end = positive("t_end", t_end)
    Is, Vs, ks, a0s = (QUICK_I, QUICK_V, QUICK_K, QUICK_ALPHA0) if quick else (GRID_I, GRID_V, GRID_K, GRID_ALPHA0)
    return [StressPoint(V=V, I=I, k=k, alpha0=a0, t_end=t_end) for I in Is for V in Vs for k in ks for a0 in a0s]


def tolerance_points(quick: bool = False) -> list[StressPoint]:
    """The tolerance sweep: :data:`TOL_POINTS` × :data:`TOL_RTOLS`, 1 s, ``save="jumps"``.

    With ``quick``, only the first two points and every second rtol (which keeps 1e-2 and 1e-14).
    """
    pts = TOL_POINTS[:2] if quick else TOL_POINTS
    rtols = TOL_RTOLS[::2] if quick else TOL_RTOLS
    return [
        StressPoint(V=V, I=I, k=k, alpha0=a0, rtol=rt, save="jumps", group="tol", label=lab)
        for (lab, V, I, k, a0) in pts
        for rt in rtols
    ]


def budget_points() -> list[StressPoint]:
    """Budget probes: tiny budgets must end in ``budget:<which>`` with a clean partial trajectory."""
    base = dict(V=4.0, I=1e-2, alpha0=0.3, group="budget")
    return [
        StressPoint(**base, max_steps=50, label="max_steps=50", expect="budget:max_steps"),
        StressPoint(**base, max_jumps=5, save="jumps", label="max_jumps=5", expect="budget:max_jumps"),
        StressPoint(**base, max_points=100, label="max_points=100", expect="budget:max_points"),
        StressPoint(**base, method="regularized", t_end=0.05, max_steps=50, label="regularized max_steps=50",
                    expect="budget:max_steps"),
    ]


def variant_points(quick: bool = False) -> list[StressPoint]:
    """Variants: the regularised scheme (0.05 s, rtol 1e-6) and the exact geometry on a few points."""
    reg = [(1.0, 1e-5, 0.0), (4.0, 1e-2, 0.3), (2.0, 1e-3, 0.5), (0.2, 1e-4, 0.0), (6.0, 1e-3, 0.0), (1.0, 1e-6, 1.0)]
    geo = [(1.0, 1e-5, 0.0), (4.0, 1e-2, 0.3), (2.0, 1e-3, 0.5), (0.05, 1e-2, 1.0), (8.0, 1e-1, -0.5),
           (1.0, 1e-6, 1.0)]
    if quick:
        reg, geo = reg[:2], geo[:2]
    out = [StressPoint(V=V, I=I, alpha0=a0, method="regularized", rtol=1e-6, t_end=0.05, group="variant",
                       label="regularized eps=1e-7") for (V, I, a0) in reg]
    out += [StressPoint(V=V, I=I, alpha0=a0, geometry="exact", group="variant", label="geometry=exact")
            for (V, I, a0) in geo]
    return out


def long_points(quick: bool = False) -> list[StressPoint]:
    """Long runs (:data:`LONG_RUNS`), sampled at :data:`LONG_N_EVAL` equispaced times (``t_eval``).

    With ``quick`` only the first, shortened to 20 s.
    """
    runs = LONG_RUNS[:1] if quick else LONG_RUNS
    out = []
    for (lab, V, I, k, a0, T, rt) in runs:
        T = min(T, 20.0) if quick else T
        out.append(StressPoint(V=V, I=I, k=k, alpha0=a0, t_end=T, rtol=rt, n_eval=LONG_N_EVAL, group="long",
                               label=lab, max_steps=10**8, max_jumps=10**7))
        out.append(StressPoint(V=V, I=I, k=k, alpha0=a0, t_end=T, rtol=rt, save="jumps", group="long",
                               label=lab + " (save=jumps)", max_steps=10**8, max_jumps=10**7))
    return out


#: Box of the random sample: I and k log-uniform, V, α0 uniform, rtol log-uniform.
RANDOM_BOX = dict(I=(1e-6, 1e-1), V=(0.05, 8.0), k=(100.0, 1e4), alpha0=(-1.0, 1.2), rtol=(1e-10, 1e-5))
RANDOM_SEED = 20240601
N_RANDOM = 400


def random_points(n: int = N_RANDOM, seed: int = RANDOM_SEED, t_end: float = GRID_T_END) -> list[StressPoint]:
    """A seeded random sample of the box :data:`RANDOM_BOX` (off-grid values, random rtol).

    Parameters
    ----------
    n : int
        Number of points, >= 0.
    seed : int
        Seed of ``numpy.random.default_rng``.
    t_end : float
        Horizon [s], > 0.
    """
    n = integer("n", n, lo=0)
    t_end = positive("t_end", t_end)
    rng = np.random.default_rng(int(seed))
    B = RANDOM_BOX

    def logu(lo: float, hi: float) -> float:
        return float(10.0 ** rng.uniform(math.log10(lo), math.log10(hi)))

    out = []
    for _ in range(int(n)):
        I, V, k = logu(*B["I"]), float(rng.uniform(*B["V"])), logu(*B["k"])
        a0, rt = float(rng.uniform(*B["alpha0"])), logu(*B["rtol"])
        out.append(StressPoint(V=V, I=I, k=k, alpha0=a0, rtol=rt, t_end=t_end, group="random"))
    return out


def loose_points(quick: bool = False) -> list[StressPoint]:
    """The loose-tolerance grid: :data:`LOOSE_V` × :data:`LOOSE_I` × :data:`LOOSE_ALPHA0` × :data:`LOOSE_TOLS`.

    5 s runs storing jumps only.  With ``quick``, V in (1, 8) and I in (1e-6, 1e-1) only (72 runs).
    """
    Vs = (1.0, 8.0) if quick else LOOSE_V
    Is = (1e-6, 1e-1) if quick else LOOSE_I
    return [
        StressPoint(V=V, I=I, alpha0=a0, rtol=rt, atol=at, t_end=LOOSE_T_END, save="jumps", group="loose")
        for V in Vs for I in Is for a0 in LOOSE_ALPHA0 for rt, at in LOOSE_TOLS
    ]


def all_points(quick: bool = False, t_end: float = GRID_T_END, n_random: int = N_RANDOM) -> list[StressPoint]:
    """Everything :func:`~comparisons.stress.cli.main` runs apart from
    :func:`~comparisons.stress.runner.budget_edge_probes`.

    Grid (horizon ``t_end``), random sample (``n_random`` points, a quarter
    with ``quick``), tolerance sweep, loose-tolerance grid, budget probes, variants, long runs.
    """
    nr = n_random // 4 if quick else n_random
    return (grid_points(quick, t_end) + random_points(nr, t_end=t_end) + tolerance_points(quick) + loose_points(quick)
            + budget_points() + variant_points(quick) + long_points(quick))

"""Numerical stress tests of the exact solver (:func:`exact.simulate`).

    python -m comparisons._stress [--quick] [--out DIR] [--timeout S] [--t-end S] [--n-random N]

Every run of the model must end in a :class:`~exact.Trajectory` or in one of
the documented exceptions (:class:`~exact.ModelBreakdown`,
:class:`~exact.SolverBudgetExceeded`, :class:`~exact.SolverFailure`, or a
``ValueError`` for an infeasible initial state) -- never in a non-finite
value, never in a hang.  This module runs a grid over (I, V, k, α0), a
tolerance sweep, budget probes, a few variants (regularised scheme, exact
geometry) and long runs (≥ 1e5 jumps), each point in a separate worker process
with a wall-clock timeout, and classifies each run.

Outcome classes (``record["outcome"]``)
---------------------------------------
``ok``
    Reached ``t_end``.
``breakdown:<reason>``
    :class:`~exact.ModelBreakdown` with ``reason`` (``no_root``,
    ``no_landing``, ``geometry``, ``v_ceiling``, ...).
``budget:<which>``
    :class:`~exact.SolverBudgetExceeded` for ``max_steps``, ``max_jumps`` or
    ``max_points``.
``solver_failure``
    :class:`~exact.SolverFailure`.
``invalid_initial_state``
    :func:`exact.initial_state` raised ``ValueError`` (no root of CONSTR at
    the requested α0 and default F0).
``nan``
    A non-finite value in the returned arrays (or in the partial trajectory
    attached to an exception): a bug.
``timeout``
    No answer within the wall-clock timeout: a hang, a bug.
``crash``
    The worker process died (segfault, abort): a bug.
``unexpected:<ExceptionType>``
    Any other exception (also a ``ValueError`` raised by ``simulate`` after
    the initial state was accepted): a bug.

Independently of the class, ``t_monotone`` is False if stored times or jump
times ever decrease or leave ``[0, t_end]``: a bug.
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import multiprocessing as mp
import os
import sys
import time
from collections import Counter
from dataclasses import dataclass
from typing import Any, Callable, Iterable, Optional, Sequence

import numpy as np

from peelapprox import GEOMETRIES
from peelapprox._io import write_rows
from peelapprox._params import RTOL_RANGE
from peelapprox._validate import finite, in_range, nonnegative, positive

__all__ = [
    "GRID_I", "GRID_V", "GRID_K", "GRID_ALPHA0", "RANDOM_BOX", "TOL_RTOLS", "TOL_POINTS", "LONG_RUNS",
    "ALLOWED_PREFIXES", "BUG_CLASSES",
    "LOOSE_V", "LOOSE_I", "LOOSE_ALPHA0", "LOOSE_TOLS",
    "StressPoint", "grid_points", "random_points", "tolerance_points", "loose_points", "budget_points", "variant_points",
    "long_points",
    "all_points", "run_point", "StressRunner", "run_points", "budget_edge_probes",
    "is_allowed", "is_bug", "tolerance_table", "pair_long_runs", "robustness_markdown", "write_records", "main",
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
#: The loose-tolerance grid (issue 13): 6 V × 4 I × 3 α0 × 6 (rtol, atol) = 432 runs of 5 s, ``save="jumps"``.
#: Before the kernel rejected steps whose dense output left the domain, 66 of 432 such runs ended with a NaN
#: state (a false "geometry" breakdown) or a "successful" trajectory with v < 0.
LOOSE_V: tuple[float, ...] = (0.5, 1.0, 2.0, 4.0, 6.0, 8.0)
LOOSE_I: tuple[float, ...] = (1e-6, 1e-4, 1e-2, 1e-1)
LOOSE_ALPHA0: tuple[float, ...] = (-0.5, 0.0, 0.5)
#: (rtol, atol); atol None means simulate's default ``rtol * ATOL_SCALE``.
LOOSE_TOLS: tuple[tuple[float, Optional[float]], ...] = (
    (1e-2, None), (1e-2, 1e-3), (1e-2, 1.0), (1e-8, 1e-3), (1e-8, 1e-1), (1e-8, 1.0),
)
LOOSE_T_END = 5.0

#: (label, V, I, k, α0, t_end, rtol) of the long runs (t_eval sampling).
LONG_RUNS: tuple[tuple[str, float, float, float, float, float, float], ...] = (
    ("long V=4 I=1e-2", 4.0, 1e-2, 1000.0, 0.3, 300.0, 1e-8),
    ("long V=4 I=1e-3 k=1e4", 4.0, 1e-3, 1e4, 0.3, 100.0, 1e-8),
)
LONG_N_EVAL = 10_000

#: Outcome classes (or prefixes) that are documented, legitimate endings.
ALLOWED_PREFIXES: tuple[str, ...] = ("ok", "breakdown:", "budget:", "solver_failure", "invalid_initial_state")
#: Outcome classes (or prefixes) that are bugs.
BUG_CLASSES: tuple[str, ...] = ("nan", "timeout", "crash", "unexpected:")

#: Fraction of the stored points / jumps counted as "early" and "late" in the drift check.
DRIFT_FRACTION = 0.1

_METHODS = ("hybrid", "regularized")
_SAVES = ("steps", "jumps")



def _posint(name: str, x: Any) -> int:
    if isinstance(x, bool) or not isinstance(x, (int, np.integer, float)) or int(x) != x or x < 1:
        raise ValueError(f"{name} must be a positive integer (>= 1), got {x!r}")
    return int(x)


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
    atol: Optional[float] = None
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
        object.__setattr__(self, "rtol", in_range("rtol", self.rtol, *RTOL_RANGE))
        if self.atol is not None:
            object.__setattr__(self, "atol", nonnegative("atol", self.atol))
        if self.method not in _METHODS:
            raise ValueError(f"method must be one of {_METHODS}, got {self.method!r}")
        if self.geometry not in GEOMETRIES:
            raise ValueError(f"geometry must be one of {GEOMETRIES}, got {self.geometry!r}")
        if self.save not in _SAVES:
            raise ValueError(f"save must be one of {_SAVES}, got {self.save!r}")
        if isinstance(self.n_eval, bool) or int(self.n_eval) != self.n_eval or self.n_eval < 0:
            raise ValueError(f"n_eval must be an integer >= 0 (0: no t_eval), got {self.n_eval!r}")
        object.__setattr__(self, "n_eval", int(self.n_eval))
        for name in ("max_steps", "max_jumps", "max_points"):
            object.__setattr__(self, name, _posint(name, getattr(self, name)))
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
    if isinstance(n, bool) or int(n) != n or n < 0:
        raise ValueError(f"n must be an integer >= 0, got {n!r}")
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
    """Everything :func:`main` runs apart from :func:`budget_edge_probes`.

    Grid (horizon ``t_end``), random sample (``n_random`` points, a quarter
    with ``quick``), tolerance sweep, loose-tolerance grid, budget probes, variants, long runs.
    """
    nr = n_random // 4 if quick else n_random
    return (grid_points(quick, t_end) + random_points(nr, t_end=t_end) + tolerance_points(quick) + loose_points(quick)
            + budget_points() + variant_points(quick) + long_points(quick))


# -------------------------------------------------------------- one point
def _nonfinite(*arrays: Any) -> bool:
    return any(np.size(a) and not np.all(np.isfinite(np.asarray(a, dtype=float))) for a in arrays)


def _maxabs(x: np.ndarray) -> float:
    x = np.asarray(x, dtype=float)
    if x.size == 0:
        return float("nan")
    return float(np.max(np.abs(x)))


def _early_late(x: np.ndarray) -> tuple[float, float]:
    n = len(x)
    if n == 0:
        return float("nan"), float("nan")
    m = max(1, int(math.ceil(DRIFT_FRACTION * n)))
    return _maxabs(x[:m]), _maxabs(x[-m:])


def _jump_residuals(tr: Any) -> np.ndarray:
    """Relative CONSTR residual at each jump, before and after, worst of the two [-]."""
    from peelapprox._peelforce import peel_force

    J = tr.jumps
    if len(J) == 0:
        return np.zeros(0)
    G = J.F * (1.0 + np.asarray(tr.params.closure(J.alpha)[0], dtype=float))
    with np.errstate(all="ignore"):
        fb = peel_force(np.maximum(J.v_before, 1e-300), tr.params.V)
        fa = peel_force(np.maximum(J.v_after, 1e-300), tr.params.V)
        return np.maximum(np.abs((G - fb) / fb), np.abs((G - fa) / fa))


def _inspect(tr: Any, t_end: float, rec: dict, keep_jump_times: bool) -> None:
    """Fill the trajectory-derived fields of ``rec`` from a Trajectory (complete or partial)."""
    J = tr.jumps
    rec["n_points"] = int(len(tr.t))
    rec["n_jumps"] = int(tr.stats.n_jumps)
    rec["n_steps"] = int(tr.stats.n_steps)
    rec["nonfinite"] = bool(  # a non-finite value, or a stored v <= 0 (outside the model's domain)
        _nonfinite(tr.t, tr.alpha, tr.omega, tr.F, tr.v, J.t, J.alpha, J.omega, J.F, J.v_before, J.v_after)
        or np.any(np.asarray(tr.v) <= 0.0)
    )
    ok_t = True
    for ts in (tr.t, J.t):
        ts = np.asarray(ts, dtype=float)
        if ts.size:
            ok_t &= bool(np.all(np.diff(ts) >= 0)) and bool(ts[0] >= 0.0) and bool(ts[-1] <= t_end)
    rec["t_monotone"] = bool(ok_t)
    with np.errstate(all="ignore"):
        r = tr.constraint_residual(relative=True) if len(tr.t) else np.zeros(0)
    rec["res_max"] = _maxabs(r)
    rec["res_median"] = float(np.median(np.abs(r))) if r.size else float("nan")
    rec["res_early"], rec["res_late"] = _early_late(r)
    jr = _jump_residuals(tr)
    rec["jres_max"] = _maxabs(jr)
    rec["jres_early"], rec["jres_late"] = _early_late(jr)
    if keep_jump_times:
        rec["_jump_t"] = [float(x) for x in J.t]


def _empty_record(point: StressPoint) -> dict:
    rec = point.as_dict()
    rec.update(
        outcome="", exception="", reason="", message="", t_reached=float("nan"), wall=float("nan"),
        n_steps=0, n_jumps=0, n_points=0, res_max=float("nan"), res_median=float("nan"), res_early=float("nan"), res_late=float("nan"),
        jres_max=float("nan"), jres_early=float("nan"), jres_late=float("nan"), t_monotone=True, nonfinite=False,
        expect_met=True,
    )
    return rec


def run_point(point: StressPoint, keep_jump_times: bool = False) -> dict:
    """Run one point in this process and classify how it ended.

    Parameters
    ----------
    point : StressPoint
    keep_jump_times : bool
        Also return the jump times under the private key ``"_jump_t"`` (used
        by the tolerance sweep; not written to CSV/JSON).

    Returns
    -------
    dict
        The point's fields plus ``outcome`` (see the module docstring),
        ``exception`` (type name or ""), ``reason``, ``message``,
        ``t_reached`` [s], ``wall`` [s] (initial state + integration,
        excluding kernel compilation), ``n_steps``, ``n_jumps``, ``n_points``,
        ``res_max``/``res_early``/``res_late`` (max relative CONSTR residual
        over all / the first / the last 10 % of stored points; NaN when no
        point is stored), ``res_median``, ``jres_*`` (the same at the jumps, before and after
        the jump), ``t_monotone``, ``nonfinite`` and ``expect_met``.  For
        exceptions carrying a partial trajectory the trajectory fields are
        taken from it.

    Raises
    ------
    ValueError
        If ``point`` is not a :class:`StressPoint`.
    """
    if not isinstance(point, StressPoint):
        raise ValueError(f"point must be a StressPoint, got {type(point).__name__}")
    import exact
    from exact import ModelBreakdown, SolverBudgetExceeded, SolverFailure
    from peelapprox import PeelParams

    rec = _empty_record(point)
    if point.method == "hybrid":
        exact.compile_kernels()
    params = PeelParams(V=point.V, I=point.I, k=point.k, geometry=point.geometry)
    t0 = time.perf_counter()
    try:
        exact.initial_state(params, alpha0=point.alpha0)
    except ValueError as e:
        rec.update(outcome="invalid_initial_state", exception="ValueError", message=str(e)[:300], t_reached=0.0,
                   wall=time.perf_counter() - t0)
        return _finish(point, rec)
    kw: dict[str, Any] = dict(alpha0=point.alpha0, method=point.method, rtol=point.rtol, atol=point.atol,
                              max_steps=point.max_steps, max_jumps=point.max_jumps, max_points=point.max_points)
    if point.n_eval:
        kw["t_eval"] = np.linspace(0.0, point.t_end, point.n_eval)
    else:
        kw["save"] = point.save
    tr = None
    exc: Any = None
    try:
        tr = exact.simulate(params, point.t_end, **kw)
        rec.update(outcome="ok", t_reached=float(tr.final_state.t))
    except ModelBreakdown as e:
        rec.update(outcome=f"breakdown:{e.reason}", exception="ModelBreakdown", reason=str(e.reason), t_reached=e.t)
        tr, exc = e.partial, e
        rec["message"] = str(e)[:300]
    except SolverBudgetExceeded as e:
        rec.update(outcome=f"budget:{e.budget}", exception="SolverBudgetExceeded", reason=str(e.budget), t_reached=e.t)
        tr, exc = e.partial, e
        rec["message"] = str(e)[:300]
    except SolverFailure as e:
        rec.update(outcome="solver_failure", exception="SolverFailure", t_reached=e.t, message=str(e)[:300])
        tr, exc = e.partial, e
    except Exception as e:  # noqa: BLE001 - anything else is a finding, not a crash of the suite
        rec.update(outcome=f"unexpected:{type(e).__name__}", exception=type(e).__name__, message=str(e)[:300])
        tr = None
    rec["wall"] = time.perf_counter() - t0
    if tr is not None:
        _inspect(tr, point.t_end, rec, keep_jump_times)
        if rec["outcome"] == "ok":
            fs = tr.final_state
            rec["nonfinite"] |= _nonfinite([fs.t, fs.alpha, fs.omega, fs.F, fs.v]) or not fs.v > 0
            rec["t_monotone"] &= bool(abs(fs.t - point.t_end) <= 1e-12 * max(1.0, point.t_end))
    if exc is not None:  # an exception reports a finite time and state with v > 0
        sd = exc.state
        rec["nonfinite"] |= _nonfinite([exc.t, sd["alpha"], sd["omega"], sd["F"], sd["v"]]) or not sd["v"] > 0
    if tr is not None or exc is not None:
        if rec["nonfinite"]:
            rec["outcome"] = "nan"
    if isinstance(rec["t_reached"], float) and not math.isfinite(rec["t_reached"]) and rec["outcome"] != "nan":
        rec["t_reached"] = float("nan")
    return _finish(point, rec)


def _finish(point: StressPoint, rec: dict) -> dict:
    rec["expect_met"] = (rec["outcome"] == point.expect) if point.expect else is_allowed(rec["outcome"])
    for key, val in list(rec.items()):
        if isinstance(val, (np.floating, np.integer, np.bool_)):
            rec[key] = val.item()
    return rec


def is_allowed(outcome: str) -> bool:
    """True for the documented, legitimate outcome classes (:data:`ALLOWED_PREFIXES`)."""
    return any(outcome == p or (p.endswith(":") and outcome.startswith(p)) for p in ALLOWED_PREFIXES)


def is_bug(record: dict) -> bool:
    """True if a record shows a bug: a bug outcome class or non-monotone time."""
    return (not is_allowed(record["outcome"])) or not record.get("t_monotone", True)


# ------------------------------------------------------ isolated workers
def _run_task(task: Any) -> dict:
    """Worker-side default: ``run_point(task)`` or ``run_point(*task)`` for ``(point, keep_jump_times)``."""
    if isinstance(task, tuple):
        return run_point(*task)
    return run_point(task)


def _worker_main(conn: Any, func: Callable[[Any], Any], warm: bool) -> None:
    """Worker loop: receive a task, send back ``func(task)``; ``None`` stops."""
    if warm:
        import exact

        exact.compile_kernels()
    conn.send(("ready", None))
    while True:
        try:
            task = conn.recv()
        except (EOFError, OSError):
            return
        if task is None:
            return
        try:
            res = func(task)
        except BaseException as e:  # noqa: BLE001 - reported to the parent
            res = {"outcome": f"unexpected:{type(e).__name__}", "exception": type(e).__name__,
                   "message": str(e)[:300]}
        conn.send(("result", res))


class StressRunner:
    """One worker process that runs tasks with a wall-clock timeout.

    A task that does not answer within ``timeout`` seconds is recorded as
    ``outcome="timeout"``, the worker (this runner's own process, by its
    handle) is killed and a fresh one is started for the next task; a worker
    that dies is recorded as ``outcome="crash"``.  Use as a context manager.

    Parameters
    ----------
    timeout : float
        Seconds per task, > 0.
    func : callable, optional
        Module-level (picklable) function called in the worker as
        ``func(task)``; it should return a dict.  Default: :func:`run_point`
        on a :class:`StressPoint` task, ``run_point(point, keep_jump_times)``
        on a ``(point, keep_jump_times)`` task.
    start_timeout : float
        Seconds allowed for a worker to start (import, load the compiled
        kernels), > 0.
    warm : bool
        Load the hybrid kernel when the worker starts (default True), so the
        first task's wall time does not include it.
    """

    def __init__(self, timeout: float = 60.0, func: Optional[Callable[[Any], Any]] = None, start_timeout: float = 300.0,
                 warm: bool = True):
        self.timeout = positive("timeout", timeout)
        self.start_timeout = positive("start_timeout", start_timeout)
        self.func = _run_task if func is None else func
        if not callable(self.func):
            raise ValueError(f"func must be a picklable module-level callable, got {func!r}")
        self.warm = bool(warm)
        self._ctx = mp.get_context("spawn")
        self._proc: Any = None
        self._conn: Any = None
        self.restarts = 0

    def _start(self) -> None:
        parent, child = self._ctx.Pipe()
        proc = self._ctx.Process(target=_worker_main, args=(child, self.func, self.warm), daemon=True)
        proc.start()
        child.close()
        if not parent.poll(self.start_timeout):
            proc.kill()
            proc.join()
            raise RuntimeError(f"stress worker did not start within start_timeout={self.start_timeout} s")
        try:
            parent.recv()
        except EOFError:
            proc.join()
            raise RuntimeError(f"stress worker died while starting (exit code {proc.exitcode})") from None
        self._proc, self._conn = proc, parent

    def _kill(self) -> None:
        if self._proc is not None:
            if self._proc.is_alive():
                self._proc.kill()
            self._proc.join()
            self._conn.close()
        self._proc = self._conn = None

    def run(self, task: Any, timeout: Optional[float] = None) -> dict:
        """Run one task in the worker; returns its record (or a timeout/crash record).

        Parameters
        ----------
        task : StressPoint, (StressPoint, bool) or any picklable argument of ``func``
        timeout : float, optional
            Overrides the runner's timeout for this task (> 0).
        """
        tmo = self.timeout if timeout is None else positive("timeout", timeout)
        if self._proc is None or not self._proc.is_alive():
            if self._proc is not None:
                self._kill()
            self._start()
        pt = task[0] if isinstance(task, tuple) and task and isinstance(task[0], StressPoint) else task
        task_is_point = isinstance(pt, StressPoint)
        base = _empty_record(pt) if task_is_point else {"task": repr(task)}
        t0 = time.perf_counter()
        try:
            self._conn.send(task)
            answered = self._conn.poll(tmo)
        except (BrokenPipeError, EOFError, OSError):
            answered = True  # recv below reports the crash
        if not answered:
            self._kill()
            self.restarts += 1
            base.update(outcome="timeout", wall=time.perf_counter() - t0,
                        message=f"no answer within timeout={tmo} s; worker killed")
            return _finish(pt, base) if task_is_point else base
        try:
            kind, res = self._conn.recv()
        except (EOFError, OSError):
            self._proc.join()
            code = self._proc.exitcode
            self._kill()
            self.restarts += 1
            base.update(outcome="crash", wall=time.perf_counter() - t0, message=f"worker died (exit code {code})")
            return _finish(pt, base) if task_is_point else base
        if not isinstance(res, dict):
            res = {"outcome": "ok", "result": res}
        if "wall" not in res or not isinstance(res.get("wall"), float):
            res["wall"] = time.perf_counter() - t0
        if task_is_point and res.get("outcome", "").startswith("unexpected:") and "V" not in res:
            base.update(res)
            res = _finish(pt, base)
        return res

    def close(self) -> None:
        """Stop the worker (politely, then by kill)."""
        if self._proc is not None and self._proc.is_alive():
            try:
                self._conn.send(None)
            except (BrokenPipeError, OSError):
                pass
            self._proc.join(5.0)
        self._kill()

    def __enter__(self) -> "StressRunner":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()


def _fmt_point(p: StressPoint) -> str:
    s = f"V={p.V:g} I={p.I:g} k={p.k:g} a0={p.alpha0:g}"
    if p.method != "hybrid":
        s += f" {p.method}"
    if p.geometry != "paper":
        s += f" geometry={p.geometry}"
    if p.group in ("tol", "long", "budget"):
        s += f" rtol={p.rtol:g} t_end={p.t_end:g}"
    return f"[{p.group}] {s}" + (f" ({p.label})" if p.label else "")


def run_points(points: Sequence[StressPoint], timeout: float = 60.0, progress: bool = True,
               runner: Optional[StressRunner] = None, keep_jump_times: Optional[Callable[[StressPoint], bool]] = None
               ) -> list[dict]:
    """Run points one after the other in a worker process, each with a timeout.

    Parameters
    ----------
    points : sequence of StressPoint
    timeout : float
        Wall-clock seconds per point (> 0); long runs get 10× this.
    progress : bool
        One line per point on stderr.
    runner : StressRunner, optional
        Reuse a runner (its own timeout is then overridden per point).
    keep_jump_times : callable, optional
        ``keep_jump_times(point)`` → keep the jump times (default: for the
        ``"tol"`` and ``"long"`` groups).

    Returns
    -------
    list of dict
        One record per point, in order (see :func:`run_point`).
    """
    timeout = positive("timeout", timeout)
    for p in points:
        if not isinstance(p, StressPoint):
            raise ValueError(f"points must contain StressPoint instances, got {type(p).__name__}")
    keep = keep_jump_times or (lambda p: p.group in ("tol", "long"))
    own = runner is None
    runner = runner or StressRunner(timeout=timeout)
    recs = []
    try:
        n = len(points)
        for i, p in enumerate(points, 1):
            tmo = timeout * (10 if p.group == "long" else 1)
            rec = runner.run((p, True) if keep(p) else p, timeout=tmo)
            recs.append(rec)
            if progress:
                flag = "" if not is_bug(rec) else "   <-- BUG"
                if p.expect and not rec["expect_met"]:
                    flag += f"   <-- expected {p.expect}"
                sys.stderr.write(f"{i:4d}/{n} {_fmt_point(p)} -> {rec['outcome']} "
                                 f"({rec['wall']:.3g} s, {rec['n_jumps']} jumps){flag}\n")
                sys.stderr.flush()
    finally:
        if own:
            runner.close()
    return recs


def budget_edge_probes(runner: Optional[StressRunner] = None, timeout: float = 60.0) -> list[dict]:
    """Budgets set exactly to what a run needs must not raise.

    ``simulate``'s contract: *exceeding* a budget raises.  Runs V=4, I=1e-2,
    α0=0.3 to 0.1 s once, then again with ``max_jumps``, ``max_steps`` and
    ``max_points`` equal to the counts of that run (expected: ``ok``).

    Parameters
    ----------
    runner : StressRunner, optional
    timeout : float
        Seconds per run, > 0.

    Returns
    -------
    list of dict
        The reference record and the three edge records (``expect="ok"``).
    """
    timeout = positive("timeout", timeout)
    own = runner is None
    runner = runner or StressRunner(timeout=timeout)
    try:
        base = dict(V=4.0, I=1e-2, alpha0=0.3, t_end=0.1, group="budget")
        ref = runner.run(StressPoint(**base, label="edge reference"), timeout=timeout)
        out = [ref]
        if ref["outcome"] == "ok":
            for name, val in (("max_jumps", ref["n_jumps"]), ("max_steps", ref["n_steps"]),
                              ("max_points", ref["n_points"])):
                if val >= 1:
                    p = StressPoint(**base, **{name: val}, label=f"{name}=exact count {val}", expect="ok")
                    out.append(runner.run(p, timeout=timeout))
    finally:
        if own:
            runner.close()
    return out


# ---------------------------------------------------------------- report
def tolerance_table(records: Iterable[dict]) -> list[dict]:
    """Per tolerance-sweep point and rtol: outcome, work and jump-time error against the tightest rtol.

    ``err_jump_t`` is the max |t_j - t_j^ref| over the jumps both runs have
    (``n_common``); ``dn_jumps`` the difference of jump counts; the
    reference is the run of the same point at the smallest rtol.  Records
    without ``_jump_t`` (read back from JSON) get NaN errors.
    """
    tol = [r for r in records if r.get("group") == "tol"]
    rows = []
    for key in dict.fromkeys((r["label"], r["V"], r["I"], r["k"], r["alpha0"]) for r in tol):
        sub = sorted([r for r in tol if (r["label"], r["V"], r["I"], r["k"], r["alpha0"]) == key],
                     key=lambda r: -r["rtol"])
        ref = sub[-1]
        rj = np.asarray(ref.get("_jump_t", []), dtype=float)
        for r in sub:
            jt = np.asarray(r.get("_jump_t", []), dtype=float)
            n = min(len(jt), len(rj))
            has = "_jump_t" in r and "_jump_t" in ref and r is not ref
            err = float(np.max(np.abs(jt[:n] - rj[:n]))) if (has and n) else float("nan")
            rows.append(dict(label=key[0], V=key[1], I=key[2], k=key[3], alpha0=key[4], rtol=r["rtol"],
                             outcome=r["outcome"], n_jumps=r["n_jumps"], n_steps=r["n_steps"], wall=r["wall"],
                             err_jump_t=err, n_common=n if has else 0,
                             dn_jumps=(r["n_jumps"] - ref["n_jumps"]) if has else 0, reference=r is ref))
    return rows


EXPLANATIONS: dict[str, str] = {
    "ok": "Reached t_end.",
    "invalid_initial_state": (
        "No consistent start: with the default F0 = 1.01 f(V, V) the level F0 (1 - cos θ) = F0 (1 + sin α0) lies "
        "below f(0+, V) = 130 - 2 V^1.5 (α0 = -1 gives 1 + sin α0 = 0.16), so CONSTR has no root; initial_state "
        "raises ValueError naming F0's valid range."),
    "breakdown:no_root": (
        "On AB the pull side F (1 - cos θ) falls to f(0+, V) (within 1e-10, the model's criterion; v is followed "
        "in ln v down to ~1e-67 m/s), so the peel front would have to stop, a regime the model does not contain.  "
        "Seen (i) at small I with α0 = 1, where FLOW2's angular acceleration "
        "-F R c(α)/I swings α from 1 to ≈ -0.59 within ~0.5 ms and 1 + sin α collapses; (ii) at small V "
        "(0.2-0.5), where the CD→AB jump lands at v = 2e-9 (V=0.2) to 8e-5 m/s (V=0.5), barely above 0; "
        "(iii) for soft tapes (k = 100) after a few s of growing oscillation; (iv) for starts whose level is "
        "barely above f(0+, V) (α0 = -0.5 at V = 0.05); (v) at loose tolerances (atol up to 1), on the "
        "inaccurate orbits such tolerances give."),
    "breakdown:v_floor": "v fell to a v_floor the caller passed (not used by the suite).",
    "breakdown:no_landing": (
        "V below ≈ 0.163, where f_min <= f(0+, V): at the CD fold there is no AB root to jump to (the peel "
        "front would have to stop)."),
    "breakdown:geometry": "1 - cos θ reached 0 (α → -π/2): the peel geometry degenerates.",
    "breakdown:v_ceiling": "v exceeded 1000 m/s on CD: the pull force runs away.",
    "budget:max_steps": "The step budget was used up (budget probes: deliberately tiny budgets).",
    "budget:max_jumps": "The jump budget was used up (budget probes: deliberately tiny budgets).",
    "budget:max_points": "The stored-point budget was used up (budget probes: deliberately tiny budgets).",
    "solver_failure": "The step size collapsed (the integrator could not proceed).",
    "nan": "BUG: a non-finite value in the returned (or partial) arrays.",
    "timeout": "BUG: no answer within the wall-clock timeout (a hang).",
    "crash": "BUG: the worker process died.",
}


def _g(x: Any) -> str:
    if x is None:
        return "–"
    if isinstance(x, float):
        if math.isnan(x):
            return "–"
        return f"{x:.3g}"
    return str(x)


def _example(r: dict) -> str:
    s = f"V={r['V']:g}, I={r['I']:g}, k={r['k']:g}, α0={r['alpha0']:g}"
    if r.get("method", "hybrid") != "hybrid":
        s += f", {r['method']}"
    if r.get("geometry", "paper") != "paper":
        s += f", geometry={r['geometry']}"
    if r.get("group") in ("budget", "tol"):
        s += f", rtol={r['rtol']:g}, t_end={r['t_end']:g}"
    if r.get("outcome", "").startswith(("breakdown", "budget", "solver")) and r.get("t_reached") == r.get("t_reached"):
        s += f" (at t={r['t_reached']:.4g} s)"
    return s


_ABBR = {"ok": "ok", "invalid_initial_state": "inv", "breakdown:no_root": "nr", "breakdown:v_floor": "vf",
         "breakdown:no_landing": "nl", "breakdown:geometry": "geo", "breakdown:v_ceiling": "vc",
         "solver_failure": "sf", "nan": "NAN", "timeout": "TIMEOUT", "crash": "CRASH"}


def _abbr(outcome: str) -> str:
    return _ABBR.get(outcome, outcome)


def _count_table(records: list[dict], title: str) -> list[str]:
    c = Counter(r["outcome"] for r in records)
    lines = [f"| {title} | runs |", "|---|---:|"]
    for k, v in sorted(c.items(), key=lambda kv: (-kv[1], kv[0])):
        lines.append(f"| `{k}` | {v} |")
    lines.append(f"| **total** | **{len(records)}** |")
    return lines


def robustness_markdown(records: Sequence[dict], *, command: Optional[str] = None,
                        wall_time: Optional[float] = None) -> str:
    """Render the stress-test report (markdown) from run records.

    Parameters
    ----------
    records : sequence of dict
        Records from :func:`run_point` / :func:`run_points` (any mix of the
        groups "grid", "tol", "budget", "variant", "long"; missing groups
        are skipped).
    command : str, optional
        The command line, shown at the top.
    wall_time : float, optional
        Total wall time of the suite [s].

    Returns
    -------
    str

    Raises
    ------
    ValueError
        If a record lacks the ``outcome`` or ``group`` key.
    """
    records = list(records)
    for i, r in enumerate(records):
        if not isinstance(r, dict) or "outcome" not in r or "group" not in r:
            raise ValueError(f"records[{i}] must be a dict with 'outcome' and 'group' keys (a run_point record)")
    by = {g: [r for r in records if r["group"] == g] for g in ("grid", "random", "tol", "loose", "budget", "variant",
                                                                  "long")}
    L: list[str] = []
    if command:
        L += ["```", command, "```", ""]
    bugs = [r for r in records if is_bug(r)]
    nan_n = sum(r["outcome"] == "nan" for r in records)
    to_n = sum(r["outcome"] == "timeout" for r in records)
    cr_n = sum(r["outcome"] == "crash" for r in records)
    un_n = sum(r["outcome"].startswith("unexpected:") for r in records)
    nm_n = sum(not r.get("t_monotone", True) for r in records)
    unmet = [r for r in records if not r.get("expect_met", True)]
    L += ["## Summary", ""]
    L += [f"- runs: **{len(records)}**" + (f", total wall time **{wall_time:.1f} s**" if wall_time else "")]
    L += [f"- `nan`: **{nan_n}**, `timeout`: **{to_n}**, `crash`: **{cr_n}**, unexpected exceptions: **{un_n}**, "
          f"non-monotone time: **{nm_n}**"]
    L += [f"- runs not matching their expected outcome: **{len(unmet)}**"]
    for r in unmet:
        L += [f"  - {r.get('label') or r['group']}: {_example(r)} → `{r['outcome']}` "
              f"(expected `{r.get('expect') or 'an allowed class'}`) — {r.get('message', '')[:160]}"]
    if bugs:
        L += ["- **bug records:**"]
        for r in bugs:
            L += [f"  - {_example(r)} → `{r['outcome']}`, t_monotone={r.get('t_monotone')} — "
                  f"{r.get('message', '')[:200]}"]
    L += [""]

    g = by["grid"]
    if g:
        Is = sorted({r["I"] for r in g})
        Vs = sorted({r["V"] for r in g})
        ks = sorted({r["k"] for r in g})
        a0s = sorted({r["alpha0"] for r in g})
        walls = np.array([r["wall"] for r in g], dtype=float)
        L += ["## Grid", ""]
        L += [f"I ∈ {{{', '.join(f'{x:g}' for x in Is)}}} kg m², V ∈ {{{', '.join(f'{x:g}' for x in Vs)}}} m/s, "
              f"k ∈ {{{', '.join(f'{x:g}' for x in ks)}}} N/m, α0 ∈ {{{', '.join(f'{x:g}' for x in a0s)}}} rad: "
              f"**{len(g)} points**, each {g[0]['t_end']:g} s simulated, hybrid, rtol {g[0]['rtol']:g}, "
              f"`save=\"{g[0]['save']}\"` (every step stored, so the constraint residual and time monotonicity "
              f"are checked at every step), budgets max_steps={g[0]['max_steps']:.0e}, "
              f"max_jumps={g[0]['max_jumps']:.0e}.  Per-point wall time: median {np.nanmedian(walls):.3g} s, "
              f"max {np.nanmax(walls):.3g} s.", ""]
        L += _count_table(g, "outcome (grid)") + [""]
        L += ["Outcomes by I (rows) × V (columns), each cell over k × α0 "
              f"({len(ks) * len(a0s)} runs).  Abbreviations: ok, inv = invalid_initial_state, "
              "nr = breakdown:no_root, nl = breakdown:no_landing, geo = breakdown:geometry, "
              "vc = breakdown:v_ceiling, sf = solver_failure.", ""]
        L += ["| I \\ V | " + " | ".join(f"{v:g}" for v in Vs) + " |", "|---|" + "---|" * len(Vs)]
        for I in Is:
            cells = []
            for V in Vs:
                c = Counter(_abbr(r["outcome"]) for r in g if r["I"] == I and r["V"] == V)
                cells.append(" ".join(f"{k} {v}" for k, v in sorted(c.items(), key=lambda kv: (-kv[1], kv[0]))))
            L += [f"| {I:g} | " + " | ".join(cells) + " |"]
        L += [""]
        L += ["Outcomes by α0 (rows) × k (columns), each cell over I × V:", ""]
        L += ["| α0 \\ k | " + " | ".join(f"{k:g}" for k in ks) + " |", "|---|" + "---|" * len(ks)]
        for a0 in a0s:
            cells = []
            for k in ks:
                c = Counter(_abbr(r["outcome"]) for r in g if r["alpha0"] == a0 and r["k"] == k)
                cells.append(" ".join(f"{kk} {v}" for kk, v in sorted(c.items(), key=lambda kv: (-kv[1], kv[0]))))
            L += [f"| {a0:g} | " + " | ".join(cells) + " |"]
        L += [""]
        res = np.array([r["res_max"] for r in g if r["n_points"]], dtype=float)
        jres = np.array([r["jres_max"] for r in g if r["n_jumps"] and r.get("jres_max") == r.get("jres_max")],
                        dtype=float)
        okj = [r["n_jumps"] for r in g if r["outcome"] == "ok"]
        L += [f"Max relative CONSTR residual over all stored steps of all grid runs (complete or partial): "
              f"**{np.nanmax(res) if res.size else float('nan'):.2e}**; at the jumps (level F(1 - cos θ) vs "
              f"f(v_before) and f(v_after)): **{np.nanmax(jres) if jres.size else float('nan'):.2e}**.  "
              f"Jumps per ok run: max {max(okj) if okj else 0}, total {sum(okj)}.", ""]

    rnd = by["random"]
    if rnd:
        B = RANDOM_BOX
        L += ["## Random sample", ""]
        L += [f"**{len(rnd)} points** drawn with seed {RANDOM_SEED}: I log-uniform in [{B['I'][0]:g}, {B['I'][1]:g}], "
              f"V uniform in [{B['V'][0]:g}, {B['V'][1]:g}], k log-uniform in [{B['k'][0]:g}, {B['k'][1]:g}], "
              f"α0 uniform in [{B['alpha0'][0]:g}, {B['alpha0'][1]:g}], rtol log-uniform in "
              f"[{B['rtol'][0]:g}, {B['rtol'][1]:g}]; {rnd[0]['t_end']:g} s each, `save=\"steps\"`.", ""]
        L += _count_table(rnd, "outcome (random)") + [""]
        res = np.array([r["res_max"] for r in rnd if r["n_points"]], dtype=float)
        okj = [r["n_jumps"] for r in rnd if r["outcome"] == "ok"]
        L += [f"Max relative CONSTR residual over all stored steps: **{np.nanmax(res) if res.size else float('nan'):.2e}**;"
              f" jumps per ok run: max {max(okj) if okj else 0}, total {sum(okj)}.", ""]

    loose = by["loose"]
    if loose:
        L += ["## Loose tolerances", ""]
        L += [f"**{len(loose)} runs** of {loose[0]['t_end']:g} s (`save=\"jumps\"`): V ∈ "
              f"{{{', '.join(f'{x:g}' for x in sorted({r['V'] for r in loose}))}}} m/s, I ∈ "
              f"{{{', '.join(f'{x:g}' for x in sorted({r['I'] for r in loose}))}}} kg m², α0 ∈ "
              f"{{{', '.join(f'{x:g}' for x in sorted({r['alpha0'] for r in loose}))}}} rad, (rtol, atol) ∈ "
              f"{{{', '.join(f'({rt:g}, {at:g})' if at is not None else f'({rt:g}, None)' for rt, at in LOOSE_TOLS)}}} "
              "(atol None: the default).  At such tolerances the dense output of a step can leave the model's "
              "domain (v ≤ 0) although the step's stages did not; the kernel rejects such steps, so no run "
              "may end with a non-finite or v ≤ 0 state (`nan` counts both).", ""]
        L += _count_table(loose, "outcome (loose tolerances)") + [""]

    if any(by[x] for x in by) and records:
        L += ["## Non-ok outcome classes", ""]
        L += ["| class | runs | explanation | example |", "|---|---:|---|---|"]
        cls = Counter(r["outcome"] for r in records)
        for k in sorted(cls, key=lambda s: (-cls[s], s)):
            if k == "ok":
                continue
            ex = next(r for r in records if r["outcome"] == k)
            expl = EXPLANATIONS.get(k, "BUG: unexpected exception type." if k.startswith("unexpected:") else "")
            L += [f"| `{k}` | {cls[k]} | {expl} | {_example(ex)} |"]
        L += [""]

    if by["tol"]:
        rows = tolerance_table(by["tol"])
        L += ["## Tolerance sweep", ""]
        L += ["Hybrid, 1 s, `save=\"jumps\"`, every rtol simulate accepts.  err = max |t_j − t_j^ref| over the "
              "common jumps against the same point at the smallest rtol (ref); Δn = jump-count difference.", ""]
        L += ["| point | rtol | outcome | jumps | Δn | steps | wall [s] | err jump t [s] |",
              "|---|---:|---|---:|---:|---:|---:|---:|"]
        for r in rows:
            lab = f"{r['label']} (V={r['V']:g}, I={r['I']:g}, k={r['k']:g}, α0={r['alpha0']:g})"
            L += [f"| {lab} | {r['rtol']:.0e} | `{r['outcome']}` | {r['n_jumps']} | "
                  f"{'ref' if r['reference'] else r['dn_jumps']} | {r['n_steps']} | {r['wall']:.3g} | "
                  f"{'ref' if r['reference'] else _g(r['err_jump_t'])} |"]
        L += [""]

    if by["budget"]:
        L += ["## Budget probes", ""]
        L += ["| probe | outcome | expected | t reached [s] | steps | jumps | points | partial finite, t monotone |",
              "|---|---|---|---:|---:|---:|---:|---|"]
        for r in by["budget"]:
            L += [f"| {r['label']} ({_example(r)}) | `{r['outcome']}` | `{r.get('expect') or 'any allowed'}`"
                  f"{'' if r.get('expect_met', True) else ' **NOT MET**'} | {_g(r['t_reached'])} | {r['n_steps']} | "
                  f"{r['n_jumps']} | {r['n_points']} | {not r['nonfinite']}, {r['t_monotone']} |"]
        L += [""]

    if by["variant"]:
        L += ["## Variants", ""]
        L += ["| variant | point | t_end [s] | outcome | jumps | steps | wall [s] | rel. residual median | max |",
              "|---|---|---:|---|---:|---:|---:|---:|---:|"]
        for r in by["variant"]:
            L += [f"| {r['label']} | {_example(r)} | {r['t_end']:g} | `{r['outcome']}` | {r['n_jumps']} | "
                  f"{r['n_steps']} | {r['wall']:.3g} | {_g(r.get('res_median'))} | {_g(r['res_max'])} |"]
        L += ["", "The regularised scheme does not enforce CONSTR exactly: its residual is the ε-relaxation, "
              "large during the fast transits of the jumps (where many of its steps, and so stored points, lie).  "
              "The hybrid solver computes F from CONSTR, so its residual is rounding.", ""]

    if by["long"]:
        L += ["## Long runs: constraint drift", ""]
        L += [f"Hybrid, `t_eval` at {LONG_N_EVAL} equispaced times (drift rows) and `save=\"jumps\"` (check rows). "
              f"early/late = max relative CONSTR residual over the first/last {DRIFT_FRACTION:.0%} of the samples "
              "(points) or of the jumps (level vs f(v_before), f(v_after)).", ""]
        L += ["| run | t_end [s] | outcome | jumps | steps | wall [s] | points early | points late | "
              "jumps early | jumps late | jump times = save=jumps run |",
              "|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---|"]
        for r in by["long"]:
            same = r.get("jumps_match_save_jumps")
            L += [f"| {r['label']} ({_example(r)}, rtol {r['rtol']:g}) | {r['t_end']:g} | `{r['outcome']}` | "
                  f"{r['n_jumps']} | {r['n_steps']} | {r['wall']:.3g} | {_g(r['res_early'])} | "
                  f"{_g(r['res_late'])} | {_g(r['jres_early'])} | {_g(r['jres_late'])} | "
                  f"{'–' if same is None else ('bitwise' if same else '**differ**')} |"]
        L += [""]
    return "\n".join(L)


def pair_long_runs(records: Sequence[dict]) -> None:
    """Set ``jumps_match_save_jumps`` on each long ``t_eval`` record: are its jump times bitwise
    those of the matching ``save="jumps"`` run?  (Output mode must not change the orbit.)"""
    long = [r for r in records if r.get("group") == "long"]
    for r in long:
        if not r.get("n_eval"):
            continue
        mate = next((m for m in long if m is not r and not m.get("n_eval") and m["label"].startswith(r["label"])
                     and (m["V"], m["I"], m["k"], m["alpha0"], m["t_end"], m["rtol"])
                     == (r["V"], r["I"], r["k"], r["alpha0"], r["t_end"], r["rtol"])), None)
        if mate is not None and "_jump_t" in r and "_jump_t" in mate:
            r["jumps_match_save_jumps"] = bool(np.array_equal(np.asarray(r["_jump_t"]), np.asarray(mate["_jump_t"])))


def write_records(records: Sequence[dict], out_dir: str) -> tuple[str, str]:
    """Write ``stress.csv`` and ``stress.json`` (one row per run; private ``_*`` keys dropped).

    Parameters
    ----------
    records : sequence of dict
    out_dir : str
        Directory, created if missing.

    Returns
    -------
    (csv_path, json_path)
    """
    if not isinstance(out_dir, (str, os.PathLike)) or not str(out_dir):
        raise ValueError(f"out_dir must be a non-empty path, got {out_dir!r}")
    os.makedirs(out_dir, exist_ok=True)
    rows = [{k: v for k, v in r.items() if not k.startswith("_")} for r in records]
    keys = list(dict.fromkeys(k for r in rows for k in r))
    cp = write_rows(os.path.join(out_dir, "stress.csv"), rows, fields=keys)
    jp = write_rows(os.path.join(out_dir, "stress.json"), rows)
    return cp, jp


def main(argv: Optional[Sequence[str]] = None) -> int:
    """Command-line entry point; returns 0 if no run shows a bug, 1 otherwise."""
    ap = argparse.ArgumentParser(prog="python -m comparisons._stress", description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="corner subset of the grid, shorter long run")
    ap.add_argument("--out", default="stress_out", help="output directory for stress.csv/.json/robustness.md")
    ap.add_argument("--timeout", type=float, default=60.0, help="wall-clock seconds per point (long runs: 10x)")
    ap.add_argument("--t-end", type=float, default=GRID_T_END, help="simulated horizon of grid and random points [s]")
    ap.add_argument("--n-random", type=int, default=N_RANDOM, help="size of the seeded random sample")
    ap.add_argument("--no-progress", action="store_true", help="no per-point lines on stderr")
    a = ap.parse_args(argv)
    if not (math.isfinite(a.timeout) and a.timeout > 0):
        ap.error(f"--timeout must be in (0, inf), got {a.timeout}")
    if not (math.isfinite(a.t_end) and a.t_end > 0):
        ap.error(f"--t-end must be in (0, inf), got {a.t_end}")
    if a.n_random < 0:
        ap.error(f"--n-random must be >= 0, got {a.n_random}")
    cmd = "python -m comparisons._stress" + (" --quick" if a.quick else "") + f" --out {a.out}"
    if a.t_end != GRID_T_END:
        cmd += f" --t-end {a.t_end:g}"
    if a.n_random != N_RANDOM:
        cmd += f" --n-random {a.n_random}"
    t0 = time.perf_counter()
    with StressRunner(timeout=a.timeout) as runner:
        recs = run_points(all_points(a.quick, a.t_end, a.n_random), timeout=a.timeout, progress=not a.no_progress, runner=runner)
        recs += budget_edge_probes(runner, timeout=a.timeout)
    pair_long_runs(recs)
    wall = time.perf_counter() - t0
    md = robustness_markdown(recs, command=cmd, wall_time=wall)
    write_records(recs, a.out)
    with open(os.path.join(a.out, "robustness.md"), "w") as fh:
        fh.write(md + "\n")
    sys.stdout.write("\n".join(_count_table(recs, "outcome (all runs)")) + "\n\n")
    g = [r for r in recs if r["group"] == "grid"]
    if g:
        sys.stdout.write("\n".join(_count_table(g, "outcome (grid)")) + "\n\n")
    nbug = sum(is_bug(r) for r in recs)
    sys.stdout.write(f"bugs (nan/timeout/crash/unexpected/non-monotone): {nbug}; "
                     f"unmet expectations: {sum(not r.get('expect_met', True) for r in recs)}; "
                     f"wall time {wall:.1f} s; wrote {a.out}/stress.csv, stress.json, robustness.md\n")
    return 1 if nbug else 0


if __name__ == "__main__":
    from comparisons._stress import main as _main

    sys.exit(_main())

"""The two-trajectory (Benettin) renormalisation method and the record every Lyapunov estimate returns.

* :func:`benettin` — the largest Lyapunov exponent of any flow by two-trajectory renormalisation
  (Benettin et al. 1980), tested on systems with known exponents; it runs no solver of its own (the caller
  passes ``advance``).
* :class:`BenettinResult` — its record (exponent, running estimate, local rates, standard error), built by
  :meth:`BenettinResult.from_logs` for every method of :func:`exact.lyapunov`.
* :class:`LyapunovResult` — the peeling model's largest exponent in bits/s, the one result type of
  :func:`exact.lyapunov` whatever the method (its ``method`` field says which).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, cast

import numpy as np

from peelapprox import PeelParams
from peelapprox.io import fmt_number, html_table
from peelapprox.validate import function, integer

from .._shared import natural_scales

if TYPE_CHECKING:
    from .._methods import Regularized, Smooth

__all__ = ["BenettinResult", "benettin", "LyapunovResult", "STDERR_BATCHES", "batch_means"]

#: Batches of every Lyapunov record's standard error (:meth:`BenettinResult.from_logs`, :func:`batch_means`).
STDERR_BATCHES = 10


def batch_means(logs: np.ndarray, dts: np.ndarray, m: int = STDERR_BATCHES) -> tuple[np.ndarray, np.ndarray]:
    """``(logs, dts)`` summed over ``m`` runs of consecutive intervals of about equal time (all of them, unsummed,
    when there are at most ``m``; fewer runs when a long interval spans several).

    The one batching of the Lyapunov records: :meth:`BenettinResult.from_logs` takes its standard error from the
    rates of these runs, and the tangent method keeps its record in them.
    """
    logs, dts = np.asarray(logs, float), np.asarray(dts, float)
    if logs.size <= m:
        return logs, dts
    edges = np.searchsorted(np.cumsum(dts), np.linspace(0.0, dts.sum(), m + 1)[1:-1], side="right")
    edges = np.unique(edges[(edges > 0) & (edges < logs.size)])  # no empty batch (a long interval spans several)
    return (np.array([x.sum() for x in np.split(logs, edges)]), np.array([x.sum() for x in np.split(dts, edges)]))


@dataclass
class BenettinResult:
    """Largest Lyapunov exponent by two-trajectory renormalisation.

    ``exponent`` [1/time unit, natural log] = ``Σ log(d_k/d0) / T`` over the kept intervals; ``running``
    the running estimate after each interval; ``local`` the per-interval rates ``log(d_k/d0)/Δt_k``;
    ``stderr`` the standard error of the exponent by batch means (:func:`batch_means`: the intervals grouped
    into :data:`STDERR_BATCHES` runs of consecutive intervals of about equal time, the standard error of
    their rates; successive intervals are correlated, e.g. the growth alternates with the branch, so the
    spread of single intervals misstates it; inf with fewer than two intervals, never NaN); ``time`` the
    total kept time; ``d0`` the
    reference size (the two trajectories' distance; 1 for the tangent methods, whose tangent is renormalised
    to unit size; the finite-difference step of the return-map method).
    """

    exponent: float
    running: np.ndarray
    local: np.ndarray
    stderr: float
    time: float
    n: int
    d0: float
    wall_time: float

    @classmethod
    def from_logs(cls, logs, dts, d0: float, wall_time: float) -> BenettinResult:
        """The record of per-interval log growths ``logs`` over durations ``dts`` (the one place the
        exponent, running estimate, local rates and standard error are computed from them)."""
        logs, dts = np.asarray(logs, float), np.asarray(dts, float)
        T = float(dts.sum())
        local = logs / dts
        # batch means: the rates of runs of consecutive intervals, nearly independent where single intervals
        # are not; fewer than two intervals: no spread to estimate an error from (inf, never NaN)
        b_logs, b_dts = batch_means(logs, dts, STDERR_BATCHES)
        rates = b_logs / b_dts
        stderr = float(np.std(rates, ddof=1) / math.sqrt(rates.size)) if rates.size > 1 else math.inf
        return cls(float(logs.sum() / T), np.cumsum(logs) / np.cumsum(dts), local, stderr, T, int(logs.size),
                   float(d0), float(wall_time))

    def __repr__(self) -> str:
        return (f"BenettinResult(exponent={fmt_number(self.exponent, 4)} ± {fmt_number(self.stderr, 2)}, "
                f"n={self.n} intervals over {fmt_number(self.time, 4)}, d0={fmt_number(self.d0, 3)}, "
                f"wall_time={fmt_number(self.wall_time, 3)} s)")

    def _repr_html_(self) -> str:
        return html_table("BenettinResult", {"exponent": self.exponent, "stderr": self.stderr, "intervals": self.n,
                                             "time": self.time, "d0": self.d0, "wall time [s]": self.wall_time})


def benettin(
    advance: Callable,
    x_ref,
    x_pert,
    distance: Callable,
    rescale: Callable,
    n: int,
    *,
    n_discard: int = 0,
) -> BenettinResult:
    """The largest Lyapunov exponent of a flow by the two-trajectory (Benettin) method.

    Parameters
    ----------
    advance : callable
        ``advance(x_ref, x_pert) -> (x_ref, x_pert, dt)``: both states advanced by the same time ``dt``
        (the caller chooses the renormalisation interval; it may vary, e.g. to avoid renormalising across
        a switching surface).
    x_ref, x_pert : state
        The reference state and a perturbed one at distance ``d0 = distance(x_ref, x_pert)`` (small).
    distance : callable
        ``distance(a, b) -> float``, any norm (the exponent does not depend on it).
    rescale : callable
        ``rescale(x_ref, x_pert, factor) -> x_pert`` putting the perturbation back to ``factor`` times its
        size along its current direction (or shorter: the next interval's growth is measured from the
        distance it returns).
    n : int
        Number of renormalisation intervals kept.
    n_discard : int
        Intervals run first and not counted (the perturbation aligning with the most unstable direction).

    Returns
    -------
    BenettinResult
    """
    advance, distance, rescale = (function(nm, f) for nm, f in
                                  (("advance", advance), ("distance", distance), ("rescale", rescale)))
    n, n_discard = integer("n", n, lo=2), integer("n_discard", n_discard, lo=0)
    d0 = float(distance(x_ref, x_pert))
    if not (d0 > 0.0 and math.isfinite(d0)):
        raise ValueError(f"the initial perturbation must have a finite positive size, got {d0}")
    wall0 = time.perf_counter()
    logs, dts = [], []
    d_start = d0
    for k in range(int(n_discard) + int(n)):
        x_ref, x_pert, dt = advance(x_ref, x_pert)
        d = float(distance(x_ref, x_pert))
        if not (d > 0.0 and math.isfinite(d)):
            raise ValueError(f"the perturbation collapsed or diverged at interval {k} (distance {d}); choose a "
                             f"different d0 or interval")
        if k >= n_discard:
            logs.append(math.log(d / d_start))
            dts.append(dt)
        x_pert = rescale(x_ref, x_pert, d0 / d)
        # the growth of the next interval is measured from the size rescale actually gave (it may shorten
        # the perturbation further, e.g. to keep a state feasible)
        d_start = float(distance(x_ref, x_pert))
    return BenettinResult.from_logs(logs, dts, d0, time.perf_counter() - wall0)


@dataclass
class LyapunovResult:
    """The peeling model's largest Lyapunov exponent, the result of every method of :func:`exact.lyapunov`.

    ``bits_per_s`` = ``per_s / ln 2`` (the paper's unit); ``benettin`` holds the running estimate and the
    local rates; ``n_jumps`` the jumps the reference orbit made while measured; ``method`` names the
    method that computed it (a sentence, e.g. ``"hybrid two-trajectory (Benettin)"``); ``notes`` any
    method-specific counts (steps, solves).  ``tau`` is the renormalisation interval [s] (for the methods
    that renormalise at the jumps or returns, the mean time between renormalisations); ``stderr_bits`` is inf
    when fewer than two intervals were measured (no spread to estimate an error from)."""

    per_s: float
    bits_per_s: float
    stderr_bits: float
    benettin: BenettinResult
    params: PeelParams
    tau: float
    n_jumps: int
    method: str = "hybrid two-trajectory (Benettin)"
    notes: list[str] = field(default_factory=list)

    def __repr__(self) -> str:
        p = self.params
        return (f"LyapunovResult({fmt_number(self.bits_per_s, 4)} ± {fmt_number(self.stderr_bits, 2)} bits/s, "
                f"method={self.method!r}, V={p.V:g}, I={p.I:g}, intervals={self.benettin.n}, "
                f"jumps={self.n_jumps}, tau={fmt_number(self.tau, 3)} s)")

    def _repr_html_(self) -> str:
        p = self.params
        return html_table("LyapunovResult", {
            "λ [bits/s]": f"{fmt_number(self.bits_per_s, 4)} ± {fmt_number(self.stderr_bits, 2)}",
            "λ [1/s]": self.per_s, "method": self.method, "V [m/s]": p.V, "I [kg m²]": p.I,
            "force": repr(p.force), "intervals": self.benettin.n, "time [s]": self.benettin.time,
            "jumps": self.n_jumps, "τ [s]": self.tau, "wall time [s]": self.benettin.wall_time})



def variant_two_trajectory(params: PeelParams, *, t_transient: float, tau: float, n: int, n_discard: int,
                           d0: float, alpha0: float, rtol: float, solver: str | None,
                           max_wall: float | None) -> LyapunovResult:
    """The two-trajectory method of :func:`exact.lyapunov` for a model variant (``params.variant``: the tape
    mass, the constant load), on the variant's method of :func:`exact.simulate` (``"smooth"``, or
    ``"regularized"`` for a massless tape under a load) with ``solver``.

    The variants' states are smooth ODE states ``(α, ω, F, v[, V_p])`` (v, and the pull speed V_p under a load,
    independent of CONSTR), so each interval restarts the driver from the full state and the distance is
    measured in ``(Δα/1 rad, Δω/(V/R), ΔF/f_max, Δv/V[, ΔV_p/V])``; there is no branch to wait for (the jumps are
    fast but continuous transits).  Arguments checked by the caller (:func:`exact.lyapunov`).
    """
    from peelapprox.errors import SolverBudgetExceeded, WallBudget

    from .._initial import initial_state
    from .._method_contract import method_option
    from .._model import model_of
    from .._options import output_options
    from .._trajectory import State

    # a variant's method: smooth, or regularized under a load (never the hybrid one)
    opts = cast("Regularized | Smooth", method_option(None, solver=solver, eps=None, rtol=rtol, atol=None,
                                                      v_floor=None, params=params))
    wall = WallBudget(max_wall)
    model = model_of(params)
    under_load = "Vp" in model.states
    scale = np.concatenate([natural_scales(params), [params.V] * (2 if under_load else 1)])
    jumps = [0]
    t_total = t_transient + (n + n_discard) * tau

    def run(x: np.ndarray, dt: float) -> tuple[np.ndarray, int]:
        s0 = State(0.0, float(x[0]), float(x[1]), float(x[2]), float(x[3]), "AB",
                   float(x[4]) if under_load else None)
        out, lim = output_options(opts, dt, None, None, save="jumps", t_eval=None, t_transient=0.0,
                                  max_points=5_000_000, max_steps=int(max(1e5, 2e6 * dt)), max_jumps=20_000_000,
                                  max_wall=wall.left(0.0, s0.__dict__, t_total))
        try:
            tr = opts.run(model, params, dt, s0, out, lim, None)
        except SolverBudgetExceeded as exc:
            raise wall.reraise(exc) from None
        s = tr.final_state
        return np.array([s.alpha, s.omega, s.F, s.v] + ([s.Vp] if under_load else []), dtype=float), len(tr.jumps)

    def distance(a: np.ndarray, b: np.ndarray) -> float:
        return float(np.linalg.norm((a - b) / scale))

    def rescale(ref: np.ndarray, pert: np.ndarray, factor: float) -> np.ndarray:
        return ref + factor * (pert - ref)

    def advance(ref: np.ndarray, pert: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
        ref, nj = run(ref, tau)
        pert, _ = run(pert, tau)
        jumps[0] += nj
        return ref, pert, tau

    s0 = initial_state(params, alpha0=alpha0)
    ref = np.array([s0.alpha, s0.omega, s0.F, s0.v] + ([params.V] if under_load else []), dtype=float)
    if t_transient > 0:
        ref, _ = run(ref, t_transient)
    pert = ref.copy()
    pert[2] += d0 * scale[2]  # along F, as the massless method
    res = benettin(advance, ref, pert, distance, rescale, n, n_discard=n_discard)
    ln2 = math.log(2.0)
    return LyapunovResult(res.exponent, res.exponent / ln2, res.stderr / ln2, res, params, tau, jumps[0],
                          method=f"{opts.name} {opts.solver} two-trajectory (Benettin)",
                          notes=[f"variant={params.variant}"])

"""The sweep measure ``front``: one peel-front run at a sweep point (docs/peel-front.md, "Ensembles").

:func:`measure_front` runs :func:`exact.simulate_front` at the point's :class:`peelapprox.PeelParams` (its I, V
and the sweep's ``tape_mass``, ``k``, ``R``, ...) with the front options below, drops the transient, and
returns the pattern class and its averages, the mean fraction peeling, a summary of the burst catalogue of the
AE power (and the burst energies themselves, as text, so that an ensemble can pool them across seeds), and a
chaos indicator: the largest Lyapunov exponent of the front's state by two nearby runs (Benettin's method with
finite perturbations).  It is registered as ``"front"`` in :data:`comparisons.sweep.MEASURES` when this module
is imported, so ``sweep(..., measures="front", options={...})`` runs it on any executor, resumably.

Options (all optional; :func:`check_front_options` checks them before the first point):

=====================  ===========  =====================================================================
option                 default      meaning
=====================  ===========  =====================================================================
``front_N``            16           strips
``front_gamma``        0.1          γ = 4NΓ/|f'_u| (:class:`peelapprox.FrontParams`)
``front_kappa``        0.1          κ = 4N k_c/k
``front_ends``         "free"       ``"free"`` or ``"periodic"``
``front_delta0``       0.01         initial heterogeneity δ₀
``front_seed``         0            seed of the heterogeneity
``front_t_transient``  0.02         transient dropped [s]
``front_window``       0.08         measured window after it [s]
``front_dt_save``      1e-5         sampling step of the stored series [s]
``front_rtol``         1e-8         tolerance of the runs
``front_threshold``    0.02         burst threshold, a fraction of the window's largest AE power
``front_lyapunov``     True         run the twin for the chaos indicator
``front_lyap_window``  0.04         the time the twin is followed, from the end of the transient [s]
``front_lyap_tau``     0.004        renormalisation interval of the twin [s]
``front_lyap_d0``      1e-7         the twin's separation, relative (module docstring of the indicator)
``front_steps_per_s``  5e6          step budget of each run, per simulated second (at least 5e4)
=====================  ===========  =====================================================================

The record's keys (prefixed ``front_``): ``status`` (``"ok"``, ``"breakdown:<reason>"`` with ``t_breakdown``,
``"budget:max_steps"`` with ``t_stopped``),
``pattern``, ``roughness``, ``mixed_fraction``, ``walls``, ``phi_mean`` (the mean fraction peeling),
``jumps`` (mean-front jumps in the window), ``switches_per_strip_s``, ``ae_energy`` (E_AE over the window
[J]), ``bursts`` (count), ``burst_threshold`` [W], ``burst_energy_median``, ``burst_energy_max`` [J],
``burst_energies`` (every burst's energy [J], ``repr`` floats separated by spaces), ``lyapunov`` [1/s],
``lyapunov_se``, ``lyapunov_segments``, ``chaotic`` (λ > 3 SE), ``steps``, ``cpu_s`` (the CPU seconds of the
point, for sizing ensembles).

**The chaos indicator.**  The run is continued from the end of the transient together with a twin whose
strip stretches and velocities differ by ``front_lyap_d0`` (relative, in d) (a fixed seeded direction); every
``front_lyap_tau`` the distance between the two, d (the RMS over the strips of ΔF_j/F̄ and Δv_j/V), is read and
the twin put back at distance d₀ along the current difference.  λ is the mean of ln(d/d₀)/τ over the
intervals, its standard error that of the mean; "chaotic" means λ > 3 SE.  A finite perturbation through
stick-slip jumps: a jump of the twin a little earlier or later makes d large at one reading and small at the
next, which telescopes in the mean but widens the SE; a periodic front gives λ within a few SE of 0.
"""

from __future__ import annotations

import math
import time
from collections.abc import Mapping
from typing import Any

import numpy as np

from exact import simulate_front
from peelapprox import FrontParams, ModelBreakdown, PeelParams, SolverBudgetExceeded
from peelapprox.front import FRONT_ENDS
from peelapprox.kernels import FY_EAE, FY_STRIPS
from peelapprox.validate import choice, flag, in_range, integer

from ..sweep import register_measure

__all__ = ["FRONT_DEFAULTS", "measure_front", "check_front_options", "front_params", "twin_lyapunov"]

#: The options of the ``front`` measure and their defaults (module docstring).
FRONT_DEFAULTS: dict[str, Any] = {
    "front_N": 16, "front_gamma": 0.1, "front_kappa": 0.1, "front_ends": "free", "front_delta0": 0.01,
    "front_seed": 0, "front_t_transient": 0.02, "front_window": 0.08, "front_dt_save": 1e-5, "front_rtol": 1e-8,
    "front_threshold": 0.02, "front_lyapunov": True, "front_lyap_window": 0.04, "front_lyap_tau": 0.004,
    "front_lyap_d0": 1e-7, "front_steps_per_s": 5e6,
}


def check_front_options(options: Mapping) -> dict:
    """The ``front`` measure's options with their defaults, each checked (ValueError/TypeError naming it)."""
    o = {**FRONT_DEFAULTS, **{k: v for k, v in options.items() if k in FRONT_DEFAULTS and v is not None}}
    o["front_N"] = integer("front_N", o["front_N"], 1, 4096)
    o["front_gamma"] = in_range("front_gamma", o["front_gamma"], 0.0, 1e6)
    o["front_kappa"] = in_range("front_kappa", o["front_kappa"], 0.0, 1e6)
    o["front_ends"] = choice("front_ends", o["front_ends"], FRONT_ENDS)
    o["front_delta0"] = in_range("front_delta0", o["front_delta0"], 0.0, 0.5)
    o["front_seed"] = integer("front_seed", o["front_seed"], 0, 2**32 - 1)
    o["front_t_transient"] = in_range("front_t_transient", o["front_t_transient"], 0.0, 100.0)
    o["front_window"] = in_range("front_window", o["front_window"], 0.0, 100.0, lo_open=True)
    o["front_dt_save"] = in_range("front_dt_save", o["front_dt_save"], 1e-9, o["front_window"] / 10)
    o["front_rtol"] = in_range("front_rtol", o["front_rtol"], 1e-12, 1e-4)
    o["front_threshold"] = in_range("front_threshold", o["front_threshold"], 0.0, 1.0, lo_open=True)
    o["front_lyapunov"] = flag("front_lyapunov", o["front_lyapunov"])
    o["front_lyap_window"] = in_range("front_lyap_window", o["front_lyap_window"], 0.0, 100.0, lo_open=True)
    o["front_lyap_tau"] = in_range("front_lyap_tau", o["front_lyap_tau"], 1e-5, o["front_lyap_window"] / 4)
    o["front_lyap_d0"] = in_range("front_lyap_d0", o["front_lyap_d0"], 1e-12, 1e-3)
    o["front_steps_per_s"] = in_range("front_steps_per_s", o["front_steps_per_s"], 1e3, 1e9)
    return o


def front_params(params: PeelParams, o: Mapping) -> FrontParams:
    """The :class:`peelapprox.FrontParams` of a point from its base and checked options ``o``."""
    return FrontParams(base=params, N=o["front_N"], gamma=o["front_gamma"], kappa=o["front_kappa"],
                       ends=o["front_ends"], delta0=o["front_delta0"], seed=o["front_seed"])


def _steps(per_s: float, duration: float) -> int:
    """The step budget of a run of ``duration`` [s]: ``per_s`` per simulated second, at least 5e4.  A front whose
    strip nears arrest takes ever shorter explicit steps (1.8e8 per simulated second were seen, against 2e5-2e6
    for the runs that finish): it is stopped at this budget and recorded as ``"budget:max_steps"`` instead of
    taking minutes."""
    return int(max(per_s * duration, 5e4))


def _wall(options: Mapping) -> float | None:
    left = options.get("max_wall")
    return None if left is None else max(float(left), 1e-3)


def measure_front(params: PeelParams, options: Mapping) -> dict:
    """Sweep measure ``front`` (module docstring): pattern, fraction peeling, bursts and chaos of one run."""
    c0 = time.process_time()
    o = check_front_options(options)
    fp = front_params(params, o)
    t0, t1 = o["front_t_transient"], o["front_t_transient"] + o["front_window"]
    run = dict(rtol=o["front_rtol"], store_front=False, max_wall=_wall(options))
    steps = o["front_steps_per_s"]
    try:
        head = simulate_front(fp, t0, max_steps=_steps(steps, t0), **run) if t0 > 0 else None
        y0 = None if head is None else head.final_y
        tr = simulate_front(fp, t1 - t0, y0=y0, dt_save=o["front_dt_save"], max_steps=_steps(steps, t1 - t0), **run)
        lyap = twin_lyapunov(fp, tr.initial_y, o, max_wall=_wall(options)) if o["front_lyapunov"] else None
    except ModelBreakdown as exc:
        return {"status": f"breakdown:{exc.reason}", "t_breakdown": float(exc.t),
                "cpu_s": time.process_time() - c0}
    except SolverBudgetExceeded as exc:
        if exc.budget != "max_steps":  # the sweep's max_wall: the engine leaves the point for a resume
            raise
        return {"status": "budget:max_steps", "t_stopped": float(exc.t), "cpu_s": time.process_time() - c0}
    out = {"status": "ok", **_summary(tr, fp, o)}
    if lyap is not None:
        lam, se, k = lyap
        out.update(lyapunov=lam, lyapunov_se=se, lyapunov_segments=k,
                   chaotic=bool(se is not None and lam > 3.0 * se))
    out["steps"] = int(tr.stats.n_steps) + (0 if head is None else int(head.stats.n_steps))
    out["cpu_s"] = time.process_time() - c0
    return out


def _summary(tr: Any, fp: FrontParams, o: Mapping) -> dict:
    """Pattern, fraction peeling, switches and the burst catalogue of the window ``tr``."""
    pat = tr.pattern()
    window = float(tr.t[-1] - tr.t[0])
    level = o["front_threshold"] * float(np.max(tr.ae_power)) if len(tr.ae_power) else 0.0
    energies = np.empty(0)
    if level > 0.0:
        energies = tr.bursts(level).sizes("energy")
    return {
        "pattern": pat.label, "roughness": pat.roughness, "mixed_fraction": pat.mixed_fraction,
        "walls": pat.walls, "phi_mean": float(np.trapezoid(tr.fraction_peeling, tr.t) / window),
        "jumps": len(tr.jumps), "switches_per_strip_s": tr.n_local_switches / (fp.N * window),
        "ae_energy": float(tr.ae_energy[-1] - tr.ae_energy[0]), "bursts": int(energies.size),
        "burst_threshold": level,
        "burst_energy_median": float(np.median(energies)) if energies.size else None,
        "burst_energy_max": float(np.max(energies)) if energies.size else None,
        "burst_energies": " ".join(repr(float(e)) for e in energies),
    }


def _distance(a: np.ndarray, b: np.ndarray, n: int) -> float:
    """The RMS over the strips of ΔF_j/F̄: the stretches, continuous through the jumps (a jump a little earlier
    in one run changes ΔF_j by k Δv δt only, where Δv_j itself would be of the order of the jump)."""
    F = slice(FY_STRIPS, FY_STRIPS + n)
    return math.sqrt(float(np.mean(((a[F] - b[F]) / float(np.mean(a[F]))) ** 2)))


def twin_lyapunov(fp: FrontParams, y0: np.ndarray, o: Mapping, *, max_wall: float | None = None
                  ) -> tuple[float, float | None, int]:
    """The largest Lyapunov exponent [1/s] of the front's orbit from ``y0`` over ``o["front_lyap_window"]`` by
    two nearby runs renormalised every ``o["front_lyap_tau"]`` (module docstring): ``(λ, SE or None, the
    intervals)``."""
    n, tau, d0 = fp.N, o["front_lyap_tau"], o["front_lyap_d0"]
    strips = slice(FY_STRIPS, FY_STRIPS + 2 * n)
    rng = np.random.default_rng(o["front_seed"] + 7919)
    a = np.array(y0, dtype=float)
    b = a.copy()
    scale = np.concatenate([np.full(n, float(np.mean(a[FY_STRIPS:FY_STRIPS + n]))), np.full(n, fp.base.V)])
    b[strips] += scale * rng.standard_normal(2 * n)
    b[strips] = a[strips] + (b[strips] - a[strips]) * (d0 / _distance(a, b, n))
    logs = []
    run = dict(rtol=o["front_rtol"], store_front=False, max_wall=max_wall,
               max_steps=_steps(o["front_steps_per_s"], tau))
    for _ in range(max(1, int(round(o["front_lyap_window"] / tau)))):
        a = simulate_front(fp, tau, y0=a, **run).final_y
        b = simulate_front(fp, tau, y0=b, **run).final_y
        d = _distance(a, b, n)
        if not d > 0.0:
            break
        logs.append(math.log(d / d0) / tau)
        b[strips] = a[strips] + (b[strips] - a[strips]) * (d0 / d)
        for i in (FY_EAE, FY_STRIPS + 2 * n, FY_STRIPS + 2 * n + 1):  # passive integrals: kept equal
            b[i] = a[i]
    if not logs:
        return 0.0, None, 0
    arr = np.asarray(logs)
    se = float(np.std(arr, ddof=1) / math.sqrt(arr.size)) if arr.size > 1 else None
    return float(np.mean(arr)), se, int(arr.size)


register_measure("front", measure_front, check_options=check_front_options)

"""``simulate_front``: the peel front's orbit (docs/peel-front.md), the Python side of the compiled loop
:func:`exact.front._driver.run_front` (buffers, budgets, errors, the result)."""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

import numpy as np

from peelapprox import BRANCHES, FrontParams
from peelapprox.errors import ModelBreakdown, SolverBudgetExceeded, SolverFailure
from peelapprox.kernels import (
    FY_ALPHA,
    FY_EAE,
    FY_OMEGA,
    FY_STRIPS,
    compiled_law,
    front_field,
    front_parameters,
    front_state_size,
)
from peelapprox.validate import duration, in_range, integer, optional
from peelapprox.validate import rtol as _rtol

from .._initial import initial_state
from .._trajectory import Jumps, SolverStats
from . import _driver as D
from ._trajectory import FrontTrajectory, LocalSwitches

__all__ = ["simulate_front", "ATOL_SCALE_FRONT", "V_ARREST_FRONT"]

#: Default atol = rtol * scale per component: α [rad], ω [rad/s], E_AE [J], each F_j [N], each v_j [m/s] (the
#: tape-mass model's scales, ``exact.ATOL_SCALE["smooth"]``, and 1e-6 J for the AE energy and both works).
ATOL_SCALE_FRONT = (1e-4, 1e-3, 1e-6, 1e-2, 1e-6)
#: A strip slower than this [m/s] has stopped: ModelBreakdown("arrest") (the tape-mass model's V_ARREST).
V_ARREST_FRONT = 1e-12
#: Default step budget: steps per simulated second, floor, cap (an explicit step is stability-limited near
#: m / |f'|; at m = 1e-3 kg ~2.5e6 steps per simulated second are needed at worst).
STEP_BUDGET_FRONT = (2e7, 1e6, 1e9)


def _atol(atol: Any, rtol: float, n: int) -> np.ndarray:
    size = front_state_size(n)
    if atol is None:
        a, w, e, F, v = (rtol * s for s in ATOL_SCALE_FRONT)
        return np.concatenate([[a, w, e], np.full(n, F), np.full(n, v), [e, e]])
    arr = np.asarray(atol, dtype=float)
    if arr.ndim == 0:
        arr = np.full(size, float(arr))
    if arr.shape != (size,) or not np.all(np.isfinite(arr)) or not np.all(arr > 0.0):
        raise ValueError(f"atol must be None, a positive float or {size} positive floats (5 + 2N), got shape "
                         f"{arr.shape}")
    return np.ascontiguousarray(arr)


def _start(fp: FrontParams, y0: Any, alpha0: float, omega0: float | None, F0: float | None,
           branch0: str | None) -> np.ndarray:
    """The initial state: the tape-mass model's start (``exact.initial_state``), uniform, then the stretches
    spread by ``delta0`` (mean kept), or the given full state ``y0``."""
    n = fp.N
    if y0 is not None:
        y = np.array(y0, dtype=float)
        if y.shape != (front_state_size(n),) or not np.all(np.isfinite(y)):
            raise ValueError(f"y0 must be {front_state_size(n)} finite floats (α, ω, E_AE, F_j…, v_j…, W_in, "
                             f"W_peel), got shape {y.shape}")
        if not np.all(y[FY_STRIPS + n:FY_STRIPS + 2 * n] > 0.0):
            raise ValueError("y0's velocities v_j must be > 0")
        return y
    s0 = initial_state(fp.base, alpha0=alpha0, omega0=omega0, F0=F0, branch0=branch0)
    xi = np.zeros(n)
    if fp.delta0 > 0.0 and n > 1:
        xi = np.random.default_rng(fp.seed).uniform(-1.0, 1.0, n)
        xi -= xi.mean()
    return np.concatenate([[s0.alpha, s0.omega, 0.0], s0.F * (1.0 + fp.delta0 * xi), np.full(n, s0.v), [0.0, 0.0]])


def simulate_front(params: FrontParams, t_end: float, *, rtol: float = 1e-8, atol: Any = None, alpha0: float = 0.0,
                   omega0: float | None = None, F0: float | None = None, branch0: str | None = None, y0: Any = None,
                   t_transient: float = 0.0, dt_save: float | None = None, store_front: bool = True,
                   max_values: int = 100_000_000, max_steps: int | None = None, max_local: int = 5_000_000,
                   max_jumps: int = 1_000_000, max_wall: float | None = 600.0,
                   progress: None | bool | Callable[[float, float], None] = None) -> FrontTrajectory:
    """Integrate the peel front (docs/peel-front.md) from t = 0 to ``t_end``.

    The state is ``(α, ω, E_AE, F_j, v_j)`` (``F_j = k u_j``), integrated by the package's compiled DOP853
    (explicit, order 8, scipy's tolerance semantics: the RMS over all 5 + 2N components of the scaled error
    ≤ 1) at O(N) cost per step.  Explicit: its step is limited by the fast scale ``m/|f'|`` of the strips (docs,
    "Numerics"), so very light tapes (m ≲ 1e-5 kg) take many steps; the tape-mass model's stiff solvers are
    for those (``exact.simulate(method="smooth")``, N = 1).

    Parameters
    ----------
    params : FrontParams
        The front (N strips, γ, κ, ends, δ₀, seed) and its base point model with a tape mass.
    t_end : float
        Final time [s], in (0, 1e6].
    rtol : float
        Relative tolerance, in [1e-14, 1e-2].
    atol : None, float or 5 + 2N floats
        Absolute tolerance; None: ``rtol * ATOL_SCALE_FRONT`` per component.
    alpha0, omega0, F0, branch0 : optional
        The uniform start, as for :func:`exact.simulate` (:func:`exact.initial_state` of ``params.base``); the
        stretches are then spread by ``params.delta0`` with seed ``params.seed`` (mean kept).
    y0 : array of 5 + 2N floats, optional
        The full initial state ``(α, ω, E_AE, F_j…, v_j…, W_in, W_peel)`` instead (say, a previous run's
        ``final_y``).
    t_transient : float
        Store points, jumps and local switches from this time on, in [0, t_end].
    dt_save : float, optional
        Store on the grid ``t = k dt_save`` (the dense output, 7th order) instead of at every accepted step.
    store_front : bool
        Store F_j and v_j at every stored point (memory ``2N`` floats a point); False: the global series only.
    max_values : int
        Memory budget: stored floats (points × (12 + 2N, or 12)), default 1e8 (800 MB; building the result
        copies them once more).  N = 128 over the tape-mass model's first 10 jumps at I = 1e-5 stores 240,000
        steps × 268 floats = 6.4e7: pass ``dt_save`` or ``store_front=False`` for longer or wider runs.
    max_steps : int, optional
        Accepted steps; None: 2e7 per simulated second within [1e6, 1e9].
    max_local, max_jumps : int
        Stored local switches and mean jumps.
    max_wall : float or None
        Wall-clock budget [s] (checked between compiled calls ~0.2 s apart); default 600.
    progress : bool or callable
        True prints progress to stderr; a callable receives ``(t, t_end)``.

    Returns
    -------
    FrontTrajectory

    Raises
    ------
    ValueError, TypeError
        Bad arguments, named with their ranges.
    ModelBreakdown
        A strip arrests (``reason="arrest"``, v_j ≤ 1e-12 m/s; the message names the strip), the tape goes slack
        (``"slack"``), a velocity leaves the law's domain (``"law_domain"``); with the partial trajectory.
    SolverBudgetExceeded, SolverFailure
        A budget used up (``budget`` names it) / the integrator cannot proceed; with the partial trajectory.
    """
    if not isinstance(params, FrontParams):
        raise TypeError(f"params must be a FrontParams, got {type(params).__name__}")
    kw = _checked(params.N, t_end, rtol, atol, t_transient, dt_save, store_front, max_values, max_steps, max_local,
                  max_jumps, max_wall, progress)
    y = np.ascontiguousarray(_start(params, y0, alpha0, omega0, F0, branch0))
    return _Run(params, **kw).go(y)


def _checked(n: int, t_end: float, rtol: float, atol: Any, t_transient: float, dt_save: float | None,
             store_front: bool, max_values: int, max_steps: int | None, max_local: int, max_jumps: int,
             max_wall: float | None, progress: Any) -> dict:
    """:func:`simulate_front`'s options checked (ValueError/TypeError naming each), as :class:`_Run`'s keywords."""
    t_end = duration("t_end", t_end)
    rt = _rtol("rtol", rtol)
    at = _atol(atol, rt, n)
    t_store = in_range("t_transient", t_transient, 0.0, t_end)
    dts = optional(lambda nm, x: in_range(nm, x, 0.0, t_end, lo_open=True), "dt_save", dt_save)
    if not isinstance(store_front, bool):
        raise TypeError(f"store_front must be a bool, got {type(store_front).__name__}")
    max_values = integer("max_values", max_values, 1000, 10**10)
    rate, lo, hi = STEP_BUDGET_FRONT
    max_steps = (integer("max_steps", max_steps, 1, 10**12) if max_steps is not None
                 else int(min(max(rate * t_end, lo), hi)))
    max_local = integer("max_local", max_local, 1, 10**10)
    max_jumps = integer("max_jumps", max_jumps, 1, 10**10)
    max_wall = optional(lambda nm, x: in_range(nm, x, 0.0, 1e7, lo_open=True), "max_wall", max_wall)
    if progress is True:
        import sys

        def progress(t: float, te: float) -> None:
            print(f"simulate_front N={n}: t = {t:.6g} / {te:.6g} s", file=sys.stderr, flush=True)
    elif progress is False:
        progress = None
    elif progress is not None and not callable(progress):
        raise TypeError(f"progress must be None, a bool or a callable (t, t_end), got {type(progress).__name__}")
    return dict(t_end=t_end, rtol=rt, atol=at, t_store=t_store, dt_save=dts, store_front=store_front,
                max_values=max_values, max_steps=max_steps, max_local=max_local, max_jumps=max_jumps,
                max_wall=max_wall, progress=progress)


class _Run:
    """One run's buffers and loop (:func:`simulate_front`)."""

    def __init__(self, fp: FrontParams, t_end: float, rtol: float, atol: np.ndarray, t_store: float,
                 dt_save: float | None, store_front: bool, max_values: int, max_steps: int, max_local: int,
                 max_jumps: int, max_wall: float | None, progress: Any) -> None:
        self.fp, self.t_end, self.rtol, self.atol, self.t_store, self.dt_save = fp, t_end, rtol, atol, t_store, dt_save
        self.store_front, self.max_values, self.max_steps = store_front, max_values, max_steps
        self.max_local, self.max_jumps, self.max_wall, self.progress = max_local, max_jumps, max_wall, progress
        n = fp.N
        self.cl = compiled_law(fp.base.force, fp.base.V)
        self.v_mid = self.cl.structure.v_inflection
        self.q = front_parameters(fp)
        self.width = D.N_G + (2 * n if store_front else 0)
        self.max_points = max(2, max_values // self.width)
        rows = int(min(self.max_points, max(256, 2_000_000 // self.width)))
        self.out_g = np.zeros((rows, D.N_G))
        self.out_y = np.zeros((rows, 2 * n) if store_front else (1, 1))
        self.jbuf = np.zeros((1024, 8))
        self.lbuf = np.zeros((max(4096, 4 * n), 3))
        self.cnt = np.zeros(D.N_C, dtype=np.int64)
        self.st = np.zeros(D.N_ST)
        self.g_chunks: list[np.ndarray] = []
        self.y_chunks: list[np.ndarray] = []
        self.j_chunks: list[np.ndarray] = []
        self.l_chunks: list[np.ndarray] = []
        self.n_points = self.n_jout = self.n_lout = 0
        lo, hi = self.cl.domain
        self.opts = np.array([rtol, t_end, t_store, self.v_mid, V_ARREST_FRONT, lo, hi, dt_save or 0.0])
        m = front_state_size(n)  # the DOP853 work arrays (peelapprox.kernels.workspace's layout)
        self.work = (np.zeros((16, m)), np.zeros(m), np.zeros(m), np.zeros(m), np.zeros(m), np.zeros((3, m)),
                     np.zeros((7, m)), np.zeros(m))
        self.call_steps = max(10, int(2e5 / n))  # ~0.1-0.2 s of work a call: the wall budget's granularity

    def flush(self) -> None:
        c = self.cnt
        k = int(c[D.C_NOUT])
        if k:
            self.g_chunks.append(self.out_g[:k].copy())
            if self.store_front:
                self.y_chunks.append(self.out_y[:k].copy())
            self.n_points += k
            c[D.C_NOUT] = 0
        k = int(c[D.C_NJOUT])
        if k:
            self.j_chunks.append(self.jbuf[:k].copy())
            self.n_jout += k
            c[D.C_NJOUT] = 0
        k = int(c[D.C_NLOUT])
        if k:
            self.l_chunks.append(self.lbuf[:k].copy())
            self.n_lout += k
            c[D.C_NLOUT] = 0

    def state(self, y: np.ndarray) -> dict:
        n = self.fp.N
        v = y[FY_STRIPS + n:FY_STRIPS + 2 * n]
        vm = float(v.mean())
        return {"t": float(self.st[D.S_T]), "alpha": float(y[FY_ALPHA]), "omega": float(y[FY_OMEGA]),
                "F": float(y[FY_STRIPS:FY_STRIPS + n].mean()), "v": vm, "ae_energy": float(y[FY_EAE]),
                "v_min": float(v.min()), "v_max": float(v.max()), "branch": BRANCHES[int(vm > self.v_mid)]}

    def go(self, y: np.ndarray) -> FrontTrajectory:
        y_init = y.copy()
        self.y = y
        wall0 = time.perf_counter()
        last = wall0
        K, y_new, _f0, tmp, sc, work, Fc, ye = self.work
        lim = {"max_values": self.max_points, "max_jumps": self.max_jumps, "max_local": self.max_local}
        while True:
            call = max(1, min(self.call_steps, self.max_steps - int(self.cnt[D.C_STEPS])))
            caps = {name: min(self._room(name), lim[name] - used) for name, used in
                    (("max_values", self.n_points), ("max_jumps", self.n_jout), ("max_local", self.n_lout))}
            for name, cap in caps.items():
                if cap <= (self.fp.N if name == "max_local" else 0):
                    raise self._budget(name, lim[name], y, y_init, wall0)
            og = self.out_g[:caps["max_values"]]
            oy = self.out_y[:caps["max_values"]] if self.store_front else self.out_y
            status = D.run_front(y, self.st, self.q, self.cl.fn, self.cl.coef, self.atol, self.opts, og, oy,
                                 self.jbuf[:caps["max_jumps"]], self.lbuf[:caps["max_local"]], self.cnt, call,
                                 self.store_front, K,
                                 y_new, tmp, sc, Fc, ye, work)
            if status == D.DONE:
                break
            if status not in (D.OUT_FULL, D.JUMPS_FULL, D.LOCAL_FULL, D.PAUSE):
                raise self._stop(status, y, y_init, wall0)
            if status != D.PAUSE:
                self.flush()
            now = time.perf_counter()
            if self.cnt[D.C_STEPS] >= self.max_steps:
                raise self._budget("max_steps", self.max_steps, y, y_init, wall0)
            if self.max_wall is not None and now - wall0 > self.max_wall:
                raise self._budget("max_wall", self.max_wall, y, y_init, wall0)
            if self.progress and now - last > 0.5:
                last = now
                self.progress(float(self.st[D.S_T]), self.t_end)
        if self.progress:
            self.progress(self.t_end, self.t_end)
        return self.build(y, y_init, wall0, 0, "reached t_end")

    def _room(self, name: str) -> int:
        return {"max_values": self.out_g.shape[0], "max_jumps": self.jbuf.shape[0],
                "max_local": self.lbuf.shape[0]}[name]

    def _budget(self, name: str, limit: float, y: np.ndarray, y_init: np.ndarray, wall0: float) -> Exception:
        hint = {"max_values": "; pass dt_save, store_front=False, a later t_transient or a larger max_values",
                "max_steps": "; pass a larger max_steps", "max_wall": "; pass a larger max_wall, or None",
                "max_jumps": "; pass a larger max_jumps", "max_local": "; pass a larger max_local"}[name]
        part = self.build(y, y_init, wall0, 1, f"stopped early: {name}")
        t = float(self.st[D.S_T])
        return SolverBudgetExceeded(f"simulate_front: {name}={limit:g} used up at t={t:.9g} before t_end="
                                    f"{self.t_end:g}{hint}", budget=name, limit=float(limit), t=t,
                                    state=self.state(y), partial=part)

    def _stop(self, status: int, y: np.ndarray, y_init: np.ndarray, wall0: float) -> Exception:
        t = float(self.st[D.S_T])
        part = self.build(y, y_init, wall0, 1, "stopped early")
        n = self.fp.N
        j = int(self.st[D.S_BAD_J])
        if status == D.STEP_FAIL:
            return SolverFailure(f"simulate_front: DOP853 could not take a step after t={t:.9g} (step "
                                 f"{self.st[D.S_H]:.3g} s after repeated rejections); tighten or loosen rtol",
                                 t=t, state=self.state(y), partial=part)
        if status == D.NONFINITE:
            return SolverFailure(f"simulate_front: the state became non-finite after t={t:.9g}", t=t,
                                 state=self.state(y), partial=part)
        if status == D.ARREST and not self._decelerates(y, j):
            return SolverFailure(f"simulate_front: strip j={j}'s v_j fell to {y[FY_STRIPS + n + j]:.3g} m/s after "
                                 f"t={t:.9g}, but at rest it would accelerate again: a numerical overshoot, not an "
                                 "arrest; tighten rtol", t=t, state={**self.state(y), "strip": j}, partial=part)
        if status == D.ARREST:
            return ModelBreakdown(f"model breakdown after t={t:.9g}: strip j={j} of {n} came to rest (v_j <= "
                                  f"{V_ARREST_FRONT:g} m/s): the local peel front stops, outside the model (a front "
                                  "that only advances)", t=t, state={**self.state(y), "strip": j}, reason="arrest",
                                  partial=part)
        if status == D.SLACK:
            return ModelBreakdown(f"model breakdown after t={t:.9g}: the pull force F fell to <= 0: the tape goes "
                                  "slack, outside the model", t=t, state=self.state(y), reason="slack", partial=part)
        lo, hi = self.cl.domain
        return ModelBreakdown(f"model breakdown after t={t:.9g}: strip j={j}'s v_j left the domain [{lo:.6g}, "
                              f"{hi:.6g}] m/s of the peel-force law {self.fp.base.force!r}", t=t,
                              state={**self.state(y), "strip": j}, reason="law_domain", partial=part)

    def _decelerates(self, y: np.ndarray, j: int) -> bool:
        """Whether strip j, put at rest (v_j = V_ARREST_FRONT) in state y, still decelerates: the arrest is
        physical (the tape-mass driver's test, strip by strip)."""
        z = y.copy()
        z[FY_STRIPS + self.fp.N + j] = V_ARREST_FRONT
        out = np.zeros_like(z)
        front_field()(z, self.q, self.cl.fn, self.cl.coef, out)
        return bool(out[FY_STRIPS + self.fp.N + j] <= 0.0)

    def build(self, y: np.ndarray, y_init: np.ndarray, wall0: float, status: int, message: str) -> FrontTrajectory:
        self.flush()
        n = self.fp.N
        g = np.concatenate(self.g_chunks) if self.g_chunks else np.zeros((0, D.N_G))
        fy = (np.concatenate(self.y_chunks) if self.y_chunks else np.zeros((0, 2 * n))) if self.store_front else None
        jb = np.concatenate(self.j_chunks) if self.j_chunks else np.zeros((0, 8))
        lb = np.concatenate(self.l_chunks) if self.l_chunks else np.zeros((0, 3))
        c = self.cnt
        stats = SolverStats(n_steps=int(c[D.C_STEPS]), n_rejected=int(c[D.C_REJ]), n_rhs=int(c[D.C_RHS]),
                            n_jumps=int(c[D.C_JUMPS]), wall_time=time.perf_counter() - wall0)
        return FrontTrajectory(
            params=self.fp, t=g[:, D.G_T], alpha=g[:, D.G_ALPHA], omega=g[:, D.G_OMEGA], F=g[:, D.G_F],
            v=g[:, D.G_V], ae_power=g[:, D.G_PAE], ae_energy=g[:, D.G_EAE], fraction_peeling=g[:, D.G_PHI],
            roughness=g[:, D.G_W], domain_walls=g[:, D.G_NDW].astype(np.int64), work_in=g[:, D.G_WIN],
            work_peel=g[:, D.G_WPEEL],
            front_F=None if fy is None else fy[:, :n], front_v=None if fy is None else fy[:, n:],
            jumps=Jumps.from_buffer(jb), local_switches=LocalSwitches(lb[:, 0].copy(), lb[:, 1].astype(np.int64),
                                                                        lb[:, 2].astype(np.int8)),
            stats=stats, n_local_switches=int(c[D.C_LOCAL]), rtol=self.rtol, atol=self.atol, t_end=self.t_end,
            t_transient=self.t_store, dt_save=self.dt_save, v_inflection=self.v_mid, initial_y=y_init,
            final_y=y.copy(), status=status, message=message)

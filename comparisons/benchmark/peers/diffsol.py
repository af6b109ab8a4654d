"""The diffsol peer through pydiffsol: the DiffSL model printed from the symbolic source
(:func:`peelapprox.kernels.diffsl_code`), JIT-compiled by LLVM, integrated by diffsol's BDF with the mass
matrix; its root finder stops at the crossings of ``v = v_infl`` (:mod:`comparisons.benchmark.peers` has the
common rules)."""

from __future__ import annotations

import math
import time

import numpy as np

from peelapprox.kernels import DIFFSOL_OPTIONS, diffsl_inputs, diffsl_model

__all__ = ["run", "smoke"]


def smoke(ds) -> bool:
    """Whether the imported pydiffsol ``ds`` solves ``u' = -u`` to 1e-3."""
    ode = ds.Ode("u { 1.0 } F { -u }")
    return abs(float(ode.solve(np.zeros(0), 1.0).ys[0, -1]) - math.exp(-1.0)) < 1e-3


def run(params, t_end, eps, rtol, atol, y0):
    """Integrate with diffsol's BDF from ``y0`` on the DiffSL model; the fields of a PeerResult."""
    c0 = time.perf_counter()
    ode = diffsl_model(params.geometry, force=params.force)  # ValueError for a table: no closed form
    ode.rtol, ode.atol, ode.t0 = rtol, 1.0, 0.0  # scalar atol 1 on y = X / atol
    for name, val in DIFFSOL_OPTIONS.items():
        setattr(ode.options, name, val)
    p = diffsl_inputs(params, eps, y0, atol)
    compile_time = time.perf_counter() - c0
    w0 = time.perf_counter()
    try:
        sol = ode.solve(p, t_end)
    except Exception as exc:  # noqa: BLE001 - report, never raise, a solver failure
        return dict(wall_time=time.perf_counter() - w0, compile_time=compile_time, status=f"failed: {exc}",
                    jump_t=np.zeros(0), jump_F=np.zeros(0), n_steps=-1, n_rhs=-1)
    wall = time.perf_counter() - w0
    ts = np.asarray(sol.ts, float)
    ys = np.asarray(sol.ys, float)
    dup = np.nonzero(np.diff(ts) == 0.0)[0]  # stop + identity reset: the crossing is stored twice
    jt = ts[dup].copy()
    jF = ys[2, dup] * atol[2]
    status = "ok" if ts.size and ts[-1] == t_end else f"failed: stopped at t={ts[-1] if ts.size else 0:.9g}"
    return dict(wall_time=wall, compile_time=compile_time, status=status, jump_t=jt, jump_F=jF,
                n_steps=int(ts.size - 1 - dup.size), n_rhs=-1)

"""The tape-mass model's low-mass limit, measured: convergence to the massless (hybrid) solution, and
which ε of the paper's scheme a tape mass corresponds to.

    python -m comparisons.benchmark.tape_mass_limit [--json FILE] [--figure PNG]

1. **Convergence** (:func:`convergence`).  For each scene of :data:`LIMIT_SCENES` the hybrid solution (the
   massless DAE, rtol 1e-12) gives the first 10 jumps; the horizon ends halfway between the 10th and the 11th.
   The tape-mass model (LSODA, rtol 1e-12) and, for comparison, the paper's ε-scheme at ε = m (``method=
   "regularized"``, LSODA, rtol 1e-12) are run for m = 1e-10 … 1e-4 kg, and compared with the hybrid jumps:
   ``dt = max_j |t_j - t_j^hybrid|`` over the first 10 jumps and ``dF = max_j |F_j - F_j^hybrid| / F_j^hybrid``.
   A power law ``dt = C m^p`` is fitted over the masses whose run has the hybrid's jump sequence (the same
   number of jumps, and ``dt`` below 1 % of the mean jump interval: the orbit is not another one).  The
   ε-scheme's fold-passage law is p = 2/3 (docs/theory.md).
2. **ε–m correspondence** (:func:`eps_match`).  Near the slow manifold the tape-mass model is the ε-scheme with
   ``ε_eff = m (1 + sin α)²`` (α at the fold; docs/tape-mass.md).  For each case of :data:`MATCH_CASES` (the
   first jump at α ≈ 0, ≈ -0.28 and ≈ +0.32 rad) and a few masses, the ε whose first-jump delay past the hybrid
   jump equals the mass model's is found from the fold-passage law: one ε-scheme run at ε = m gives its delay
   d_ε, and ``ε_match = m (d_m / d_ε)^(3/2)``; a second run at ε_match checks it (its delay against d_m).
3. **The neglected term** (:func:`ribbon_rotation`): the ribbon's transverse kinetic energy against the
   translational one the model keeps, along the orbits at m = 1e-3 kg.
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

import numpy as np

import exact
from peelapprox import PeelParams
from peelapprox.plotting import save_figure

from .eps import fit_power_law

__all__ = ["LIMIT_MASSES", "LIMIT_SCENES", "MATCH_CASES", "convergence", "eps_match", "main", "plot_limit",
           "ribbon_rotation"]

#: (name, V, I): the paper's scene and one with large excursions of α (I = 1e-2).
LIMIT_SCENES = (("V1 I1e-5", 1.0, 1e-5), ("V1 I1e-2", 1.0, 1e-2))
LIMIT_MASSES = (1e-10, 1e-9, 1e-8, 1e-7, 1e-6, 1e-5, 1e-4)
#: (name, V, I, branch0, alpha0, F0): starts whose first jump happens at different α (≈ 0, -0.28, +0.32 rad).
MATCH_CASES = (("V1 I1e-5 AB a0=0", 1.0, 1e-5, "AB", 0.0, None),
               ("V1 I1e-2 CD a0=-0.2", 1.0, 1e-2, "CD", -0.2, None),
               ("V1 I1e-2 AB a0=0.3 F0=215", 1.0, 1e-2, "AB", 0.3, 215.0))
RTOL = 1e-12
N_JUMPS = 10


def _horizon(p: PeelParams, n: int = N_JUMPS) -> tuple[float, exact.Jumps]:
    h = exact.simulate(p, 2.0, rtol=RTOL, save="jumps")
    if len(h.jumps) <= n:
        raise ValueError(f"the scene needs more than {n} jumps in 2 s, has {len(h.jumps)}")
    T = 0.5 * float(h.jumps.t[n - 1] + h.jumps.t[n])
    return T, exact.simulate(p, T, rtol=RTOL, save="jumps").jumps


def _diff(tr: exact.Trajectory, ref: exact.Jumps) -> tuple[float, float, float, int]:
    """(dt, dF, first-jump dt, jumps) of a run against the hybrid jumps."""
    n = min(len(tr.jumps), len(ref))
    dt = float(np.max(np.abs(tr.jumps.t[:n] - ref.t[:n])))
    dF = float(np.max(np.abs(tr.jumps.F[:n] - ref.F[:n]) / ref.F[:n]))
    return dt, dF, float(tr.jumps.t[0] - ref.t[0]), len(tr.jumps)


def convergence(masses=LIMIT_MASSES, scenes=LIMIT_SCENES, say=print) -> dict:
    """Rows and fits of part 1 (module docstring)."""
    out: dict = {}
    for name, V, I in scenes:
        p0 = PeelParams(V=V, I=I)
        T, ref = _horizon(p0)
        Tbar = float(ref.t[-1] - ref.t[0]) / (len(ref) - 1)
        rows = []
        for m in masses:
            tm = exact.simulate(PeelParams(V=V, I=I, tape_mass=m), T, rtol=RTOL, save="jumps", max_steps=10**7)
            te = exact.simulate(p0, T, method="regularized", solver="LSODA", eps=m, rtol=RTOL, save="jumps",
                                max_steps=10**7)
            (dt, dF, d1, n), (edt, edF, ed1, en) = _diff(tm, ref), _diff(te, ref)
            rows.append(dict(mass=m, dt=dt, dF=dF, first=d1, jumps=n, eps_dt=edt, eps_dF=edF, eps_first=ed1,
                             eps_jumps=en, same_orbit=bool(n == len(ref) and dt < 0.01 * Tbar),
                             eps_same_orbit=bool(en == len(ref) and edt < 0.01 * Tbar)))
            say(f"limit {name} m={m:.0e}: dt {dt:.3e} s dF {dF:.2e} first {d1:.3e} s ({n} jumps) | eps=m: dt "
                f"{edt:.3e} s first {ed1:.3e} s ({en} jumps)")
        fits = {}
        for key, ok in (("dt", "same_orbit"), ("first", "same_orbit"), ("dF", "same_orbit"),
                        ("eps_dt", "eps_same_orbit"), ("eps_first", "eps_same_orbit")):
            use = [r for r in rows if r[ok]]
            if len(use) >= 3:
                C, pw, res = fit_power_law(np.array([r["mass"] for r in use]), np.array([abs(r[key]) for r in use]))
                fits[key] = dict(C=C, p=pw, max_residual=res, masses=[r["mass"] for r in use])
        out[name] = dict(V=V, I=I, horizon=T, hybrid_t=ref.t.tolist(), hybrid_alpha=ref.alpha.tolist(),
                         rows=rows, fits=fits)
        say(f"fits {name}: " + "; ".join(f"{k} ~ m^{v['p']:.3f}" for k, v in fits.items()))
    return out


def eps_match(masses=(1e-8, 1e-6), cases=MATCH_CASES, say=print) -> list[dict]:
    """Rows of part 2 (module docstring): the measured ε_match / m against the predicted (1 + sin α_fold)²."""
    rows = []
    for name, V, I, br, a0, F0 in cases:
        p0 = PeelParams(V=V, I=I)
        kw = dict(branch0=br, alpha0=a0, F0=F0, rtol=RTOL, save="jumps", max_steps=10**7)
        h = exact.simulate(p0, 0.05, **kw).jumps  # type: ignore[arg-type]
        T = 0.5 * float(h.t[0] + h.t[1])
        a = float(h.alpha[0])
        for m in masses:
            tm = exact.simulate(PeelParams(V=V, I=I, tape_mass=m), T, **kw)  # type: ignore[arg-type]
            te = exact.simulate(p0, T, method="regularized", solver="LSODA", eps=m, **kw)  # type: ignore[arg-type]
            dm, de = float(tm.jumps.t[0] - h.t[0]), float(te.jumps.t[0] - h.t[0])
            e_match = m * (dm / de) ** 1.5
            tc = exact.simulate(p0, T, method="regularized", solver="LSODA", eps=e_match, **kw)  # type: ignore[arg-type]
            dc = float(tc.jumps.t[0] - h.t[0])
            rows.append(dict(case=name, mass=m, alpha_fold=a, from_branch=int(h.from_branch[0]),
                             predicted=(1.0 + math.sin(a)) ** 2, measured=e_match / m, delay_mass=dm,
                             delay_eps_m=de, delay_eps_match=dc))
            say(f"eps match {name} m={m:.0e}: alpha {a:+.4f}, eps/m measured {e_match / m:.4f}, predicted "
                f"{(1 + math.sin(a)) ** 2:.4f} (delays: mass {dm:.4e}, eps=m {de:.4e}, eps_match {dc:.4e} s)")
    return rows


def ribbon_rotation(m: float = 1e-3, scenes=LIMIT_SCENES, t_end: float = 0.5, say=print) -> list[dict]:
    """The size of the term the model neglects: the ribbon's transverse (rotational) kinetic energy against the
    translational one it keeps, along the tape-mass model's orbit (200 001 points over ``t_end``), averaged on each
    branch; and the ribbon's moment of inertia seen by α against the roller's I.

    The ribbon is the straight segment PO'.  Its direction φ = atan2(-R sin α, l - R cos α) turns at
    ``φ̇ = -R sin θ α̇ / L`` (P moves at R α̇ along the roller, O' only along the ribbon), so a uniform rod
    turning about O' carries ``m L² φ̇² / 6 = m R² sin²θ α̇² / 6`` (exact geometry for sin θ and L); the
    translational term is ``m (V - u̇)² / 2`` with ``u̇ = V + R c α̇ - v`` (Eq. v) and ``α̇ = ω - v/R`` (FLOW1),
    all from the stored states.  Seen by α the rotation is an added moment of inertia ``m R² sin²θ / 3``
    (``m R² / 3`` at α = 0).  (Not θ̇: θ is measured from the roller's tangent at P, which turns with α.)"""
    rows = []
    for name, V, I in scenes:
        p = PeelParams(V=V, I=I, tape_mass=m)
        tr = exact.simulate(p, t_end, rtol=1e-9, t_eval=np.linspace(0.0, t_end, 200_001))
        a = tr.alpha
        L = np.sqrt(p.l**2 + p.R**2 - 2 * p.l * p.R * np.cos(a))
        sin_th = (p.l * np.cos(a) - p.R) / L
        a_dot = tr.omega - tr.v / p.R
        c = np.asarray(p.closure(a)[0])
        u_dot = V + p.R * c * a_dot - tr.v
        e_rot = m * (p.R * sin_th * a_dot) ** 2 / 6
        e_tr = m * (V - u_dot) ** 2 / 2
        row: dict = dict(scene=name, mass=m, inertia_ratio=m * p.R**2 / (3 * I))
        for b, br in ((0, "AB"), (1, "CD")):
            sel = tr.branch == b
            row[f"rot_over_trans_{br}"] = float(e_rot[sel].mean() / e_tr[sel].mean())
            row[f"time_fraction_{br}"] = float(sel.mean())
        rows.append(row)
        say(f"ribbon rotation {name} m={m:g}: <E_rot>/<E_trans> on AB {row['rot_over_trans_AB']:.3g}, on CD "
            f"{row['rot_over_trans_CD']:.3g}; m R^2/(3 I) = {row['inertia_ratio']:.3g}")
    return rows


def plot_limit(conv: dict, path: Path) -> None:
    """The convergence figure: dt against m for the mass model and the ε-scheme (ε = m), each scene."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.0, 4.0), dpi=110)
    for (name, res), col in zip(conv.items(), ("C0", "C1")):
        m = np.array([r["mass"] for r in res["rows"]])
        ax.loglog(m, [r["dt"] for r in res["rows"]], "o-", color=col, label=f"tape mass m, {name}")
        ax.loglog(m, [r["eps_dt"] for r in res["rows"]], "x--", color=col, alpha=0.6, label=f"ε-scheme ε = m, {name}")
    mm = np.array([1e-10, 1e-4])
    ax.loglog(mm, 1.5e-1 * mm ** (2 / 3), "k:", label="∝ m^(2/3)")
    ax.set_xlabel("tape mass m [kg]  (ε for the ε-scheme)")
    ax.set_ylabel("max |t_j − t_j(hybrid)| over 10 jumps [s]")
    ax.set_title("Low-mass limit: jump times → the massless (hybrid) solution")
    ax.legend(fontsize=7)
    ax.grid(True, which="major", alpha=0.3)
    fig.tight_layout()
    save_figure(fig, path, dpi=fig.dpi)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m comparisons.benchmark.tape_mass_limit",
                                 description=__doc__.split("\n")[0])
    ap.add_argument("--json", type=Path, default=None, help="also write the results as JSON")
    ap.add_argument("--figure", type=Path, default=None, help="write the convergence figure (PNG)")
    args = ap.parse_args(argv)
    rotation = ribbon_rotation()
    match = eps_match()
    conv = convergence()
    if args.figure:
        plot_limit(conv, args.figure)
    if args.json:
        args.json.write_text(json.dumps(dict(convergence=conv, eps_match=match, ribbon_rotation=rotation), indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

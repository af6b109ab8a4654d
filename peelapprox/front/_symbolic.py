"""The peel front's equations from its Lagrangian and Rayleigh function, in sympy: the source the compiled field
(:mod:`peelapprox.front._field`) is checked against (``tests/test_front.py``), and the energy.

Coordinates: the roller angle α and the N local stretches u_j.  Kinematics (the library's, per strip):
``v_j = V + R c(α) α̇ - u̇_j``, ``ω = α̇ + v̄/R``.  With ``c = -cos θ`` the closure::

    L = I ω²/2 + Σ_j m/(2N) (V - u̇_j)² - Σ_j k/(2N) u_j² - k_c/2 Σ_bonds (u_{j+1} - u_j)²
    R = N⁻¹ Σ_j Φ(v_j) + Γ/2 Σ_bonds (u̇_{j+1} - u̇_j)²,   Φ' = f

and Lagrange's equations ``d/dt ∂L/∂q̇ - ∂L/∂q + ∂R/∂q̇ = 0``.  N = 1 is the tape-mass model's Lagrangian
(``tape_mass_lagrange_equations`` in ``peelapprox/_compiled/_symbolic.py``).  Only f's values enter (not its slope), so
here f(v_j) are symbols ``f_j`` and ``c, c'`` are symbols of the closure at α.
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["front_lagrange_rates", "front_energy"]


def _bonds(n: int, ends: str) -> list[tuple[int, int]]:
    b = [(j, j + 1) for j in range(n - 1)]
    if ends == "periodic" and n > 1:
        b.append((n - 1, 0))
    return b


def front_lagrange_rates(n: int, ends: str, values: dict[str, float], alpha: float, omega: float,
                         F: Any, v: Any, f: Any, c: float, dc: float) -> np.ndarray:
    """The rates ``(α̇, ω̇, Ḟ_j…, v̇_j…)`` at one state, from Lagrange's equations derived in sympy.

    Parameters
    ----------
    n, ends : int, str
        Number of strips and the ends ("free" or "periodic").
    values : dict
        ``V, I, k, R, m, k_c, Gamma``.
    alpha, omega, F, v, f, c, dc : float or arrays of n floats
        The state (``F_j = k u_j``), f(v_j) and the closure ``c(α)``, ``c'(α)``.
    """
    import sympy as sp

    t = sp.Symbol("t")
    V, I, k, R, m, kc, G = sp.symbols("V I k R m k_c Gamma")
    a = sp.Function("alpha")(t)
    u = [sp.Function(f"u{j}")(t) for j in range(n)]
    cf = sp.Function("c")
    fs = sp.symbols(f"f0:{n}")
    ad = a.diff(t)
    vs = [V + R * cf(a) * ad - uj.diff(t) for uj in u]
    vbar = sum(vs) / n
    om = ad + vbar / R
    bonds = _bonds(n, ends)
    T = I * om ** 2 / 2 + sum(m / (2 * n) * (V - uj.diff(t)) ** 2 for uj in u)
    U = sum(k / (2 * n) * uj ** 2 for uj in u) + kc / 2 * sum((u[b] - u[a_]) ** 2 for a_, b in bonds)
    Lag = T - U
    qs = [a] + u
    qd = [q.diff(t) for q in qs]
    # the Rayleigh part: dR/dq̇ = N⁻¹ Σ f_j ∂v_j/∂q̇ + Γ Σ_bonds (u̇_b - u̇_a) ∂(u̇_b - u̇_a)/∂q̇
    Rg = [sum(fs[j] / n * vs[j].diff(qd_i) for j in range(n)) for qd_i in qd]
    Rg = [Rg[i] + G * sum((u[b].diff(t) - u[a_].diff(t)) * (u[b].diff(t) - u[a_].diff(t)).diff(qd[i])
                          for a_, b in bonds) for i in range(n + 1)]
    eqs = [Lag.diff(qd[i]).diff(t) - Lag.diff(qs[i]) + Rg[i] for i in range(n + 1)]
    acc = sp.symbols(f"acc0:{n + 1}")
    vel = sp.symbols(f"vel0:{n + 1}")
    pos = sp.symbols(f"pos0:{n + 1}")
    cs, dcs, ddcs = sp.symbols("c_ dc_ ddc_")
    rep = {}
    for i, q in enumerate(qs):
        rep[q.diff(t, 2)] = acc[i]
    eqs = [e.subs(rep) for e in eqs]
    rep = {q.diff(t): vel[i] for i, q in enumerate(qs)}
    eqs = [e.subs(rep) for e in eqs]
    eqs = [e.subs({cf(a).diff(a, 2) if False else sp.Derivative(cf(a), a): dcs}) for e in eqs]
    eqs = [e.replace(lambda x: isinstance(x, sp.Subs), lambda x: dcs) for e in eqs]
    eqs = [e.subs({cf(a): cs}).subs({q: pos[i] for i, q in enumerate(qs)}) for e in eqs]
    # numbers: the velocities from the state (u̇_j = V + R c α̇ - v_j, α̇ = ω - v̄/R), the stretches u_j = F_j/k
    F = np.asarray(F, float)
    v = np.asarray(v, float)
    f = np.asarray(f, float)
    vb = v.mean()
    adot = omega - vb / values["R"]
    udot = values["V"] + values["R"] * c * adot - v
    num = {V: values["V"], I: values["I"], k: values["k"], R: values["R"], m: values["m"], kc: values["k_c"],
           G: values["Gamma"], cs: c, dcs: dc, pos[0]: alpha, vel[0]: adot}
    for j in range(n):
        num[pos[j + 1]] = F[j] / values["k"]
        num[vel[j + 1]] = udot[j]
        num[fs[j]] = f[j]
    M, rhs = sp.linear_eq_to_matrix([sp.expand(e.subs(num)) for e in eqs], list(acc))
    x = np.linalg.solve(np.array(M, dtype=float), np.array(rhs, dtype=float).ravel())
    aa, ua = x[0], x[1:]
    vdot = values["R"] * dc * adot ** 2 + values["R"] * c * aa - ua  # d/dt (V + R c α̇ - u̇_j)
    wdot = aa + vdot.mean() / values["R"]
    return np.concatenate([[adot, wdot], values["k"] * udot, vdot])


def front_energy(y: Any, n: int, ends: str, values: dict[str, float], c: Any) -> Any:
    """The front's mechanical energy ``E = I ω²/2 + Σ m/(2N) w_j² + Σ F_j²/(2kN) + k_c/2 Σ_bonds (Δu)²`` at the
    state ``y = (α, ω, E_AE, F_j…, v_j…)`` (real or complex, for a complex-step derivative), with
    ``w_j = V - u̇_j = v_j - c (R ω - v̄)`` the ribbon's velocity and ``c`` the closure at α (a function of α)."""
    al, om = y[0], y[1]
    F = y[3:3 + n]
    v = y[3 + n:3 + 2 * n]
    cc = c(al)
    w = v - cc * (values["R"] * om - v.mean())
    k = values["k"]
    e = values["I"] * om ** 2 / 2 + values["m"] / (2 * n) * np.sum(w ** 2) + np.sum(F ** 2) / (2 * k * n)
    for a_, b in _bonds(n, ends):
        e = e + values["k_c"] / 2 * ((F[b] - F[a_]) / k) ** 2
    return e

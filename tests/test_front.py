"""The peel front (peelapprox.FrontParams, exact.simulate_front): equations against their sympy derivation, the
energy balance, the transverse modes, the tape-mass limits (N = 1 and a uniform front), budgets and bad input."""

from __future__ import annotations

import tracemalloc

import numpy as np
import pytest

import exact
from peelapprox import FrontParams, PeelForce, PeelParams, front_pattern, transverse_growth_rates
from peelapprox.errors import SolverBudgetExceeded
from peelapprox.front._symbolic import front_energy, front_lagrange_rates
from peelapprox.kernels import compiled_law, front_field, front_parameters

BASE = PeelParams(V=1.0, I=1e-2, tape_mass=1e-3)


def _field(fp, y):
    cl = compiled_law(fp.base.force, fp.base.V)
    out = np.zeros_like(y)
    front_field()(y, front_parameters(fp), cl.fn, cl.coef, out)
    return out


def _random_state(rng, n):
    F = 250.0 + 30.0 * rng.standard_normal(n)
    v = np.exp(rng.uniform(-4.0, 2.5, n))
    return np.concatenate([[rng.uniform(-0.2, 0.2), rng.uniform(0.0, 20.0), 0.0], F, v, [0.0, 0.0]])


def _values(fp):
    b = fp.base
    return dict(V=b.V, I=b.I, k=b.k, R=b.R, m=fp.m, k_c=fp.k_c, Gamma=fp.Gamma)


@pytest.mark.parametrize("n,ends", [(1, "free"), pytest.param(2, "free", marks=pytest.mark.slow), (3, "free"),
                                    (2, "periodic"), pytest.param(4, "periodic", marks=pytest.mark.slow)])
def test_field_is_lagrange(n, ends):
    """The compiled field equals the rates of Lagrange's equations derived in sympy from the front's Lagrangian
    and Rayleigh function (an independent derivation: linear solve for the accelerations), at 5 seeded random
    states.  1e-12 relative: the two evaluate the same rational expressions in different orders (rounding
    ~1e-15, amplified by cancellation in v̇ up to ~1e-13 measured).

    The sympy derivation grows fast with N (N = 4 periodic: ~7 s CPU): N = 2 free and N = 4 periodic are slow,
    covered in the default tier by N = 1 and 3 free (an end strip, and an interior one with two bonds) and N = 2
    periodic (the wrap-around bond)."""
    rng = np.random.default_rng(n * 10 + len(ends))
    for _ in range(5):
        base = PeelParams(V=rng.uniform(0.5, 3.0), I=10 ** rng.uniform(-5, -2), tape_mass=10 ** rng.uniform(-4, -2))
        fp = FrontParams(base=base, N=n, gamma=10 ** rng.uniform(-2, 1), kappa=10 ** rng.uniform(-2, 1), ends=ends)
        y = _random_state(rng, n)
        out = _field(fp, y)
        v = y[3 + n:3 + 2 * n]
        c, dc = base.closure(y[0])
        ref = front_lagrange_rates(n, ends, _values(fp), y[0], y[1], y[3:3 + n], v, base.force.f(v, base.V),
                                   float(c), float(dc))
        mine = np.concatenate([out[:2], out[3:3 + 2 * n]])
        np.testing.assert_allclose(mine, ref, rtol=1e-12, atol=1e-12 * np.max(np.abs(ref)))


@pytest.mark.parametrize("ends", ["free", "periodic"])
def test_energy_balance_pointwise(ends):
    """dE/dt along the field (a complex-step derivative of the energy: exact to rounding) equals the power
    F̄ V - N⁻¹ Σ f(v_j) v_j - R_AE, with R_AE the field's own dE_AE/dt, at 10 seeded random states of N = 7
    strips.  Tolerance 1e-9 of the largest power term (the acceptance target; rounding gives ~1e-13)."""
    rng = np.random.default_rng(7)
    n = 7
    for _ in range(10):
        base = PeelParams(V=rng.uniform(0.5, 3.0), I=10 ** rng.uniform(-5, -2), tape_mass=10 ** rng.uniform(-4, -2))
        fp = FrontParams(base=base, N=n, gamma=10 ** rng.uniform(-2, 1), kappa=10 ** rng.uniform(-2, 1), ends=ends)
        y = _random_state(rng, n)
        ydot = _field(fp, y)
        h = 1e-30
        dE = float(np.imag(front_energy(y + 1j * h * ydot, n, ends, _values(fp), np.sin)) / h)
        F = y[3:3 + n].mean()
        v = y[3 + n:3 + 2 * n]
        p_in, p_peel, p_ae = F * base.V, float(np.mean(base.force.f(v, base.V) * v)), ydot[2]
        assert p_ae >= 0.0
        assert abs(ydot[-2] - p_in) <= 1e-14 * abs(p_in) and abs(ydot[-1] - p_peel) <= 1e-13 * abs(p_peel)
        assert abs(dE - (p_in - p_peel - p_ae)) <= 1e-9 * max(abs(p_in), abs(p_peel), p_ae)


@pytest.mark.parametrize("n,ends", [(8, "free"), (8, "periodic"), (64, "free"), (64, "periodic")])
def test_transverse_modes(n, ends):
    """The field's Jacobian at a uniform front (central differences, relative step 1e-6) leaves each Laplacian
    mode invariant (the α, ω and other-mode components of J e below 1e-6 of its own) and acts on it as the 2 × 2
    matrix whose eigenvalues are transverse_growth_rates' roots of m λ² + (f' + 4NΓ s) λ + k + 4N k_c s = 0, to 1e-6
    relative (the target; differencing error ~1e-9 measured)."""
    rng = np.random.default_rng(n)
    base = PeelParams(V=1.5, I=1e-3, tape_mass=1e-3)
    fp = FrontParams(base=base, N=n, gamma=0.3, kappa=0.5, ends=ends)
    modes = transverse_growth_rates(fp)
    v0 = modes.v
    y = np.concatenate([[0.05, 15.0, 0.0], np.full(n, 240.0), np.full(n, v0), [0.0, 0.0]])
    j = np.arange(n)
    for idx in rng.choice(n - 1, size=min(6, n - 1), replace=False):
        k_mode = modes.n[idx]
        e = (np.cos(2 * np.pi * k_mode * j / n) if ends == "periodic" else np.cos(np.pi * k_mode * (j + 0.5) / n))
        e /= np.linalg.norm(e)
        A = np.zeros((2, 2))
        for col, (dF, dv) in enumerate(((1.0, 0.0), (0.0, 1.0))):
            hF, hv = 1e-6 * 240.0 * dF, 1e-6 * v0 * dv
            d = np.concatenate([[0.0, 0.0, 0.0], hF * e, hv * e, [0.0, 0.0]])
            Je = (_field(fp, y + d) - _field(fp, y - d)) / 2.0
            Je /= (hF + hv)
            comp = (Je[3:3 + n] @ e, Je[3 + n:3 + 2 * n] @ e)
            A[:, col] = comp
            scale = np.hypot(*comp)
            assert abs(Je[0]) + abs(Je[1]) <= 1e-6 * scale
            assert (np.linalg.norm(Je[3:3 + n] - comp[0] * e) + np.linalg.norm(Je[3 + n:3 + 2 * n] - comp[1] * e)
                    <= 1e-6 * scale)
        lam = np.sort_complex(np.linalg.eigvals(A))
        ref = np.sort_complex(modes.rates[idx])
        np.testing.assert_allclose(lam, ref, rtol=1e-6)


def test_growth_rule():
    """A mode grows iff f' + 4NΓ s_q < 0 (the relation's damping term), so on the inflection velocity with
    γ = 0.5 exactly the modes with s_q < 1/γ = 2 ... i.e. all of them grow (s ≤ 1), and with γ = 4 those with
    s_q < 1/4; counted against the closed form."""
    for gamma, n in ((0.5, 32), (4.0, 32)):
        fp = FrontParams(base=BASE, N=n, gamma=gamma, ends="periodic")
        m = transverse_growth_rates(fp)
        np.testing.assert_array_equal(m.unstable, m.s < 1.0 / gamma)


def _tape_jumps(base, n_jumps=10, t_max=2.0):
    ref = exact.simulate(base, t_max, method="smooth", rtol=1e-10, save="jumps")
    assert len(ref.jumps) > n_jumps
    return ref.jumps, float(0.5 * (ref.jumps.t[n_jumps - 1] + ref.jumps.t[n_jumps]))


@pytest.mark.parametrize("I", [1e-2, 1e-5])
def test_one_strip_is_the_tape_mass_model(I):
    """N = 1 reproduces exact.simulate(method="smooth") (LSODA, rtol 1e-10) at V = 1, m = 1e-3 kg: the first 10
    jump times within 1e-8 s (the target; measured 4e-11 s at I = 1e-2, 2.5e-10 s at I = 1e-5, the two solvers'
    own errors) and F at them within 1e-9 relative (measured 2.5e-10; F moves ~1e3 N/s there)."""
    base = PeelParams(V=1.0, I=I, tape_mass=1e-3)
    ref, T = _tape_jumps(base, t_max=0.6 if I == 1e-5 else 0.3)
    tr = exact.simulate_front(FrontParams(base=base, N=1), T, rtol=1e-10, store_front=False)
    assert len(tr.jumps) == 10
    np.testing.assert_allclose(tr.jumps.t, ref.t[:10], rtol=0, atol=1e-8)
    np.testing.assert_allclose(tr.jumps.F, ref.F[:10], rtol=1e-9)
    np.testing.assert_array_equal(tr.jumps.to_branch, ref.to_branch[:10])
    assert tr.stats.n_steps > 0 and tr.stats.n_rhs >= 12 * tr.stats.n_steps


@pytest.mark.parametrize("n,ends", [(2, "free"), (16, "free"), (16, "periodic")])
def test_uniform_front_is_the_tape_mass_model(n, ends):
    """A uniform front of N strips (δ₀ = 0) stays uniform (max |v_j - v̄|/v̄ ≤ 1e-9, the target) and has the
    tape-mass model's first 10 jump times within 1e-8 s, with no AE (R_AE ≡ 0 on a uniform front)."""
    ref, T = _tape_jumps(BASE, t_max=0.3)
    tr = exact.simulate_front(FrontParams(base=BASE, N=n, gamma=0.05, kappa=0.1, ends=ends), T, rtol=1e-10)
    np.testing.assert_allclose(tr.jumps.t, ref.t[:10], rtol=0, atol=1e-8)
    v = tr.v_j
    assert np.max(np.abs(v - tr.v[:, None]) / tr.v[:, None]) <= 1e-9
    assert np.max(tr.ae_power) <= 1e-9 * np.max(tr.F * BASE.V)


@pytest.mark.slow
@pytest.mark.parametrize("ends", ["free", "periodic"])
def test_uniform_front_128(ends):
    """As test_uniform_front_is_the_tape_mass_model for N = 128 (the target's largest N)."""
    ref, T = _tape_jumps(BASE, t_max=0.3)
    tr = exact.simulate_front(FrontParams(base=BASE, N=128, gamma=0.05, ends=ends), T, rtol=1e-10)
    np.testing.assert_allclose(tr.jumps.t, ref.t[:10], rtol=0, atol=1e-8)
    assert np.max(np.abs(tr.v_j - tr.v[:, None]) / tr.v[:, None]) <= 1e-9


def test_mixed_front_energy_and_determinism():
    """A heterogeneous front (δ₀ = 0.05, γ = 0.05): (1) E_AE, integrated as a state, equals the trapezoid
    integral of the stored AE power over every step to 1e-3 relative (the trapezoid rule's error on steps of
    ~1e-6 s through bursts; the state is the exact one); (2) the same seed gives bitwise-identical output,
    another seed a different one; (3) the front is rough (W > 0) and strips switch branches."""
    fp = FrontParams(base=BASE, N=16, gamma=0.05, kappa=0.05, delta0=0.05, seed=3)
    a = exact.simulate_front(fp, 0.03, rtol=1e-8)
    b = exact.simulate_front(fp, 0.03, rtol=1e-8)
    c = exact.simulate_front(FrontParams(base=BASE, N=16, gamma=0.05, kappa=0.05, delta0=0.05, seed=4), 0.03,
                             rtol=1e-8)
    for name in ("t", "F", "v", "ae_power", "ae_energy", "front_v"):
        assert np.array_equal(getattr(a, name), getattr(b, name))
    assert not np.array_equal(a.front_F[0], c.front_F[0])
    trap = float(np.sum(np.diff(a.t) * (a.ae_power[1:] + a.ae_power[:-1]) / 2))
    assert a.ae_energy[-1] > 0
    assert abs(a.ae_energy[-1] - trap) <= 1e-3 * a.ae_energy[-1]
    assert np.max(a.roughness) > 0.0 and a.n_local_switches > 0


def test_no_dense_array_at_1e4_strips():
    """N = 1e4 strips for a few steps: the peak of Python-allocated memory stays below 60 MB (a dense N × N float
    array would be 800 MB; the run's buffers are O(N): 20 work rows of 2e4 floats, output chunks of ~2e6 floats)."""
    fp = FrontParams(base=BASE, N=10_000, gamma=0.5, delta0=1e-3)
    tracemalloc.start()
    tr = exact.simulate_front(fp, 2e-6, rtol=1e-6, store_front=False)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert tr.stats.n_steps >= 1
    assert peak < 60e6


@pytest.mark.parametrize("kw,match", [
    (dict(N=0), "N"), (dict(N=10**6), "N"), (dict(N=2.5), "N"), (dict(N=4, gamma=-0.1), "gamma"),
    (dict(N=4, Gamma=-1.0), "Gamma"), (dict(N=4, kappa=-1.0), "kappa"), (dict(N=4, gamma=1.0, Gamma=1.0), "not both"),
    (dict(N=4, ends="closed"), "ends"), (dict(N=4, delta0=0.9), "delta0"), (dict(N=4, seed=-1), "seed"),
])
def test_bad_front_params(kw, match):
    """Each bad field raises a ValueError (TypeError for the wrong kind) naming it."""
    with pytest.raises((ValueError, TypeError), match=match):
        FrontParams(base=BASE, **kw)


def test_bad_base_and_calls():
    """A base without a tape mass, a law without folds, absurd durations and budgets: named errors; a tiny
    max_wall or max_values stops the run with SolverBudgetExceeded (bounded work and memory)."""
    with pytest.raises(ValueError, match="tape_mass"):
        FrontParams(base=PeelParams(V=1.0, I=1e-2), N=2)
    with pytest.raises(ValueError, match="folds"):
        FrontParams(base=PeelParams(V=1.0, I=1e-2, tape_mass=1e-3, force=PeelForce.expression("100 + 10*v")), N=2)
    fp = FrontParams(base=BASE, N=4)
    for t_end in (0.0, -1.0, 1e9, float("nan")):
        with pytest.raises(ValueError, match="t_end"):
            exact.simulate_front(fp, t_end)
    with pytest.raises(ValueError, match="rtol"):
        exact.simulate_front(fp, 0.01, rtol=0.5)
    with pytest.raises(TypeError, match="params"):
        exact.simulate_front(BASE, 0.01)
    with pytest.raises(SolverBudgetExceeded) as e:
        exact.simulate_front(fp, 10.0, max_wall=0.05)
    assert e.value.budget == "max_wall" and e.value.partial.t[-1] < 10.0
    with pytest.raises(SolverBudgetExceeded) as e:
        exact.simulate_front(FrontParams(base=BASE, N=100), 1.0, max_values=5000)
    assert e.value.budget == "max_values"


def test_pattern_rules():
    """front_pattern's rules on synthetic series with known averages (exact arithmetic on equal steps)."""
    t = np.linspace(0.0, 1.0, 101)
    zero = np.zeros_like(t)
    assert front_pattern(t, zero, zero + 0.01, zero).label == "smooth"
    assert front_pattern(t, zero, zero + 0.2, zero).label == "rugged"
    phi = np.where(t < 0.5, 0.5, 0.0)
    p = front_pattern(t, phi, zero + 0.2, np.where(t < 0.5, 3, 0))
    assert p.label == "stuck-peeled" and abs(p.mixed_fraction - 0.5) < 0.011 and abs(p.walls - 3.0) < 1e-12
    with pytest.raises(ValueError, match="roughness"):
        front_pattern(t, zero, zero[:-1], zero)


def test_cli_front(tmp_path, capsys):
    """``peelapprox front`` runs a small front, prints its summary as JSON (the counters equal the library's for
    the same call: the CLI adds nothing of its own), writes the series and the space-time image; a missing ``--N`` is
    exit status 2 naming it.  Run in this process through ``peelapprox.cli.main`` (the command ``python -m
    peelapprox`` calls; that entry itself is tests/test_cli_conventions.py's): a second interpreter would add only
    its start-up, ~3 s CPU."""
    import json

    from peelapprox.cli import main

    out, png = tmp_path / "s.csv", tmp_path / "f.png"
    argv = ["front", "--V", "1", "--I", "1e-2", "--tape-mass", "1e-3", "--N", "4", "--gamma", "0.05", "--delta0",
            "0.01", "--t-end", "0.004", "--format", "json", "--out", str(out), "--plot", str(png)]
    capsys.readouterr()
    assert main(argv) == 0
    row = json.loads(capsys.readouterr().out)
    fp = FrontParams(base=BASE, N=4, gamma=0.05, delta0=0.01)
    tr = exact.simulate_front(fp, 0.004, store_front=False)
    assert row["steps"] == tr.stats.n_steps and row["jumps"] == len(tr.jumps)
    assert out.read_text().count("\n") == len(tr.t) + 1 and png.stat().st_size > 1000
    with pytest.raises(SystemExit) as bad:
        main(argv[:6] + ["0", "--t-end", "0.004"])
    assert bad.value.code == 2 and "--N" in capsys.readouterr().err


def test_spatial_convergence_order():
    """Under the continuum scaling (k_c = K N/b, Γ = G N/b) a smooth front converges to its continuum limit at
    second order: comparisons.benchmark.front.convergence on N = 16, 48, 144 (each against 3N, at coinciding strip
    centres) gives orders in [1.8, 2.2] (the design's target; measured 1.993 and 1.999)."""
    from comparisons.benchmark.front import convergence

    rows = convergence(ns=(16, 48, 144, 432))
    orders = [r["order"] for r in rows if "order" in r]
    assert len(orders) == 2 and all(1.8 <= o <= 2.2 for o in orders)


def test_series_doors():
    """The AE power and the pull force of a gridded run are ForceSeries holding the run's very samples (the
    library's series tools take them); a run stored at its steps is refused (those tools assume a grid)."""
    fp = FrontParams(base=BASE, N=8, gamma=0.05, delta0=0.01)
    tr = exact.simulate_front(fp, 0.01, dt_save=1e-5, store_front=False)
    s = tr.ae_series()
    assert np.array_equal(s.F, tr.ae_power) and np.array_equal(s.t, tr.t) and len(s) == 1001
    assert np.array_equal(tr.force_series().F, tr.F)
    with pytest.raises(ValueError, match="dt_save"):
        exact.simulate_front(fp, 1e-4, store_front=False).ae_series()


def test_strip_arrest_is_a_named_breakdown():
    """γ = 10, κ = 0.1, δ₀ = 1e-2, seed 1, N = 32 (the γ sweep of docs/peel-front.md): the edge strip 31 comes to
    rest at t = 3.953 ms (measured 0.00395281727 s) and still decelerates there, so the run ends in
    ModelBreakdown("arrest") naming the strip, with a finite time, state and the partial trajectory; 1e-6 s is far
    below the step (~2e-5 s) and far above the solver's time error."""
    from peelapprox.errors import ModelBreakdown

    fp = FrontParams(base=BASE, N=32, gamma=10.0, kappa=0.1, delta0=1e-2, seed=1)
    with pytest.raises(ModelBreakdown) as e:
        exact.simulate_front(fp, 0.006, dt_save=1e-5, store_front=False)
    err = e.value
    assert err.reason == "arrest" and err.state["strip"] == 31 and "strip j=31" in str(err)
    assert abs(err.t - 0.0039528) < 1e-6 and np.isfinite(err.partial.final_y).all()


def test_mirror_and_shift_symmetry():
    """The front's equations are symmetric under the mirror j -> N-1-j (free ends) and the shift j -> j+s
    (periodic): a mirrored or shifted heterogeneous start gives the mirrored or shifted front.  Only the order of
    the strips' sums changes, so the runs agree to the solver's accuracy: max |Δv_j| / max v_j ≤ 10 rtol at the
    end and the mean jump times within 10 rtol × t_end (the design's target; measured at rtol 1e-9: 4.6e-11 and
    3.6e-12 in v, 8e-17 s and 6e-16 s in the 2 jump times, through 14 local switches)."""
    rtol = 1e-9
    for ends, perm, back in (("free", lambda a: a[::-1], lambda a: a[::-1]),
                             ("periodic", lambda a: np.roll(a, 5), lambda a: np.roll(a, -5))):
        fp = FrontParams(base=BASE, N=12, gamma=0.05, kappa=0.1, ends=ends, delta0=0.01, seed=2)
        a = exact.simulate_front(fp, 0.012, rtol=rtol, dt_save=1e-3)
        y0 = a.initial_y.copy()
        y0[3:15], y0[15:27] = perm(y0[3:15]), perm(y0[15:27])
        b = exact.simulate_front(fp, 0.012, rtol=rtol, y0=y0, dt_save=1e-3)
        vb = np.array([back(row) for row in b.front_v])
        assert np.max(np.abs(vb[-1] - a.front_v[-1])) <= 10 * rtol * np.max(a.front_v[-1])
        assert len(a.jumps) == len(b.jumps) >= 1
        assert np.max(np.abs(a.jumps.t - b.jumps.t)) <= 10 * rtol * 0.012


def test_energy_balance_over_ten_jumps():
    """Integrated energy balance of a mixed front (N = 8, γ = 0.05, κ = 0.1, δ₀ = 0.01, rtol 1e-10) over the
    tape-mass model's first 10 jumps: the mechanical energy E (front_energy, at the stored states) changes by
    W_in - W_peel - E_AE, all three integrated as states, to 1e-6 of W_peel at every stored point (the design's
    target; the tape-mass model reaches 7e-8; measured 1.2e-14 over 14 mean jumps and 48 local switches).  The
    check is independent of the field's derivation: E is summed from its definition, the works from their
    integrands."""
    fp = FrontParams(base=BASE, N=8, gamma=0.05, kappa=0.1, delta0=0.01, seed=5)
    _, T = _tape_jumps(BASE, t_max=0.3)
    tr = exact.simulate_front(fp, T, rtol=1e-10, dt_save=T / 400)
    n = 8
    vals = _values(fp)
    ys = [np.concatenate([[a, w, 0.0], F, v, [0.0, 0.0]])
          for a, w, F, v in zip(tr.alpha, tr.omega, tr.front_F, tr.front_v)]
    E = np.array([front_energy(y, n, "free", vals, np.sin) for y in ys])
    resid = ((E - E[0]) - (tr.work_in - tr.work_in[0]) + (tr.work_peel - tr.work_peel[0])
             + (tr.ae_energy - tr.ae_energy[0]))
    assert tr.n_local_switches > 0 and tr.ae_energy[-1] > 0
    assert np.max(np.abs(resid)) <= 1e-6 * tr.work_peel[-1]


# --- bursts of the AE power (FrontTrajectory.bursts, `peelapprox front --bursts`) ---------------------------------

_BURST_FP = FrontParams(base=BASE, N=4, gamma=0.05, kappa=0.05, delta0=0.05, seed=4)
_BURST_ARGS = ["front", "--V", "1", "--I", "1e-2", "--tape-mass", "1e-3", "--N", "4", "--gamma", "0.05", "--kappa",
               "0.05", "--delta0", "0.05", "--seed", "4", "--dt-save", "1e-5"]


def test_front_bursts_are_the_catalogue_of_the_ae_power():
    """FrontTrajectory.bursts is burst_catalogue(t, ae_power): the same function on the same arrays, so every
    column is compared bitwise (tolerance 0), for the default threshold (0.05 × max R_AE, stated in the docstring)
    and an explicit one with min_gap.  Independent check: each burst's energy (the trapezoid of the stored samples
    on [start, end]) against the exact state E_AE interpolated at start and end; with dt_save = 1e-5 s, far below
    a burst's duration (>= 1e-4 s here), the trapezoid is second-order accurate in dt_save: measured 4.5e-6
    relative, asserted to 1e-4 (a 20× margin that still fails if the samples and the state disagreed)."""
    from peelapprox import burst_catalogue

    tr = exact.simulate_front(_BURST_FP, 0.06, dt_save=1e-5, store_front=False)
    cat = tr.bursts()
    assert cat.threshold == 0.05 * float(np.max(tr.ae_power))
    for th, gap in ((None, 0.0), (1e-3 * float(np.max(tr.ae_power)), 2e-4)):
        mine = tr.bursts(th, min_gap=gap)
        direct = burst_catalogue(tr.t, tr.ae_power, threshold=mine.threshold, min_gap=gap)
        assert len(mine) == len(direct) >= 3 and mine.n_dropped == direct.n_dropped
        for col in ("start", "end", "duration", "energy", "excess", "peak", "t_peak"):
            np.testing.assert_array_equal(getattr(mine, col), getattr(direct, col))
    assert np.all(cat.duration >= 1e-4)
    e_state = np.interp(cat.end, tr.t, tr.ae_energy) - np.interp(cat.start, tr.t, tr.ae_energy)
    np.testing.assert_allclose(cat.energy, e_state, rtol=1e-4)


def test_front_bursts_bad_threshold():
    """A threshold that is negative, NaN or infinite is a ValueError naming it; a string, a TypeError; and the CLI
    rejects them as a usage error (status 2) before integrating."""
    from peelapprox.cli import main

    tr = exact.simulate_front(_BURST_FP, 2e-4, dt_save=1e-5, store_front=False)
    for bad in (-1.0, float("nan"), float("inf")):
        with pytest.raises(ValueError, match="threshold"):
            tr.bursts(bad)
    with pytest.raises(TypeError, match="threshold"):
        tr.bursts("1")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="min_gap"):
        tr.bursts(1.0, min_gap=-1.0)
    for argv in (["--bursts", "--threshold", "-1"], ["--threshold", "1"], ["--bursts", "--min-tail", "4"]):
        with pytest.raises(SystemExit) as e:
            main([*_BURST_ARGS, "--t-end", "1e-4", *argv])
        assert e.value.code == 2


def test_front_cli_bursts_prints_the_fit(tmp_path, capsys):
    """`peelapprox front --bursts` prints the catalogue's summary and the power-law fit of the burst energies:
    the same numbers (tolerance 0: the same deterministic computations, seed 0) as FrontTrajectory.bursts and
    fit_power_law on the run made through the API, alpha within its bootstrap interval; --out writes the
    catalogue, which reads back with BurstCatalogue.from_csv to the same energies (CSV round trip: rtol 1e-12)."""
    import json

    from peelapprox import BurstCatalogue, fit_power_law
    from peelapprox.cli import main

    out = tmp_path / "bursts.csv"
    assert main([*_BURST_ARGS, "--t-end", "0.1", "--bursts", "--threshold", "1", "--min-tail", "5",
                 "--format", "json", "--out", str(out)]) == 0
    row = json.loads(capsys.readouterr().out)
    tr = exact.simulate_front(_BURST_FP, 0.1, dt_save=1e-5, store_front=False)
    cat = tr.bursts(1.0)
    fit = fit_power_law(cat.sizes("energy"), min_tail=5, n_bootstrap=100, seed=0, max_wall=60.0)
    assert row["bursts"] == len(cat) >= 5 and row["threshold"] == 1.0
    assert row["alpha"] == fit.alpha and row["n_tail"] == fit.n_tail
    assert row["alpha_lo"] <= row["alpha"] <= row["alpha_hi"]
    back = BurstCatalogue.from_csv(str(out))
    np.testing.assert_allclose(back.energy, cat.energy, rtol=1e-12)

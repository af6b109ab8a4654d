"""External peer solvers (comparisons.benchmark.peers) on the ε-regularised system, and its ε-variational Lyapunov
exponent (exact.lyapunov_variational, on the diffsol peer's tangent model).

Each peer is skipped when its package is missing.  The shared Radau
reference (rtol 1e-10, ~6 s) is computed once per module, and only when a peer is installed.
"""

import numpy as np
import pytest

import exact
from comparisons.benchmark import peers as P
from comparisons.benchmark.peers import common as PC
from comparisons.benchmark.peers import diffsol as PD
from exact._regularized import _fun
from exact.dynamics import _variational as LV
from peelapprox import PeelParams, branch_structure
from peelapprox import kernels as K

PACKAGES = {"ida": "sksundae", "cvode": "sksundae", "diffsol": "pydiffsol"}
EPS = 1e-7
T_END = 0.12


@pytest.fixture(scope="module")
def reference(p_low):
    """Jumps of the scipy-Radau regularised run the peers are compared with."""
    tr = exact.simulate(p_low, T_END, method="regularized", solver="Radau", eps=EPS, rtol=1e-10, save="jumps")
    return tr.jumps.t, tr.jumps.F


@pytest.mark.parametrize("geometry", ["paper", "exact"])
def test_diffsl_rhs_matches_generated_kernel(geometry):
    """The DiffSL transcription equals ``exact._regularized._fun`` to 1e-12 relative.

    Both evaluate the same formulas in double precision with the same operation
    order (same constants, pow/sqrt/exp/sin/cos from libm or LLVM's
    intrinsics); the only differences are the state scaling ``X = s y`` and
    the ``/ s``, ``* s``, ``/ eps`` applied around it, a few roundings each,
    amplified at most ~10x by the cancellation in ``F (1 + c) - f``.
    Measured: at most 2.5e-16 relative over 200 random states per geometry,
    so 1e-12 is a wide margin that still catches any transcription slip (a
    wrong constant or exponent shows at 1e-3 or worse).
    """
    pytest.importorskip("pydiffsol")
    params = PeelParams(V=1.3, I=2e-5, k=900.0, R=0.12, l=1.1, geometry=geometry)
    ode = K.diffsl_model(geometry)
    rng = np.random.default_rng(7)
    scale = np.array([3e-5, 2e-4, 5e-3, 7e-7])
    q = K.regularized_parameters(params, EPS)
    for _ in range(8):
        X = np.array([rng.uniform(-0.6, 0.6), rng.uniform(-80, 80), rng.uniform(120, 320), 10 ** rng.uniform(-3, 1.3)])
        y = X / scale
        Xs = y * scale  # what the DiffSL model sees: alpha = ya * sa, ...
        inp = K.diffsl_inputs(params, EPS, X, scale)
        rhs = np.asarray(ode.rhs(inp, 0.0, y), dtype=float) * scale / np.array([1.0, 1.0, 1.0, EPS])
        np.testing.assert_allclose(rhs, _fun(Xs, q), rtol=1e-12, atol=0)
        assert np.allclose(ode.y0(inp) * scale, X, rtol=1e-15, atol=0)


@pytest.mark.parametrize("peer", P.PEERS)
def test_peer_jumps_match_radau(peer, p_low, request):
    """Each peer finds the Radau reference's inflection crossings, within 1e-6 s.

    Same ε-system, same initial state, rtol 1e-8 vs the reference's 1e-10:
    the measured differences are ~2e-9 s (IDA), ~1e-8 s (CVODE) and ~3e-10 s
    (diffsol), so 1e-6 s is a wide margin that still fails for a wrong model
    (a 1 % error in any term moves the first jump by > 1e-5 s) or a missed or
    spurious crossing (count check).  F at the crossings: F changes by
    |dF/dt| ~ k v ~ 2e3 N/s there, so 1e-6 s in time is ~2e-3 N; measured
    ≤ 2e-5 N, asserted to 1e-2 N.
    """
    pytest.importorskip(PACKAGES[peer])
    ref_t, ref_F = request.getfixturevalue("reference")  # after the skip: no reference without a peer (~17 s CPU)
    r = P.run_peer(peer, p_low, T_END, eps=EPS, rtol=1e-8)
    assert r.status == "ok", r.status
    assert r.jump_t.size == ref_t.size == 4
    np.testing.assert_allclose(r.jump_t, ref_t, rtol=0, atol=1e-6)
    np.testing.assert_allclose(r.jump_F, ref_F, rtol=0, atol=1e-2)
    assert r.n_steps > 0 and r.wall_time > 0 and r.compile_time >= 0
    np.testing.assert_array_equal(r.atol, 1e-8 * np.asarray(exact.ATOL_SCALE["regularized"]))


def test_available_peers_lists_importable_packages():
    """Every listed peer's package imports; the order follows PEERS (exact check, no tolerance)."""
    avail = P.available_peers()
    assert set(avail) <= set(P.PEERS)
    assert list(avail) == [p for p in P.PEERS if p in avail]
    for peer in avail:
        pytest.importorskip(PACKAGES[peer])


@pytest.mark.parametrize(
    "kwargs, name",
    [
        (dict(peer="lsoda"), "peer"),
        (dict(eps=0.0), "eps"),
        (dict(eps=-1e-7), "eps"),
        (dict(rtol=0.0), "rtol"),
        (dict(rtol=1.0), "rtol"),
        (dict(atol=[1e-9, 1e-9]), "atol"),
        (dict(t_end=0.0), "t_end"),
    ],
)
def test_run_peer_rejects_bad_arguments(kwargs, name, p_low):
    """Bad arguments raise ValueError naming the argument (checked before any import or solve)."""
    args = dict(peer="ida", params=p_low, t_end=0.01, eps=EPS, rtol=1e-6)
    args.update(kwargs)
    with pytest.raises(ValueError, match=name):
        P.run_peer(args.pop("peer"), args.pop("params"), args.pop("t_end"), **args)


def test_missing_package_raises_import_error(monkeypatch, p_low):
    """A missing peer package is an ImportError subclass naming the pip package (no tolerance involved)."""
    monkeypatch.setitem(PC._PACKAGES, "diffsol", ("no_such_module_for_peelapprox", "pydiffsol"))
    with pytest.raises(ImportError, match="pydiffsol"):
        P.run_peer("diffsol", p_low, 0.01, eps=EPS, rtol=1e-6)


def test_solver_failure_is_reported_not_raised(monkeypatch, p_low):
    """An exception inside the integration call becomes ``status="failed: ..."`` (no tolerance involved)."""
    pytest.importorskip("pydiffsol")

    class Broken:
        rtol = atol = t0 = 0.0

        class options:
            pass

        def solve(self, params, t_end):
            raise RuntimeError("ODE solver error: Step size is too small")

    monkeypatch.setattr(PD, "diffsl_model", lambda geometry, force=None: Broken())
    r = P.run_peer("diffsol", p_low, 0.01, eps=EPS, rtol=1e-6)
    assert r.status.startswith("failed: ") and "Step size is too small" in r.status
    assert r.jump_t.size == 0 and r.n_steps == -1


# --------------------------------------------------------------------------------- the tangent (variational) model
@pytest.mark.parametrize("geometry", ["paper", "exact"])
def test_diffsl_tangent_rhs_is_the_generated_jacobian_times_the_tangent(geometry):
    """The tangent rows of the ``tangent=True`` DiffSL model equal ``M⁻¹ (∂φ/∂X) δX`` from the numba kernel
    ``exact._regularized._jac`` (both printed from the sympy source, by different printers), and the state
    rows are unchanged.

    Each component is compared relative to ``|J| |δX|`` (the sum of the magnitudes of its terms), the
    scale of the rounding error of a 2-4 term sum: measured ≤ 4.9e-15 over 200 random states and tangents
    per geometry; asserted to 1e-12.  A wrong entry, sign or closure derivative is an O(1) error.
    """
    pytest.importorskip("pydiffsol")
    from exact._regularized import _jac

    params = PeelParams(V=1.3, I=2e-5, k=900.0, R=0.12, l=1.1, geometry=geometry)
    ode = K.diffsl_model(geometry, tangent=True)
    rng = np.random.default_rng(11)
    scale = np.array([3e-5, 2e-4, 5e-3, 7e-7])
    tscale = np.array([1e-3, 2e-2, 1e-1, 3e-4])
    q = K.regularized_parameters(params, EPS)
    for _ in range(20):
        X = np.array([rng.uniform(-0.6, 0.6), rng.uniform(-80, 80), rng.uniform(120, 320), 10 ** rng.uniform(-3, 1.3)])
        d = rng.normal(size=4) * np.array([0.1, 10.0, 10.0, 1.0])
        y = np.concatenate([X / scale, d / tscale])
        inp = K.diffsl_inputs(params, EPS, X, scale, d, tscale)
        rhs = np.asarray(ode.rhs(inp, 0.0, y), dtype=float)
        Xs, ds = y[:4] * scale, y[4:] * tscale
        mass = np.array([1.0, 1.0, 1.0, EPS])
        tang = rhs[4:] * tscale / mass
        J = _jac(Xs, q)
        assert np.all(np.abs(tang - J @ ds) <= 1e-12 * (np.abs(J) @ np.abs(ds)))
        np.testing.assert_allclose(rhs[:4] * scale / mass, _fun(Xs, q), rtol=1e-12, atol=0)
        np.testing.assert_allclose(ode.y0(inp)[4:] * tscale, d, rtol=1e-15, atol=0)


def test_tangent_follows_finite_differences_across_the_jumps():
    """Over 0.4 s with 58 fast jump transits (V = 2, I = 1e-4, ε = 1e-7), the tangent integrated by diffsol
    equals the central difference ``[X(x0 + h d) − X(x0 − h d)] / 2h`` of two state-only solves.

    Hypothesis: the variational equations are the linearisation of the flow, through the transits too.
    With h = 1e-6 and rtol 1e-11 the difference, in the (δα, δω/(V/R), δF/f_max) norm relative to the
    tangent, was 3.2e-4 (2.2e-3 at h = 1e-5: the O(h²) term; 0.23 at 1e-4); asserted to 3e-3.  A wrong
    Jacobian entry, or a tangent lost at the crossings' stop/reset, is an O(1) error.
    """
    pytest.importorskip("pydiffsol")
    p = PeelParams(V=2.0, I=1e-4)
    rtol, h = 1e-11, 1e-6
    a = exact.default_atol("regularized", rtol)
    ode = K.diffsl_model("paper", tangent=True)
    ode.rtol, ode.atol, ode.t0 = rtol, 1.0, 0.0
    for name, val in LV.TANGENT_OPTIONS.items():
        setattr(ode.options, name, val)
    s0 = exact.initial_state(p)
    x = np.array([s0.alpha, s0.omega, s0.F, s0.v])
    x, _, _, _ = LV.tangent_solve(ode, p, EPS, a, x, np.zeros(4), 0.9)
    scale = np.array([1.0, p.V / p.R, branch_structure(p.V).f_max])
    d = LV._slow_tangent(p, x, np.array([0.3, 0.3, 1.0]), scale)
    _, d1, steps, crossings = LV.tangent_solve(ode, p, EPS, a, x, d, 0.4)
    xp = LV.tangent_solve(ode, p, EPS, a, x + h * d, np.zeros(4), 0.4)
    xm = LV.tangent_solve(ode, p, EPS, a, x - h * d, np.zeros(4), 0.4)
    assert crossings == xp[3] == xm[3] >= 40 and steps > 0
    fd = (xp[0] - xm[0]) / (2 * h)
    assert np.linalg.norm((fd - d1)[:3] / scale) <= 3e-3 * np.linalg.norm(d1[:3] / scale)


@pytest.mark.parametrize("V, I", [(0.05, 1e-4), (0.1, 1e-2)])
def test_lyapunov_variational_at_a_stable_fixed_point_is_the_leading_eigenvalue(V, I):
    """At a stable steady sliding point (α = 0, ω = V/R, v = V, F = f(V); f'(V) > 0) the largest Lyapunov
    exponent is the largest real part of the eigenvalues of M⁻¹ ∂φ/∂X there, in bits/s: the analytic oracle.

    The run starts off the fixed point (F0 = 1.01 f(V)) and relaxes to it in the 15 s transient; the
    leading eigenvalue is real and separated from the next by > 0.8 /s, so the tangent is aligned to
    e^-12 when measuring starts.  Measured relative errors ≤ 1.2e-7 at rtol 1e-8; asserted to 1e-5.
    """
    pytest.importorskip("pydiffsol")
    from exact._regularized import _jac, param_vector
    from peelapprox.law._paper import peel_force

    p = PeelParams(V=V, I=I)
    x = np.array([0.0, V / p.R, float(peel_force(V, V)), V])
    ev = np.linalg.eigvals(_jac(x, param_vector(p, EPS)))
    lead = sorted(ev, key=lambda z: -z.real)
    assert lead[0].imag == 0.0 and lead[0].real - lead[1].real > 0.8
    expected = lead[0].real / np.log(2.0)
    r = LV.lyapunov_variational(p, eps=EPS, t_transient=15.0, T=10.0, rtol=1e-8)
    assert r.bits_per_s == pytest.approx(expected, rel=1e-5)
    assert r.n_jumps == 0 and r.benettin.n == 20 and r.benettin.wall_time > 0
    assert any(n.startswith("steps=") and int(n[6:]) > 0 for n in r.notes)


@pytest.mark.parametrize(
    "kwargs, name",
    [(dict(eps=0.0), "eps"), (dict(T=0.0), "T"), (dict(tau=-1.0), "tau"), (dict(rtol=1.0), "rtol"),
     (dict(t_transient=-1.0), "t_transient"), (dict(progress=3), "progress")],
)
def test_lyapunov_variational_rejects_bad_arguments(kwargs, name):
    """Bad arguments raise ValueError naming the argument, before any compilation or solve."""
    with pytest.raises(ValueError, match=name):
        LV.lyapunov_variational(PeelParams(V=2.0, I=1e-4), **kwargs)


def test_lyapunov_variational_reports_a_diffsol_failure_with_time_and_state(monkeypatch):
    """A diffsol failure inside an interval raises SolverFailure carrying the interval's start time and the
    state and tangent there (no tolerance involved)."""
    pytest.importorskip("pydiffsol")
    from peelapprox import SolverFailure

    real = K.diffsl_model

    class FailsLater:
        def __init__(self):
            self.ode, self.calls = real("paper", tangent=True), 0
            self.options = self.ode.options

        def __setattr__(self, name, value):
            if name in ("rtol", "atol", "t0"):
                setattr(self.ode, name, value)
            object.__setattr__(self, name, value)

        def solve(self, inp, t):
            self.calls += 1
            if self.calls == 3:
                raise RuntimeError("ODE solver error: Exceeded maximum number of error test failures (41)")
            return self.ode.solve(inp, t)

    monkeypatch.setattr(LV, "diffsl_model", lambda geometry, tangent=False, force=None: FailsLater())
    with pytest.raises(SolverFailure, match="error test failures") as info:
        LV.lyapunov_variational(PeelParams(V=2.0, I=1e-4), t_transient=0.0, T=1.0, tau=0.25)
    assert info.value.t == pytest.approx(0.5, abs=1e-12)
    assert set(info.value.state) == {"alpha", "omega", "F", "v", "tangent"}


@pytest.mark.slow
def test_regularized_variational_lyapunov_agrees_with_the_hybrid_two_trajectory_estimate():
    """Hypothesis: as ε → 0 the ε-system's largest exponent (its own variational equations, no saltation)
    is the hybrid one.  At V = 2.5, I = 1e-4 over the same 200 s after 30 s: measured 5.22 bits/s at
    ε = 1e-8 against 5.52 by the hybrid two-trajectory method (docs/dynamics.md, "Four methods").  Over
    50 s windows single estimates move by ±0.5 bits/s (5.81 at ε = 1e-8), hence 200 s and a 10 % band.
    ~130 s of wall time."""
    pytest.importorskip("pydiffsol")
    from peelapprox import lyapunov

    p = PeelParams(V=2.5, I=1e-4)
    reg = LV.lyapunov_variational(p, eps=1e-8, T=200.0).bits_per_s
    hyb = lyapunov(p, n=40000).bits_per_s
    assert abs(reg - hyb) / hyb < 0.10


@pytest.mark.slow
def test_paper_eps_turns_the_chaotic_point_V2_I1e4_into_a_period_42_orbit():
    """At the paper's ε = 1e-7 the regularised system at V = 2, I = 1e-4 (α0 = 0) is not chaotic: the return
    map of F at the upward crossings, t = 30-80 s, repeats with period 42 to 1.6e-7 N (asserted with
    ``periodicity``'s 1e-6 relative tolerance), while the hybrid (ε → 0) orbit is chaotic with λ ≈ 4.2
    bits/s (paper-notes 24).  ~12 s."""
    pytest.importorskip("pydiffsol")
    from peelapprox import periodicity

    r = P.run_peer("diffsol", PeelParams(V=2.0, I=1e-4), 80.0, eps=1e-7, rtol=1e-8)
    assert r.status == "ok"
    t, F = r.jump_t, r.jump_F
    k = 0 if F[0] > F[1] else 1  # crossings alternate; the upward (AB→CD) ones carry the high F
    x = F[k::2][t[k::2] > 30.0]
    per = periodicity(x, max_period=64)
    assert per.period == 42 and x.size > 3000


def test_lyapunov_variational_without_pydiffsol_names_the_bench_extra(monkeypatch):
    """Without pydiffsol, exact.lyapunov_variational raises an ImportError subclass naming the package and the
    ``bench`` extra, after the argument checks (no tolerance involved)."""
    import sys

    from peelapprox.kernels import PeerUnavailableError

    monkeypatch.setitem(sys.modules, "pydiffsol", None)  # makes ``import pydiffsol`` raise ImportError
    with pytest.raises(PeerUnavailableError, match=r"pydiffsol.*peelapprox\[bench\]"):
        exact.lyapunov_variational(PeelParams(V=2.0, I=1e-4), T=1.0)
    assert issubclass(PeerUnavailableError, ImportError) and P.PeerUnavailableError is PeerUnavailableError

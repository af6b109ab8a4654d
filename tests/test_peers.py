"""External peer solvers (comparisons._peers) on the ε-regularised system.

Each peer is skipped when its package is missing.  The shared Radau
reference (rtol 1e-10, ~6 s) is computed once per module.
"""

import numpy as np
import pytest

import exact
from comparisons import _peers as P
from exact._regularized import _fun
from peelapprox import PeelParams

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
    ode = P.diffsl_model(geometry)
    rng = np.random.default_rng(7)
    scale = np.array([3e-5, 2e-4, 5e-3, 7e-7])
    q = P._qvec(params, EPS)
    for _ in range(8):
        X = np.array([rng.uniform(-0.6, 0.6), rng.uniform(-80, 80), rng.uniform(120, 320), 10 ** rng.uniform(-3, 1.3)])
        y = X / scale
        Xs = y * scale  # what the DiffSL model sees: alpha = ya * sa, ...
        inp = P.diffsl_inputs(params, EPS, X, scale)
        rhs = np.asarray(ode.rhs(inp, 0.0, y), dtype=float) * scale / np.array([1.0, 1.0, 1.0, EPS])
        np.testing.assert_allclose(rhs, _fun(Xs, q), rtol=1e-12, atol=0)
        assert np.allclose(ode.y0(inp) * scale, X, rtol=1e-15, atol=0)


@pytest.mark.parametrize("peer", P.PEERS)
def test_peer_jumps_match_radau(peer, p_low, reference):
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
    ref_t, ref_F = reference
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
    monkeypatch.setitem(P._PACKAGES, "diffsol", ("no_such_module_for_peelapprox", "pydiffsol"))
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

    monkeypatch.setattr(P, "diffsl_model", lambda geometry: Broken())
    r = P.run_peer("diffsol", p_low, 0.01, eps=EPS, rtol=1e-6)
    assert r.status.startswith("failed: ") and "Step size is too small" in r.status
    assert r.jump_t.size == 0 and r.n_steps == -1

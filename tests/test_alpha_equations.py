"""Each fact in one place: the reduced α equations and the parameter packings.

The reduced α equations used to be written in ``peelapprox/_reduced/_alpha.py`` (the public closed forms and
``alpha_numerical``) and again inside the reduced-segment kernel; the kernels' parameter vectors each had their
own index constants for the same model parameters.  These tests would catch the two copies drifting apart
again: the segment kernel's α must be the public formula's, and every driver's vector must start with the one
model block.
"""

from __future__ import annotations

import numpy as np
import pytest

import peelapprox as pa
from peelapprox import PeelParams
from peelapprox.kernels import M_A, M_B, M_GEOM, M_I, M_K, M_L, M_R, M_V, MODEL_FIELDS, N_M, model_block

EPS = np.finfo(float).eps
CASES = [(1.0, 1e-5), (0.5, 1e-3), (3.0, 1e-4)]


def _entry(p: PeelParams, branch: str) -> tuple[float, float]:
    """(F_in, v_in) of a jump onto ``branch``: the landing force and velocity."""
    bs = pa.branch_structure(p.V)
    return (bs.f_min, bs.v_land_ab) if branch == "AB" else (bs.f_max, bs.v_land_cd)


def _close(kernel_side: np.ndarray, public: np.ndarray) -> None:
    """Agreement to 4 ulp of the curve's scale: numpy's vectorised exp/sin/cos (SIMD) and the libm functions
    of the compiled kernel may differ in the last bit (measured: exp on ~5 % of arguments, sin/cos on none of
    10^5), and α̇ of the sinusoid and harmonic forms is a difference of two such terms.  A drifted formula
    (another factor, sign or term) differs by orders of magnitude more."""
    scale = float(np.max(np.abs(public)))
    np.testing.assert_allclose(kernel_side, public, rtol=0, atol=4 * EPS * scale)


@pytest.mark.parametrize("V,I", CASES)
@pytest.mark.parametrize("branch", ["AB", "CD"])
def test_segment_sinusoid_is_the_public_sinusoid(V, I, branch):
    """Hypothesis: the α(t), α̇(t) the segment kernel stores at each accepted step are those of the public
    :func:`peelapprox.sinusoid_alpha` at the same t (same amplitude, phase and force rate); tolerance in
    ``_close``."""
    p = PeelParams(V=V, I=I)
    F_in, v_in = _entry(p, branch)
    seg = pa.reduced_segment(p, branch, F_in=F_in, alpha_model="sinusoid", amplitude=0.1, phase=0.3)
    assert seg.t.size > 5
    a, ad = pa.sinusoid_alpha(p, seg.t, F_in=F_in, amplitude=0.1, phase=0.3, F_rate=p.k * (V - v_in))
    _close(seg.alpha, a)
    _close(seg.alphadot, ad)


@pytest.mark.parametrize("V,I", CASES)
@pytest.mark.parametrize("branch", ["AB", "CD"])
def test_segment_harmonic_is_the_public_harmonic(V, I, branch):
    """Hypothesis: the segment's ``"harmonic"`` α is :func:`peelapprox.harmonic_alpha` at the entry force, at
    every stored t; tolerance in ``_close``."""
    p = PeelParams(V=V, I=I)
    F_in, _ = _entry(p, branch)
    seg = pa.reduced_segment(p, branch, F_in=F_in, alpha_model="harmonic", alpha_in=0.1, alphadot_in=3.0)
    a, ad = pa.harmonic_alpha(p, seg.t, F=F_in, alpha_in=0.1, alphadot_in=3.0)
    _close(seg.alpha, a)
    _close(seg.alphadot, ad)


@pytest.mark.parametrize("V,I", CASES)
@pytest.mark.parametrize("branch", ["AB", "CD"])
def test_segment_exponential_is_the_public_cd_decay(V, I, branch):
    """Hypothesis: the segment's ``"exponential"`` α is :func:`peelapprox.cd_decay_alpha` (τ = R f'(v_in)/F_in)
    at every stored t, and its entry α̇ is the decay's ``-α_in/τ`` computed by the same formula, exactly (both
    scalar); curves within ``_close``."""
    p = PeelParams(V=V, I=I)
    F_in, v_in = _entry(p, branch)
    seg = pa.reduced_segment(p, branch, F_in=F_in, alpha_model="exponential", alpha_in=0.1)
    a, ad = pa.cd_decay_alpha(p, seg.t, F_in=F_in, alpha_in=0.1, v_in=v_in)
    _close(seg.alpha, a)
    _close(seg.alphadot, ad)
    assert seg.alphadot_in == -0.1 / pa.cd_damping_time(p, F_in, v_in)


def test_segment_static_is_constant_alpha():
    """Hypothesis: ``"static"`` holds α = α_in and α̇ = 0 exactly (no arithmetic on them)."""
    p = PeelParams(V=1.0, I=1e-5)
    F_in, _ = _entry(p, "AB")
    seg = pa.reduced_segment(p, "AB", F_in=F_in, alpha_model="static", alpha_in=0.07)
    assert np.all(seg.alpha == 0.07) and np.all(seg.alphadot == 0.0)


@pytest.mark.parametrize("V,I", [(1.0, 1e-4), (3.0, 1e-3)])
def test_segment_frozen_airy2_is_alpha_numerical_airy2(V, I):
    """Hypothesis: the segment's ``"airy2_frozen"`` equation, ``α̈ = -F_in R α/I - F_in α̇/(R f'(v_in))``, is the
    Airy2 of :func:`peelapprox.alpha_numerical` with the force rate 0 and v = v_in: the same ODE, integrated by
    two DOP853 drivers (the segment in the desingularised time s, solve_ivp in t), both at rtol 1e-12.  They
    agree to 1.6e-12 of the curves' scale over the CD stay (measured at both cases); the tolerance 1e-8 leaves
    room for other platforms, and a drifted restoring or damping term (a factor, a sign) moves α by many orders
    more over a stay of 0.1-0.5 inertial periods."""
    p = PeelParams(V=V, I=I)
    F_in, v_in = _entry(p, "CD")
    probe = pa.reduced_segment(p, "CD", F_in=F_in, alpha_model="airy2_frozen", alpha_in=0.05, alphadot_in=2.0,
                               save="none")
    t = np.linspace(0.0, probe.dt, 41)[:-1]
    seg = pa.reduced_segment(p, "CD", F_in=F_in, alpha_model="airy2_frozen", alpha_in=0.05, alphadot_in=2.0,
                             t_eval=t, rtol=1e-12)
    a, ad = pa.alpha_numerical(p, t, F_in=F_in, alpha_in=0.05, alphadot_in=2.0, form="airy2", v=v_in, F_rate=0.0,
                               rtol=1e-12, atol=1e-16)
    np.testing.assert_allclose(seg.alpha, a, rtol=0, atol=1e-8 * np.max(np.abs(a)))
    np.testing.assert_allclose(seg.alphadot, ad, rtol=0, atol=1e-8 * np.max(np.abs(ad)))


# ------------------------------------------------------------------------------------- parameter packings


@pytest.mark.parametrize("geometry", ["paper", "exact"])
def test_model_block_layout(geometry):
    """Hypothesis: the model block is ``(V, I, k, R, l, b, A, geometry flag)`` at the named indices, exactly
    (values copied; b and A those of the generated peel-force law at this V)."""
    from peelapprox.law._paper import peel_force_coefficients

    p = PeelParams(V=2.0, I=1e-3, k=900.0, R=0.12, l=0.8, geometry=geometry)
    m = model_block(p)
    b, A = peel_force_coefficients(2.0)
    assert m.shape == (N_M,) == (len(MODEL_FIELDS),)
    assert (m[M_V], m[M_I], m[M_K], m[M_R], m[M_L], m[M_B], m[M_A]) == (2.0, 1e-3, 900.0, 0.12, 0.8, b, A)
    assert m[M_GEOM] == (0.0 if geometry == "paper" else 1.0)
    assert sorted((M_V, M_I, M_K, M_R, M_L, M_B, M_A, M_GEOM)) == list(range(N_M))
    longer = model_block(p, N_M + 3)
    assert np.array_equal(longer[:N_M], m) and np.all(longer[N_M:] == 0.0)
    with pytest.raises(ValueError, match="size"):
        model_block(p, N_M - 1)


def test_every_driver_vector_starts_with_the_model_block():
    """Hypothesis: the hybrid driver's, the regularised system's and the reduced segment's vectors are the model
    block followed by their own fields, numbered from ``N_M`` without gaps or overlaps (exact comparisons of
    indices and values)."""
    from exact import _hybrid as H
    from exact._hybrid_driver import param_vector as _param_vector
    from peelapprox._reduced import _segment_kernel as K

    p = PeelParams(V=1.0, I=1e-5, geometry="exact")
    pv = _param_vector(p, 1e-9)
    assert pv.shape == (H.N_P,) and np.array_equal(pv[:N_M], model_block(p))
    hybrid = (H.P_VMAX, H.P_VMIN, H.P_VLCD, H.P_VLAB, H.P_UFLOOR, H.P_UCEIL, H.P_FOLDS, H.P_UEV_AB, H.P_UEV_CD)
    assert sorted(hybrid) == list(range(N_M, H.N_P))
    seg = (K.Q_AM, K.Q_VE, K.Q_FIN, K.Q_VIN, K.Q_FPIN, K.Q_S, K.Q_AMP, K.Q_PH, K.Q_AIN, K.Q_ADIN, K.Q_TAU)
    assert sorted(seg) == list(range(N_M, K.N_Q))
    from peelapprox import kernels

    q = kernels.regularized_parameters(p, 1e-7)
    assert kernels.Q_EPS == N_M and q.shape == (N_M + 1,) and q[kernels.Q_EPS] == 1e-7
    assert np.array_equal(q[:N_M], model_block(p))


def test_jitable_refuses_a_function_outside_the_kernel_sources():
    """A formula shared with kernels must live in a hashed kernel source (else a change to it would not
    invalidate the cached kernels that inline it): :func:`peelapprox._compiled._jit.jitable` refuses this test's own."""
    from peelapprox._compiled._jit import jitable

    def f(x):
        return 2.0 * x

    with pytest.raises(RuntimeError, match="KERNEL_SOURCES"):
        jitable(f)

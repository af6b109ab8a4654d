"""The scipy-free Brent root finder (``peelapprox/_brentq.py``) is bitwise :func:`scipy.optimize.brentq`.

The folds of every peel-force law are found with it on a solver's first call, so any difference in the last bit
would change every trajectory: each comparison here is of the float's bytes (``==`` on Python floats, which are
the same double or not; no tolerance), and of the exception's type and message where scipy raises.  The oracle is
scipy's own compiled ``brentq``, an independent implementation (C) of the same algorithm.
"""

from __future__ import annotations

import dataclasses
import math
import struct

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import brentq as scipy_brentq

from peelapprox import PeelForce, branch_structure
from peelapprox._brentq import RTOL, brentq
from peelapprox.law import _compiled, _folds, _paper


def _outcome(solver, f, a, b, **kw):
    """``("ok", the root's 8 bytes)`` or ``(exception type name, message)`` (an exception of ``f`` passes through
    both solvers unchanged)."""
    try:
        return ("ok", struct.pack("<d", solver(f, a, b, **kw)))
    except (ValueError, RuntimeError, ArithmeticError) as exc:  # ArithmeticError: raised by f itself
        return (type(exc).__name__, str(exc))


#: Functions with a root at ``r`` (``c`` shape constants): smooth, flat (a triple root), steep, with a numpy scalar
#: result, a step (exact zeros, bisection only), the peel-force-like sum of powers and an exponential, and values
#: so small that their products underflow (hypothesis found scipy's sign test there: ``signbit``, not a product).
FUNCTIONS = [
    lambda x, r, c: (x - r) * (1.0 + c * x * x),
    lambda x, r, c: (x - r) ** 3 * (1.0 + abs(c)),
    lambda x, r, c: math.atan(c * 50.0 * (x - r)),
    lambda x, r, c: np.float64(math.expm1(c * (x - r))),
    lambda x, r, c: float(np.sign(x - r)),
    lambda x, r, c: math.tanh(x - r) + c * 1e-3 * (x - r) ** 2,
    lambda x, r, c: abs(x) ** 0.35 - abs(r) ** 0.35 + 0.1 * (math.exp((x - r) / 11.0) - 1.0),
    lambda x, r, c: 1e-200 * (x - r) * (1.0 + c * c),  # f(a) f(b) underflows to -0.0: the signs must decide
]


def _case(rng: np.random.Generator):
    """A seeded random function, bracket (around its root, either order; sometimes not bracketing), tolerances
    (xtol from 1e-300, as the fold search uses, to 1e-2; rtol from scipy's minimum 4 ulp) and maxiter (0 to 120:
    non-convergence included)."""
    k = int(rng.integers(len(FUNCTIONS)))
    r, c = float(rng.normal(scale=2.0)), float(rng.normal())
    lo, hi = r - float(10 ** rng.uniform(-8, 1)), r + float(10 ** rng.uniform(-8, 1))
    if rng.random() < 0.1:  # no sign change (scipy's ValueError) or a root at an end
        lo = r + float(rng.uniform(0, 1)) * (rng.random() < 0.5)
    a, b = (lo, hi) if rng.random() < 0.5 else (hi, lo)
    kw = dict(xtol=float(10 ** rng.uniform(-300 if rng.random() < 0.3 else -16, -2)),
              rtol=float(RTOL * 10 ** rng.uniform(0, 9) if rng.random() < 0.7 else RTOL),
              maxiter=int(rng.integers(0, 121)))
    return (lambda x, f=FUNCTIONS[k], r=r, c=c: f(x, r, c)), a, b, kw


def test_bitwise_scipy_on_seeded_random_functions():
    """Hypothesis: on 3000 seeded random functions, brackets and tolerances the port returns scipy's root to the
    bit, and raises scipy's exception (type and message) where scipy does.  Exact equality: the port performs the
    same double operations in the same order, so any difference is a bug (no tolerance)."""
    rng = np.random.default_rng(20261128)
    kinds = {"ok": 0, "ValueError": 0, "RuntimeError": 0}
    for _ in range(3000):
        f, a, b, kw = _case(rng)
        ours, theirs = _outcome(brentq, f, a, b, **kw), _outcome(scipy_brentq, f, a, b, **kw)
        assert ours == theirs, (a, b, kw)
        kinds[ours[0]] += 1
    assert kinds["ok"] > 2000 and kinds["ValueError"] > 0 and kinds["RuntimeError"] > 0, kinds  # all paths run


@settings(max_examples=300, deadline=None)
@given(r=st.floats(-1e6, 1e6), w1=st.floats(1e-12, 1e3), w2=st.floats(1e-12, 1e3), c=st.floats(-5, 5),
       k=st.integers(0, len(FUNCTIONS) - 1), xtol=st.floats(1e-300, 1e-1), rtol_factor=st.floats(1.0, 1e8),
       args=st.booleans())
def test_bitwise_scipy_property(r, w1, w2, c, k, xtol, rtol_factor, args):
    """Hypothesis (property): for any root, bracket widths, tolerances and with the function's constants passed
    as ``args`` or bound, the root is scipy's to the bit (or the same exception).  Exact equality, as above."""
    f = FUNCTIONS[k]
    kw = dict(xtol=xtol, rtol=RTOL * rtol_factor)
    if args:
        assert _outcome(brentq, f, r - w1, r + w2, args=(r, c), **kw) == _outcome(
            scipy_brentq, f, r - w1, r + w2, args=(r, c), **kw)
    else:
        g = lambda x: f(x, r, c)  # noqa: E731
        assert _outcome(brentq, g, r - w1, r + w2, **kw) == _outcome(scipy_brentq, g, r - w1, r + w2, **kw)


def test_argument_checks_and_nan_are_scipys():
    """Hypothesis: the checks of scipy's wrapper are kept: xtol <= 0, rtol below 4 ulp, a negative maxiter and a
    NaN function value raise scipy's ValueError (same message); a non-tuple ``args`` is one argument."""
    f = lambda x, s=0.0: x - 0.5 + s  # noqa: E731
    for kw in (dict(xtol=0.0), dict(rtol=RTOL / 2), dict(maxiter=-1)):
        assert _outcome(brentq, f, 0.0, 1.0, **kw) == _outcome(scipy_brentq, f, 0.0, 1.0, **kw)
    nan_at = lambda x: math.nan if x > 0.7 else x - 0.5  # noqa: E731
    assert _outcome(brentq, nan_at, 0.0, 1.0)[0] == "ValueError"
    assert _outcome(brentq, nan_at, 0.0, 1.0) == _outcome(scipy_brentq, nan_at, 0.0, 1.0)
    assert brentq(f, 0.0, 1.0, args=0.25) == scipy_brentq(f, 0.0, 1.0, args=0.25) == 0.25


def _fields(obj) -> list[str]:
    return [repr(getattr(obj, f.name)) for f in dataclasses.fields(obj)]


def test_real_fold_calls_are_bitwise_scipys(monkeypatch):
    """Hypothesis: the folds, landings, inflection and breakdown velocities of fvV at 40 seeded random V in
    [0.05, 9] m/s, its branch inverses at random levels, and the folds and branch structure of two families at 4
    random V, are bitwise those computed with scipy's ``brentq`` in its place (every field's repr, which prints
    the shortest string that round-trips a double: equal reprs are equal bits)."""
    rng = np.random.default_rng(37)
    Vs = [float(v) for v in rng.uniform(0.05, 9.0, 40)]
    levels = rng.uniform(0.0, 1.0, (40, 3))

    def paper() -> list:
        out = []
        for V, u in zip(Vs, levels, strict=True):
            bs = _paper._branch_structure.__wrapped__(V)
            out.append(_fields(bs))
            if bs.has_folds:
                b, A = _paper.peel_force_coefficients(V)
                lo = max(bs.f_min, bs.f_zero)
                out += [repr(_paper._invert(lo + x * (bs.f_max - lo), bs, br, b, A)) for x in u for br in ("AB", "CD")]
        return out

    def families() -> list:
        out = []
        for V in Vs[:4]:
            for law in (PeelForce.paper_family(), PeelForce.cubic()):
                _compiled._CACHE.clear()
                out += [_fields(law.folds(V)), _fields(branch_structure(V, force=law))]
        return out

    ours = paper(), families()
    for module in (_paper, _folds, _compiled):
        monkeypatch.setattr(module, "brentq", scipy_brentq)
    theirs = paper(), families()
    assert ours == theirs
    assert sum(1 for row in ours[0] if isinstance(row, str)) >= 60  # the inverses ran (folds at most V)


@pytest.mark.parametrize("maxiter", [0, 1, 3])
def test_nonconvergence_message(maxiter):
    """Hypothesis: too few iterations raise scipy's RuntimeError with scipy's message (the law's fold search turns
    it into a ValueError naming the law, ``_root`` in ``peelapprox/law/_folds.py``)."""
    f = lambda x: x**3 - 2.0  # noqa: E731
    assert _outcome(brentq, f, 0.0, 5.0, maxiter=maxiter) == _outcome(scipy_brentq, f, 0.0, 5.0, maxiter=maxiter)
    assert _outcome(brentq, f, 0.0, 5.0, maxiter=maxiter)[0] == "RuntimeError"

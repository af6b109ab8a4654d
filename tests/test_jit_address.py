"""The one private numba name the package uses: the compiled wrapper's address of a dispatcher.

``peelapprox._compiled._jit.wrapper_address`` reaches ``numba.experimental.function_type._get_wrapper_address`` (its
docstring says why no public route serves: ``cfunc`` compiles a second time, a dispatcher argument costs ~35 µs
a call).  These tests fail first, and say so, if a numba release drops or changes it.
"""

from __future__ import annotations

import ctypes

import numpy as np
from numba import njit, types
from numba.experimental import function_type

from peelapprox._compiled._jit import wrapper_address


def test_numba_still_has_the_private_wrapper_address():
    """Hypothesis: this numba keeps ``_get_wrapper_address`` (a callable); if it fails, numba dropped it:
    change ``peelapprox._compiled._jit.wrapper_address`` to a public route (``numba.cfunc(sig)(fn).address``)."""
    assert callable(getattr(function_type, "_get_wrapper_address", None))


def test_the_address_calls_the_same_compiled_code():
    """Hypothesis: calling the address through ctypes gives the dispatcher's results bitwise (the same
    compiled function, so exact equality, no tolerance) on 50 seeded random points."""
    f = njit(lambda x, y: np.exp(0.35 * np.log(x)) - y / 11.0 + np.sqrt(x) * y)
    sig = types.float64(types.float64, types.float64)
    addr = wrapper_address(f, sig)
    assert isinstance(addr, int) and addr != 0
    c = ctypes.CFUNCTYPE(ctypes.c_double, ctypes.c_double, ctypes.c_double)(addr)
    rng = np.random.default_rng(38)
    for x, y in zip(rng.uniform(1e-3, 30.0, 50), rng.uniform(-5.0, 5.0, 50)):
        assert c(float(x), float(y)) == f(float(x), float(y))

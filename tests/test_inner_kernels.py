"""Helpers compiled into their callers (``kernel(inner=True)``): plain functions for Python, one compilation per
argument types for compiled callers, whatever flags those callers were compiled with."""

from __future__ import annotations

import numpy as np
from numba import njit
from numba.core import event

from peelapprox._compiled import _dop853 as D


def test_inner_helper_is_a_plain_function_that_compiled_callers_compile_once():
    """Hypothesis: ``interp1`` (inner) is the plain Python function (no dispatcher attributes) and gives, run by
    Python, bitwise what a compiled caller gets; compiled directly by a plain ``njit`` caller and through
    ``interp`` (another inner helper, compiled with other wrapper flags), it is compiled at most once (zero if an
    earlier test of this process compiled it).  Exact comparisons."""
    assert not hasattr(D.interp1, "signatures") and not hasattr(D.interp, "py_func")
    y = np.array([1.0, 2.0, -0.5])
    Fc = np.linspace(-1.0, 2.0, 21).reshape(7, 3)

    @njit
    def direct(y, Fc, x):
        return D.interp1(y, Fc, x, 1)

    @njit
    def through_interp(y, Fc, x, out):
        D.interp(y, Fc, x, out)
        return out[1]

    rec = event.RecordingListener()
    with event.install_listener("numba:compile", rec):
        a = direct(y, Fc, 0.3)
        b = through_interp(y, Fc, 0.3, np.empty(3))
    names = [e.data["dispatcher"].py_func.__name__ for _, e in rec.buffer if e.is_start]
    assert names.count("interp1") <= 1, names
    assert a == b == D.interp1(y, Fc, 0.3, 1)


def test_dop853_pieces_are_a_module_of_plain_functions():
    """Hypothesis: ``make_dop853`` returns a :class:`~peelapprox._compiled._dop853.Dop853` module whose four pieces are
    plain
    functions named after the field (the names a cold run's compile listing shows)."""
    from exact._hybrid_field import _rhs

    d = D.make_dop853(_rhs)
    assert isinstance(d, D.Dop853)
    for piece in ("initial_step", "step", "dense", "ensure_dense"):
        fn = getattr(d, piece)
        assert not hasattr(fn, "signatures")
        assert fn.__name__ == f"{piece}__exact__hybrid_field__rhs"

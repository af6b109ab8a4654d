"""The GIL-share benchmark (comparisons.benchmark.gil) on one short atlas point."""

from __future__ import annotations

import warnings

import numba.core.serialize as ser
import numba.experimental.function_type as ft
from numba.core import dispatcher as dm

from comparisons.benchmark.gil import measure


def test_split_adds_up_and_is_undone():
    """The parts (three measures and the rest) add up to the total per point (1e-9 ms: float sums of the same
    timer readings), every share lies in (0, 1], the held time is at most the CPU time, the point called
    kernels, and the instrumentation of numba is removed afterwards (its dispatcher class has no ``__call__``
    of its own again, the unboxing helpers are numba's)."""
    helpers = (ft._get_wrapper_address, ft._get_jit_address, ser._numba_unpickle)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = measure([1e-4], [1.0], t_transient=1.0, window=1.0)
    parts = ("atlas_exact", "atlas_segments", "atlas_approx", "rest")
    for key in ("cpu_ms", "kernels_ms", "unboxing_ms", "held_ms"):
        assert abs(sum(r[p][key] for p in parts) - r["total"][key]) <= 1e-9
    for p in (*parts[:3], "total"):
        assert 0.0 < r[p]["share"] <= 1.0 + 1e-12 and r[p]["held_ms"] <= r[p]["cpu_ms"] + 1e-9
    assert r["calls"] >= 1 and r["total"]["kernels_ms"] > 0 and r["ceiling"] >= 1.0
    assert "__call__" not in vars(dm.Dispatcher)
    assert (ft._get_wrapper_address, ft._get_jit_address, ser._numba_unpickle) == helpers

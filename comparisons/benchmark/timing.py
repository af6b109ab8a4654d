"""How the benchmark times a run, and keeps its stdout clean of the C solvers' messages.

As the SciML work-precision benchmarks: one untimed warm-up per configuration, then the minimum over repeats.
The multi-second scipy Radau/BDF runs are warmed up on the horizon up to the reference's second jump (which
exercises every code path) and timed once.
"""

from __future__ import annotations

import contextlib
import math
import os
import sys
import time
from collections.abc import Callable

__all__ = ["timed", "c_stdout_to_stderr"]


def timed(fn: Callable, repeats: int, warm: Callable | None = None):
    (warm or fn)()  # warm-up, untimed (``warm``: a shorter run, for the multi-second scipy stiff runs)
    best, out = math.inf, None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


@contextlib.contextmanager
def c_stdout_to_stderr():
    """SUNDIALS prints its failure messages on the C-level stdout; route them to stderr so that the
    benchmark's stdout stays a clean table (``--format json`` must parse)."""
    sys.stdout.flush()
    saved = os.dup(1)
    try:
        os.dup2(2, 1)
        yield
    finally:
        sys.stdout.flush()
        os.dup2(saved, 1)
        os.close(saved)

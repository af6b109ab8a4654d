"""Test-only approximations for the atlas.

A module (not a test file) so that spawned worker processes can import them by ``module:qualname`` (spawn
gives the workers the parent's ``sys.path``, which holds ``tests/`` under pytest and in the kill-and-resume
subprocess).  Registering them is left to each test (``register_approximation``), so the built-in registry
of other tests is not changed by importing this module.
"""

import os
import time

from comparisons.atlas import estimate_observables
from peelapprox import StickSlipObservables


def slow(params):
    """:func:`comparisons.atlas.estimate_observables`, after sleeping ``PEELAPPROX_TEST_ATLAS_SLEEP`` seconds
    (default 0: the records do not depend on the sleep)."""
    time.sleep(float(os.environ.get("PEELAPPROX_TEST_ATLAS_SLEEP", "0")))
    return estimate_observables(params)


def nan_slip_interval(params):
    """A broken approximation: stick-slip with a NaN slip interval (must become an error status, not NaN)."""
    return {"status": "stick-slip", "reason": "test", "slip_interval": float("nan")}


def as_observables(params):
    """estimate's prediction as a :class:`peelapprox.StickSlipObservables` (the other return type)."""
    d = estimate_observables(params)
    fields = {f: d.get(f) for f in ("slip_interval", "force_drop", "slip_time", "stick_time", "F_max", "F_min")}
    spreads = {f"{f}_spread": None for f in ("slip_interval", "force_drop", "slip_time", "stick_time")}
    return StickSlipObservables(status=d["status"], reason=d["reason"], method=d["method"], V=params.V, I=params.I,
                                n_slips=0, period=d["period"], period_label="period-1", t_start=None, t_end=None,
                                **fields, **spreads)

"""Test-only sweep measures.

A module (not a test file) so that spawned worker processes can import it by
``module:qualname``: spawn gives the workers the parent's ``sys.path``, which
holds ``tests/`` under pytest and in the kill-and-resume subprocess.
"""

import math
import os
import time

from comparisons.sweep import register_measure


def slowprod(params, options):
    """Sleeps ``options["sleep"]`` s (default 0), then returns deterministic numbers of (I, V)."""
    time.sleep(float(options.get("sleep", 0.0)))
    return {"value": params.I * params.V, "log_ratio": math.log(params.V / params.I), "tag": f"V={params.V:g}"}


def flaky(params, options):
    """Raises at ``V >= options["fail_at_V"]``; otherwise returns one number."""
    if params.V >= float(options.get("fail_at_V", math.inf)):
        raise RuntimeError(f"boom at V={params.V:g}")
    return {"x": params.V}


def envfail(params, options):
    """Raises while the environment variable ``PEELAPPROX_TEST_FAIL`` is set (a transient failure that the same
    options do not reproduce once it is unset); otherwise returns one number."""
    if os.environ.get("PEELAPPROX_TEST_FAIL"):
        raise OSError(f"transient failure at V={params.V:g}")
    return {"x": params.I + params.V}


register_measure("slowprod", slowprod)
register_measure("flaky", flaky)
register_measure("envfail", envfail)

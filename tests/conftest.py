import os

import pytest

from peelapprox import PeelParams


@pytest.fixture(scope="session")
def p_low():
    """V=1, I=1e-5: the paper's low-inertia case (Fig. 3b,c)."""
    return PeelParams(V=1.0, I=1e-5)


@pytest.fixture(scope="session")
def p_high():
    """V=1, I=1e-2: the paper's high-inertia case (Fig. 4)."""
    return PeelParams(V=1.0, I=1e-2)


def pytest_xdist_auto_num_workers(config: pytest.Config) -> int:
    """The workers of ``-n auto`` (pyproject's addopts): one per usable CPU, at least 2 (a worker often waits on
    a subprocess it started: examples, cold starts, CLI runs) and at most 4 (each worker's tests start process
    pools of their own).  ``-n 0`` runs in one process; ``-p no:xdist`` without the plugin."""
    try:
        cpus = len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        cpus = os.cpu_count() or 1
    return max(2, min(4, cpus))

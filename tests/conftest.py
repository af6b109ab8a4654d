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


#: The default tier's costliest files, costliest first (CPU seconds of their tests from an empty kernel cache
#: under 2 xdist workers, ``--durations=0``, 2026-11-29: 44 ... 10 s; the median file takes ~2 s).  Handed out
#: first (pyproject's ``--no-loadscope-reorder`` keeps this order; xdist's own reorder puts files with many
#: tests first and these few-test files last, where one of them alone kept a worker busy while the other idled).
#: A file's cost depends on its place: the first to need a kernel compiles it (~75 s of the tier's CPU).  Later the
#: same day test_infer.py had grown to ~30 s of CPU (its aperiodic fits; each test's process CPU with its
#: subprocesses, empty cache, 2 workers, loaded machine), the costliest after test_bounded.py, test_cold_start.py
#: and test_front.py: handed out fifth, no longer eleventh, where it came among the last long files.
HEAVY_FIRST = ("test_bounded.py", "test_cold_start.py", "test_named_errors.py", "test_front.py", "test_infer.py",
               "test_readme.py", "test_atlas_sets.py", "test_branch_events.py", "test_sweep.py", "test_law.py",
               "test_plotting.py", "test_basins.py", "test_orbits.py", "test_parallel.py", "test_variants_cli.py",
               "test_law_dynamics.py", "test_kernel_cache.py", "test_law_reduced.py", "test_examples.py",
               "test_series_lyapunov.py")


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """The files of :data:`HEAVY_FIRST` first, in its order; the others after them in collection order (a stable
    sort, so the tests of a file keep theirs).  No test depends on the order (each file runs alone too)."""
    rank = {name: i for i, name in enumerate(HEAVY_FIRST)}
    items.sort(key=lambda item: rank.get(item.path.name, len(rank)))


def pytest_xdist_auto_num_workers(config: pytest.Config) -> int:
    """The workers of ``-n auto`` (pyproject's addopts): one per usable CPU, at least 2 (a worker often waits on
    a subprocess it started: examples, cold starts, CLI runs) and at most 4 (each worker's tests start process
    pools of their own).  ``-n 0`` runs in one process; ``-p no:xdist`` without the plugin."""
    try:
        cpus = len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        cpus = os.cpu_count() or 1
    return max(2, min(4, cpus))

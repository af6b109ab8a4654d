"""Backward-compatible alias of :mod:`comparisons.benchmark` (the work-precision benchmark moved there in 0.2.0).

``from comparisons._benchmark import ...`` keeps working; new code should use ``comparisons.benchmark``.
"""

from comparisons.benchmark import *  # noqa: F401,F403 - the shim re-exports the package's public names
from comparisons.benchmark import __all__  # noqa: F401

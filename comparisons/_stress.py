"""Backward-compatible alias of :mod:`comparisons.stress` (the stress suite moved there in 0.2.0).

``from comparisons._stress import ...`` and ``python -m comparisons._stress`` keep working; new code
should use ``comparisons.stress`` and ``python -m comparisons.stress``.
"""

import sys

from comparisons.stress import *  # noqa: F401,F403 - the shim re-exports the package's public names
from comparisons.stress import __all__, main  # noqa: F401

if __name__ == "__main__":
    sys.exit(main())

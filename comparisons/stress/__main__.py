"""``python -m comparisons.stress``: runs :func:`comparisons.stress.cli.main`."""

import sys

from comparisons.stress.cli import main

sys.exit(main())

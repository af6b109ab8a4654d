"""``python -m comparisons.front``: the peel front's reproduction report (:mod:`comparisons.front.report`)."""

import sys

from .report import main

sys.exit(main())

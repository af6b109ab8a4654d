"""``python -m peelapprox.cli ...``: the ``peelapprox`` command."""

import sys

from . import main

sys.exit(main())

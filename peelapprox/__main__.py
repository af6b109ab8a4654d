"""``python -m peelapprox ...``: the ``peelapprox`` command (:func:`peelapprox.cli.main`)."""

import sys

from .cli import main

sys.exit(main())

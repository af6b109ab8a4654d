"""``python -m comparisons.sweep ARGS``: the command line of a sweep, ``peelapprox sweep ARGS``."""

import sys

from peelapprox.cli import main

if __name__ == "__main__":
    sys.exit(main(["sweep", *sys.argv[1:]]))

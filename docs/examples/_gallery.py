"""The one piece the gallery's scripts share: where they write their figure.

``--out DIR``, else the environment variable ``PEELAPPROX_EXAMPLES_OUT``, else a new temporary directory
(never the working directory).  Copying an example elsewhere: copy this file beside it, or replace the
``output_dir(...)`` line with your own path.
"""

import argparse
import os
import tempfile
from pathlib import Path


def arguments(doc: str) -> argparse.ArgumentParser:
    """A parser with ``--out``, its help the example's docstring."""
    ap = argparse.ArgumentParser(description=doc, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default=os.environ.get("PEELAPPROX_EXAMPLES_OUT"),
                    help="directory for the figure (default: $PEELAPPROX_EXAMPLES_OUT, else a new temporary one)")
    return ap


def output_dir(out: str | None) -> Path:
    """``out`` (created if missing), or a new temporary directory when it is None or empty."""
    path = Path(out or tempfile.mkdtemp(prefix="peelapprox-example-"))
    path.mkdir(parents=True, exist_ok=True)
    return path

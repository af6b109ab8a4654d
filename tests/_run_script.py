"""Run a Python script in this process as ``python SCRIPT ARGS`` would: ``__main__``, its own ``sys.argv``, a
fresh namespace, stdout and stderr captured.  The one body of the batched drivers of test_examples and
test_readme (each runs several scripts in one child process to save the interpreter's and imports' start)."""

import contextlib
import io
import runpy
import sys
import traceback


def run_script(script: str, argv: list[str]) -> tuple[int, str, str]:
    """``(exit status, stdout, stderr)`` of ``script`` run with ``sys.argv = [script, *argv]``."""
    sys.argv = [script, *argv]
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            runpy.run_path(script, run_name="__main__")
            status = 0
        except SystemExit as exc:
            status = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
        except BaseException:
            traceback.print_exc()
            status = 1
    return status, out.getvalue(), err.getvalue()

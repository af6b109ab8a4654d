"""``ast.parse`` with the garbage collector held off, for the tests that read the package's sources.

CPython 3.11 fails a parse with ``SystemError: AST constructor recursion depth mismatch`` when a collection
inside it runs a ``__del__`` that raises.  One such object is llvmlite's ``OutputString`` left half-built when
:func:`peelapprox._deadline.time_limit` interrupts a law's compilation (its ``__del__`` reads the ``_ptr`` its
``__init__`` never set): seen once in ``.ci/run`` (fresh venv, compiles under load), in
``tests/test_security.py``.  With the collector off during the parse, any such ``__del__`` runs at a later
collection, outside it.  (Not a ``gc.collect()`` per parse: with numba's heap loaded it costs ~0.15 s, 60 s over
the package's files.)"""

import ast
import gc


def parse(source: str) -> ast.Module:
    """``ast.parse(source)`` with no garbage collection during the parse."""
    enabled = gc.isenabled()
    gc.disable()
    try:
        return ast.parse(source)
    finally:
        if enabled:
            gc.enable()

"""``ast.parse`` with the garbage collector held off, for the tests that read the package's sources.

CPython 3.11 fails a parse with ``SystemError: AST constructor recursion depth mismatch`` when a collection
inside it runs a ``__del__`` that raises.  One such object is llvmlite's ``OutputString`` left half-built when
:func:`peelapprox._deadline.time_limit` interrupts a law's compilation (its ``__del__`` reads the ``_ptr`` its
``__init__`` never set): seen once in ``.ci/run`` (fresh venv, compiles under load), in
``tests/test_security.py``.  Collecting first, then parsing with the collector off, keeps any such ``__del__`` out
of the parse (it runs, and is reported, at the collection)."""

import ast
import gc


def parse(source: str) -> ast.Module:
    """``ast.parse(source)`` with pending garbage collected first and no collection during the parse."""
    gc.collect()
    enabled = gc.isenabled()
    gc.disable()
    try:
        return ast.parse(source)
    finally:
        if enabled:
            gc.enable()

"""Wall-clock limits on work that has no clock of its own: sympy's algebra and numba's compilation of a law.

A solver checks its wall budget between steps; differentiating a law with sympy or compiling it with numba is
one long call that checks nothing.  :func:`time_limit` bounds such a call: in the main thread of a POSIX
process it arms an interval timer (``signal.setitimer``) whose handler raises :class:`Expired` inside the
running code (sympy and numba's front end are Python, so the exception lands within milliseconds; a single
LLVM optimisation pass is not interrupted but is itself bounded by the size limits of the expression grammar and
of a law's derivatives, ``MAX_DERIVATIVE_NODES`` of ``peelapprox/law/_expression.py``, checked before rendering).
Elsewhere (another thread, Windows, a caller's own timer already armed) it cannot interrupt and checks the
clock when the call returns instead.  The previous signal handler and timer are restored on exit, and the
submodules of an import the limit interrupted are forgotten (:func:`_drop_orphans`), so that the same process
can import that package again (the CLI's ``main`` is called in-process too).

:func:`caller_budget` hands a public call's ``max_wall`` (e.g. :func:`exact.simulate`'s) down to the law
compilation it triggers without threading it through every signature: the nearer of the two deadlines
applies, and :attr:`Expired.caller` says whether the caller's was the one that expired.
"""

from __future__ import annotations

import contextvars
import signal
import sys
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

__all__ = ["LAW_BUILD_SECONDS", "Expired", "WallSpent", "caller_budget", "time_limit"]

#: The longest a law may take to be built (sympy: parse, derivatives, probe) or compiled (render, numba) [s]:
#: the families and the paper's law written out take well under 1 s; a law needing a minute of algebra is one
#: to write differently (expanded, fewer factors).
LAW_BUILD_SECONDS = 60.0

#: The longest limit armed as a timer [s] (about 3 years; ``setitimer`` overflows ``time_t`` near 1e10 s).
MAX_TIMER = 1e8
#: Seconds between the timer's repeated firings after the limit (module docstring of :func:`time_limit`).
REPEAT = 0.05

#: The caller's deadline (``time.perf_counter()`` value), if a public call set one (:func:`caller_budget`).
_CALLER: contextvars.ContextVar[float | None] = contextvars.ContextVar("peelapprox_caller_deadline", default=None)


class Expired(BaseException):  # noqa: N818 - an event, not an error the user sees (callers turn it into theirs)
    """The time limit of :func:`time_limit` ran out; ``seconds`` is the limit that applied, ``caller`` is True
    when it was the caller's budget (:func:`caller_budget`) rather than the limit of the call itself.

    A ``BaseException``, as ``KeyboardInterrupt`` is: the code it interrupts (sympy's assumptions, numba's
    passes) has ``except Exception`` clauses that would otherwise swallow it and carry on."""

    def __init__(self, seconds: float, caller: bool) -> None:
        super().__init__(f"more than {seconds:g} s")
        self.seconds = seconds
        self.caller = caller


@contextmanager
def caller_budget(max_wall: float | None) -> Iterator[None]:
    """Make ``max_wall`` seconds from now the deadline of every :func:`time_limit` inside (None: no change)."""
    if max_wall is None:
        yield
        return
    deadline = time.perf_counter() + max_wall
    outer = _CALLER.get()
    token = _CALLER.set(deadline if outer is None else min(outer, deadline))
    try:
        yield
    finally:
        _CALLER.reset(token)


def _can_interrupt() -> bool:
    return (hasattr(signal, "setitimer") and threading.current_thread() is threading.main_thread()
            and signal.getitimer(signal.ITIMER_REAL)[0] == 0.0)


class WallSpent(BaseException):
    """A whole command's wall budget is spent (the CLI's ``--max-wall``): a ``BaseException``, as
    ``KeyboardInterrupt`` is, so that no ``except Exception`` on the way (a benchmark row, a sweep point, a law
    build's own :class:`Expired`) takes it for its own failure."""

    def __init__(self, seconds: float, caller: bool = False) -> None:
        super().__init__(f"more than {seconds:g} s")
        self.seconds = seconds


def _disarm(previous: Any, error: type[BaseException]) -> None:
    """Stop the timer and put the previous handler back, also when the timer fires once more on the way (its
    expiry is then raised by the caller's check of the elapsed time, after the clean-up)."""
    while True:
        try:
            signal.setitimer(signal.ITIMER_REAL, 0.0)
            signal.signal(signal.SIGALRM, previous)
            return
        except error:
            continue


def _drop_orphans(before: set[str]) -> None:
    """Forget the modules imported since ``before`` (a set of ``sys.modules``' names) whose package is no longer
    in ``sys.modules``: what an import interrupted by the limit leaves.  Python drops the module whose code was
    interrupted, but keeps its submodules imported so far, and those refer to the dropped module: importing the
    package again would run its code with them and fail (``import matplotlib`` interrupted, the next one raised
    ``AttributeError: module 'matplotlib' has no attribute 'get_data_path'`` from ``matplotlib.cbook``)."""
    orphans = [name for name in list(sys.modules) if name not in before and "." in name
               and any(name.rsplit(".", k)[0] not in sys.modules for k in range(1, name.count(".") + 1))]
    for name in orphans:
        sys.modules.pop(name, None)


@contextmanager
def time_limit(seconds: float, error: type[BaseException] = Expired) -> Iterator[None]:
    """Raise ``error(limit, caller)`` (:class:`Expired`) if the body runs longer than ``seconds`` or past the
    caller's deadline.

    Interrupts the body where it can (module docstring), else raises when the body returns late.
    """
    now = time.perf_counter()
    outer = _CALLER.get()
    caller = outer is not None and outer - now < seconds
    limit = (outer - now) if caller and outer is not None else seconds
    if limit <= 0.0:
        raise error(0.0, caller)
    if limit > MAX_TIMER or not _can_interrupt():  # beyond the timer's range (time_t): a check on return
        yield
        if time.perf_counter() - now > limit:
            raise error(limit, caller)
        return

    def _expire(signum: int, frame: object) -> None:
        raise error(limit, caller)

    previous = signal.signal(signal.SIGALRM, _expire)
    before = set(sys.modules)
    # repeating: an exception raised where Python cannot propagate it (a weakref callback, a ctypes callback of
    # llvmlite) is printed and dropped, so the timer fires again every REPEAT seconds until one lands
    try:  # armed inside the try: a timer firing at once (a limit of microseconds) still reaches the finally
        signal.setitimer(signal.ITIMER_REAL, limit, REPEAT)
        yield
    except BaseException:  # the limit (or a Ctrl-C) may have landed inside an import
        _disarm(previous, error)  # first: a repeated firing cannot interrupt the clean-up
        _drop_orphans(before)
        raise
    finally:
        _disarm(previous, error)
    # every firing may have landed where Python drops exceptions (a __del__, a gc callback) while the body ran
    # on to its end: a body that returned late is late all the same
    if time.perf_counter() - now > limit:
        raise error(limit, caller)

"""The one progress reporter of the long loops (sweep, basins, orbit diagram, a long simulate): :class:`ProgressLine`.

It writes few lines wherever it runs.  To a terminal or a log (any stream that is not Jupyter's) it writes
one clean line for the first point, for the last, each time another ``every`` fraction of the points is done
(5 %: at most ~22 lines whatever the size of the run) and for every failed point, with its reason.  In a
Jupyter kernel (``"ipykernel" in sys.modules`` when the reporter is made: IPython is never imported here) the
same rate-limited updates overwrite one line (carriage return), so a saved notebook holds one short output;
failed points still get their own line.  The rate limit counts points, not seconds: what is written does not
depend on the machine's speed (the clock gives only the elapsed time and the ETA).
"""

from __future__ import annotations

import math
import sys
import time
from collections.abc import Callable
from typing import IO

__all__ = ["ProgressLine", "hms", "in_jupyter"]


def in_jupyter() -> bool:
    """Whether this process is a Jupyter kernel (``ipykernel`` has been imported), checked at call time."""
    return "ipykernel" in sys.modules


def hms(s: float) -> str:
    """Seconds as ``m:ss`` or ``h:mm:ss``; ``"?"`` if not finite."""
    if not math.isfinite(s):
        return "?"
    s = int(round(s))
    return f"{s // 3600}:{s // 60 % 60:02d}:{s % 60:02d}" if s >= 3600 else f"{s // 60}:{s % 60:02d}"


class ProgressLine:
    """Rate-limited progress of a run of ``total`` points of which ``done0`` were done before it started.

    Parameters
    ----------
    label : str
        The first word of every line, e.g. ``"sweep"``.
    total : int
        Number of points of the whole run (done before included).
    done0 : int
        Points done before this run (a resumed sweep): the first update of this run is always written and the
        ETA uses only this run's rate.
    every : float
        Fraction of ``total`` between two written updates, in (0, 1].
    stream : file-like, optional
        Where to write; default ``sys.stderr`` (the one of the moment the reporter is made).
    jupyter : bool, optional
        One updating line (True) or clean lines (False); default :func:`in_jupyter`.
    clock : callable
        Seconds, for the elapsed time and the ETA (a fake clock in tests).
    count : bool
        Show ``[done/total]`` (points); False for a run measured in another unit (a simulation's time,
        reported in per mille of ``t_end`` with the time in ``detail``).

    Raises
    ------
    ValueError
        ``total`` or ``done0`` negative, ``done0 > total``, or ``every`` not in (0, 1].
    """

    def __init__(self, label: str, total: int, *, done0: int = 0, every: float = 0.05, stream: IO[str] | None = None,
                 jupyter: bool | None = None, clock: Callable[[], float] = time.perf_counter, count: bool = True):
        if total < 0 or not 0 <= done0 <= total:
            raise ValueError(f"total and done0 must satisfy 0 <= done0 <= total, got total={total}, done0={done0}")
        if not 0 < every <= 1:
            raise ValueError(f"every must be in (0, 1], got {every!r}")
        self.label, self.total, self.done0 = label, int(total), int(done0)
        self.step = max(1, math.ceil(every * total))
        self.stream = sys.stderr if stream is None else stream
        self.jupyter = in_jupyter() if jupyter is None else bool(jupyter)
        self.clock = clock
        self.count = bool(count)
        self.t0 = clock()
        self._written = self.done0  # done at the last written update
        self._open = 0  # Jupyter: width of the line being overwritten (0: none)
        self.lines = 0  # writes so far (a write in Jupyter mode may overwrite the line)

    def prefix(self, done: int) -> str:
        """``"[done/total]"``, ``done`` padded to the width of ``total``."""
        return f"[{done:>{len(str(self.total))}}/{self.total}]"

    def times(self, done: int) -> str:
        """``"elapsed m:ss, ETA m:ss"``, the ETA from the rate of this run's own points."""
        el = self.clock() - self.t0
        n = done - self.done0
        eta = el / n * (self.total - done) if n > 0 else float("nan")
        return f"elapsed {hms(el)}, ETA {hms(eta)}"

    def due(self, done: int) -> bool:
        """Whether an update at ``done`` is written: this run's first point, the last, or the first update at or
        past another multiple of the step since the last written one (callers may skip counts)."""
        return done == self.done0 + 1 or done >= self.total or done // self.step > self._written // self.step

    def update(self, done: int, detail: str = "", *, failed: str | None = None) -> None:
        """Report that ``done`` points are done; ``detail`` describes the latest one, ``failed`` its failure.

        A failed point is always written, on a line of its own, with ``failed`` (its reason); other updates only
        when :meth:`due`.
        """
        if failed is None and not self.due(done):
            return
        pct = 100 * done // self.total if self.total else 100
        head = f"{self.label} {self.prefix(done)}" if self.count else self.label
        text = " ".join(s for s in (f"{head} {pct:3d}%", detail,
                                    f"FAILED: {failed}" if failed is not None else "", self.times(done)) if s)
        if self.jupyter and failed is None and done < self.total:
            self.stream.write("\r" + text.ljust(self._open))
            self._open = len(text)
        else:
            self.stream.write(("\r" if self._open else "") + text.ljust(self._open) + "\n")
            self._open = 0
        self.lines += 1
        self._written = done
        self.stream.flush()

    def close(self) -> None:
        """End the updating line of Jupyter mode, if one is open (a run stopped early)."""
        if self._open:
            self.stream.write("\n")
            self.stream.flush()
            self._open = 0

"""The progress reporter of the long loops (:class:`peelapprox.io.ProgressLine`) and the one lazy-import helper.

Every test counts what is written to an in-memory stream with a fake clock: what is written depends on the
number of points only, never on timing, so the assertions are exact counts (no tolerance needed).
"""

from __future__ import annotations

import io
import sys
import types

import pytest

from peelapprox.io import ProgressLine, optional_import


class FakeClock:
    """A clock that advances 1 s per reading: elapsed times and ETAs are whole seconds."""

    def __init__(self) -> None:
        self.t = 0.0

    def __call__(self) -> float:
        self.t += 1.0
        return self.t


def _run(n: int, failed: set[int] = frozenset(), **kw) -> str:  # type: ignore[assignment]
    out = io.StringIO()
    line = ProgressLine("sweep", n, stream=out, clock=FakeClock(), **kw)
    for done in range(1, n + 1):
        line.update(done, f"point {done}", failed=f"error: boom at {done}" if done in failed else None)
    line.close()
    return out.getvalue()


def test_rate_limit_counts_points_not_time():
    """400 points at 5 %: a line at point 1 and at every multiple of 20 (20, 40, ..., 400) = 21 lines, each one
    clean line ending in a newline with no carriage return (a log file reads it as is)."""
    text = _run(400, jupyter=False)
    lines = text.splitlines()
    assert len(lines) == 21 and "\r" not in text
    assert lines[0].startswith("sweep [  1/400]   0% point 1 ")
    assert lines[-1].startswith("sweep [400/400] 100% point 400 ")
    assert [int(s.split("[")[1].split("/")[0]) for s in lines[1:]] == list(range(20, 401, 20))


def test_hundred_points_with_failures_non_tty():
    """A 100-point sweep-like loop to a non-TTY stream with 3 failed points: at most ~25 lines (21 rate-limited +
    one per failure = 24) and every failed point named with its reason."""
    text = _run(100, failed={7, 33, 34}, jupyter=False)
    lines = text.splitlines()
    assert len(lines) <= 25
    assert len(lines) == 24
    for k in (7, 33, 34):
        assert sum(f"point {k} FAILED: error: boom at {k}" in s for s in lines) == 1


def test_eta_from_the_fake_clock_and_resumed_points():
    """done0 = 50 of 100 (a resumed sweep): the first line is point 51, and with a clock that advances 1 s per
    reading (t0 read at 1 s, the line at 2 s) the ETA is 1 s / 1 point * 49 points = 49 s = 0:49."""
    out = io.StringIO()
    line = ProgressLine("sweep", 100, done0=50, stream=out, clock=FakeClock(), jupyter=False)
    line.update(51)
    line.update(52)  # not due: neither first, last nor a multiple of 5
    assert out.getvalue() == "sweep [ 51/100]  51% elapsed 0:01, ETA 0:49\n"


def test_jupyter_mode_one_updating_line(monkeypatch):
    """With ipykernel in sys.modules (detected at construction, IPython never imported) the 21 updates of 400
    points overwrite one line with carriage returns: one newline at the end, a failed point on a line of its
    own, and no newline between two ordinary updates."""
    monkeypatch.setitem(sys.modules, "ipykernel", types.ModuleType("ipykernel"))
    text = _run(400, failed={123})
    assert text.count("\r") == 22 and text.count("\n") == 2
    assert text.endswith("\n")
    visible = [seg.split("\r")[-1] for seg in text.split("\n")]  # what a notebook shows of each line
    assert "FAILED: error: boom at 123" in visible[0]
    assert visible[1].startswith("sweep [400/400] 100%")


def test_jupyter_close_ends_an_open_line(monkeypatch):
    """A run stopped early (5 of 100 points) leaves no open line after close()."""
    monkeypatch.setitem(sys.modules, "ipykernel", types.ModuleType("ipykernel"))
    out = io.StringIO()
    line = ProgressLine("x", 100, stream=out, clock=FakeClock())
    for done in range(1, 6):
        line.update(done)
    assert not out.getvalue().endswith("\n")
    line.close()
    assert out.getvalue().endswith("\n") and out.getvalue().count("\n") == 1


@pytest.mark.parametrize("kw", [dict(total=-1), dict(total=5, done0=6), dict(total=5, every=0.0),
                                dict(total=5, every=1.5)])
def test_bad_arguments(kw):
    """Negative counts, done0 > total and a step fraction outside (0, 1] are ValueErrors naming the argument."""
    total = kw.pop("total")
    with pytest.raises(ValueError, match="total|every"):
        ProgressLine("x", total, **kw)


def test_sweep_progress_line_counts(capsys):
    """The sweep's ``progress=True`` reporter on 400 finished records, 2 of them failed (neither on a 5 % step):
    21 + 2 lines on stderr (it wrote 400 before), the failures with their status."""
    from comparisons.sweep.engine import _progress_line

    report = _progress_line(400, 0)
    for done in range(1, 401):
        status = "error: ValueError: bad point" if done in (10, 201) else "ok"
        report(done, 400, {"I": 1e-5, "V": 0.1 * done, "status": status})
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 23
    assert sum("FAILED: error: ValueError: bad point" in s for s in err) == 2


def test_import_optional_is_optional_import():
    """The peers' lazy import and the data methods' share one helper: a missing module is the peers'
    PeerUnavailableError (an ImportError) naming the pip package and the bench extra, and the data extra's
    message is unchanged."""
    from peelapprox.kernels import PeerUnavailableError, import_optional

    with pytest.raises(PeerUnavailableError, match=r"peer 'x' needs no_such_mod_1: pip install 'peelapprox\[bench\]' "
                                                   r"\(or pip install no-such-pip\)"):
        import_optional("no_such_mod_1", "no-such-pip", "peer 'x'")
    with pytest.raises(ImportError, match=r"^f needs no_such_mod_1: pip install 'peelapprox\[data\]' "
                                          r"\(or pip install no_such_mod_1\)$") as ei:
        optional_import("no_such_mod_1", "f")
    assert type(ei.value) is ImportError


def test_skipped_counts_write_once_per_crossed_step():
    """A caller that reports irregular counts (a simulation reporting per mille of its time every ~0.3 s) gets a
    line at the first update past each 5 % multiple, not only at exact multiples: counts 3, 47, 52, 58, 149,
    151, 990, 1000 of 1000 (step 50) write 52 (crossed 50), 149 (crossed 100), 151 (crossed 150), 990 (crossed
    200..950 at once: one line) and 1000 — 5 lines, exactly; 3 is neither the first point nor past a step."""
    out = io.StringIO()
    line = ProgressLine("simulate", 1000, stream=out, clock=FakeClock(), jupyter=False, count=False)
    for done in (3, 47, 52, 58, 149, 151, 990, 1000):
        line.update(done, f"t = {done}")
    lines = out.getvalue().splitlines()
    assert [s.split()[2] for s in lines] == ["t", "t", "t", "t", "t"]
    assert [int(s.split("t = ")[1].split()[0]) for s in lines] == [52, 149, 151, 990, 1000]
    assert all("[" not in s for s in lines)  # count=False: no [done/total]


def test_simulate_progress_true_writes_few_lines_and_ends_at_100(capsys):
    """``exact.simulate(progress=True)`` reports through ProgressLine: at most 21 lines (one per 5 % crossed plus
    the end) however long the run, the last one at 100 % with the final time."""
    import exact
    from peelapprox import PeelParams

    exact.simulate(PeelParams(V=1.0, I=1e-5), 5.0, progress=True)
    lines = capsys.readouterr().err.splitlines()
    assert 1 <= len(lines) <= 21
    assert lines[-1].startswith("simulate V=1.0 I=1e-05 100% t = 5 / 5 s")

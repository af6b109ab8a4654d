"""Named errors instead of tracebacks: each reproducer of a probe of the package gives the right exception class
and a message naming the argument (and the default, when the user passed none); the command line never prints a
traceback.

Reproducers: ``--force-table`` on a FIFO (blocked forever), on ``/dev/zero`` (a MemoryError after 5.6 GB), on a
CSV with a field over csv's limit (``_csv.Error``) and on a file with a UTF-8 byte-order mark (refused); a law
scaled by 1e300 (``ZeroDivisionError`` in the solver) and coefficients from 1e-300 to 1e300 (``OverflowError``,
``ZeroDivisionError``, scipy's ``RuntimeError``); a 700 KB input echoed whole; ``--loading load --load-mass 1e-6``
blaming a ``--load`` the user never gave; ``--out x.txt`` writing ``x.txt.npz``; a bug printing its traceback;
``--I -1e-5`` read as an unknown option; ``tape_mass=1e-15``, the documented minimum, failing at t = 0.
"""

from __future__ import annotations

import os
import re
import stat
import threading

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import exact
from peelapprox import ModelBreakdown, PeelForce, PeelParams, SolverBudgetExceeded, SolverFailure, estimate
from peelapprox.cli import main
from peelapprox.cli._checks import EXIT_INTERNAL, MESSAGE_LIMIT, TRACEBACK_ENV
from peelapprox.cli._force import MAX_TABLE_BYTES, read_force_table
from peelapprox.validate import shown

SIM = ["simulate", "--V", "1", "--I", "1e-2", "--t-end", "0.01", "--quiet"]
V5, F5 = [0.1, 0.5, 1.0, 2.0, 5.0], [100.0, 200.0, 150.0, 120.0, 300.0]  # an N-shaped table, 5 points


def _cli(argv: list[str], capsys) -> tuple[int, str, str]:
    """``main(argv)`` -> (exit status, stdout, stderr); a SystemExit is caught, a return value is the status."""
    try:
        code = main(argv)
    except SystemExit as exc:
        code = exc.code
    cap = capsys.readouterr()
    return int(code or 0), cap.out, cap.err


def _one_error_line(err: str, command: str = "simulate") -> str:
    """The last stderr line, which must be the CLI's error line, with no traceback anywhere."""
    assert "Traceback" not in err, err
    last = err.strip().splitlines()[-1]
    assert last.startswith(f"peelapprox {command}: "), err
    return last


def _table(path, text: str | bytes) -> str:
    if isinstance(text, str):
        text = text.encode()
    path.write_bytes(text)
    return str(path)


# ------------------------------------------------------------------------------------------------ table files

def test_fifo_is_refused_without_waiting(tmp_path):
    """Hypothesis: a FIFO given as ``--force-table`` is a ValueError naming the path and saying it is a FIFO, within
    a few seconds (it blocked forever: ``open`` waits for a writer).  The read runs in a thread joined with a 10 s
    timeout, so the test cannot hang; the refusal takes microseconds, 10 s is a slow shared machine's margin."""
    fifo = tmp_path / "table.fifo"
    os.mkfifo(fifo)
    out: dict[str, BaseException] = {}

    def read() -> None:
        try:
            read_force_table(str(fifo))
        except BaseException as exc:  # noqa: BLE001 - handed to the test thread
            out["exc"] = exc

    th = threading.Thread(target=read, daemon=True)
    th.start()
    th.join(10.0)
    if th.is_alive():  # unblock the reader (open for writing pairs with it) before failing
        fd = os.open(fifo, os.O_WRONLY | os.O_NONBLOCK)
        os.close(fd)
        pytest.fail("read_force_table blocked on a FIFO")
    exc = out.get("exc")
    assert isinstance(exc, ValueError), exc
    assert str(fifo) in str(exc) and "FIFO" in str(exc) and "regular file" in str(exc)


@pytest.mark.skipif(not os.path.exists("/dev/zero"), reason="no /dev/zero")
def test_device_and_directory_are_refused(tmp_path):
    """Hypothesis: ``/dev/zero`` (a MemoryError after 5.6 GB) and a directory are ValueErrors naming the path and
    its kind, read without reading a byte."""
    with pytest.raises(ValueError, match=r"'/dev/zero': is a character device; a table must be a regular file"):
        read_force_table("/dev/zero")
    with pytest.raises(ValueError, match=r"is a directory; a table must be a regular file"):
        read_force_table(str(tmp_path))


def test_size_limit(tmp_path):
    """Hypothesis: a file one byte over MAX_TABLE_BYTES (16 MiB) is refused by its size, with the limit and the
    reason in the message; the limit is 16 MiB exactly (no tolerance: a count of bytes)."""
    assert MAX_TABLE_BYTES == 16 * 1024 * 1024
    big = tmp_path / "big.csv"
    with open(big, "wb") as fh:
        fh.truncate(MAX_TABLE_BYTES + 1)  # sparse: no 16 MiB written
    with pytest.raises(ValueError, match=r"16777217 bytes, more than the 16 MiB a table may have \(a measured curve"):
        read_force_table(str(big))


def test_csv_error_names_file_and_line(tmp_path, capsys):
    """Hypothesis: a field longer than csv's limit (131072 characters; here 200,000) on line 3 is a ValueError
    naming the file and line 3 (it was a ``_csv.Error`` traceback), and on the CLI one line with exit status 2
    whose length stays below MESSAGE_LIMIT."""
    path = _table(tmp_path / "wide.csv", "v,f\n0.1,100\n0.5,\"" + "1" * 200_000 + "\"\n")
    with pytest.raises(ValueError, match=r"wide\.csv' line 3: not a CSV row \(field larger than field limit"):
        read_force_table(path)
    code, out, err = _cli(SIM + ["--force-table", path], capsys)
    line = _one_error_line(err)
    assert code == 2 and out == "" and "line 3" in line and len(line) < MESSAGE_LIMIT


def test_byte_order_mark_is_accepted(tmp_path):
    """Hypothesis: a UTF-8 byte-order mark before the header (as spreadsheets write it) is skipped: the law equals
    the one of the same file without it (equality of the plain data: exact)."""
    body = "v,f\n" + "".join(f"{v},{f}\n" for v, f in zip(V5, F5))
    with_bom = read_force_table(_table(tmp_path / "bom.csv", b"\xef\xbb\xbf" + body.encode()))
    assert with_bom == read_force_table(_table(tmp_path / "plain.csv", body)) == PeelForce.tabulated(V5, F5)


def test_not_utf8_names_line(tmp_path):
    """Hypothesis: a byte that is not UTF-8 (Latin-1 é) is a ValueError naming the file and its line."""
    path = _table(tmp_path / "latin1.csv", b"v,f\n0.1,100\n0.5,2\xe900\n")
    with pytest.raises(ValueError, match=r"latin1\.csv' line 3: not UTF-8 text"):
        read_force_table(path)


# ------------------------------------------------------------------------------------------------ huge and tiny laws

def test_law_scaled_by_1e300_names_the_default_start():
    """Hypothesis: ``PeelForce.cubic(c=-1e300)`` and a table scaled by 1e300 ran into ZeroDivisionError in the
    solver; now ``exact.simulate`` raises a ValueError saying that F0 was not given, its default 1.01 f(V, V) and
    the valid range of F (and ``estimate`` names F and its range); ``initial_state`` with an F0 in range says
    there is no root (the level is below f(0+))."""
    for law in (PeelForce.cubic(c=-1e300), PeelForce.tabulated(V5, [f * 1e300 for f in F5])):
        p = PeelParams(V=1.0, I=1e-2, force=law)
        with pytest.raises(ValueError, match=r"F0 was not given, so its default 1\.01 f\(V, V\) = .* N was used .*"
                                             r"outside STATE_RANGES\['F'\] = \[0\.001, 1e7\] N"):
            exact.simulate(p, 0.01)
    p = PeelParams(V=1.0, I=1e-2, force=PeelForce.tabulated(V5, [f * 1e300 for f in F5]))
    with pytest.raises(ValueError, match=r"F must be finite and in \[0\.001, 1e7\]"):
        estimate(p)
    with pytest.raises(ValueError, match=r"F0=100\.0 gives .* below f\(0\+, V\)=.* at alpha0=0\.0 \(the default\)"):
        exact.initial_state(p, F0=100.0)


def test_tiny_law_folds_and_tiny_table():
    """Hypothesis: the folds of a table scaled by 1e-104 in f and 1000 in v (scipy's brentq gave RuntimeError
    "failed to converge": its interpolation underflows) are the data's extrema, v_max = 500 and v_min = 2000 m/s to
    1e-12 relative (PCHIP puts the folds at the data, the root to 4 ulp in ln v); a table at v ~ 1e-281 m/s
    (ZeroDivisionError in the compiled f'') is a ValueError naming params.force and the range of v."""
    fo = PeelForce.tabulated([v * 1000 for v in V5], [f * 1e-104 for f in F5]).folds(1.0)
    assert fo.has_folds and abs(fo.v_max / 500.0 - 1) < 1e-12 and abs(fo.v_min / 2000.0 - 1) < 1e-12
    tiny = PeelParams(V=1.0, I=1e-3, force=PeelForce.tabulated([v * 1e-281 for v in V5], F5))
    with pytest.raises(ValueError, match=r"params\.force: the table starts at v=1e-282 m/s, below the model's "
                                         r"velocities STATE_RANGES\['v'\]"):
        estimate(tiny)


def test_family_pack_overflow_is_a_value_error():
    """Hypothesis: paper-family coefficients whose packed terms overflow (V**q6 with q6 = 9447) or divide by an
    underflowed square (a3/v3**2, v3 = 1e-208) gave OverflowError / ZeroDivisionError from plain Python
    arithmetic; now a ValueError naming the family and V."""
    for coef in ({"a6": 3.8e243, "q6": 9447.0}, {"v3": 7.4e-208}):
        law = PeelForce.paper_family(**coef)
        with pytest.raises(ValueError, match=r"the 'paper' family: its coefficients give no finite law at V=14\.9"):
            law.f(1.0, 14.9)
        with pytest.raises(ValueError, match=r"params\.force=PeelForce\.paper_family\(.*no finite law at V=14\.9"):
            estimate(PeelParams(V=14.9, I=1e-3, force=law))


_MAG = st.tuples(st.sampled_from([-1.0, 1.0]), st.floats(-300.0, 300.0)).map(lambda t: t[0] * 10.0 ** t[1])
_NAMED = (ValueError, TypeError, ModelBreakdown, SolverFailure, SolverBudgetExceeded)


@settings(max_examples=60, deadline=None, derandomize=True)
@given(family=st.sampled_from(["cubic", "power_branches", "paper"]), data=st.data(), logV=st.floats(-6.0, 2.0))
def test_any_coefficient_magnitude_gives_a_named_outcome(family, data, logV):
    """Property: for any family and coefficients of any sign and magnitude in 1e-300..1e300 (each coefficient
    drawn or left at its default), constructing the law, its folds, ``estimate`` and a 1 ms ``exact.simulate``
    either succeed or raise a named exception of the package (ValueError/TypeError for bad input; the model's
    stops); never ZeroDivisionError, OverflowError or scipy's RuntimeError.  No tolerance: classes of outcome."""
    from peelapprox.law._families import FAMILIES

    names = FAMILIES[family].names
    coefs = {n: data.draw(_MAG, label=n) for n in names if data.draw(st.booleans(), label=f"set {n}")}
    V = 10.0**logV
    try:
        law = PeelForce.family(family, **coefs)
    except (ValueError, TypeError):
        return
    p = PeelParams(V=V, I=1e-3, force=law)
    for step in (lambda: law.folds(V), lambda: law.f(np.geomspace(1e-9, 1e3, 20), V), lambda: estimate(p),
                 lambda: exact.simulate(p, 1e-3, max_wall=5.0, save="jumps")):
        try:
            step()
        except _NAMED:
            pass


@pytest.mark.parametrize("V", [0.01, 1.0])
def test_lightest_tape_starts(V):
    """Hypothesis: at the documented minimum tape mass, 1e-15 kg, the smooth model's default LSODA failed its first
    step (SolverFailure "after t=0" at V = 0.01 and 1 m/s, I = 1e-4); retried on the fast time scale it reaches
    t_end = 1 ms (exact: the last stored time is t_end)."""
    tr = exact.simulate(PeelParams(V=V, I=1e-4, tape_mass=1e-15), 1e-3)
    assert tr.t[-1] == 1e-3 and tr.final_state.t == 1e-3


# ------------------------------------------------------------------------------------------------ messages

def test_shown_cuts_long_values():
    """Hypothesis: ``shown`` is ``repr`` up to its limit, then the first ``limit`` characters and the length of the
    value (characters of a str; of the repr otherwise)."""
    assert shown("abc") == "'abc'"
    assert shown("x" * 700_000) == "'" + "x" * 199 + "... (700000 characters)"
    assert shown(list(range(100)), 10) == "[0, 1, 2, ... (390 characters)"


_LONG = "x" * 700_000


@pytest.mark.parametrize("option,extra", [
    ("--force-family", ["--force-family", _LONG]),
    ("--force-family", ["--force-family", "cubic", "--coef", _LONG + "=1"]),
    ("--const", ["--force", "v", "--const", "a=" + _LONG]),
    ("--geometry", ["--geometry", _LONG]),
    ("--force-table", ["--force-table", _LONG]),
    ("--out", ["--out", "/nonexistent/" + _LONG + ".npz"]),
    ("--out", ["--out", _LONG]),
], ids=["family", "coef-name", "const-value", "geometry", "table-path", "out-dir", "out-name"])
def test_long_inputs_are_cut_in_messages(option, extra, capsys):
    """Hypothesis: a 700 KB option value (echoed whole before: 700 KB of stderr) gives an error line naming the
    option, shorter than MESSAGE_LIMIT (2000 characters) and saying how much was left out ("... (N characters)");
    exit status 2 (a usage error), no traceback, nothing on stdout."""
    code, out, err = _cli(SIM + extra, capsys)
    line = _one_error_line(err)
    assert code == 2 and out == ""
    assert len(line) < MESSAGE_LIMIT and len(err) < MESSAGE_LIMIT + 2000  # the line and argparse's usage lines
    assert option in line and "characters)" in line


def test_default_load_is_named(capsys):
    """Hypothesis: ``--loading load --load-mass 1e-6`` (no --load) says that --load was not given, the default
    --load-mass times g = 9.80665e-06 N that was used, the range of the load and the range of --load-mass that
    gives a valid default (1e-3/9.80665 = 1.01972e-4 kg up); PeelParams says the same in its own names."""
    code, _out, err = _cli(SIM + ["--loading", "load", "--load-mass", "1e-6"], capsys)
    line = _one_error_line(err)
    assert code == 2
    assert ("--load was not given, so its default --load-mass times g = 1e-06 kg * 9.80665 m/s^2 = 9.80665e-06 N "
            "was used; the load must be in [0.001, 1e7] N: give --load, or a --load-mass in [0.000101972, 1e6] kg"
            in line)
    with pytest.raises(ValueError, match=r"^load was not given, so its default load_mass \* g = 1e-06 kg"):
        PeelParams(V=1.0, I=1e-2, loading="load", load_mass=1e-6)


def test_out_with_another_suffix_is_refused(tmp_path, capsys):
    """Hypothesis: ``--out x.txt`` (numpy wrote x.txt.npz silently) is refused before the run, exit status 2,
    naming the path and the suffix; nothing is written."""
    code, out, err = _cli(SIM + ["--out", str(tmp_path / "x.txt")], capsys)
    line = _one_error_line(err)
    assert code == 2 and out == ""
    assert "x.txt'" in line and "must end in .npz" in line and "'.txt'" in line
    assert os.listdir(tmp_path) == []


def test_negative_option_values(capsys):
    """Hypothesis: ``--I -1e-5`` reaches the range check (argparse read it as an unknown option: "expected one
    argument"): the message names --I, its range and the value; other values that start with '-' get the hint
    ``--opt=VALUE``."""
    code, _out, err = _cli(["simulate", "--V", "1", "--I", "-1e-5", "--t-end", "1"], capsys)
    assert code == 2 and "--I must be finite and in [1e-12, 1e6], got -1e-05" in _one_error_line(err)
    code, _out, err = _cli(SIM + ["--alpha0", "-1.5E-3", "--F0", "-inf"], capsys)
    assert code == 2 and "F0" in _one_error_line(err) and "got -inf" in err
    code, _out, err = _cli(SIM + ["--force", "-v"], capsys)
    assert code == 2 and "(a value that starts with '-' is written --force=VALUE)" in _one_error_line(err)


# ------------------------------------------------------------------------------------------------ internal errors

def _boom(args):
    raise KeyError("a bug")


def test_internal_error_is_one_line(monkeypatch, capsys):
    """Hypothesis: an exception that is neither a user error nor a documented stop (here a KeyError raised by the
    subcommand) is one line, ``peelapprox folds: internal error: KeyError: 'a bug' (a bug: ...)``, exit status
    EXIT_INTERNAL = 4, no traceback; with PEELAPPROX_TRACEBACK=1 it propagates (its traceback)."""
    from peelapprox import cli

    monkeypatch.setattr(cli, "_folds", _boom)  # build_parser binds the subcommand's function when main() runs
    monkeypatch.delenv(TRACEBACK_ENV, raising=False)
    code, out, err = _cli(["folds", "--V", "1"], capsys)
    assert code == EXIT_INTERNAL == 4 and out == ""
    assert _one_error_line(err, "folds") == ("peelapprox folds: internal error: KeyError: 'a bug' (a bug: please "
                                             "report it; set PEELAPPROX_TRACEBACK=1 to see the traceback)")
    monkeypatch.setenv(TRACEBACK_ENV, "1")
    with pytest.raises(KeyError, match="a bug"):
        main(["folds", "--V", "1"])


def test_warning_is_one_line(monkeypatch, capsys):
    """Hypothesis: a warning issued while a command runs (scipy's LSODA warns in the fast transits of a light tape)
    is one stderr line ``peelapprox folds: warning: UserWarning: <message>``, without Python's second line (the
    source line of the library, which reads like part of a traceback); the command's status is unchanged (0)."""
    import warnings

    from peelapprox import cli

    def warn(args):
        warnings.warn("lsoda: Repeated error test failures\n(internal error).", UserWarning, stacklevel=1)
        return 0

    monkeypatch.setattr(cli, "_folds", warn)
    code, _out, err = _cli(["folds", "--V", "1"], capsys)
    assert code == 0
    assert err == "peelapprox folds: warning: UserWarning: lsoda: Repeated error test failures (internal error).\n"


def test_read_error_of_a_table_is_usage_error(tmp_path, capsys):
    """Hypothesis: an unreadable table (mode 000; skipped as root, who reads anything) is exit status 2 naming the
    path, not an OSError traceback."""
    if os.geteuid() == 0:
        pytest.skip("root reads files of mode 000")
    path = _table(tmp_path / "locked.csv", "v,f\n")
    os.chmod(path, 0)
    try:
        code, _out, err = _cli(SIM + ["--force-table", path], capsys)
    finally:
        os.chmod(path, stat.S_IRUSR | stat.S_IWUSR)
    assert code == 2 and "cannot read it" in _one_error_line(err)


def test_a_law_that_overflows_while_its_root_is_sought_is_named():
    """Hypothesis: a cubic with b = 1e-300 and no fold has its AB root sought up to v ~ e^700, where d v^3 is
    0 * inf = NaN; the start is then a ValueError naming params.force, the v where it failed and why, with no
    NaN in its text (was
    scipy's "The function value at x=237.03 is NaN" from brentq, found by the slow fuzz tier)."""
    import exact
    from peelapprox import PeelForce, PeelParams

    with pytest.raises(ValueError, match=r"params.force: .* is not finite at v = .* m/s") as e:
        exact.simulate(PeelParams(V=1.2, I=1e-5, force=PeelForce.cubic(a=0.001, b=1e-300, c=0, d=0)), 1.0)
    assert "x=" not in str(e.value) and "nan" not in str(e.value).lower()


# ------------------------------------------------------------------------------------ stored laws, traces
@pytest.mark.parametrize("d, match", [
    ({"kind": "family", "name": ["cubic"]}, r"name must be a string or None, got list \['cubic'\]"),
    ({"kind": "family", "name": "cubic", "coefficients": [1, 2]}, r"coefficients must be \(name, value\) pairs"),
    ({"kind": "family", "name": "cubic", "coefficients": "abc"}, r"coefficients must be \(name, value\) pairs"),
    ({"kind": ["family"]}, r"kind must be a string, got list"),
    ({"kind": "expression", "source": 3}, r"source must be a string or None, got int"),
])
def test_from_dict_names_a_field_of_the_wrong_type(d, match):
    """A stored law with a list as its family name (``unhashable type: 'list'``) or a flat list as coefficients
    ("dictionary update sequence element #0") is a TypeError naming the field (categorical)."""
    with pytest.raises(TypeError, match=match):
        PeelForce.from_dict(d)


def test_from_dict_takes_coefficients_as_json_lists_or_a_mapping():
    """What ``json.dumps(dataclasses.asdict(law))`` gives back (pairs as lists) and a mapping both rebuild the law
    (equality of the canonical content: exact)."""
    law = PeelForce.cubic(a=120.0)
    assert PeelForce.from_dict({"kind": "family", "name": "cubic", "coefficients": [["a", 120.0]]}) == law
    assert PeelForce.from_dict({"kind": "family", "name": "cubic", "coefficients": {"a": 120.0}}) == law


@pytest.mark.parametrize("t, match", [
    (1e-300 * np.arange(2000), r"t must step by at least 1e-12 s .*t\[1\] - t\[0\] = 1e-300 s"),
    (1e4 * np.arange(2000), r"t must span at most 1e\+06 s"),
])
def test_force_series_time_steps_out_of_range_are_named(t, match):
    """Times 1e-300 s apart used to reach numpy's LinAlgError (and six LAPACK lines) in ``observables()``; now
    the trace is refused when built, naming t and the range (categorical)."""
    from peelapprox import ForceSeries

    F = 200.0 + 50.0 * ((np.arange(2000) * 0.0073) % 1.0)
    with pytest.raises(ValueError, match=match):
        ForceSeries(t, F, V=1.0)


def test_force_series_refuses_more_samples_than_its_limit():
    """A trace of more than MAX_SAMPLES samples (1e8 took 11 GB in infer) is refused before any copy, naming the
    limit (categorical); checked on a read-only broadcast view, which costs no memory."""
    from peelapprox import ForceSeries
    from peelapprox._measured._series import MAX_SAMPLES

    big = np.broadcast_to(np.float64(200.0), (MAX_SAMPLES + 1,))
    with pytest.raises(ValueError, match=rf"more than the {MAX_SAMPLES} a force series may have"):
        ForceSeries(big, big, V=1.0)


def test_flat_trace_has_no_spectral_peak():
    """A constant trace (its peak was 0.7996 Hz, rounding's largest bin) and a pure ramp have no peak (None);
    a sine of 1e-6 N on 200 N (5e-9 of it, above FLAT_RTOL 1e-9) still has its peak at 37 Hz within one bin
    (Welch's resolution, the tolerance of tests/test_series.py)."""
    from peelapprox import ForceSeries

    t = np.arange(2000) * 1e-3
    assert ForceSeries(t, np.full(2000, 200.0), V=1.0).spectrum().peak is None
    assert ForceSeries(t, 200.0 + 3.0 * t, V=1.0).spectrum().peak is None
    sp = ForceSeries(t, 200.0 + 1e-6 * np.sin(2 * np.pi * 37.0 * t), V=1.0).spectrum()
    assert sp.peak is not None and abs(sp.peak - 37.0) <= float(sp.frequency[1] - sp.frequency[0])


def test_out_to_a_device_is_refused(capsys):
    """``simulate --out /dev/full`` used to write ``/dev/full.npz`` beside the device, silently: a device given
    as an output is now a usage error naming it, before any run (categorical: exit status 2 and the message)."""
    code, _out, err = _cli([*SIM, "--out", "/dev/full"], capsys)
    assert code == 2
    assert "--out '/dev/full' is a character device; an output must be a regular file" in _one_error_line(err)
    assert not os.path.exists("/dev/full.npz")


# ------------------------------------------------------------------------------------ big numbers in laws
@pytest.mark.parametrize("text, constants, at_1", [
    ("1e20*v", {}, 1e20),
    ("a*v", {"a": 1e20}, 1e20),
    ("2**70*v", {}, 2.0**70),
    ("1e20*v + 1/v", {}, 1e20 + 1.0),
    ("v/2**70 + 100", {}, 100.0 + 2.0**-70),
])
def test_numbers_beyond_two_to_the_53_are_floats(text, constants, at_1):
    """Constants >= 2**64 (``1e20``, ``2**70``) used to be Python integers: numpy's ``ufunc 'isfinite' not
    supported`` at construction, numba's ``TypingError: Int value is too large`` in simulate.  Now every number
    of magnitude >= 2**53 is a float: the law is built and f(1) is the float sum, to 1e-15 relative (one
    rounding of each term)."""
    import sympy as sp

    from peelapprox.law._expression import from_text

    law = PeelForce.expression(text, **constants)
    assert law.f(np.array([1.0]), 1.0)[0] == pytest.approx(at_1, rel=1e-15)
    big = [n for n in from_text(law.source).atoms(sp.Rational) if abs(n.p) >= 2**53 or n.q >= 2**53]
    assert big == []
    from peelapprox.law._kernels import expression_source

    src = expression_source(law.source)  # what numba compiles: no integer literal of 17 digits or more
    assert re.search(r"(?<![\w.])\d{17,}(?![\w.])", src) is None, src


def test_numbers_beyond_the_float_range_are_named():
    """A product of literals beyond the float range is refused by name (categorical)."""
    with pytest.raises(ValueError, match=r"exceeds"):
        PeelForce.expression("1e300*1e300*v")


# ------------------------------------------------------------------------------------ trajectory files
@pytest.fixture(scope="module")
def npz_arrays(tmp_path_factory):
    """The arrays of a short run's file (0.02 s of the period-3 orbit's neighbourhood: one jump or more)."""
    import json

    path = tmp_path_factory.mktemp("npz") / "run.npz"
    exact.simulate(PeelParams(V=1.0, I=1e-5), 0.02).to_npz(path)
    with np.load(path, allow_pickle=False) as z:
        arrays = {k: z[k] for k in z.files}
    return arrays, json.loads(str(arrays["meta"]))


def _npz_with(tmp_path, npz_arrays, change) -> str:
    """The run's file with ``change(arrays, meta)`` applied, written to a new file."""
    import copy
    import json

    arrays, meta = npz_arrays
    original = arrays["meta"]
    arrays, meta = dict(arrays), copy.deepcopy(meta)
    change(arrays, meta)
    if arrays.get("meta") is original:  # the metadata as changed, unless the change replaced or dropped it
        arrays["meta"] = np.array(json.dumps(meta))
    path = tmp_path / "bad.npz"
    np.savez(path, **arrays)
    return str(path)


def _arr(key, value):
    def change(arrays, meta):
        arrays[key] = value
    return change


def _set(key, value):
    def change(arrays, meta):
        *path, last = key.split(".")
        for p in path:
            meta = meta[p]
        meta[last] = value
    return change


def _drop(key):
    def change(arrays, meta):
        del (arrays if key in arrays else meta)[key]
    return change


@pytest.mark.parametrize("change, field", [
    (_arr("t", np.array([0.0, 0.01])), r"field alpha: \d+ values, but t has 2"),
    (_arr("F", np.zeros(150)), r"field F: 150 values, but t has \d+"),
    (_arr("t", np.array(["a", "b"])), r"field t: must be a 1-D array of numbers, got dtype <U1"),
    (_arr("branch", np.array(["__import__('os')"])), r"field branch: must be \d+ integer codes"),
    (_arr("jumps", np.zeros(7)), r"field jumps: must be rows of 8 numbers"),
    (_arr("meta", np.array("{not json")), r"field meta: not JSON"),
    (_arr("meta", np.array("[" * 100_000 + "]" * 100_000)), r"field meta: (JSON nested too deeply|must be a JSON)"),
    (_arr("meta", np.array(3.0)), r"field meta: must be one JSON text"),
    (_drop("atol"), r"field atol: missing"),
    (_drop("stats"), r"field meta.stats: missing"),
    (_arr("extra", np.zeros(2)), r"field extra: unknown"),
    (_set("method", "<script>alert(1)</script>"), r"field meta.method: must be a name"),
    (_set("solver", {"a": 1}), r"field meta.solver: must be a name"),
    (_set("status", "0; rm -rf"), r"field meta.status: must be an integer"),
    (_set("status", True), r"field meta.status: must be an integer"),
    (_set("t_end", -1), r"field meta.t_end: must be finite and in \[0, inf\], got -1"),
    (_set("t_transient", 1e9), r"field meta.t_transient: must be finite and in \[0, 0.02\]"),
    (_set("rtol", 2.0), r"field meta.rtol: must be finite and in \(0, 1\)"),
    (_set("stats.n_steps", -3), r"field meta.stats.n_steps: must be finite and in \[0, inf\]"),
    (_set("stats.bogus", 1), r"field meta.stats.bogus: unknown"),
    (_set("initial_state.branch", "XY"), r"field meta.initial_state.branch: must be one of AB, CD"),
    (_set("final_state", [1, 2]), r"field meta.final_state: must be a JSON object, got list"),
    (_set("params.V", "fast"), r"field meta.params: .*V"),
    (_set("params.hack", 1), r"field meta.params.hack: unknown"),
    (_set("message", "x" * 5000), r"field meta.message: must be a string of at most 2000"),
    (_set("status", 10**400), r"field meta.status: must be finite and in \[-99, 99\], got 1000"),
    (_set("stats.n_steps", 10**400), r"field meta.stats.n_steps: must be finite"),
    (_set("rtol", -10**400), r"field meta.rtol: must be finite"),
    (_set("t_end", 10**400), r"field meta.t_end: must be finite"),
    (_set("final_state.alpha", 10**400), r"field meta.final_state.alpha: must be finite"),
])
def test_trajectory_file_fields_are_checked(tmp_path, npz_arrays, change, field):
    """Each malformed field of a trajectory file (the probe's KeyError, unexpected keyword, RecursionError,
    JSONDecodeError, reshape errors; t of 2 samples beside F of 150, a payload string as branch, method or
    status, t_end = -1 accepted; OverflowError on a JSON integer of 400 digits) is a ValueError naming the file
    and the field (categorical)."""
    path = _npz_with(tmp_path, npz_arrays, change)
    with pytest.raises(ValueError, match=rf"Trajectory\.from_npz\('.*bad\.npz'\): {field}"):
        exact.Trajectory.from_npz(path)


@pytest.mark.parametrize("content", [b"", b"PK\x03\x04truncated", b"\x93NUMPY garbage", b"just text"])
def test_a_file_that_is_no_npz_is_named(tmp_path, content):
    """Empty, truncated, a broken .npy or text: a ValueError naming the file (EOFError, BadZipFile before)."""
    path = tmp_path / "bad.npz"
    path.write_bytes(content)
    with pytest.raises(ValueError, match=r"Trajectory\.from_npz\('.*bad\.npz'\): "):
        exact.Trajectory.from_npz(path)


def test_a_trajectory_file_round_trips(tmp_path, npz_arrays):
    """The unchanged file reads back: every array equal (exact, as written) and the metadata's fields."""
    path = _npz_with(tmp_path, npz_arrays, lambda arrays, meta: None)
    back = exact.Trajectory.from_npz(path)
    arrays, meta = npz_arrays
    for name in ("t", "alpha", "omega", "F", "v", "branch", "atol"):
        assert np.array_equal(getattr(back, name), arrays[name])
    assert back.t_end == meta["t_end"] and back.method == meta["method"] and back.status == 0
    assert back.stats.n_steps == meta["stats"]["n_steps"] and back.final_state.branch == meta["final_state"]["branch"]


def test_a_missing_trajectory_file_is_what_open_raises(tmp_path):
    """A path that does not exist is FileNotFoundError naming it, as open() gives (the CLI's exit status 1 for a
    failed read), not a content error (categorical)."""
    with pytest.raises(FileNotFoundError, match="nope.npz"):
        exact.Trajectory.from_npz(tmp_path / "nope.npz")


def _npy_member(shape, payload=b""):
    """The bytes of a ``.npy`` float64 array member declaring ``shape`` and holding ``payload`` as its data."""
    import io

    from numpy.lib import format as npy

    buf = io.BytesIO()
    npy.write_array_header_1_0(buf, {"descr": "<f8", "fortran_order": False, "shape": shape})
    return buf.getvalue() + payload


def _peak_bytes(fn, *args):
    """The peak of memory allocated during ``fn(*args)`` (tracemalloc: Python objects and numpy's arrays, which
    numpy reports to it, committed or not): a count of bytes, the same on any machine."""
    import tracemalloc

    message = ""
    tracemalloc.start()
    try:
        try:
            fn(*args)
        except ValueError as exc:
            message = str(exc)
        return tracemalloc.get_traced_memory()[1], message
    finally:
        tracemalloc.stop()


def test_a_trajectory_file_declaring_a_huge_array_is_refused_before_loading(tmp_path, npz_arrays):
    """A member whose ``.npy`` header declares 250,000,000 floats (2 GB, what numpy allocates before reading the
    data) is refused from its header, naming the file, the field and MAX_ARRAY_BYTES, with a peak of at most 5 MB
    allocated (tracemalloc, machine-independent; the 2 GB array was allocated before): the bound is the header
    check, not the machine."""
    import zipfile

    arrays, _ = npz_arrays
    path = tmp_path / "bad.npz"
    np.savez(path, **{k: v for k, v in arrays.items() if k != "t"})
    with zipfile.ZipFile(path, "a") as zf:
        zf.writestr("t.npy", _npy_member((250_000_000,)))
    peak, message = _peak_bytes(exact.Trajectory.from_npz, str(path))
    assert re.match(r"Trajectory\.from_npz\('.*bad\.npz'\): field t: the arrays take \d+ bytes up to this one, "
                    r"more than MAX_ARRAY_BYTES = 1073741824", message), message
    assert peak < 5e6, peak


def test_a_compressed_trajectory_bomb_is_refused_before_loading(tmp_path, npz_arrays, monkeypatch):
    """A zip member that inflates far beyond its file (the probe's 1.9 MB of 250,000,000 zeros cost 2.29 GB) is
    refused from the zip's sizes before it is inflated: with the limit lowered to 1 MB (so that the bomb, 16 MB of
    zeros in ~16 kB, is quick to write), the peak allocated is at most 1 MB (tracemalloc: the 16 MB array, or the
    file's bytes, were never allocated)."""
    import zipfile

    from exact import _trajectory_file

    arrays, _ = npz_arrays
    path = tmp_path / "bad.npz"
    np.savez_compressed(path, **{k: v for k, v in arrays.items() if k != "t"}, t=np.zeros(2_000_000))
    assert path.stat().st_size < 200_000
    with zipfile.ZipFile(path) as zf:
        assert zf.getinfo("t.npy").file_size > 16e6
    monkeypatch.setattr(_trajectory_file, "MAX_ARRAY_BYTES", 1 << 20)
    peak, message = _peak_bytes(exact.Trajectory.from_npz, str(path))
    assert "field t: the arrays take" in message and "MAX_ARRAY_BYTES = 1048576" in message, message
    assert peak < 1 << 20, peak


# ------------------------------------------------------------------------------------ laws without folds
_NO_FOLDS = "300+1e-9*v"  # f rises by 1e-6 N over its v range [1e-6, 1000] m/s: no folds, AB everywhere


def test_a_law_without_folds_whose_root_is_beyond_its_domain_is_named():
    """``exact.simulate`` of a law without folds whose default F0 = 1.01 f(V, V) = 303 N has its AB root at
    v ~ 3e9 m/s, beyond the law's v range [1e-6, 1000]: brentq's "f(a) and f(b) must have different signs"
    escaped; now a ValueError naming F0, params.force, the domain, the f range there, and that the law has no
    folds (categorical)."""
    params = PeelParams(V=1.0, I=1e-5, force=PeelForce.expression(_NO_FOLDS))
    with pytest.raises(ValueError) as info:
        exact.simulate(params, 0.01)
    msg = str(info.value)
    assert "different signs" not in msg
    for part in ("F0 (not given: the default 1.01 f(V, V) = 303.0", "params.force=PeelForce.expression(",
                 "no AB root within the peel-force law's domain [1e-06, 1000.0] m/s", "a law without folds",
                 "f runs from 300 N at v = 1e-06 m/s to 300 N at v = 1000 m/s", "cannot be bracketed"):
        assert part in msg, (part, msg)


def test_a_law_without_folds_still_finds_roots_inside_its_domain():
    """The bracket check refuses only roots outside the domain: at seeded F0 whose root v = (F0 - 300)/1e-9 lies in
    [1, 900] m/s, the initial state's v is that closed form to 2e-4 m/s (the rounding of f near 300 N, ulp 5.7e-14
    N, over the slope 1e-9 N s/m: 5.7e-5 m/s, a few times)."""
    params = PeelParams(V=1.0, I=1e-5, force=PeelForce.expression(_NO_FOLDS))
    rng = np.random.default_rng(3)
    for v_true in rng.uniform(1.0, 900.0, 5):
        F0 = 300.0 + 1e-9 * float(v_true)
        s = exact.initial_state(params, F0=F0)
        assert s.branch == "AB"
        assert s.v == pytest.approx((F0 - 300.0) / 1e-9, abs=2e-4)


# ------------------------------------------------------------------------------------ traces beyond newtons
@pytest.mark.parametrize("scale", [1e200, -1e13, 2e12])
def test_a_trace_beyond_max_force_is_refused_naming_its_sample(scale):
    """A trace with |F| beyond MAX_FORCE = 1e12 N (the probe's F ~ 1e202 N made ``spectrum()`` raise
    OverflowError) is a ValueError naming F, its first offending sample and the limit (categorical)."""
    from peelapprox import ForceSeries

    t = np.linspace(0.0, 1.0, 2000)
    F = 100.0 + 10.0 * np.sin(40.0 * t)
    F[7:] *= scale / 100.0
    with pytest.raises(ValueError, match=r"F\[7\] = .* N: \|F\| must be at most MAX_FORCE = 1e\+12 N"):
        ForceSeries(t, F, V=1.0)


def test_a_trace_at_max_force_has_its_spectral_peak():
    """A trace reaching the limit, F = (100 + 10 sin(2 pi 6.4 t)) 1e12/110 N (|F| up to 1e12 N), has a finite
    spectrum whose peak is its sine's 6.4 Hz to one frequency bin (the resolution of the spectrum)."""
    from peelapprox import ForceSeries

    t = np.linspace(0.0, 10.0, 20_000)
    F = (100.0 + 10.0 * np.sin(2 * np.pi * 6.4 * t)) * (1e12 / 110.0)
    spec = ForceSeries(t, F, V=1.0).spectrum()
    assert np.all(np.isfinite(spec.power))
    assert spec.peak == pytest.approx(6.4, abs=float(spec.frequency[1] - spec.frequency[0]))


@pytest.mark.parametrize("field, kind", [("coefficients", "family"), ("tables", "tabulated"),
                                         ("coefficients", "expression")])
def test_from_dict_refuses_deep_nesting_by_name(field, kind):
    """A field nested 100,000 deep (a probe's RecursionError) is a TypeError naming the field and MAX_NESTING,
    found by an iterative walk; the laws' own dicts (nesting 3 at most) still read back equal (categorical)."""
    import dataclasses

    deep: list = [1.0]
    for _ in range(100_000):
        deep = [deep]
    d = {"kind": kind, "name": "cubic" if kind == "family" else None, field: deep}
    with pytest.raises(TypeError, match=rf"d\['{field}'\] is nested more than MAX_NESTING = 8 deep"):
        PeelForce.from_dict(d)
    v = [0.1, 0.2, 0.3, 0.4, 0.5]
    for law in (PeelForce.family("cubic"), PeelForce.tabulated(tables=[(1.0, v, [200, 250, 220, 210, 260]),
                                                                       (2.0, v, [210, 260, 230, 220, 270])])):
        assert PeelForce.from_dict(dataclasses.asdict(law)) == law

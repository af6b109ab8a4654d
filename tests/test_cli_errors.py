"""User errors on the command line: one line on stderr, a nonzero exit status, never a traceback.

Each row of :data:`CASES` is a reproducer that gave a traceback (or silently accepted nonsense) before: an output
path into a missing directory, through a file or onto a directory (found only *after* the run, so the work was
lost), an unknown image format, a solver failure, ``sweep --plot nosuchkey`` after the whole sweep, and
out-of-range ``dynamics`` arguments.  All are now rejected before any computation (the summary on stdout, printed
after the run, stays empty) with exit status 2, or 3 when the model's solver stops.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time

import pytest

from peelapprox.cli import _checks as _cli_checks
from peelapprox.cli import main

SIM = ["simulate", "--V", "1", "--I", "1e-5", "--t-end", "0.01", "--quiet"]
SEG = ["segment", "--V", "1", "--I", "1e-2", "--branch", "AB", "--F-in", "186.95", "--alpha-in", "0.0599",
       "--alphadot-in", "9.7"]
DYN = ["dynamics", "--V", "1", "--I", "1e-2", "--t-transient", "0.1", "--window", "0.1"]
SWEEP = ["sweep", "--I", "1e-3", "--V", "1", "--measure", "regime", "--workers", "0", "--quiet"]

#: (id, argv, exit status, fragments the one-line message must contain).  Run in a directory holding a file
#: ``afile`` and a directory ``adir``; ``nodir`` does not exist.
CASES = [
    # output paths of simulate (checked before the run)
    ("simulate-out-missing-dir", SIM + ["--out", "nodir/r.npz"], 2, ["--out", "'nodir' does not exist"]),
    ("simulate-out-through-file", SIM + ["--out", "afile/r.npz"], 2, ["--out", "'afile' is not a directory"]),
    ("simulate-out-onto-dir", SIM + ["--out", "adir"], 2, ["--out", "'adir' is a directory"]),
    ("simulate-jumps-csv-missing-dir", SIM + ["--jumps-csv", "nodir/j.csv"], 2, ["--jumps-csv", "'nodir'"]),
    ("simulate-jumps-csv-onto-dir", SIM + ["--jumps-csv", "adir"], 2, ["--jumps-csv", "'adir' is a directory"]),
    ("simulate-plot-missing-dir", SIM + ["--plot", "nodir/p.png"], 2, ["--plot", "'nodir' does not exist"]),
    ("simulate-plot-onto-dir", SIM + ["--plot", "adir"], 2, ["--plot", "'adir' is a directory"]),
    ("simulate-plot-unknown-format", SIM + ["--plot", "p.xyz"], 2, ["--plot", "unknown image format 'xyz'", "png"]),
    ("simulate-plot-jumps-only", SIM + ["--jumps-only", "--plot", "p.png"], 2, ["--plot", "--jumps-only"]),
    # the solver stops: the model's exception, exit 3
    ("simulate-lsoda-eps-1e-30", SIM + ["--method", "regularized", "--solver", "LSODA", "--eps", "1e-30"], 2,
     ["eps", "1e-15"]),
    # table outputs of estimate, segment, dynamics
    ("estimate-out-missing-dir", ["estimate", "--V", "1", "--I", "1e-2", "--out", "nodir/e.csv"], 2,
     ["--out", "'nodir' does not exist"]),
    ("estimate-out-extension", ["estimate", "--V", "1", "--I", "1e-2", "--out", "e.txt"], 2,
     ["--out", ".csv or .json", "'e.txt'"]),
    ("segment-out-missing-dir", SEG + ["--out", "nodir/s.json"], 2, ["--out", "'nodir' does not exist"]),
    ("segment-curves-missing-dir", SEG + ["--curves", "nodir/c.csv"], 2, ["--curves", "'nodir' does not exist"]),
    ("segment-plot-missing-dir", SEG + ["--plot", "nodir/p.png"], 2, ["--plot", "'nodir' does not exist"]),
    ("dynamics-out-missing-dir", DYN + ["--out", "nodir/d.json"], 2, ["--out", "'nodir' does not exist"]),
    # directory outputs
    ("sweep-out-through-file", SWEEP + ["--out", "afile/sub"], 2, ["--out", "'afile' is not a directory"]),
    ("sweep-out-onto-file", SWEEP + ["--out", "afile"], 2, ["--out", "'afile' exists and is not a directory"]),
    ("sweep-plot-unknown-key", SWEEP + ["--out", "sw", "--plot", "nosuchkey"], 2,
     ["--plot", "'nosuchkey'", "regime_"]),
    ("compare-out-onto-file", ["compare", "--scene", "case-III-bounds", "--no-stats", "--out", "afile"], 2,
     ["--out", "'afile' exists and is not a directory"]),
    ("benchmark-out-through-file", ["benchmark", "--quick", "--no-peers", "--out", "afile/bench"], 2,
     ["--out", "'afile' is not a directory"]),
    ("figures-out-onto-file", ["figures", "--only", "fig2", "--out", "afile"], 2,
     ["--out", "'afile' exists and is not a directory"]),
    ("figures-markdown-missing-dir", ["figures", "--only", "fig2", "--out", "figs", "--markdown", "nodir/f.md"], 2,
     ["--markdown", "'nodir' does not exist"]),
    # nonsense that was accepted (item 6): argparse types, exit 2
    ("dynamics-lyapunov-time-negative", DYN + ["--lyapunov", "--lyapunov-time", "-1"], 2,
     ["argument --lyapunov-time", "(0, inf)", "got -1.0"]),
    ("dynamics-window-negative", DYN + ["--window", "-5"], 2, ["argument --window", "(0, inf)", "got -5.0"]),
    ("dynamics-t-transient-negative", DYN + ["--t-transient", "-1"], 2, ["argument --t-transient", "[0, inf)"]),
    ("dynamics-max-period-zero", DYN + ["--max-period", "0"], 2, ["argument --max-period", "integer >= 1"]),
    ("dynamics-attractors-nan", DYN + ["--attractors=nan"], 2, ["argument --attractors", "finite", "got nan"]),
    ("dynamics-attractors-empty-item", DYN + ["--attractors=0.1,,0.2"], 2, ["argument --attractors", "comma list"]),
    # ("dynamics-return-map-alpha0", the refusal of --alpha0 with --lyapunov-method return-map, is
    # gone: exact.lyapunov's return-map method starts from any alpha0; tests/test_cli.py runs it)
    ("dynamics-lyapunov-eps", DYN + ["--lyapunov-method", "regularized", "--eps", "1e-30"], 2,
     ["eps", "1e-15", "got 1e-30"]),
]


@pytest.fixture
def workdir(tmp_path, monkeypatch):
    """A fresh current directory with a file ``afile`` and a directory ``adir`` (``nodir`` is absent)."""
    (tmp_path / "afile").write_text("x")
    (tmp_path / "adir").mkdir()
    monkeypatch.chdir(tmp_path)
    return tmp_path


def _fails(argv: list[str], capsys) -> tuple[int, str, str]:
    """Run ``main(argv)``, which must exit through SystemExit; returns (status, stdout, stderr)."""
    with pytest.raises(SystemExit) as exc:
        main(argv)
    cap = capsys.readouterr()
    return exc.value.code, cap.out, cap.err


@pytest.mark.parametrize("argv,status,fragments", [c[1:] for c in CASES], ids=[c[0] for c in CASES])
def test_user_error_is_one_line_before_the_run(workdir, capsys, argv, status, fragments):
    """Hypothesis: each reproducer exits with its status and one stderr line ``peelapprox <cmd>: error: ...`` naming
    the argument and the path or value, with no traceback, before any result is printed, and writes no file."""
    before = sorted(os.listdir(workdir))
    code, out, err = _fails(argv, capsys)
    assert code == status
    assert "Traceback" not in err
    last = err.strip().splitlines()[-1]
    assert last.startswith(f"peelapprox {argv[0]}: error: "), err
    for frag in fragments:
        assert frag in last, (frag, last)
    assert out == ""  # nothing computed: the summaries are printed after the run
    assert sorted(os.listdir(workdir)) == before


def test_sweep_plot_key_missing_after_the_sweep_keeps_results(workdir, capsys):
    """Hypothesis: a --plot key with a measure's prefix but absent from every record is found only after the sweep;
    it is then a one-line usage error (exit 2) that lists the real keys, and the sweep's results stay on disk."""
    code, _out, err = _fails(SWEEP + ["--out", "sw", "--plot", "regime_nosuch"], capsys)
    assert code == 2 and "Traceback" not in err
    assert "'regime_nosuch': no record has this key" in err and "regime_label" in err and "saved in sw" in err
    assert (workdir / "sw" / "results.jsonl").read_text().count("\n") == 1
    assert not (workdir / "sw" / "regime_nosuch.png").exists()


def test_written_paths_are_printed_exactly(workdir, capsys):
    """Hypothesis: ``simulate --out run --plot pic`` writes ``run.npz`` and ``pic.png`` (the extensions numpy and
    matplotlib append) and says so: every 'wrote X' line names a file that exists, and nothing else is written."""
    assert main(SIM + ["--out", "run", "--plot", "pic", "--jumps-csv", "jumps"]) == 0
    err = capsys.readouterr().err
    wrote = [line.removeprefix("wrote ") for line in err.splitlines() if line.startswith("wrote ")]
    assert wrote == ["run.npz", "jumps", "pic.png"]
    assert sorted(os.listdir(workdir)) == sorted(["afile", "adir", *wrote])


def test_dask_scheduler_unreachable_fails_fast(workdir, capsys, monkeypatch):
    """Hypothesis: an address where no scheduler listens is a one-line error (exit 1) naming --dask-scheduler and
    the address, within the connect timeout (set to 1 s here), and no sweep directory is written."""
    pytest.importorskip("distributed")
    monkeypatch.setattr(_cli_checks, "DASK_CONNECT_TIMEOUT_S", 1.0)
    t0 = time.perf_counter()
    code, _out, err = _fails(["sweep", "--I", "1e-3", "--V", "1", "--out", "sw", "--quiet",
                              "--dask-scheduler", "tcp://127.0.0.1:1"], capsys)
    assert time.perf_counter() - t0 < 15
    assert code == 1 and "Traceback" not in err
    assert "peelapprox sweep: error: --dask-scheduler 'tcp://127.0.0.1:1': cannot connect" in err
    assert not (workdir / "sw").exists()


def test_dask_scheduler_malformed_address_is_a_usage_error(workdir, capsys):
    """Hypothesis: an address without a port is a usage error (exit 2) naming --dask-scheduler."""
    pytest.importorskip("distributed")
    code, _out, err = _fails(SWEEP[:-3] + ["--quiet", "--out", "sw", "--dask-scheduler", "nonsense"], capsys)
    assert code == 2 and "--dask-scheduler 'nonsense'" in err and "port" in err


@pytest.mark.parametrize("argv,status,fragment", [
    (SIM + ["--method", "regularized", "--solver", "LSODA", "--eps", "1e-30"], 2, "eps"),
    (DYN + ["--window", "-5"], 2, "argument --window"),
], ids=["solver-failure", "argparse-type"])
def test_subprocess_has_no_traceback(workdir, argv, status, fragment):
    """Hypothesis: run as a user runs it (a new interpreter), the status and the one-line message are the same as
    in-process, and stderr holds no traceback."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [os.path.dirname(os.path.dirname(
        os.path.abspath(__file__))), os.environ.get("PYTHONPATH")]))}
    res = subprocess.run([sys.executable, "-m", "peelapprox.cli", *argv], capture_output=True, text=True,
                         env=env, timeout=300, check=False)
    assert res.returncode == status, res.stderr
    assert "Traceback" not in res.stderr
    assert res.stderr.strip().splitlines()[-1].startswith(f"peelapprox {argv[0]}: error: ")
    assert fragment in res.stderr


# ------------------------------------------------------------------------------------------ the helpers directly

def test_check_output_path_names_and_errors(tmp_path):
    """Hypothesis: the exact name written is returned (``.npz``/``.png`` appended as numpy/matplotlib do, tables
    unchanged), and each unwritable target is a ValueError naming the option."""
    cop = _cli_checks.check_output_path
    assert cop(str(tmp_path / "run"), "npz", "--out") == str(tmp_path / "run.npz")
    assert cop(str(tmp_path / "run.npz"), "npz", "--out") == str(tmp_path / "run.npz")
    assert cop(str(tmp_path / "pic."), "image", "--plot") == str(tmp_path / "pic.png")
    assert cop(str(tmp_path / "pic.PDF"), "image", "--plot") == str(tmp_path / "pic.PDF")
    assert cop(str(tmp_path / "t.json"), "table", "--out") == str(tmp_path / "t.json")
    assert cop(str(tmp_path / "a" / "b"), "dir", "--out") == str(tmp_path / "a" / "b")  # parents are created
    (tmp_path / "run2.npz").mkdir()
    with pytest.raises(ValueError, match=r"--out '.*run2' would write '.*run2\.npz', which is a directory"):
        cop(str(tmp_path / "run2"), "npz", "--out")
    with pytest.raises(ValueError, match="--x must not be empty"):
        cop("", "file", "--x")
    with pytest.raises(ValueError, match="kind must be one of"):
        cop("x", "csv", "--x")


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into read-only directories")
def test_check_output_path_read_only(tmp_path):
    """Hypothesis: a read-only parent directory is refused before the run; a read-only existing sweep directory is
    accepted with read_only_ok (a complete sweep is only read)."""
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o555)
    try:
        with pytest.raises(ValueError, match="not writable"):
            _cli_checks.check_output_path(str(ro / "x.csv"), "table", "--out")
        with pytest.raises(ValueError, match="not writable"):
            _cli_checks.check_output_path(str(ro), "dir", "--out")
        assert _cli_checks.check_output_path(str(ro), "dir", "--out", read_only_ok=True) == str(ro)
    finally:
        ro.chmod(0o755)


def test_sweep_plot_key_rule():
    """Hypothesis: a --plot key passes before the sweep iff it is an engine key or carries a chosen measure's
    prefix (the engine's own rule), and a path separator is refused."""
    check = _cli_checks.check_sweep_plot_key
    for key in ("status", "I", "regime_label", "jumps_mean_period", "jumps"):
        check(key, ["regime", "jumps"])
    for key in ("label", "period_period", "regimelabel", "regime_../x".replace("/", os.sep)):
        with pytest.raises(ValueError, match="--plot"):
            check(key, ["regime", "jumps"])


def test_argument_types():
    """Hypothesis: the argparse types return the parsed value in range and raise ArgumentTypeError (argparse's
    'argument --x: ...' exit 2) with the range outside it."""
    import argparse

    assert _cli_checks.positive_float("2.5") == 2.5
    assert _cli_checks.nonnegative_float("0") == 0.0
    assert _cli_checks.positive_int("3") == 3
    assert _cli_checks.finite_float_list("-0.4, 0,0.2") == [-0.4, 0.0, 0.2]
    for fn, text in ((_cli_checks.positive_float, "0"), (_cli_checks.positive_float, "inf"),
                     (_cli_checks.nonnegative_float, "-1e-300"), (_cli_checks.positive_int, "0"),
                     (_cli_checks.positive_int, "2.0"), (_cli_checks.finite_float_list, ""),
                     (_cli_checks.finite_float_list, "1,abc")):
        with pytest.raises(argparse.ArgumentTypeError):
            fn(text)


def test_unexpected_exceptions_are_internal_errors(monkeypatch, capsys):
    """Hypothesis: main() turns a bug (here a KeyError raised by the subcommand) into one line and exit status 4
    (an internal error, no traceback); with PEELAPPROX_TRACEBACK=1 it propagates with its traceback.
    tests/test_named_errors.py checks the line word for word."""
    from peelapprox import cli

    def boom(args):
        raise KeyError("a bug")

    monkeypatch.setattr(cli, "_folds", boom)  # build_parser binds the subcommand's function when main() runs
    monkeypatch.delenv("PEELAPPROX_TRACEBACK", raising=False)
    code, _out, err = _fails(["folds", "--V", "1"], capsys)
    assert code == 4 and "Traceback" not in err and "internal error: KeyError: 'a bug'" in err
    monkeypatch.setenv("PEELAPPROX_TRACEBACK", "1")
    with pytest.raises(KeyError, match="a bug"):
        cli.main(["folds", "--V", "1"])

"""The command line, run as a user would (in-process via main())."""

import json

import numpy as np
import pytest

from exact import Trajectory
from peelapprox.cli import main


def test_simulate_writes_npz_csv_plot(tmp_path, capsys):
    """`peelapprox simulate` writes a loadable .npz, a jumps CSV with one row per jump, and a PNG."""
    out, csv, png = tmp_path / "r.npz", tmp_path / "j.csv", tmp_path / "r.png"
    rc = main(["simulate", "--V", "1", "--I", "1e-5", "--t-end", "0.2", "--out", str(out), "--jumps-csv", str(csv),
               "--plot", str(png), "--format", "json", "--quiet"])
    assert rc == 0
    summary = json.loads(capsys.readouterr().out)
    tr = Trajectory.from_npz(out)
    assert summary["jumps"] == len(tr.jumps) >= 4
    lines = csv.read_text().splitlines()
    assert lines[0].startswith("t,from_branch,to_branch") and len(lines) == len(tr.jumps) + 1
    assert png.stat().st_size > 20_000
    assert np.isclose(float(lines[1].split(",")[0]), tr.jumps.t[0], rtol=0, atol=0)


def test_bad_argument_exit_code(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["simulate", "--V", "1", "--I", "-1", "--t-end", "1"])
    assert exc.value.code == 2
    assert "I must be finite and in [1e-12, 1e6], got -1.0" in capsys.readouterr().err


def test_folds_json(capsys):
    assert main(["folds", "--V", "4", "--format", "json"]) == 0
    row = json.loads(capsys.readouterr().out)
    assert row["has_folds"] and abs(row["f_max"] - 307.21) < 0.01 and abs(row["f_min"] - 293.34) < 0.01


def test_cli_dynamics_reports_the_period_and_force_drop(capsys):
    """``peelapprox dynamics --V 1 --I 1e-2`` (Fig. 4's point) prints the return-map period (period-8, as in
    the paper) and a positive mean force drop; JSON output parses."""
    import json as _json

    from peelapprox.cli import main

    assert main(["dynamics", "--V", "1", "--I", "1e-2", "--format", "json"]) == 0
    row = _json.loads(capsys.readouterr().out)
    assert row["period"] == "period-8" and row["mean_force_drop"] > 0


def test_cli_dynamics_lyapunov_methods(capsys):
    """``--lyapunov-method regularized`` at a stable sliding point (V = 0.05, I = 1e-2) prints the leading
    eigenvalue of the linearisation, -4.7642 bits/s (oracle: ``np.linalg.eigvals`` of the ε-system's
    Jacobian there, see tests/test_peers.py; measured error 4e-7 relative, asserted 1e-4), with progress on
    stderr; ``return-map`` without stick-slip is a clean usage error (exit 2) naming the missing returns."""
    import json as _json

    from peelapprox.cli import main

    pytest.importorskip("pydiffsol")
    assert main(["dynamics", "--V", "0.05", "--I", "1e-2", "--t-transient", "15", "--window", "1",
                 "--lyapunov-method", "regularized", "--lyapunov-time", "10", "--format", "json"]) == 0
    cap = capsys.readouterr()
    row = _json.loads(cap.out)
    assert row["lyapunov_method"] == "regularized" and row["eps"] == 1e-7
    assert row["lyapunov_bits_per_s"] == pytest.approx(-4.764227, rel=1e-4)
    assert "25/25 s" in cap.err
    with pytest.raises(SystemExit) as exc:
        main(["dynamics", "--V", "0.05", "--I", "1e-2", "--t-transient", "1", "--window", "1",
              "--lyapunov-method", "return-map"])
    assert exc.value.code == 2 and "no" in capsys.readouterr().err


def test_cli_lyapunov_methods_are_exact_lyapunov_methods():
    """``dynamics --lyapunov-method`` takes exact.lyapunov's method names (the CLI writes them out so
    that building the parser loads no ``exact``) and maps the earlier names saltation and regularized onto
    tangent and variational.  Hypothesis: exact set equality with
    ``exact.dynamics._lyapunov_options.LYAPUNOV_METHODS``."""
    from exact.dynamics._lyapunov_options import LYAPUNOV_METHODS as METHODS
    from peelapprox.cli.dynamics import LYAPUNOV_ALIASES, LYAPUNOV_METHODS

    assert LYAPUNOV_METHODS == tuple(METHODS)
    assert LYAPUNOV_ALIASES == {"saltation": "tangent", "regularized": "variational"}


DYN_LY = ["dynamics", "--V", "1", "--I", "1e-3", "--t-transient", "0.5", "--window", "1", "--format", "json"]


@pytest.mark.parametrize("name", ["two-trajectory", "tangent", "saltation"])
def test_cli_lyapunov_is_exact_lyapunov_bitwise(name, capsys):
    """the CLI calls ``exact.lyapunov(p, method, t_transient=..., alpha0=..., max_wall=..., T=...)``.
    Hypothesis: its exponent equals, exactly, the call the CLI made before (two-trajectory: ``n =
    max(2, int(round(T/tau)))`` intervals of LYAPUNOV_TAU; saltation: ``lyapunov_tangent(p, T=T, ...)``), and
    the alias saltation gives tangent's number."""
    import exact
    from peelapprox import LYAPUNOV_TAU, PeelParams

    T = 0.3
    assert main([*DYN_LY, "--lyapunov-method", name, "--lyapunov-time", str(T)]) == 0
    row = json.loads(capsys.readouterr().out)
    p = PeelParams(V=1.0, I=1e-3)
    if name == "two-trajectory":
        old = exact.lyapunov(p, t_transient=0.5, tau=LYAPUNOV_TAU, n=max(2, int(round(T / LYAPUNOV_TAU))))
    else:
        old = exact.lyapunov_tangent(p, t_transient=0.5, T=T)
    assert row["lyapunov_method"] == name and row["lyapunov_bits_per_s"] == old.bits_per_s


def test_cli_return_map_lyapunov_starts_from_alpha0(capsys):
    """``--lyapunov-method return-map`` with ``--alpha0`` was refused (the named function started
    from alpha0 = 0 only); it now runs ``exact.lyapunov(p, "return-map", alpha0=...)``.  Hypothesis: the CLI's
    exponent equals that call with the CLI's ``n_returns = max(2, round(returns / window * T))`` exactly."""
    import exact
    from peelapprox import PeelParams

    T = 0.4
    assert main([*DYN_LY, "--alpha0", "0.1", "--lyapunov-method", "return-map", "--lyapunov-time", str(T)]) == 0
    row = json.loads(capsys.readouterr().out)
    n = max(2, int(round(row["returns"] / 1.0 * T)))
    ref = exact.lyapunov(PeelParams(V=1.0, I=1e-3), "return-map", t_transient=0.5, alpha0=0.1, n_returns=n)
    assert row["lyapunov_bits_per_s"] == ref.bits_per_s


def test_cli_bad_lyapunov_option_is_refused_before_the_window_run(monkeypatch, capsys):
    """a bad ``--eps`` was reported only after the window run.  Hypothesis: with ``exact.simulate``
    replaced by a function that fails the test, ``--lyapunov-method regularized --eps 1e-30`` still exits
    with status 2 naming eps and its range: the option is checked before any run (categorical)."""
    import exact

    def no_run(*args, **kwargs):
        raise AssertionError("the window run started")

    monkeypatch.setattr(exact, "simulate", no_run)
    with pytest.raises(SystemExit) as exc:
        main([*DYN_LY, "--lyapunov-method", "regularized", "--eps", "1e-30"])
    assert exc.value.code == 2 and "eps must be finite and in [1e-15, 0.01]" in capsys.readouterr().err


def test_cli_figures_list_and_bad_name(capsys, tmp_path):
    """``figures --list`` names fig2 … fig9; an unknown ``--only`` is a clean usage error (exit 2)."""
    from peelapprox.cli import main

    assert main(["figures", "--list"]) == 0
    out = capsys.readouterr().out
    assert all(f"fig{n}:" in out for n in range(2, 10))
    with pytest.raises(SystemExit) as exc:
        main(["figures", "--only", "fig1", "--out", str(tmp_path / "unused-figs")])  # a path of this test's own
    assert exc.value.code == 2


def test_folds_loads_neither_solvers_nor_harness():
    """the CLI crosses the doors lazily per subcommand; ``peelapprox folds`` needs only the peel-force
    law.  Hypothesis: after it runs, neither ``exact`` nor ``comparisons`` is imported (exact: module set)."""
    import subprocess
    import sys

    code = ("import sys, contextlib, io\nfrom peelapprox.cli import main\n"
            "with contextlib.redirect_stdout(io.StringIO()):\n    main(['folds', '--V', '1'])\n"
            "print(sorted(m for m in sys.modules if m.split('.')[0] in ('exact', 'comparisons')))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip().splitlines()[-1] == "[]"

"""``peelapprox sweep``: measures over an (I, V) grid (:func:`comparisons.sweep.sweep`), locally or on dask."""

from __future__ import annotations

import argparse
import json
import os
import sys
import time

from ._checks import (
    add_pool_options,
    check_output_path,
    check_sweep_plot_key,
    worker_pool,
)
from ._common import (
    FromMethods,
    add_grid_params,
    add_max_wall_option,
    add_variant_options,
    scipy_solvers,
    subcommand,
)
from ._force import add_force_options, force_from_args

__all__ = ["MEASURES_HELP", "add_parser", "run"]


#: The built-in measures of ``comparisons.sweep`` and what each records (for ``--help``; the parser is built
#: without loading ``comparisons``: tests/test_cli_conventions.py keeps the names equal to its ``MEASURES``).
MEASURES_HELP = {
    "regime": "the paper's regime in closed form (peelapprox.estimate: inertia and velocity labels, periods, times "
              "[s]); instant",
    "jumps": "jump statistics of one exact run (count, slips, mean interval and period [s], mean force drop [N]); "
             "options --t-transient, --t-end or --window, --rtol, --alpha0",
    "period": "the return map's period over the same run (label, period [returns], mismatch); options as jumps, "
              "and --period-rtol",
    "lyapunov": "the largest Lyapunov exponent [bits/s] and its standard error, by the two-trajectory method "
                "(exact.lyapunov's default; the other methods: peelapprox dynamics --lyapunov-method); options "
                "--t-transient, --lyapunov-time, --alpha0",
}


def add_parser(sub) -> argparse.ArgumentParser:
    sw = subcommand(
        sub, "sweep", help="measures over an (I, V) grid on a thread pool or a dask cluster; incremental output, "
                           "resumes automatically",
        description="Measures over an (I, V) grid (and optionally a coefficient of a family law as a third axis), "
                    "one point a task on a local process pool or a dask cluster; every finished point is appended "
                    "to DIR/results.jsonl, so an interrupted sweep resumes where it stopped.  Measures "
                    "(--measure, comma-separated; more with comparisons.sweep.register_measure):\n\n"
                    + "\n\n".join(f"{k}: {v}" for k, v in MEASURES_HELP.items())
                    + "\n\nOptions left out take each measure's own default (given below).",
        examples=["peelapprox sweep --I 1e-5:1e-2:4:log --V 1:4:4 --measure period,jumps --out sweep/   # resumable",
                  "peelapprox sweep --I 1e-4 --V 1.5:3:4 --measure lyapunov --lyapunov-time 20 --out ly/ "
                  "--plot lyapunov_bits_per_s",
                  "peelapprox sweep --I 1e-5 --V 1:2:3 --force-family cubic --coef-axis c=290,300,310 "
                  "--measure period --out cubic/",
                  "peelapprox sweep --I 1e-5:1e-2:8:log --V 0.5:4:8 --dask-local 4 --out big/"])
    sw.add_argument("--I", required=True, metavar="SPEC",
                    help="roller inertias [kg m^2]: start:stop:num[:log] or a comma list, e.g. 1e-5:1e-2:8:log; "
                         "the grid (--I x --V, x --coef-axis) holds at most 1000000 points")
    sw.add_argument("--V", required=True, metavar="SPEC", help="pull speeds [m/s], same syntax, e.g. 0.4:4:10")
    sw.add_argument("--measure", default="regime", metavar="NAMES",
                    help=f"comma-separated measures: {', '.join(MEASURES_HELP)} (above), or registered ones")
    sw.add_argument("--out", required=True, metavar="DIR",
                    help="output directory: sweep.json, results.jsonl (one line per point), results.csv; "
                         "an existing DIR with the same grid, measures and options is resumed")
    add_pool_options(sw)
    m = sw.add_argument_group("options of the measures (left out: the measure's default)")
    m.add_argument("--t-end", type=float, default=None,
                   help="final time [s] (jumps, period; default: t_transient + window)")
    m.add_argument("--window", type=float, default=None, help="measured window [s] (jumps, period; default: 20)")
    m.add_argument("--t-transient", type=float, default=None, help="transient skipped [s] (default: 30)")
    m.add_argument("--rtol", type=float, default=None, help="solver tolerance (jumps, period; default: 1e-10)")
    m.add_argument("--alpha0", type=float, default=None, help="initial peel angle [rad] (default: 0)")
    m.add_argument("--period-rtol", type=float, default=None,
                   help="relative tolerance of a repeat of the return map (period; default: 1e-6)")
    m.add_argument("--lyapunov-time", type=float, default=None, help="measured time [s] (lyapunov; default: 50)")
    add_grid_params(sw)
    v = sw.add_argument_group("model variant at every point (docs/tape-mass.md, docs/constant-load.md; the measures "
                              "jumps, period and lyapunov run it, regime refuses it; to sweep m, one sweep per "
                              "mass into its own --out)")
    add_variant_options(v, loading_default=None)
    v.add_argument("--solver", choices=FromMethods(scipy_solvers), default=None,
                   help="the variant's scipy solver (default: the method's, LSODA for a tape mass)")
    sw.add_argument("--retry-failed", action="store_true",
                    help="compute again the points of DIR whose status is an error (else they count as done)")
    sw.add_argument("--plot", metavar="KEY", help="draw KEY over (V, I) to DIR/KEY.png, e.g. regime_label "
                                                  "(not with --coef-axis)")
    add_force_options(sw)
    sw.add_argument("--coef-axis", type=_coef_axis, metavar="NAME=SPEC",
                    help="sweep the coefficient NAME of --force-family as a third grid axis (I x V x values; give "
                         "one --I or --V value to sweep it instead), SPEC as for --I, e.g. c=290,300,310; every "
                         "record holds its coef and its law")
    sw.add_argument("--format", choices=("table", "md", "csv", "json"), default="table",
                    help="the table printed at the end: table (markdown; md is the same), csv or json")
    sw.add_argument("--quiet", action="store_true", help="no per-point progress on stderr")
    add_max_wall_option(sw, what="this run",
                        spent="when it is spent no point is started, the points done stay in DIR, the exit status "
                              "is 3, and the same command again resumes the rest")
    return sw


def _coef_axis(text: str) -> tuple[str, str]:
    """Argparse type of ``--coef-axis``: ``NAME=SPEC`` (SPEC parsed by ``parse_grid`` when the sweep runs)."""
    name, sep, spec = text.partition("=")
    name = name.strip()
    if not sep or not name.isidentifier() or not spec.strip():
        raise argparse.ArgumentTypeError(f"value must be NAME=SPEC (e.g. c=290,300,310 or c=250:350:5), got {text!r}")
    return name, spec


#: The sweep options the command line sets (each only when given: a resumed sweep's options must match).
_OPTIONS = ("t_end", "window", "t_transient", "rtol", "alpha0", "period_rtol", "lyapunov_time", "k", "R", "l",
            "geometry", "tape_mass", "loading", "load_mass", "load", "solver")


def _options(args: argparse.Namespace) -> dict:
    return {key: getattr(args, key) for key in _OPTIONS if getattr(args, key) is not None}


def run(args: argparse.Namespace) -> int:
    from comparisons.sweep import MANIFEST, RESULTS, check_grid_size, load_sweep, parse_grid, sweep

    I_values = parse_grid(args.I, name="--I")
    V_values = parse_grid(args.V, name="--V")
    check_grid_size({"--I": I_values.size, "--V": V_values.size})
    options = _options(args)
    force = force_from_args(args)
    coef = None
    if args.coef_axis:
        name, spec = args.coef_axis
        if args.force_family is None:
            raise ValueError("--coef-axis sweeps a coefficient of --force-family NAME; there is no --force-family")
        if args.plot:
            raise ValueError("--plot draws a 2-D (V, I) grid; with --coef-axis the grid is 3-D: plot from "
                             "load_sweep(DIR).values(KEY) instead")
        coef = (name, parse_grid(spec, name=f"--coef-axis {name}"))
        check_grid_size({"--I": I_values.size, "--V": V_values.size, f"--coef-axis {name}": coef[1].size})
    check_output_path(args.out, "dir", "--out", read_only_ok=True)  # a complete sweep is only read
    if args.plot:
        check_sweep_plot_key(args.plot, [m.strip() for m in args.measure.split(",") if m.strip()])
    if os.path.exists(os.path.join(args.out, MANIFEST)):
        prev = load_sweep(args.out)
        print(f"{args.out} holds a sweep with {len(prev.records)}/{prev.I_values.size * prev.V_values.size} points "
              "done: resuming it if grid, measures and options match", file=sys.stderr)
    t0 = time.perf_counter()
    try:
        with worker_pool(args) as (executor, max_workers):
            result = sweep(I_values, V_values, args.measure, out=args.out, executor=executor,
                           max_workers=max_workers, options=options, progress=not args.quiet,
                           retry_failed=args.retry_failed, force=force, coef=coef, max_wall=args.max_wall)
    except RuntimeError as exc:
        print(f"peelapprox sweep: error: {exc}", file=sys.stderr)
        return 3
    where = os.path.join(args.out, RESULTS)
    print(f"sweep: {len(result.records)} points in {where} ({time.perf_counter() - t0:.1f} s)", file=sys.stderr)
    csv_path = os.path.join(args.out, "results.csv")
    try:
        result.to_csv(csv_path)
        print(f"wrote {csv_path}", file=sys.stderr)
    except OSError as exc:  # e.g. a complete sweep in a read-only directory: still report it
        print(f"note: cannot write {csv_path} ({exc}); the table is printed only", file=sys.stderr)
    _print_table(result.rows(), result.keys(), args.format)
    if args.plot:
        from ..plotting import plot_phase_diagram

        if args.plot not in result.keys():
            raise ValueError(f"--plot {args.plot!r}: no record has this key (the sweep is saved in {args.out}); "
                             f"keys: {', '.join(result.keys())}")
        png = os.path.join(args.out, f"{args.plot}.png")
        plot_phase_diagram(result, args.plot, png)
        print(f"wrote {png}", file=sys.stderr)
    return 1 if result.failed() else 0


def _print_table(rows: list[dict], cols: list[str], fmt: str) -> None:
    """The sweep's records as JSON, CSV or a markdown table (floats to 6 significant digits)."""
    from ..io import fmt_number, write_csv

    if fmt == "json":
        print(json.dumps(rows, indent=2))
    elif fmt == "csv":
        write_csv(sys.stdout, rows, fields=cols)
    else:
        print("| " + " | ".join(cols) + " |")
        print("|" + "|".join("---" for _ in cols) + "|")
        for r in rows:
            print("| " + " | ".join(fmt_number(r.get(c), 6, missing="", nan="nan") for c in cols) + " |")

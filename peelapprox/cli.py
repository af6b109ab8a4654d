"""Command line: ``peelapprox simulate | folds | estimate | segment ...``.

The CLI is the only place that ties the three packages (peelapprox, exact,
comparisons) together; it imports the solvers lazily per subcommand.

Output paths are checked before any computation and reported exactly as
written (:mod:`peelapprox._cli_checks`).  A user error is one line on stderr,
``peelapprox <command>: error: <message>``, never a traceback; exit status 2
for a usage error (a bad argument or output path), 3 when the model or solver
stops (ModelBreakdown, SolverBudgetExceeded, SolverFailure, TransientNotPassed),
1 when writing fails (OSError) or, for ``sweep``, when a point failed.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from collections.abc import Sequence

from ._cli_checks import (
    check_output_path,
    check_sweep_plot_key,
    connect_dask_scheduler,
    finite_float_list,
    nonnegative_float,
    one_line,
    positive_float,
    positive_int,
)
from ._params import GEOMETRIES, LYAPUNOV_TAU, T_TRANSIENT, PeelParams

__all__ = ["main"]


def _simulate(args: argparse.Namespace) -> int:
    from exact import simulate

    if args.plot and args.jumps_only:
        raise ValueError("--plot needs stored steps; drop --jumps-only")
    out = check_output_path(args.out, "npz", "--out") if args.out else None
    jumps_csv = check_output_path(args.jumps_csv, "file", "--jumps-csv") if args.jumps_csv else None
    plot = check_output_path(args.plot, "image", "--plot") if args.plot else None
    params = PeelParams(V=args.V, I=args.I, k=args.k, R=args.R, l=args.l, geometry=args.geometry)
    save = "jumps" if args.jumps_only else "steps"
    traj = simulate(
        params,
        args.t_end,
        alpha0=args.alpha0,
        omega0=args.omega0,
        F0=args.F0,
        branch0=args.branch0,
        method=args.method,
        solver=args.solver,
        rtol=args.rtol,
        eps=args.eps,
        t_transient=args.t_transient,
        save=save,
        max_wall=args.max_wall,
        progress=not args.quiet,
    )
    s = traj.stats
    summary = {
        "V": params.V,
        "I": params.I,
        "method": traj.method,
        "solver": traj.solver,
        "rtol": traj.rtol,
        "t_end": traj.t_end,
        "points": int(len(traj.t)),
        "jumps": int(len(traj.jumps)),
        "steps": s.n_steps,
        "rejected": s.n_rejected,
        "rhs_evaluations": s.n_rhs,
        "wall_time_s": round(s.wall_time, 6),
        "compile_time_s": round(s.compile_time, 3),
        "final_state": traj.final_state.as_dict(),
    }
    if len(traj.jumps):
        summary["F_at_jumps_range"] = [float(traj.jumps.F.min()), float(traj.jumps.F.max())]
    if args.format == "json":
        print(json.dumps(summary, indent=2))
    else:
        for key, val in summary.items():
            print(f"{key:>18}: {val}")
    if out:
        traj.to_npz(out)
        print(f"wrote {out}", file=sys.stderr)
    if jumps_csv:
        traj.jumps.to_csv(jumps_csv)
        print(f"wrote {jumps_csv}", file=sys.stderr)
    if plot:
        from .plotting import plot_trajectory

        plot_trajectory(traj, plot)
        print(f"wrote {plot}", file=sys.stderr)
    return 0


def _folds(args: argparse.Namespace) -> int:
    from ._peelforce import branch_structure, fixed_point

    bs = branch_structure(args.V)
    fp = fixed_point(args.V)
    row = {**bs.__dict__, "fixed_point_stable": fp.stable, "fprime_at_V": fp.fprime}
    if args.format == "json":
        print(json.dumps(row, indent=2))
    else:
        for key, val in row.items():
            print(f"{key:>18}: {val}")
    return 0


def _write_rows(path: str, rows: list[dict]) -> None:
    """Write rows as CSV or JSON, chosen by the file extension (:func:`peelapprox.io.write_rows`).

    ``path`` was checked by :func:`check_output_path` (kind ``"table"``) before the run.
    """
    from .io import write_rows

    write_rows(path, rows)
    print(f"wrote {path}", file=sys.stderr)


def _print_mapping(row: dict, fmt: str) -> None:
    if fmt == "json":
        print(json.dumps(row, indent=2))
    else:
        width = max(len(k) for k in row)
        for key, val in row.items():
            if isinstance(val, float):
                val = f"{val:.6g}"
            print(f"{key:>{width}}: {val}")


def _estimate(args: argparse.Namespace) -> int:
    from ._estimate import estimate

    out = check_output_path(args.out, "table", "--out") if args.out else None
    params = PeelParams(V=args.V, I=args.I, k=args.k, R=args.R)
    row = estimate(params, alpha_min=args.alpha_min, alpha_max=args.alpha_max).as_dict()
    _print_mapping(row, args.format)
    if out:
        _write_rows(out, [row])
    return 0


def _segment(args: argparse.Namespace) -> int:
    from ._segment import reduced_segment

    out = check_output_path(args.out, "table", "--out") if args.out else None
    curves = check_output_path(args.curves, "table", "--curves") if args.curves else None
    plot = check_output_path(args.plot, "image", "--plot") if args.plot else None
    params = PeelParams(V=args.V, I=args.I, k=args.k, R=args.R)
    seg = reduced_segment(
        params, args.branch, F_in=args.F_in, alpha_in=args.alpha_in, alphadot_in=args.alphadot_in,
        amplitude=args.amplitude, phase=args.phase, v_in=args.v_in, v_f=args.v_f,
        alpha_model=args.alpha_model, v_equation=args.v_equation, rtol=args.rtol,
    )
    _print_mapping(seg.as_dict(), args.format)
    if out:
        _write_rows(out, [seg.as_dict()])
    if curves or plot:
        # smooth curves: the same integration again, sampled by dense output
        import numpy as np

        seg = reduced_segment(
            params, args.branch, F_in=args.F_in, alpha_in=args.alpha_in, alphadot_in=args.alphadot_in,
            amplitude=args.amplitude, phase=args.phase, v_in=args.v_in, v_f=args.v_f,
            alpha_model=args.alpha_model, v_equation=args.v_equation, rtol=args.rtol,
            t_eval=np.linspace(0.0, seg.dt, 801)[:-1],
        )
    if curves:
        rows = [dict(t=float(a), v=float(b), F=float(c), alpha=float(d), alphadot=float(e))
                for a, b, c, d, e in zip(seg.t, seg.v, seg.F, seg.alpha, seg.alphadot)]
        _write_rows(curves, rows)
    if plot:
        from .plotting import plot_segment

        plot_segment(seg, plot)
        print(f"wrote {plot}", file=sys.stderr)
    return 0


def _compare(args: argparse.Namespace) -> int:

    from comparisons import RUNS, SCENES, STAT_RUNS, markdown, run_compare

    if args.list:
        for name, sc in SCENES.items():
            sp = RUNS[sc.run]
            print(f"{name:18s} {sc.title}  [run {sc.run}: V={sp.V:g}, I={sp.I:g}, alpha0={sp.alpha0:g}, "
                  f"transient {sp.t_transient:g} s, window {sp.window:g} s]")
        return 0
    figdir = None
    if args.out:
        check_output_path(args.out, "dir", "--out")
        figdir = os.path.join(args.out, "figures")
        os.makedirs(figdir, exist_ok=True)
    report = run_compare(args.scene, statistics_runs=() if args.no_stats else STAT_RUNS,
                         figures_dir=None if args.no_figures else figdir,
                         progress=lambda msg: print(msg, file=sys.stderr, flush=True))
    rows, stats = report.row_dicts(), report.stat_dicts()
    if args.format == "md":
        print(markdown(report, figures_rel="figures" if figdir else None), end="")
    elif args.format == "json":
        print(json.dumps({"rows": rows, "statistics": stats, "transients": report.transients,
                          "timings": report.timings}, indent=2))
    else:
        import csv

        w = csv.DictWriter(sys.stdout, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    if args.out:
        with open(os.path.join(args.out, "tables.md"), "w") as fh:
            fh.write("# Approximate vs exact: the paper's scenes\n\n"
                     "Generated by `peelapprox compare --out docs`; do not edit by hand. Columns: "
                     "`rel. error` = (ours approx - ours exact)/|ours exact|; `claim` = the agreement the paper "
                     "claims for the number; seeds: `paper` = the paper's quoted initial data as printed, "
                     "`paper, corrected` = with the misprint fixed (docs/paper-notes.md), `exact` = our exact "
                     "segment's entry state.\n\n")
            fh.write(markdown(report, figures_rel="figures" if figdir else None))
        for stem, data in (("compare_rows", rows), ("compare_statistics", stats)):
            for ext in ("csv", "json"):
                if data:
                    _write_rows(os.path.join(args.out, f"{stem}.{ext}"), data)
        print(f"wrote {os.path.join(args.out, 'tables.md')}", file=sys.stderr)
    return 0


def _benchmark(args: argparse.Namespace) -> int:

    from comparisons.benchmark import markdown, plot_eps_study, plot_work_precision, rows_as_dicts, run_benchmark

    if args.out:
        check_output_path(args.out, "dir", "--out")
    t0 = time.perf_counter()

    def say(msg: str) -> None:
        print(f"[{time.perf_counter() - t0:6.1f} s] {msg}", file=sys.stderr, flush=True)

    peers = () if args.no_peers else None
    report = run_benchmark(quick=args.quick, peers=peers, progress=say)
    wp, eps = rows_as_dicts(report)
    if args.format == "md":
        print(markdown(report), end="")
    elif args.format == "json":
        print(json.dumps({"work_precision": wp, "eps_study": eps, "ratios": report.ratios,
                          "targets": report.targets}, indent=2, default=float))
    else:
        import csv

        w = csv.DictWriter(sys.stdout, fieldnames=list(wp[0]))
        w.writeheader()
        w.writerows(wp)
    if args.out:
        os.makedirs(args.out, exist_ok=True)
        with open(os.path.join(args.out, "benchmark.md"), "w") as fh:
            fh.write(f"# peelapprox benchmark{' --quick' if args.quick else ''}\n\n"
                     "Generated by `peelapprox benchmark`; methodology in `comparisons/benchmark/` and "
                     "docs/performance.md.\n\n![work precision](work_precision.png)\n\n"
                     "![eps study](eps_study.png)\n\n")
            fh.write(markdown(report))
        for stem, data in (("work_precision", wp), ("eps_study", eps), ("ratios", report.ratios),
                           ("targets", report.targets)):
            for ext in ("csv", "json"):
                if data:
                    _write_rows(os.path.join(args.out, f"{stem}.{ext}"), data)
        plot_work_precision(report, os.path.join(args.out, "work_precision.png"))
        plot_eps_study(report, os.path.join(args.out, "eps_study.png"))
        print(f"wrote {os.path.join(args.out, 'benchmark.md')} and the plots", file=sys.stderr)
    return 0


def _sweep(args: argparse.Namespace) -> int:
    from comparisons.sweep import load_sweep, parse_grid, sweep
    from comparisons.sweep.store import MANIFEST, RESULTS

    I_values = parse_grid(args.I, name="--I")
    V_values = parse_grid(args.V, name="--V")
    options = {key: val for key, val in (("t_end", args.t_end), ("t_transient", args.t_transient),
                                         ("rtol", args.rtol), ("alpha0", args.alpha0), ("k", args.k),
                                         ("R", args.R)) if val is not None}
    if args.workers is not None and args.workers < 0:
        raise ValueError(f"--workers must be >= 0 (0: in this process), got {args.workers}")
    if args.dask_local is not None and args.dask_local < 1:
        raise ValueError(f"--dask-local must be >= 1 workers, got {args.dask_local}")
    check_output_path(args.out, "dir", "--out", read_only_ok=True)  # a complete sweep is only read
    if args.plot:
        check_sweep_plot_key(args.plot, [m.strip() for m in args.measure.split(",") if m.strip()])
    if os.path.exists(os.path.join(args.out, MANIFEST)):
        prev = load_sweep(args.out)
        print(f"{args.out} holds a sweep with {len(prev.records)}/{prev.I_values.size * prev.V_values.size} points "
              "done: resuming it if grid, measures and options match", file=sys.stderr)
    client = cluster = None
    executor, max_workers = None, None
    if args.dask_local or args.dask_scheduler:
        try:
            from distributed import Client, LocalCluster
        except ImportError:
            print("error: --dask-local/--dask-scheduler need dask.distributed: pip install 'peelapprox[distributed]'",
                  file=sys.stderr)
            return 2
        if args.dask_local:
            cluster = LocalCluster(n_workers=args.dask_local, threads_per_worker=1, dashboard_address=None)
            client = Client(cluster)
        else:
            client = connect_dask_scheduler(args.dask_scheduler)
        print(f"dask: {client}", file=sys.stderr)
        executor = client.get_executor()
    else:
        max_workers = args.workers  # 0: in this process
    t0 = time.perf_counter()
    try:
        result = sweep(I_values, V_values, args.measure, out=args.out, executor=executor, max_workers=max_workers,
                       options=options, progress=not args.quiet, retry_failed=args.retry_failed)
    except RuntimeError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 3
    finally:
        if client is not None:
            client.close()
        if cluster is not None:
            cluster.close()
    print(f"sweep: {len(result.records)} points in {args.out}/{RESULTS} ({time.perf_counter() - t0:.1f} s)",
          file=sys.stderr)
    csv_path = os.path.join(args.out, "results.csv")
    try:
        result.to_csv(csv_path)
        print(f"wrote {csv_path}", file=sys.stderr)
    except OSError as exc:  # e.g. a complete sweep in a read-only directory: still report it
        print(f"note: cannot write {csv_path} ({exc}); the table is printed only", file=sys.stderr)
    rows = result.rows()
    cols = result.keys()
    if args.format == "json":
        print(json.dumps(rows, indent=2))
    elif args.format == "csv":
        from .io import write_csv

        write_csv(sys.stdout, rows, fields=cols)
    else:
        def cell(v) -> str:
            return "" if v is None else (f"{v:.6g}" if isinstance(v, float) else str(v))

        print("| " + " | ".join(cols) + " |")
        print("|" + "|".join("---" for _ in cols) + "|")
        for r in rows:
            print("| " + " | ".join(cell(r.get(c)) for c in cols) + " |")
    if args.plot:
        from .plotting import plot_phase_diagram

        if args.plot not in cols:
            raise ValueError(f"--plot {args.plot!r}: no record has this key (the sweep is saved in {args.out}); "
                             f"keys: {', '.join(cols)}")
        png = os.path.join(args.out, f"{args.plot}.png")
        plot_phase_diagram(result, args.plot, png)
        print(f"wrote {png}", file=sys.stderr)
    return 1 if result.failed() else 0


def _figures(args: argparse.Namespace) -> int:
    from comparisons._figures import FIGURES, figures_markdown, make_figures

    if args.list:
        for name, fig in FIGURES.items():
            print(f"{name}: {fig.caption}  [{fig.params}]")
        return 0
    check_output_path(args.out, "dir", "--out")
    markdown = check_output_path(args.markdown, "file", "--markdown") if args.markdown else None
    files = make_figures(args.only, args.out, progress=lambda msg: print(msg, file=sys.stderr, flush=True))
    for name, paths in files.items():
        print(f"{name}: {', '.join(paths)}")
    if markdown:
        rel = os.path.relpath(args.out, os.path.dirname(os.path.abspath(markdown)) or ".")
        with open(markdown, "w") as fh:
            fh.write(figures_markdown(files, rel=rel))
        print(f"wrote {markdown}", file=sys.stderr)
    return 0


def _dynamics(args: argparse.Namespace) -> int:
    from exact import ModelBreakdown, attractors, simulate

    from ._returnmap import force_drops, periodicity, return_map, settle_time

    out = check_output_path(args.out, "table", "--out") if args.out else None
    if args.lyapunov_method == "return-map" and args.alpha0 != 0.0:
        raise ValueError("--lyapunov-method return-map starts from alpha0 = 0 only; drop --alpha0")
    p = PeelParams(V=args.V, I=args.I, k=args.k, R=args.R)
    if args.attractors:  # checked before the run, named as the user wrote it
        from .validate import states

        states("--attractors", args.attractors, "alpha")
    row: dict = dict(V=args.V, I=args.I, alpha0=args.alpha0, t_transient=args.t_transient, window=args.window)
    try:
        # one run from t = 0: the window's jumps for the return map and force drops, all of them for the
        # settle time
        full = simulate(p, args.t_transient + args.window, alpha0=args.alpha0, rtol=args.rtol, save="jumps",
                        max_wall=args.max_wall)
        t_k, x_all = return_map(full, with_times=True)
        in_window = t_k >= args.t_transient
        x = x_all[in_window]
        per = periodicity(x, max_period=args.max_period) if x.size > 1 else None
        d = force_drops(full)
        d = d[in_window[: d.size]] if d.size else d
        row.update(returns=int(x.size), period=per.label if per else "no stick-slip",
                   period_mismatch=per.mismatch if per else None,
                   settle_time=settle_time(full, max_period=args.max_period),
                   mean_force_drop=float(d.mean()) if d.size else None,
                   force_drop_std=float(d.std()) if d.size else None,
                   F_min_at_jumps=float(x.min()) if x.size else None, F_max_at_jumps=float(x.max()) if x.size else None)
    except ModelBreakdown as exc:
        row.update(status=f"breakdown:{exc.reason} at t={exc.t:.6g}")
    if args.lyapunov or args.lyapunov_method:
        method = args.lyapunov_method or "two-trajectory"
        print(f"lyapunov ({method}, {args.lyapunov_time:g} s after {args.t_transient:g} s) ...", file=sys.stderr,
              flush=True)
        ly = _lyapunov_by_method(p, method, args, row.get("returns"))
        row.update(lyapunov_method=method, lyapunov_time=args.lyapunov_time, lyapunov_bits_per_s=ly.bits_per_s,
                   lyapunov_stderr=ly.stderr_bits, lyapunov_wall_time=ly.benettin.wall_time)
        if method == "regularized":
            row.update(eps=args.eps)
    _print_mapping(row, args.format)
    if args.attractors:
        a0s = args.attractors
        res = attractors(p, a0s, t_transient=args.t_transient, window=args.window, max_wall=args.max_wall,
                         progress=lambda msg: print(msg, file=sys.stderr, flush=True))
        rows = [dict(attractor=a.label, starts=" ".join(f"{s:g}" for s in a.starts), F_min=a.F_range[0],
                     F_max=a.F_range[1]) for a in res]
        if args.format == "json":
            print(json.dumps(rows, indent=2))
        else:
            print(f"{len(res)} attractor(s) from {len(a0s)} starts:")
            for r in rows:
                print(f"  {r['attractor']:>14}  F at AB→CD jumps {r['F_min']:.4g}…{r['F_max']:.4g} N  "
                      f"from alpha0 = {r['starts']}")
    if out:
        _write_rows(out, [row])
    return 0


#: ``peelapprox dynamics --lyapunov-method`` choices.
LYAPUNOV_METHODS = ("two-trajectory", "saltation", "return-map", "regularized")


def _lyapunov_by_method(p: PeelParams, method: str, args: argparse.Namespace, returns):
    """The largest Lyapunov exponent at ``p`` by one of :data:`LYAPUNOV_METHODS` over ``args.lyapunov_time`` s."""
    import exact

    T, common = args.lyapunov_time, dict(t_transient=args.t_transient, alpha0=args.alpha0)
    if method == "two-trajectory":
        tau = LYAPUNOV_TAU
        return exact.lyapunov(p, tau=tau, n=max(2, int(round(T / tau))), max_wall=args.max_wall, **common)
    if method == "saltation":
        return exact.lyapunov_tangent(p, T=T, **common)
    if method == "return-map":  # alpha0 = 0: checked by the subcommand before the run
        if not returns:
            raise ValueError("--lyapunov-method return-map needs AB→CD returns in the window; there are none")
        return exact.lyapunov_return_map(p, t_transient=args.t_transient, max_wall=args.max_wall,
                                         n_returns=max(2, int(round(returns / args.window * T))))

    step = max(args.t_transient + T, 1e-9) / 10.0
    mark = [step]

    def progress(t_done, t_total):
        if t_done >= mark[0] - 1e-9 or t_done >= t_total:
            print(f"  {t_done:g}/{t_total:g} s", file=sys.stderr, flush=True)
            mark[0] += step

    return exact.lyapunov_variational(p, eps=args.eps, T=T, progress=progress, **common)


def _add_params(sp: argparse.ArgumentParser) -> None:
    sp.add_argument("--V", type=float, required=True, help="pull speed [m/s]")
    sp.add_argument("--I", type=float, required=True, help="roller inertia [kg m^2]")
    sp.add_argument("--k", type=float, default=1000.0, help="tape stiffness [N/m] (1000)")
    sp.add_argument("--R", type=float, default=0.1, help="roller radius [m] (0.1)")


def build_parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="peelapprox", description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="command", required=True)

    sp = sub.add_parser("simulate", help="integrate the full model (exact solution)")
    sp.add_argument("--V", type=float, required=True, help="pull speed [m/s]")
    sp.add_argument("--I", type=float, required=True, help="roller inertia [kg m^2]")
    sp.add_argument("--k", type=float, default=1000.0, help="tape stiffness [N/m] (1000)")
    sp.add_argument("--R", type=float, default=0.1, help="roller radius [m] (0.1)")
    sp.add_argument("--l", type=float, default=1.0, help="roller-motor distance [m] (1)")
    sp.add_argument("--geometry", choices=GEOMETRIES, default="paper")
    sp.add_argument("--t-end", type=float, required=True, help="final time [s]")
    sp.add_argument("--alpha0", type=float, default=0.0)
    sp.add_argument("--omega0", type=float, default=None, help="default V/R")
    sp.add_argument("--F0", type=float, default=None, help="default 1.01 f(V, V)")
    sp.add_argument("--branch0", choices=("AB", "CD"), default=None, help="default: lowest-velocity stable root")
    sp.add_argument("--method", choices=("hybrid", "regularized"), default="hybrid")
    sp.add_argument("--solver", choices=("Radau", "BDF", "LSODA"), default=None,
                    help="for --method regularized (Radau)")
    sp.add_argument("--rtol", type=float, default=1e-8)
    sp.add_argument("--eps", type=float, default=None, help="regularisation epsilon (regularized only; 1e-7)")
    sp.add_argument("--max-wall", type=positive_float, default=600.0, metavar="S",
                    help="wall-clock budget of the integration [s] (600)")
    sp.add_argument("--t-transient", type=float, default=0.0, help="store nothing before this time [s]")
    sp.add_argument("--jumps-only", action="store_true", help="store only the jumps (long runs)")
    sp.add_argument("--out", help="write the trajectory to this .npz")
    sp.add_argument("--jumps-csv", help="write the jumps to this CSV")
    sp.add_argument("--plot", help="write F(t), alpha(t), v(t) and the v-F plane to this image")
    sp.add_argument("--format", choices=("table", "json"), default="table", help="summary format")
    sp.add_argument("--quiet", action="store_true", help="no progress on stderr")
    sp.set_defaults(func=_simulate)

    fo = sub.add_parser("folds", help="folds, landing velocities and fixed point of f(v, V)")
    fo.add_argument("--V", type=float, required=True)
    fo.add_argument("--format", choices=("table", "json"), default="table")
    fo.set_defaults(func=_folds)

    es = sub.add_parser("estimate", help="regime estimate from the reduced equations (no DAE solve)")
    _add_params(es)
    es.add_argument("--alpha-min", type=float, default=None, help="for the force bound f_max/(1+sin alpha_min)")
    es.add_argument("--alpha-max", type=float, default=None, help="for the force bound f_min/(1+sin alpha_max)")
    es.add_argument("--format", choices=("table", "json"), default="table")
    es.add_argument("--out", help="also write the estimate to this .csv or .json")
    es.set_defaults(func=_estimate)

    from ._segment import ALPHA_MODELS, V_EQUATIONS

    sg = sub.add_parser("segment", help="one branch from the reduced v equation coupled to an alpha model")
    _add_params(sg)
    sg.add_argument("--branch", choices=("AB", "CD"), required=True)
    sg.add_argument("--F-in", type=float, required=True, help="pull force at entry [N]")
    sg.add_argument("--alpha-in", type=float, default=None, help="peel angle at entry [rad]")
    sg.add_argument("--alphadot-in", type=float, default=None, help="its rate at entry [rad/s]")
    sg.add_argument("--amplitude", type=float, default=None, help="sinusoid amplitude (alpha-model sinusoid)")
    sg.add_argument("--phase", type=float, default=None, help="sinusoid phase (alpha-model sinusoid)")
    sg.add_argument("--v-in", type=float, default=None, help="entry velocity (default: landing velocity)")
    sg.add_argument("--v-f", type=float, default=None, help="exit velocity (default: the branch's fold)")
    sg.add_argument("--alpha-model", choices=ALPHA_MODELS, default="approxalpha")
    sg.add_argument("--v-equation", choices=V_EQUATIONS, default="approxvdot")
    sg.add_argument("--rtol", type=float, default=1e-10)
    sg.add_argument("--format", choices=("table", "json"), default="table")
    sg.add_argument("--out", help="also write the summary to this .csv or .json")
    sg.add_argument("--curves", help="write t, v, F, alpha, alphadot to this .csv or .json")
    sg.add_argument("--plot", help="write v(t), alpha(t), F(t) to this image")
    sg.set_defaults(func=_segment)

    cp = sub.add_parser("compare", help="the paper's approximate-vs-exact scenes, error tables and Figs. 8-9")
    cp.add_argument("--scene", action="append", metavar="NAME",
                    help="run only this scene (repeatable); default all. Names: see `--list`")
    cp.add_argument("--list", action="store_true", help="list the scenes and exit")
    cp.add_argument("--format", choices=("md", "csv", "json"), default="md", help="what to print (md)")
    cp.add_argument("--out", metavar="DIR",
                    help="write DIR/tables.md, DIR/compare_rows.{csv,json}, DIR/compare_statistics.{csv,json} "
                         "and DIR/figures/fig8_ab.png, fig8_cd.png, fig9.png")
    cp.add_argument("--no-stats", action="store_true", help="skip the per-regime error statistics")
    cp.add_argument("--no-figures", action="store_true", help="do not draw Figs. 8-9 (with --out)")
    cp.set_defaults(func=_compare)

    bm = sub.add_parser("benchmark", help="work-precision vs the paper's regularised scheme and peers, ε study, "
                                          "speed targets (minutes)")
    bm.add_argument("--quick", action="store_true", help="thinner grids, ε = 1e-7 only (< 5 min on 2 cores)")
    bm.add_argument("--no-peers", action="store_true", help="skip the optional SUNDIALS/diffsol peers")
    bm.add_argument("--format", choices=("md", "csv", "json"), default="md", help="what to print (md)")
    bm.add_argument("--out", metavar="DIR", help="write DIR/benchmark.md, work_precision.{csv,json,png}, "
                                                 "eps_study.{csv,json,png}, ratios.{csv,json}, targets.{csv,json}")
    bm.set_defaults(func=_benchmark)

    sw = sub.add_parser("sweep", help="measures over an (I, V) grid on a process pool or a dask cluster; "
                                      "incremental output, resumes automatically")
    sw.add_argument("--I", required=True, metavar="SPEC",
                    help="roller inertias [kg m^2]: start:stop:num[:log] or a comma list, e.g. 1e-5:1e-2:8:log")
    sw.add_argument("--V", required=True, metavar="SPEC", help="pull speeds [m/s], same syntax, e.g. 0.4:4:10")
    sw.add_argument("--measure", default="regime", metavar="NAMES",
                    help="comma-separated measures (regime; jumps; others registered via register_measure)")
    sw.add_argument("--out", required=True, metavar="DIR",
                    help="output directory: sweep.json, results.jsonl (one line per point), results.csv; "
                         "an existing DIR with the same grid, measures and options is resumed")
    where = sw.add_mutually_exclusive_group()
    where.add_argument("--workers", type=int, default=None, metavar="N",
                       help="local worker processes (default: all CPUs; 0: in this process)")
    where.add_argument("--dask-local", type=int, default=None, metavar="N",
                       help="start a dask LocalCluster with N single-threaded worker processes")
    where.add_argument("--dask-scheduler", default=None, metavar="ADDR",
                       help="connect to a running dask scheduler, e.g. tcp://host:8786")
    sw.add_argument("--t-end", type=float, default=None, help="final time [s] (jumps, period: t_transient + 20)")
    sw.add_argument("--t-transient", type=float, default=None, help="transient skipped [s] (30)")
    sw.add_argument("--rtol", type=float, default=None, help="solver tolerance (jumps, period: 1e-10)")
    sw.add_argument("--alpha0", type=float, default=None, help="initial peel angle [rad] (0)")
    sw.add_argument("--k", type=float, default=None, help="tape stiffness [N/m] (1000)")
    sw.add_argument("--R", type=float, default=None, help="roller radius [m] (0.1)")
    sw.add_argument("--retry-failed", action="store_true",
                    help="compute again the points of DIR whose status is an error (else they count as done)")
    sw.add_argument("--plot", metavar="KEY", help="draw KEY over (V, I) to DIR/KEY.png, e.g. regime_label")
    sw.add_argument("--format", choices=("md", "csv", "json"), default="md", help="table printed at the end (md)")
    sw.add_argument("--quiet", action="store_true", help="no per-point progress on stderr")
    sw.set_defaults(func=_sweep)

    fg = sub.add_parser("figures", help="the paper's Figs. 2-9 from our exact solutions")
    fg.add_argument("--only", action="append", metavar="NAME", help="draw only this figure (repeatable): fig2 … fig9")
    fg.add_argument("--out", default="docs/figures", help="output directory (docs/figures)")
    fg.add_argument("--markdown", metavar="PATH", help="also write the captioned page, e.g. docs/figures.md")
    fg.add_argument("--list", action="store_true", help="list the figures and exit")
    fg.set_defaults(func=_figures)

    dy = sub.add_parser("dynamics", help="period of the return map, force drops, settle time, attractors, "
                                         "Lyapunov exponent at one (V, I)")
    _add_params(dy)
    dy.add_argument("--alpha0", type=float, default=0.0)
    dy.add_argument("--t-transient", type=nonnegative_float, default=T_TRANSIENT,
                    help=f"discarded [s] ({T_TRANSIENT:g})")
    dy.add_argument("--window", type=positive_float, default=20.0, help="analysed [s] (20)")
    dy.add_argument("--rtol", type=float, default=1e-10)
    dy.add_argument("--max-period", type=positive_int, default=32)
    dy.add_argument("--lyapunov", action="store_true", help="also the largest Lyapunov exponent (a few s)")
    dy.add_argument("--lyapunov-method", choices=LYAPUNOV_METHODS,
                    help="how (implies --lyapunov): two-trajectory renormalisation (the default), saltation "
                         "(tangent dynamics with saltation matrices), return-map (tangent of the jump-to-jump "
                         "map), regularized (variational equations of the ε-system; needs pydiffsol)")
    dy.add_argument("--lyapunov-time", type=positive_float, default=50.0, help="measured time [s] (50)")
    dy.add_argument("--eps", type=float, default=1e-7, help="ε of --lyapunov-method regularized (1e-7)")
    dy.add_argument("--attractors", type=finite_float_list, metavar="A0,A0,...",
                    help="sample these initial peel angles for coexisting attractors")
    dy.add_argument("--format", choices=("table", "json"), default="table")
    dy.add_argument("--out", help="also write the summary row to this .csv or .json")
    dy.add_argument("--max-wall", type=positive_float, default=600.0, metavar="S",
                    help="wall-clock budget of each computation (run, two-trajectory λ, attractors) [s] (600)")
    dy.set_defaults(func=_dynamics)
    return ap


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line on ``argv`` (default ``sys.argv[1:]``); returns the exit status.

    User errors end in ``SystemExit`` with one line on stderr (module docstring
    for the statuses); any other exception is a bug and propagates with its
    traceback.
    """
    ap = build_parser()
    args = ap.parse_args(argv)
    try:
        return args.func(args)
    except Exception as exc:
        status = _exit_status(exc)
        if status is None:  # not a user error or a documented stop: a bug, with its traceback
            raise
        ap.exit(status, f"peelapprox {args.command}: error: {one_line(exc)}\n")


def _loaded(module: str, name: str) -> tuple[type, ...]:
    """``module.name`` if the subcommand imported that module, else nothing (the CLI loads no package it does
    not use: ``peelapprox folds`` never imports the harness)."""
    mod = sys.modules.get(module)
    return (getattr(mod, name),) if mod is not None else ()


def _exit_status(exc: BaseException) -> int | None:
    """2 for a bad argument, output path or missing optional package; 3 when the model or solver stopped; 1
    when writing failed after the checks (disk full, a path changed meanwhile); None for anything else."""
    from ._diffsl import PeerUnavailableError
    from .errors import ModelBreakdown, SolverBudgetExceeded, SolverFailure

    if isinstance(exc, (ValueError, PeerUnavailableError)):
        return 2
    if isinstance(exc, (ModelBreakdown, SolverBudgetExceeded, SolverFailure,
                        *_loaded("comparisons._runs", "TransientNotPassed"))):
        return 3
    if isinstance(exc, OSError):
        return 1
    return None


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())

"""``peelapprox simulate``: integrate the full model (:func:`exact.simulate`) and summarise the run."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Mapping
from dataclasses import fields
from typing import Any

import numpy as np

from ._checks import check_output_path, positive_float, positive_int
from ._common import (
    FromMethods,
    HelpFromMethods,
    add_format,
    add_params,
    params_from_args,
    print_mapping,
    scipy_solvers,
    subcommand,
    variant_summary,
)
from ._force import law_fields

__all__ = ["PLOT_SAMPLES", "add_parser", "run"]

#: The points ``--plot`` samples its window at (by the solver's dense output, besides the stored steps).
PLOT_SAMPLES = 4000


def _default_solver(method: Any) -> str:
    return str(next(f.default for f in fields(method) if f.name == "solver"))


def _method_help(methods: Mapping[str, Any]) -> str:
    return "; ".join(f"{name}: {m.about}" for name, m in methods.items()) + (
        " (default: the model's, the first of these that solves it)")


def _solver_help(methods: Mapping[str, Any]) -> str:
    return "scipy solver of " + "; ".join(
        f"--method {name}: {', '.join(m.solvers)} (default: {_default_solver(m)})"
        for name, m in methods.items() if m.solvers)


def add_parser(sub) -> argparse.ArgumentParser:
    sp = subcommand(
        sub, "simulate", help="integrate the full model (exact solution)",
        description="Integrate the full model (the DAE of the paper, its jumps between the branches of f(v, V) "
                    "included) from an initial state and print a summary of the run: steps, jumps, the force at "
                    "the jumps, the final state, by one of exact.simulate's solver methods (--method, --solver).  "
                    "The model variants: --tape-mass (the peeled ribbon's mass, docs/tape-mass.md) and "
                    "--loading load --load-mass [--load] (a constant load instead of a constant pull speed; the "
                    "pull speed Vp is then a state, in the summary and the plot; docs/constant-load.md).",
        examples=["peelapprox simulate --V 1 --I 1e-2 --t-end 20 --t-transient 10 --plot fig4.png --out run.npz",
                  "peelapprox simulate --V 4 --I 1e-2 --t-end 200 --jumps-only --jumps-csv jumps.csv",
                  "peelapprox simulate --V 1.2 --I 1e-5 --t-end 1 --force-family cubic --coef c=280",
                  "peelapprox simulate --V 1 --I 1e-2 --t-end 1 --method regularized --eps 1e-7 --format json",
                  "peelapprox simulate --V 1 --I 1e-5 --t-end 0.05 --tape-mass 1e-4 --solver LSODA",
                  "peelapprox simulate --V 1 --I 1e-5 --t-end 0.05 --loading load --load-mass 25 --load 245"])
    add_params(sp)
    g = sp.add_argument_group("the run")
    g.add_argument("--t-end", type=float, required=True, help="final time [s]")
    g.add_argument("--alpha0", type=float, default=0.0, help="initial peel angle [rad]")
    g.add_argument("--omega0", type=float, default=None, help="initial roller speed [rad/s] (default: V/R)")
    g.add_argument("--F0", type=float, default=None, help="initial pull force [N] (default: 1.01 f(V, V))")
    g.add_argument("--branch0", choices=("AB", "CD"), default=None,
                   help="initial branch of f (default: the lowest-velocity stable root)")
    g.add_argument("--method", choices=FromMethods(lambda methods: methods), default=None,
                   help=HelpFromMethods("the solver method", _method_help))
    g.add_argument("--solver", default=None, help=HelpFromMethods("the scipy solver", _solver_help),
                   choices=FromMethods(scipy_solvers))
    g.add_argument("--rtol", type=float, default=1e-8, help="relative tolerance of the integration")
    g.add_argument("--eps", type=float, default=None,
                   help="the paper's regularisation parameter epsilon of --method regularized (default: 1e-7)")
    g.add_argument("--max-wall", type=positive_float, default=600.0, metavar="S",
                   help="wall-clock budget of the integration [s]")
    g.add_argument("--t-transient", type=float, default=0.0, help="store nothing before this time [s]")
    g.add_argument("--jumps-only", action="store_true", help="store only the jumps (long runs)")
    o = sp.add_argument_group("output")
    add_format(o)
    o.add_argument("--out", help="write the trajectory to this .npz")
    o.add_argument("--jumps-csv", help="write the jumps to this CSV")
    o.add_argument("--plot", help="write F(t), alpha(t), v(t) and the v-F plane to this image (.png, .pdf, .svg, ...)")
    o.add_argument("--plot-cycles", type=positive_int, default=5, metavar="N",
                   help="--plot shows at least the last N stick-slip cycles (AB->CD jump to AB->CD jump), whole "
                        "periods of the return map when the run has settled on a periodic orbit")
    o.add_argument("--plot-all", action="store_true", help="--plot shows the whole stored run")
    o.add_argument("--quiet", action="store_true", help="no progress on stderr")
    return sp


def run(args: argparse.Namespace) -> int:
    from exact import simulate

    if args.plot and args.jumps_only:
        raise ValueError("--plot needs stored steps; drop --jumps-only")
    out = check_output_path(args.out, "npz", "--out") if args.out else None
    jumps_csv = check_output_path(args.jumps_csv, "file", "--jumps-csv") if args.jumps_csv else None
    plot = check_output_path(args.plot, "image", "--plot") if args.plot else None
    params = params_from_args(args)
    law = params.force
    kwargs: dict[str, Any] = dict(alpha0=args.alpha0, omega0=args.omega0, F0=args.F0, branch0=args.branch0,
                                  method=args.method, solver=args.solver, rtol=args.rtol, eps=args.eps,
                                  t_transient=args.t_transient, max_wall=args.max_wall)
    traj = simulate(params, args.t_end, save="jumps" if args.jumps_only else "steps", progress=not args.quiet,
                    **kwargs)
    s = traj.stats
    summary: dict[str, Any] = {
        "V": params.V,
        "I": params.I,
        **variant_summary(params),
        "method": traj.method,
        "solver": traj.solver,
        "rtol": traj.rtol,
        "t_end": traj.t_end,
        "points": int(len(traj.t)),
        "jumps": int(len(traj.jumps)),
        "steps": s.n_steps,
        "rejected": s.n_rejected if s.n_rejected is not None else f"not reported by {traj.solver}",
        "rhs_evaluations": s.n_rhs,
        "wall_time_s": round(s.wall_time, 6),
        "compile_time_s": round(s.compile_time, 3),
        "final_state": traj.final_state.as_dict(),
    }
    if traj.Vp is not None and len(traj.Vp):
        summary["Vp_range"] = [float(traj.Vp.min()), float(traj.Vp.max())]
    if len(traj.jumps):
        summary["F_at_jumps_range"] = [float(traj.jumps.F.min()), float(traj.jumps.F.max())]
    summary.update(law_fields(law, spec=args.format == "json"))
    print_mapping(summary, args.format)
    if out:
        traj.to_npz(out)  # records the law: its params (with force) as dataclasses.asdict
        print(f"wrote {out}", file=sys.stderr)
    if jumps_csv:
        traj.jumps.to_csv(jumps_csv, extra=law_fields(law))  # the run's law on every row
        print(f"wrote {jumps_csv}", file=sys.stderr)
    if plot:
        from ..plotting import plot_trajectory, trajectory_window

        cycles = None if args.plot_all else args.plot_cycles
        w = trajectory_window(traj, cycles)
        # smooth curves: the same run again (the same steps, ~the first run's cost) up to the window's end,
        # sampled densely over the window by the solver's own dense output, merged with the stored steps
        dense = simulate(params, w.end, **{**kwargs, "t_eval": np.linspace(w.start, w.end, PLOT_SAMPLES),
                                           "save": "steps", "progress": False}) if w.end > w.start else None
        plot_trajectory(traj, plot, cycles=cycles, dense=dense)
        print(f"wrote {plot}", file=sys.stderr)
    return 0

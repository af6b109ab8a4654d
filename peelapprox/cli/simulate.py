"""``peelapprox simulate``: integrate the full model (:func:`exact.simulate`) and summarise the run."""

from __future__ import annotations

import argparse
import json
import sys

from .. import GEOMETRIES, PeelParams
from ._checks import check_output_path, positive_float
from ._common import add_params
from ._force import force_from_args, law_fields

__all__ = ["add_parser", "run"]


def add_parser(sub) -> argparse.ArgumentParser:
    sp = sub.add_parser("simulate", help="integrate the full model (exact solution)")
    add_params(sp)
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
    return sp


def run(args: argparse.Namespace) -> int:
    from exact import simulate

    if args.plot and args.jumps_only:
        raise ValueError("--plot needs stored steps; drop --jumps-only")
    out = check_output_path(args.out, "npz", "--out") if args.out else None
    jumps_csv = check_output_path(args.jumps_csv, "file", "--jumps-csv") if args.jumps_csv else None
    plot = check_output_path(args.plot, "image", "--plot") if args.plot else None
    law = force_from_args(args)
    params = PeelParams(V=args.V, I=args.I, k=args.k, R=args.R, l=args.l, geometry=args.geometry, force=law)
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
        save="jumps" if args.jumps_only else "steps",
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
    summary.update(law_fields(law, spec=args.format == "json"))
    if args.format == "json":
        print(json.dumps(summary, indent=2))
    else:
        for key, val in summary.items():
            print(f"{key:>18}: {val}")
    if out:
        traj.to_npz(out)  # records the law: its params (with force) as dataclasses.asdict
        print(f"wrote {out}", file=sys.stderr)
    if jumps_csv:
        traj.jumps.to_csv(jumps_csv, extra=law_fields(law))  # the run's law on every row
        print(f"wrote {jumps_csv}", file=sys.stderr)
    if plot:
        from ..plotting import plot_trajectory

        plot_trajectory(traj, plot)
        print(f"wrote {plot}", file=sys.stderr)
    return 0

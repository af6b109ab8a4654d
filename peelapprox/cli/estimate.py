"""``peelapprox folds | estimate | segment``: the core's own answers, from the peel-force law and the reduced
equations (no DAE solve, neither ``exact`` nor ``comparisons`` is imported)."""

from __future__ import annotations

import argparse
import json
import sys

from .. import ALPHA_MODELS, V_EQUATIONS, PeelParams
from ._checks import check_output_path
from ._common import add_params, print_mapping, write_table
from ._force import add_force_options, force_from_args, law_fields

__all__ = ["add_estimate_parser", "add_folds_parser", "add_segment_parser", "run_estimate", "run_folds", "run_segment"]


def add_folds_parser(sub) -> argparse.ArgumentParser:
    fo = sub.add_parser("folds", help="folds, landing velocities and fixed point of f(v, V) (the paper's fvV or "
                                      "the law given)")
    fo.add_argument("--V", type=float, required=True)
    add_force_options(fo)
    fo.add_argument("--format", choices=("table", "json"), default="table")
    return fo


def run_folds(args: argparse.Namespace) -> int:
    from .. import branch_structure, fixed_point

    law = force_from_args(args)
    if law.kind == "paper":
        bs = branch_structure(args.V)
        fp = fixed_point(args.V)
        row = {**bs.__dict__, "fixed_point_stable": fp.stable, "fprime_at_V": fp.fprime}
    else:  # the law's own folds (PeelForce.folds) and the steady sliding v = V, stable iff f'(V, V) > 0
        import dataclasses

        fprime = float(law.df(args.V, args.V))
        row = {**dataclasses.asdict(law.folds(args.V)), "fixed_point_stable": fprime > 0, "fprime_at_V": fprime}
    row.update(law_fields(law, spec=args.format == "json"))
    if args.format == "json":
        print(json.dumps(row, indent=2))
    else:
        for key, val in row.items():
            print(f"{key:>18}: {val}")
    return 0


def add_estimate_parser(sub) -> argparse.ArgumentParser:
    es = sub.add_parser("estimate", help="regime estimate from the reduced equations (no DAE solve)")
    add_params(es)
    es.add_argument("--alpha-min", type=float, default=None, help="for the force bound f_max/(1+sin alpha_min)")
    es.add_argument("--alpha-max", type=float, default=None, help="for the force bound f_min/(1+sin alpha_max)")
    es.add_argument("--format", choices=("table", "json"), default="table")
    es.add_argument("--out", help="also write the estimate to this .csv or .json")
    return es


def run_estimate(args: argparse.Namespace) -> int:
    from .. import estimate

    out = check_output_path(args.out, "table", "--out") if args.out else None
    law = force_from_args(args)
    params = PeelParams(V=args.V, I=args.I, k=args.k, R=args.R, force=law)
    row = estimate(params, alpha_min=args.alpha_min, alpha_max=args.alpha_max).as_dict()
    print_mapping({**row, **law_fields(law, spec=args.format == "json")}, args.format)
    if out:
        write_table(out, [row], law)
    return 0


def add_segment_parser(sub) -> argparse.ArgumentParser:
    sg = sub.add_parser("segment", help="one branch from the reduced v equation coupled to an alpha model")
    add_params(sg)
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
    return sg


def run_segment(args: argparse.Namespace) -> int:
    from .. import reduced_segment

    out = check_output_path(args.out, "table", "--out") if args.out else None
    curves = check_output_path(args.curves, "table", "--curves") if args.curves else None
    plot = check_output_path(args.plot, "image", "--plot") if args.plot else None
    law = force_from_args(args)
    params = PeelParams(V=args.V, I=args.I, k=args.k, R=args.R, force=law)
    entry = dict(F_in=args.F_in, alpha_in=args.alpha_in, alphadot_in=args.alphadot_in, amplitude=args.amplitude,
                 phase=args.phase, v_in=args.v_in, v_f=args.v_f, alpha_model=args.alpha_model,
                 v_equation=args.v_equation, rtol=args.rtol)
    seg = reduced_segment(params, args.branch, **entry)
    print_mapping({**seg.as_dict(), **law_fields(law, spec=args.format == "json")}, args.format)
    if out:
        write_table(out, [seg.as_dict()], law)
    if curves or plot:
        # smooth curves: the same integration again, sampled by dense output
        import numpy as np

        seg = reduced_segment(params, args.branch, **entry, t_eval=np.linspace(0.0, seg.dt, 801)[:-1])
    if curves:
        rows = [dict(t=float(a), v=float(b), F=float(c), alpha=float(d), alphadot=float(e))
                for a, b, c, d, e in zip(seg.t, seg.v, seg.F, seg.alpha, seg.alphadot)]
        write_table(curves, rows, law)
    if plot:
        from ..plotting import plot_segment

        plot_segment(seg, plot)
        print(f"wrote {plot}", file=sys.stderr)
    return 0

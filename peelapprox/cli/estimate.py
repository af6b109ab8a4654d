"""``peelapprox folds | estimate | segment``: the core's own answers, from the peel-force law and the reduced
equations (no DAE solve, neither ``exact`` nor ``comparisons`` is imported)."""

from __future__ import annotations

import argparse
import sys

from .. import ALPHA_MODELS, V_EQUATIONS
from ._checks import check_output_path
from ._common import REDUCED_ONLY, add_format, add_params, params_from_args, print_mapping, subcommand, write_table
from ._force import add_force_options, force_from_args, law_fields

__all__ = ["add_estimate_parser", "add_folds_parser", "add_segment_parser", "run_estimate", "run_folds", "run_segment"]


def add_folds_parser(sub) -> argparse.ArgumentParser:
    fo = subcommand(
        sub, "folds", help="folds, landing velocities and fixed point of f(v, V) (the paper's fvV or the law given)",
        description="The branch structure of the peel-force law f(v, V) at one pull speed V: its folds B (v_max, "
                    "f_max) and D (v_min, f_min), where a jump lands on the other branch (v_land_ab, v_land_cd), "
                    "and whether steady peeling at v = V is stable (f'(V, V) > 0).  Needs no solver.",
        examples=["peelapprox folds --V 4 --format json",
                  "peelapprox folds --V 1 --force-family cubic --coef c=280"])
    fo.add_argument("--V", type=float, required=True, help="pull speed [m/s]")
    add_force_options(fo)
    add_format(fo)
    return fo


def run_folds(args: argparse.Namespace) -> int:
    from .. import branch_structure, fixed_point

    law = force_from_args(args)
    fp = fixed_point(args.V, force=law)  # the steady sliding v = V, stable iff f'(V, V) > 0
    row = {**branch_structure(args.V, force=law).__dict__, "fixed_point_stable": fp.stable, "fprime_at_V": fp.fprime}
    row.update(law_fields(law, spec=args.format == "json"))
    print_mapping(row, args.format)
    return 0


def add_estimate_parser(sub) -> argparse.ArgumentParser:
    es = subcommand(
        sub, "estimate", help="regime estimate from the reduced equations (no DAE solve)",
        description="The paper's regime of (V, I) from the reduced equations in closed form (no DAE solve): the "
                    "folds, the fixed point, the periods and stick/slip times, and the labels inertia (low, "
                    "intermediate, high) and velocity (stable, low, high) with the rules that set them.",
        examples=["peelapprox estimate --V 1 --I 1e-2 --format json",
                  "peelapprox estimate --V 1 --I 1e-5 --attractor",
                  "peelapprox estimate --V 4 --I 1e-5 --alpha-min -0.3 --alpha-max 0.3 --out estimate.csv"])
    add_params(es, geometry=False, variants=REDUCED_ONLY)
    es.add_argument("--alpha-min", type=float, default=None,
                    help="peel angle [rad] of the force bound f_max/(1+sin alpha_min) (default: no bound)")
    es.add_argument("--alpha-max", type=float, default=None,
                    help="peel angle [rad] of the force bound f_min/(1+sin alpha_max) (default: no bound)")
    es.add_argument("--attractor", action="store_true",
                    help="also predict the stick-slip attractor from the reduced equations (approximate_attractor: "
                         "slip interval, force drop, slip and stick times, force extremes, period; milliseconds) "
                         "and say how often such a prediction held in this regime, as the atlas measured it")
    add_format(es, "the estimate")
    es.add_argument("--out", help="also write the estimate to this .csv or .json")
    return es


def run_estimate(args: argparse.Namespace) -> int:
    from .. import estimate

    out = check_output_path(args.out, "table", "--out") if args.out else None
    params = params_from_args(args)
    law = params.force
    est = estimate(params, alpha_min=args.alpha_min, alpha_max=args.alpha_max)
    row = est.as_dict()
    if args.attractor:
        att = est.attractor().as_dict()
        row.update({f"attractor_{k}": v for k, v in att.items() if k not in ("V", "I")})
        row.update({f"validity_{k}": v for k, v in est.validity.items()})
    print_mapping({**row, **law_fields(law, spec=args.format == "json")}, args.format)
    if out:
        write_table(out, [row], law)
    return 0


def add_segment_parser(sub) -> argparse.ArgumentParser:
    sg = subcommand(
        sub, "segment", help="one branch from the reduced v equation coupled to an alpha model",
        description="One stay on a branch of f (AB: stick, v rising to the fold B; CD: slip, v falling to the fold "
                    "D) by the paper's reduced equations: the v equation (approxvdot or fullvdot) coupled to an "
                    f"alpha model; prints its duration dt and force change dF.  alpha models: "
                    f"{', '.join(ALPHA_MODELS)}; v equations: {', '.join(V_EQUATIONS)}.",
        examples=["peelapprox segment --V 1 --I 1e-2 --branch CD --F-in 295.6 --alpha-in -0.0304 "
                  "--alphadot-in -160 --v-in 15.54 --v-f 8.7 --alpha-model airy2 --plot cd.png",
                  "peelapprox segment --V 1 --I 1e-2 --branch AB --F-in 200 --alpha-in 0 --alphadot-in 0 "
                  "--format json"])
    add_params(sg, geometry=False, variants=REDUCED_ONLY)
    sg.add_argument("--branch", choices=("AB", "CD"), required=True, help="AB: v rises to v_max; CD: v falls to v_min")
    sg.add_argument("--F-in", type=float, required=True, help="pull force at entry [N]")
    sg.add_argument("--alpha-in", type=float, default=None,
                    help="peel angle at entry [rad] (default: none; every alpha model needs it, but sinusoid given "
                         "--amplitude and --phase)")
    sg.add_argument("--alphadot-in", type=float, default=None,
                    help="its rate at entry [rad/s] (default: none; exponential and static derive it, the "
                         "others need it)")
    sg.add_argument("--amplitude", type=float, default=None,
                    help="amplitude [rad] of --alpha-model sinusoid (default: from --alpha-in, --alphadot-in)")
    sg.add_argument("--phase", type=float, default=None,
                    help="phase [rad] of --alpha-model sinusoid (default: from --alpha-in, --alphadot-in)")
    sg.add_argument("--v-in", type=float, default=None, help="entry velocity [m/s] (default: the landing velocity)")
    sg.add_argument("--v-f", type=float, default=None, help="exit velocity [m/s] (default: the branch's fold)")
    sg.add_argument("--alpha-model", choices=ALPHA_MODELS, default="approxalpha", help="how alpha evolves")
    sg.add_argument("--v-equation", choices=V_EQUATIONS, default="approxvdot", help="the reduced v equation")
    sg.add_argument("--rtol", type=float, default=1e-10, help="relative tolerance of the integration")
    add_format(sg)
    sg.add_argument("--out", help="also write the summary to this .csv or .json")
    sg.add_argument("--curves", help="write t, v, F, alpha, alphadot to this .csv or .json")
    sg.add_argument("--plot", help="write v(t), alpha(t), F(t) to this image (.png, .pdf, .svg, ...)")
    return sg


def run_segment(args: argparse.Namespace) -> int:
    from .. import reduced_segment

    out = check_output_path(args.out, "table", "--out") if args.out else None
    curves = check_output_path(args.curves, "table", "--curves") if args.curves else None
    plot = check_output_path(args.plot, "image", "--plot") if args.plot else None
    params = params_from_args(args)
    law = params.force
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

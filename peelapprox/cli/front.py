"""``peelapprox front``: the peel front of N strips (:func:`exact.simulate_front`), its pattern and AE, a plot."""

from __future__ import annotations

import argparse
import sys
from typing import Any

import numpy as np

from ._checks import check_output_path
from ._common import add_format, add_params, params_from_args, print_mapping, subcommand, write_table

__all__ = ["add_parser", "run"]


def add_parser(sub) -> argparse.ArgumentParser:
    sp = subcommand(
        sub, "front", help="the peel front of N strips and its acoustic emission (needs --tape-mass)",
        description="Integrate the peel front (docs/peel-front.md): N strips across the tape's width sharing the "
                    "roller, coupled by a bond spring and a bond dissipation whose power is the acoustic emission "
                    "(AE).  Prints the run's counters, the mean front's jumps, the strips' branch switches, the AE "
                    "energy and the pattern class (smooth, rugged, stuck-peeled); --out writes the time series "
                    "(t, alpha, omega, F, v, ae_power, ae_energy, fraction_peeling, roughness, domain_walls), "
                    "--plot the space-time image of the front; --bursts the AE bursts' catalogue and a power-law fit "
                    "of their energies (docs/bursts.md), --out then writing the catalogue.",
        examples=["peelapprox front --V 1 --I 1e-2 --tape-mass 1e-3 --N 64 --gamma 0.05 --delta0 0.01 --t-end 0.03 "
                  "--plot front.png",
                  "peelapprox front --V 1 --I 1e-2 --tape-mass 1e-3 --N 1 --t-end 0.1 --format json"])
    add_params(sp)
    g = sp.add_argument_group("front (FrontParams)")
    g.add_argument("--N", type=int, required=True, help="number of strips, 1 to 100000")
    g.add_argument("--gamma", type=float, default=1.0, help="AE dissipation 4 N Gamma / |f'_u| (default 1)")
    g.add_argument("--kappa", type=float, default=1.0, help="bond stiffness 4 N k_c / k (default 1)")
    g.add_argument("--ends", choices=("free", "periodic"), default="free", help="the front's ends (default free)")
    g.add_argument("--delta0", type=float, default=0.0, help="initial spread of the stretches, 0 to 0.5 (default 0)")
    g.add_argument("--seed", type=int, default=0, help="seed of the initial spread (default 0)")
    r = sp.add_argument_group("run")
    r.add_argument("--t-end", type=float, required=True, help="final time [s]")
    r.add_argument("--rtol", type=float, default=1e-8, help="relative tolerance (default 1e-8)")
    r.add_argument("--dt-save", type=float, default=None,
                   help="store on the grid k*dt_save [s] (default: every accepted step)")
    r.add_argument("--max-wall", type=float, default=600.0, help="wall-clock budget [s] (default 600)")
    r.add_argument("--out", default=None, help="write the time series to this .csv or .json file")
    r.add_argument("--plot", default=None, help="write the space-time image of the front to this image file")
    b = sp.add_argument_group("bursts (docs/bursts.md)")
    b.add_argument("--bursts", action="store_true",
                   help="catalogue the AE power's bursts (FrontTrajectory.bursts), print its summary and a power-law "
                        "fit of the burst energies (fit_power_law) with its 95%% interval; with --out, write the "
                        "catalogue instead of the time series")
    b.add_argument("--threshold", type=float, default=None,
                   help="burst threshold on the AE power [W], >= 0 (default 0.05 x the largest AE power)")
    b.add_argument("--min-gap", type=float, default=0.0, help="merge bursts closer than this [s] (default 0)")
    b.add_argument("--min-tail", type=int, default=50, help="fewest bursts in the fitted tail, >= 5 (default 50)")
    add_format(sp)
    return sp


def run(args: argparse.Namespace) -> int:
    from exact import simulate_front

    from .. import FrontParams

    if not args.bursts and (args.threshold is not None or args.min_gap != 0.0):
        raise ValueError("--threshold and --min-gap need --bursts")
    if args.threshold is not None and not (np.isfinite(args.threshold) and args.threshold >= 0):
        raise ValueError(f"--threshold must be a finite AE power >= 0 [W], got {args.threshold!r}")
    if args.min_tail < 5:
        raise ValueError(f"--min-tail must be >= 5, got {args.min_tail!r}")
    out = check_output_path(args.out, "table", "--out") if args.out else None
    plot = check_output_path(args.plot, "image", "--plot") if args.plot else None
    fp = FrontParams(base=params_from_args(args), N=args.N, gamma=args.gamma, kappa=args.kappa, ends=args.ends,
                     delta0=args.delta0, seed=args.seed)
    tr = simulate_front(fp, args.t_end, rtol=args.rtol, dt_save=args.dt_save, store_front=plot is not None,
                        max_wall=args.max_wall, progress=True if sys.stderr.isatty() else None)
    row = {"N": fp.N, "gamma": fp.gamma, "Gamma": fp.Gamma, "kappa": fp.kappa, "k_c": fp.k_c, "ends": fp.ends,
           "t_end": tr.t_end, "points": len(tr.t), "steps": tr.stats.n_steps, "rhs": tr.stats.n_rhs,
           "wall_time": tr.stats.wall_time, "jumps": len(tr.jumps), "local_switches": tr.n_local_switches,
           "ae_energy": float(tr.final_y[2]), "F_final": float(tr.F[-1]), "v_final": float(tr.v[-1])}
    if len(tr.t) >= 2:
        p = tr.pattern()
        row.update(pattern=p.label, roughness_mean=p.roughness, mixed_fraction=p.mixed_fraction, walls=p.walls)
    cat = _bursts(tr, args, row) if args.bursts else None
    print_mapping(row, args.format)
    if cat is not None and out is not None:
        cat.write(out)
        print(f"wrote {out}", file=sys.stderr)
    elif out is not None:
        keys = ("t", "alpha", "omega", "F", "v", "ae_power", "ae_energy", "fraction_peeling", "roughness",
                "domain_walls")
        cols = [getattr(tr, k) for k in keys]
        write_table(out, [dict(zip(keys, (float(c[i]) for c in cols))) for i in range(len(tr.t))])
    if plot is not None:
        from ..plotting import plot_front

        plot_front(tr, path=plot)
        print(f"wrote {plot}", file=sys.stderr)
    return 0


def _bursts(tr, args: argparse.Namespace, row: dict) -> Any:
    """The AE bursts' catalogue; adds its summary and a power-law fit of its energies to ``row``."""
    from .. import fit_power_law

    cat = tr.bursts(args.threshold, min_gap=args.min_gap)
    energy = cat.sizes("energy")
    row.update({"bursts": len(cat), "threshold": cat.threshold, "dropped": cat.n_dropped,
                "energy_median": float(np.median(energy)) if energy.size else None,
                "energy_max": float(energy.max()) if energy.size else None})
    if energy.size >= args.min_tail:
        fit = fit_power_law(energy, min_tail=args.min_tail, n_bootstrap=100, seed=0, max_wall=60.0)
        lo_hi = fit.alpha_interval
        row.update(alpha=fit.alpha, alpha_lo=None if lo_hi is None else lo_hi[0],
                   alpha_hi=None if lo_hi is None else lo_hi[1], xmin=fit.xmin, n_tail=fit.n_tail, ks=fit.ks,
                   fit_status=fit.status, fit_message=fit.message)
    else:
        row.update(alpha=None, fit_message=f"no power-law fit: {energy.size} burst energies, fewer than "
                                           f"--min-tail {args.min_tail}")
    return cat

"""``peelapprox warmup | doctor``: compile the kernels of a user's first calls ahead of time, and say what the private
kernel cache holds (where, for which CPU, whether private and fresh)."""

from __future__ import annotations

import argparse
import json
import sys

from ._common import add_format, add_max_wall_option, print_mapping, subcommand

__all__ = ["add_doctor_parser", "add_warmup_parser", "run_doctor", "run_warmup"]


def add_warmup_parser(sub) -> argparse.ArgumentParser:
    wu = subcommand(
        sub, "warmup", help="compile the kernels of the first calls into the private cache (a first call in ~1 s)",
        description="Compile, or load, every kernel a user's first calls need (simulate with the paper's law, "
                    "approximate_attractor, attractor_observables) into the private kernel cache "
                    "(~/.cache/peelapprox/numba, or NUMBA_CACHE_DIR when it is private), so that the first such call "
                    "of a later process loads them instead of compiling (exact.compile_kernels).  A stale or "
                    "foreign cache is rebuilt, never used.  With --cpu generic the kernels are compiled for any "
                    "machine of this architecture, for a cache several machines share (run them with "
                    "NUMBA_CPU_NAME=generic).",
        examples=["peelapprox warmup", "peelapprox warmup --cpu generic", "peelapprox warmup --format json"])
    wu.add_argument("--cpu", default=None, metavar="NAME",
                    help="CPU to compile for, numba's NUMBA_CPU_NAME (generic: any machine of this architecture; "
                         "default: this one)")
    add_format(wu, "the report")
    add_max_wall_option(wu, what="the warm-up")
    return wu


def run_warmup(args: argparse.Namespace) -> int:
    from exact import compile_kernels

    def say(line: str) -> None:
        print(f"peelapprox warmup: {line}", file=sys.stderr, flush=True)

    r = compile_kernels(cpu=args.cpu, progress=say, max_wall=args.max_wall)
    if args.format == "table":
        print(r.message)
    else:
        print_mapping(dict(status=r.status, message=r.message, cpu=r.cpu, cache=r.cache, seconds=round(r.seconds, 3),
                           record=r.record, jobs=r.rows()), args.format)
    return 0 if r.status == 0 else 1


def add_doctor_parser(sub) -> argparse.ArgumentParser:
    dr = subcommand(
        sub, "doctor", help="what the kernel cache holds, where, for which CPU, whether it is private and fresh",
        description="Report the private kernel cache: its root and whether it is private (and any location "
                    "refused, with why), the expression-law directory, each folder with its number of kernels and "
                    "files (and files that would be refused), this process's CPU and versions, the warm-up records "
                    "(fresh or stale, for which CPU), and a verdict.  Reads no compiled kernel.",
        examples=["peelapprox doctor", "peelapprox doctor --format json"])
    add_format(dr, "the report")
    return dr


def run_doctor(args: argparse.Namespace) -> int:
    from ..kernels import cache_status

    s = cache_status()
    if args.format == "json":
        print(json.dumps(s, indent=2))
        return 0
    if args.format == "csv":
        print_mapping({k: v for k, v in s.items()}, "csv")
        return 0
    print(f"verdict: {s['verdict']}")
    print(f"kernel cache: {s['kernel_root'] or 'none'} (from {s['kernel_root_from']}; private, mode 0700)"
          if s["kernel_root"] else "kernel cache: none (kernels are compiled in every process)")
    if s["refused"]:
        print(f"refused: {s['refused']}")
    print(f"expression laws: {s['law_dir_used']}" + ("" if s["law_dir_used"] == s["law_dir"] else
                                                     f" (instead of {s['law_dir']})"))
    print(f"this process: CPU {s['cpu']}, numba {s['numba']}, Python {s['python']}, kernel sources {s['source_tag']}")
    for f in s["folders"]:
        bad = f"; {f['not_private']} files not private (refused when read)" if f["not_private"] else ""
        prob = f"; NOT PRIVATE: {f['problem']} (replaced when used)" if f["problem"] else ""
        print(f"  {f['folder']}: {f['kernels']} kernels, {f['data_files']} compiled files, "
              f"{f['bytes'] / 1e6:.1f} MB{bad}{prob}")
    for w in s["warmups"]:
        print(f"warm-up {w['written']} for CPU {w['cpu']}: {'fresh' if w['fresh'] else 'stale'}"
              f"{'' if w['this_cpu'] else ' (another CPU than this process)'}; {', '.join(map(str, w['jobs']))}")
    return 0

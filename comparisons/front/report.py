"""The peel front's reproduction report: ``python -m comparisons.front --size small|full --out DIR``.

What the follow-up papers claim (their abstracts only are public; docs/peel-front.md), measured on our
reconstruction with an ensemble on the sweep engine (:func:`comparisons.front.front_ensemble`):

1. **pattern maps** over the tape/roller inertia ratio r_m = m R²/I and V, one panel per dissipation γ: the
   class (smooth, rugged, stuck-peeled, unclassified) the majority of the seeds gives;
2. **burst exponents against V**: at the reference γ, the burst energies of every seed and r_m pooled at each V,
   one power law (:func:`peelapprox.fit_power_law`, KS-chosen xmin, bootstrap 95 % interval) and two regimes
   against one (:func:`peelapprox.fit_broken_power_law`, parametric-bootstrap likelihood ratio; "two" at
   p < 0.01);
3. **the chaotic window**: the twin-run Lyapunov exponent (:mod:`comparisons.front.measure`) against V, and the
   V where most seeds are chaotic (λ > 3 SE);
4. **burst-exponent stability**: at one cell, the exponent across the burst threshold, the sampling step,
   the seed and the initial heterogeneity δ₀, each against the base catalogue's interval.

Output, all in ``--out`` (7 files, no subfolder): ``report.md``, ``runs.csv`` (every run), ``exponents.csv``,
``stability.csv``, ``pattern_map.png``, ``exponents.png``, ``chaos.png``.  The ensemble's sweeps live in
``--work`` (default a fixed directory under the system's temporary directory, so the same command again resumes).
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import tempfile
import time
from collections.abc import Sequence
from typing import Any

import numpy as np

from exact import simulate_front
from peelapprox import (
    FrontParams,
    PeelParams,
    burst_catalogue,
    fit_broken_power_law,
    fit_power_law,
)
from peelapprox.io import ProgressLine, fmt_number, write_rows
from peelapprox.parallel import map_points

from .ensemble import FrontEnsemble, front_ensemble, inertia_of_ratio
from .measure import FRONT_DEFAULTS, measure_front

__all__ = ["SIZES", "PATTERN_COLOURS", "run_report", "burst_stability", "exponent_table", "cost_sample", "main"]

#: The report's sizes.  ``small``: a few minutes on 2 loaded cores; ``full``: 16 cores for ~4 minutes
#: (docs/peel-front.md, "Reproduction": the CPU seconds per run measured on the small size).
SIZES: dict[str, dict[str, Any]] = {
    "small": dict(r_m=(1e-3, 1e-1), V=(1.0, 2.0, 3.0), gammas=(0.1, 3.0), seeds=(0, 1), ref_r_m=1e-3, ref_gamma=0.1,
                  options=dict(front_N=16, front_t_transient=0.01, front_window=0.1, front_lyap_window=0.02),
                  stab=dict(V=1.0, r_m=1e-3, gamma=0.1, seeds=(0, 1, 2), window=0.1, thresholds=(0.01, 0.02, 0.05))),
    "full": dict(r_m=(1e-4, 1e-3, 1e-2, 1e-1), V=(1.0, 1.25, 1.5, 1.75, 2.0, 2.5, 3.0, 3.5, 4.0, 4.5),
                 gammas=(0.1, 1.0, 10.0), seeds=(0, 1, 2, 3), ref_r_m=1e-3, ref_gamma=0.1,
                 options=dict(front_N=16, front_t_transient=0.02, front_window=0.3, front_lyap_window=0.08),
                 stab=dict(V=1.0, r_m=1e-3, gamma=0.1, seeds=(0, 1, 2, 3), window=1.0,
                           thresholds=(0.01, 0.02, 0.05))),
}
#: Colours of the pattern classes in the map.
PATTERN_COLOURS = {"smooth": "#4c72b0", "rugged": "#dd8452", "stuck-peeled": "#c44e52", "unclassified": "#bbbbbb",
                   "breakdown": "#222222", "budget": "#8172b3", "failed": "#ffffff"}
TAPE_MASS, RADIUS = 1e-3, 0.1
#: Null catalogues of the broken-law test: p can reach 1/(1 + N_NULL) = 0.005, below the report's 0.01.
N_NULL = 199


def _majority(labels: Sequence[str]) -> tuple[str, int]:
    best = max(sorted(set(labels)), key=labels.count)
    return best, labels.count(best)


def _label(r: dict) -> str:
    """The run's class, or why it has none: ``breakdown`` (a strip arrests), ``budget`` (its step budget)."""
    status = str(r.get("status", ""))
    return r.get("front_pattern") or next((k for k in ("breakdown", "budget") if status.startswith(k)), "failed")


def pattern_table(ens: FrontEnsemble) -> list[dict]:
    """One row per (γ, r_m, V): the majority class over the seeds, its count, and the mean ⟨W⟩, Φ_mix, φ."""
    rows = []
    for g in ens.gammas:
        for rm in ens.inertia_ratios:
            for V in ens.V_values:
                recs = ens.select(gamma=float(g), r_m=float(rm), V=float(V))
                labels = [_label(r) for r in recs]
                lab, k = _majority(labels) if labels else ("none", 0)
                ok = [r for r in recs if r.get("status") == "ok"]

                def mean(key: str, ok: list = ok) -> float | None:
                    return float(np.mean([r[key] for r in ok])) if ok else None
                rows.append({"gamma": float(g), "r_m": float(rm), "V": float(V), "pattern": lab, "agree": k,
                             "runs": len(recs), "roughness": mean("front_roughness"),
                             "mixed_fraction": mean("front_mixed_fraction"), "phi_mean": mean("front_phi_mean"),
                             "lyapunov": mean("front_lyapunov"),
                             "chaotic": sum(bool(r.get("front_chaotic")) for r in ok)})
    return rows


def _fits(e: np.ndarray, seed: int = 0) -> dict:
    """One power law and two regimes against one on the energies ``e`` (fields None where too few)."""
    row: dict[str, Any] = {"n_bursts": int(e.size)}
    try:
        f = fit_power_law(e, min_tail=30, n_bootstrap=100, seed=seed, max_wall=60.0)
        lo, hi = f.alpha_interval or (None, None)
        row.update(alpha=f.alpha, alpha_lo=lo, alpha_hi=hi, xmin=f.xmin, n_tail=f.n_tail, ks=f.ks)
    except ValueError as exc:
        row.update(alpha=None, note=str(exc)[:120])
        return row
    try:
        b = fit_broken_power_law(e, min_regime=20, n_bootstrap=30, n_null=N_NULL, seed=seed, max_wall=60.0)
        row.update(alpha1=b.alpha1, alpha2=b.alpha2, x_break=b.x_break, p_broken=b.p_value,
                   regimes="two" if b.p_value is not None and b.p_value < 0.01 else "one")
    except ValueError as exc:
        row.update(regimes="one (too few for two)", note=str(exc)[:120])
    return row


def _fit_all(samples: list[np.ndarray], executor: Any = None, max_workers: int | None = None) -> list[dict]:
    """:func:`_fits` of each sample, on the pool (each fit's bootstraps are seconds)."""
    found: dict = {}
    map_points(_fits, [(k, (e,)) for k, e in enumerate(samples)], found.__setitem__, pool=executor or "auto",
               max_workers=max_workers, cost=[float(e.size) for e in samples])
    return [found.get(k, {"n_bursts": int(e.size), "note": "fit lost by the pool"}) for k, e in enumerate(samples)]


def exponent_table(ens: FrontEnsemble, gamma: float, *, executor: Any = None,
                   max_workers: int | None = None) -> list[dict]:
    """Per V: the burst energies at γ of every seed and inertia ratio pooled, and their fits (:func:`_fits`).
    Pooled over r_m too: a run of the sizes here holds tens of bursts (about one per slip), a fit needs
    hundreds."""
    fits = _fit_all([ens.burst_energies(gamma=gamma, V=float(V)) for V in ens.V_values], executor, max_workers)
    return [{"V": float(V), "gamma": gamma, **f} for V, f in zip(ens.V_values, fits)]


def _ae_run(V: float, I: float, gamma: float, seed: int, delta0: float, N: int, t_transient: float,
            window: float, dt_save: float, rtol: float) -> Any:
    """The AE power (t, R_AE) of one run after its transient, or the error's text (a pool task)."""
    try:
        fp = FrontParams(base=PeelParams(V=V, I=I, tape_mass=TAPE_MASS, R=RADIUS), N=N, gamma=gamma,
                         kappa=FRONT_DEFAULTS["front_kappa"], delta0=delta0, seed=seed)
        cap = FRONT_DEFAULTS["front_steps_per_s"]  # the measure's step budget (a strip nearing arrest)
        head = simulate_front(fp, t_transient, rtol=rtol, store_front=False, max_steps=int(max(cap * t_transient,
                                                                                              5e4)))
        tr = simulate_front(fp, window, y0=head.final_y, rtol=rtol, dt_save=dt_save, store_front=False,
                            max_steps=int(max(cap * window, 5e4)))
        return tr.t, tr.ae_power
    except Exception as exc:  # a breakdown or budget: reported in the table
        return f"{type(exc).__name__}: {exc}"[:200]


def burst_stability(stab: dict, options: dict, *, executor: Any = None, max_workers: int | None = None,
                    progress: bool = True) -> list[dict]:
    """The burst exponent at one cell across threshold, sampling step, seed and δ₀ (module docstring, 4.).

    The base catalogue pools the seeds at δ₀ = 1e-2, the ensemble's ``front_dt_save`` and the middle threshold;
    each variant changes one of them.  Each row: the variant, its fit, and whether its 95 % interval overlaps
    the base's (``consistent``)."""
    o = {**FRONT_DEFAULTS, **options}
    I = inertia_of_ratio(stab["r_m"], TAPE_MASS, RADIUS)
    dt = o["front_dt_save"]
    sets = {"base": (1e-2, dt), "dt/2": (1e-2, dt / 2), "delta0=1e-4": (1e-4, dt)}
    tasks = [((name, s), (stab["V"], I, stab["gamma"], s, d0, o["front_N"], o["front_t_transient"], stab["window"],
                          dts, o["front_rtol"])) for name, (d0, dts) in sets.items() for s in stab["seeds"]]
    runs: dict = {}
    line = ProgressLine("burst stability", len(tasks)) if progress else None

    def done(key: Any, val: Any) -> None:
        runs[key] = val
        if line is not None:
            line.update(len(runs))
    map_points(_ae_run, tasks, done, pool=executor or "auto", max_workers=max_workers,
               cost=[1.0 / t[1][5] for t in tasks])
    th_mid = stab["thresholds"][len(stab["thresholds"]) // 2]

    def energies(name: str, seeds: Sequence[int], frac: float) -> np.ndarray:
        parts = []
        for s in seeds:
            val = runs.get((name, s))
            if isinstance(val, tuple) and np.max(val[1]) > 0:
                parts.append(burst_catalogue(*val, threshold=frac * float(np.max(val[1]))).sizes("energy"))
        return np.concatenate(parts) if parts else np.empty(0)

    variants = [("base", "base", stab["seeds"], th_mid)]
    variants += [(f"threshold={th:g}", "base", stab["seeds"], th) for th in stab["thresholds"] if th != th_mid]
    variants += [("dt_save/2", "dt/2", stab["seeds"], th_mid), ("delta0=1e-4", "delta0=1e-4", stab["seeds"], th_mid)]
    variants += [(f"seed={s} alone", "base", (s,), th_mid) for s in stab["seeds"]]
    rows = []
    fits = _fit_all([energies(name, seeds, th) for _, name, seeds, th in variants], executor, max_workers)
    for (label, _, _, th), f in zip(variants, fits):
        rows.append({"variant": label, "threshold": th, **{k: f.get(k) for k in
                     ("n_bursts", "alpha", "alpha_lo", "alpha_hi", "xmin", "n_tail", "p_broken", "note")}})
    base = rows[0]
    for r in rows:
        ok = None not in (r["alpha_lo"], base["alpha_lo"])
        r["consistent"] = (r["alpha_lo"] <= base["alpha_hi"] and base["alpha_lo"] <= r["alpha_hi"]) if ok else None
    errors = sorted({v for v in runs.values() if isinstance(v, str)})
    if errors:
        rows.append({"variant": "runs that failed", "note": "; ".join(errors)[:300]})
    return rows


def _plot_patterns(rows: list[dict], ens: FrontEnsemble, path: str) -> None:
    from peelapprox.plotting import new_figure, save_figure

    gs = list(ens.gammas)
    fig = new_figure(figsize=(3.2 * len(gs) + 1.2, 3.2))
    axes = fig.subplots(1, len(gs), squeeze=False)[0]
    for ax, g in zip(axes, gs):
        for r in (r for r in rows if r["gamma"] == float(g)):
            ax.scatter(r["V"], r["r_m"], s=260, marker="s", color=PATTERN_COLOURS.get(r["pattern"], "white"),
                       edgecolors="k")
            ax.annotate(f"{r['agree']}/{r['runs']}", (r["V"], r["r_m"]), ha="center", va="center", fontsize=6,
                        color="w")
        ax.set(yscale="log", xlabel="V [m/s]", title=f"γ = {g:g}")
    axes[0].set_ylabel("r_m = m R²/I")
    for lab, c in PATTERN_COLOURS.items():
        axes[-1].scatter([], [], color=c, marker="s", label=lab)
    axes[-1].legend(fontsize=6, loc="upper left", bbox_to_anchor=(1.0, 1.0))
    save_figure(fig, path)


def _plot_exponents(rows: list[dict], path: str, ref: str) -> None:
    from peelapprox.plotting import new_figure, save_figure

    fig = new_figure(figsize=(5, 3.2))
    ax = fig.subplots()
    for r in rows:
        if r.get("alpha") is None:
            continue
        err = None if r.get("alpha_lo") is None else [[r["alpha"] - r["alpha_lo"]], [r["alpha_hi"] - r["alpha"]]]
        ax.errorbar(r["V"], r["alpha"], yerr=err, fmt="o", color="k" if r.get("regimes") != "two" else "C3")
        if r.get("regimes") == "two":
            ax.plot([r["V"]] * 2, [r["alpha1"], r["alpha2"]], "v", color="C3")
    ax.set(xlabel="V [m/s]", ylabel="burst-energy exponent α", title=f"bursts {ref} (red: two regimes, p < 0.01)")
    save_figure(fig, path)


def _plot_chaos(ens: FrontEnsemble, path: str, gamma: float) -> None:
    from peelapprox.plotting import new_figure, save_figure

    fig = new_figure(figsize=(5, 3.2))
    ax = fig.subplots()
    for k, rm in enumerate(ens.inertia_ratios):
        pts = []
        for V in ens.V_values:
            lam = [r["front_lyapunov"] for r in ens.select(gamma=gamma, r_m=float(rm), V=float(V))
                   if r.get("front_lyapunov") is not None]
            if lam:
                pts.append((V, np.mean(lam), np.std(lam) / math.sqrt(len(lam))))
        if pts:
            a = np.array(pts)
            ax.errorbar(a[:, 0], a[:, 1], yerr=a[:, 2], fmt="o-", color=f"C{k}", label=f"r_m = {rm:g}")
    ax.axhline(0.0, color="k", lw=0.5)
    ax.set(xlabel="V [m/s]", ylabel="λ [1/s] (twin runs; mean ± SE over seeds)", title=f"γ = {gamma:g}")
    ax.legend(fontsize=7)
    save_figure(fig, path)


def _md_table(rows: list[dict], cols: Sequence[str]) -> str:
    def cell(v: Any) -> str:
        return fmt_number(v, 3) if isinstance(v, float) else ("" if v is None else str(v))
    head = "| " + " | ".join(cols) + " |\n|" + "---|" * len(cols) + "\n"
    return head + "".join("| " + " | ".join(cell(r.get(c)) for c in cols) + " |\n" for r in rows)


def chaotic_window(rows: list[dict], r_m: float, gamma: float) -> list[float]:
    """The V at (r_m, γ) where most seeds are chaotic (λ > 3 SE)."""
    return [r["V"] for r in rows if r["r_m"] == r_m and r["gamma"] == gamma and r["runs"]
            and r["chaotic"] * 2 > r["runs"]]


def run_report(size: str, out: str, *, work: str | None = None, executor: Any = None,
               max_workers: int | None = None, progress: bool = True) -> dict:
    """Run the ensemble and the stability runs of ``SIZES[size]`` and write the report into ``out``; returns a
    summary (the files, CPU seconds, wall time)."""
    cfg = SIZES[size]
    t0, c0 = time.time(), time.process_time()
    os.makedirs(out, exist_ok=True)
    work = work or os.path.join(tempfile.gettempdir(), f"peelapprox-front-{size}")
    # compile the kernels here once (into the cache the workers then load) instead of in every worker at once
    measure_front(PeelParams(V=1.0, I=1e-2, tape_mass=TAPE_MASS, R=RADIUS),
                  {"front_N": 2, "front_t_transient": 1e-3, "front_window": 2e-3, "front_lyap_window": 1e-3,
                   "front_lyap_tau": 2.5e-4})
    t_warm = time.time() - t0
    ens = front_ensemble(cfg["r_m"], cfg["V"], gammas=cfg["gammas"], seeds=cfg["seeds"], out=work,
                         tape_mass=TAPE_MASS, R=RADIUS, options=cfg["options"], executor=executor,
                         max_workers=max_workers, progress=progress, retry_failed=True)
    t_ens = time.time() - t0
    stab = burst_stability(cfg["stab"], cfg["options"], executor=executor, max_workers=max_workers,
                           progress=progress)
    pats = pattern_table(ens)
    ref = (float(cfg["ref_r_m"]), float(cfg["ref_gamma"]))
    exps = exponent_table(ens, ref[1], executor=executor, max_workers=max_workers)
    files = {k: os.path.join(out, k) for k in ("report.md", "runs.csv", "exponents.csv", "stability.csv",
                                                "pattern_map.png", "exponents.png", "chaos.png")}
    ens.write(files["runs.csv"])
    write_rows(files["exponents.csv"], exps)
    write_rows(files["stability.csv"], stab)
    _plot_patterns(pats, ens, files["pattern_map.png"])
    _plot_exponents(exps, files["exponents.png"], f"γ = {ref[1]:g}, all r_m and seeds")
    _plot_chaos(ens, files["chaos.png"], ref[1])
    window = chaotic_window(pats, *ref)
    summary = {"size": size, "runs": ens.n_runs, "cpu_s_runs": ens.cpu_s, "wall_s": time.time() - t0,
               "wall_s_ensemble": t_ens, "wall_s_warmup": t_warm, "cpu_s_main": time.process_time() - c0,
               "cpu_s_per_run": ens.cpu_s / max(ens.n_runs, 1), "chaotic_V": window, "files": files}
    with open(files["report.md"], "w", encoding="utf-8") as fh:
        fh.write(_markdown(cfg, size, ens, pats, exps, stab, summary, ref))
    return summary


def _markdown(cfg: dict, size: str, ens: FrontEnsemble, pats: list, exps: list, stab: list, summary: dict,
              ref: tuple[float, float]) -> str:
    o = {**FRONT_DEFAULTS, **cfg["options"]}
    return "\n".join([
        f"# Peel-front reproduction report (size {size})", "",
        f"`python -m comparisons.front --size {size}`: {ens.n_runs} runs (r_m {list(cfg['r_m'])} × V "
        f"{list(cfg['V'])} × γ {list(cfg['gammas'])} × seeds {list(cfg['seeds'])}), N = {o['front_N']}, "
        f"κ = {o['front_kappa']}, δ₀ = {o['front_delta0']}, m = {TAPE_MASS} kg, R = {RADIUS} m, transient "
        f"{o['front_t_transient']} s, window {o['front_window']} s (twin {o['front_lyap_window']} s), burst "
        f"threshold {o['front_threshold']} × the window's largest R_AE.  Wall {summary['wall_s']:.0f} s "
        f"(compiling {summary['wall_s_warmup']:.0f} s, ensemble {summary['wall_s_ensemble']:.0f} s with it); the "
        f"runs' CPU {summary['cpu_s_runs']:.0f} s, "
        f"{summary['cpu_s_per_run']:.2f} s a run.", "",
        "## Pattern map (majority class over the seeds)", "", "![pattern map](pattern_map.png)", "",
        _md_table(pats, ("gamma", "r_m", "V", "pattern", "agree", "runs", "roughness", "mixed_fraction",
                         "phi_mean", "lyapunov", "chaotic")),
        f"## Burst-energy exponents against V (γ = {ref[1]:g}; every r_m and seed pooled)", "",
        "![exponents](exponents.png)", "",
        _md_table(exps, ("V", "n_bursts", "alpha", "alpha_lo", "alpha_hi", "xmin", "n_tail", "alpha1", "alpha2",
                         "x_break", "p_broken", "regimes")),
        f"## The chaotic window (r_m = {ref[0]:g}, γ = {ref[1]:g})", "", "![chaos](chaos.png)", "",
        f"V where most seeds give λ > 3 SE: {summary['chaotic_V'] or 'none'}.", "",
        "## Burst-exponent stability", "",
        f"V = {cfg['stab']['V']}, r_m = {cfg['stab']['r_m']}, γ = {cfg['stab']['gamma']}, seeds "
        f"{list(cfg['stab']['seeds'])}, window {cfg['stab']['window']} s; `consistent`: the 95 % interval overlaps "
        "the base's.", "",
        _md_table(stab, ("variant", "threshold", "n_bursts", "alpha", "alpha_lo", "alpha_hi", "n_tail",
                         "consistent", "note")),
    ])


def cost_sample(size: str, n: int = 24, *, seed: int = 39) -> dict:
    """The CPU seconds of ``n`` of the ensemble's runs of ``SIZES[size]`` drawn at random (``seed``), run here one
    after the other: their mean, SD, largest, and the ensemble's total estimated as mean × runs with its SE."""
    cfg = SIZES[size]
    grid = [(rm, V, g, s) for rm in cfg["r_m"] for V in cfg["V"] for g in cfg["gammas"] for s in cfg["seeds"]]
    cpu = []
    for k in np.random.default_rng(seed).choice(len(grid), min(n, len(grid)), replace=False):
        rm, V, g, s = grid[k]
        rec = measure_front(PeelParams(V=V, I=inertia_of_ratio(rm, TAPE_MASS, RADIUS), tape_mass=TAPE_MASS, R=RADIUS),
                            {**cfg["options"], "front_gamma": g, "front_seed": s})
        cpu.append(rec["cpu_s"])
    c = np.asarray(cpu)
    sd = float(np.std(c, ddof=1)) if c.size > 1 else 0.0
    return {"runs": len(grid), "sampled": int(c.size), "mean_s": float(c.mean()), "sd_s": sd, "max_s": float(c.max()),
            "total_s": len(grid) * float(c.mean()), "total_se_s": len(grid) * sd / math.sqrt(c.size)}


def main(argv: Sequence[str] | None = None) -> int:
    """``python -m comparisons.front``: the report (module docstring)."""
    ap = argparse.ArgumentParser(prog="python -m comparisons.front", description=__doc__.split("\n\n")[0])
    ap.add_argument("--size", choices=sorted(SIZES), default="small")
    ap.add_argument("--out", default="front-report", help="directory of the report's 7 files")
    ap.add_argument("--work", default=None, help="directory of the ensemble's sweeps (resumable)")
    ap.add_argument("--workers", type=int, default=None, help="local pool size (0: this process)")
    ap.add_argument("--quiet", action="store_true", help="no progress on stderr")
    ap.add_argument("--cost-sample", type=int, default=0, metavar="N",
                    help="only time N randomly drawn runs of the size's ensemble here and estimate its CPU seconds")
    a = ap.parse_args(argv)
    if a.cost_sample:
        c = cost_sample(a.size, a.cost_sample)
        print(f"{c['sampled']} of {c['runs']} runs: mean {c['mean_s']:.3f} CPU s (SD {c['sd_s']:.3f}, max "
              f"{c['max_s']:.2f}); the ensemble ~{c['total_s']:.0f} +- {c['total_se_s']:.0f} CPU s")
        return 0
    s = run_report(a.size, a.out, work=a.work, max_workers=a.workers, progress=not a.quiet)
    print(f"front report ({a.size}): {s['runs']} runs, wall {s['wall_s']:.1f} s, runs' CPU {s['cpu_s_runs']:.1f} s "
          f"({s['cpu_s_per_run']:.2f} s a run), chaotic V {s['chaotic_V']}; files in {a.out}", file=sys.stderr)
    return 0

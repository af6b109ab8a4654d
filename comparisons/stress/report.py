"""The stress report: tables and markdown from run records, and the CSV/JSON files.

:func:`tolerance_table` (jump-time errors of the tolerance sweep),
:func:`pair_long_runs` (do long runs' jump times depend on the output mode?),
:data:`EXPLANATIONS` (what each outcome class means), :func:`robustness_markdown`
(the report, as in ``docs/robustness.md``) and :func:`write_records`
(``stress.csv``, ``stress.json``).
"""

from __future__ import annotations

import os
from collections import Counter
from collections.abc import Iterable, Sequence

import numpy as np

from peelapprox.io import fmt_number as _g  # 3 significant digits, None/NaN as a dash
from peelapprox.io import write_rows

from .points import LONG_N_EVAL, LOOSE_TOLS, RANDOM_BOX, RANDOM_SEED
from .run import DRIFT_FRACTION, is_bug

__all__ = ["EXPLANATIONS", "tolerance_table", "pair_long_runs", "robustness_markdown", "write_records"]


def tolerance_table(records: Iterable[dict]) -> list[dict]:
    """Per tolerance-sweep point and rtol: outcome, work and jump-time error against the tightest rtol.

    ``err_jump_t`` is the max ``|t_j - t_j^ref|`` over the jumps both runs have
    (``n_common``); ``dn_jumps`` the difference of jump counts; the
    reference is the run of the same point at the smallest rtol.  Records
    without ``_jump_t`` (read back from JSON) get NaN errors.
    """
    tol = [r for r in records if r.get("group") == "tol"]
    rows = []
    for key in dict.fromkeys((r["label"], r["V"], r["I"], r["k"], r["alpha0"]) for r in tol):
        sub = sorted([r for r in tol if (r["label"], r["V"], r["I"], r["k"], r["alpha0"]) == key],
                     key=lambda r: -r["rtol"])
        ref = sub[-1]
        rj = np.asarray(ref.get("_jump_t", []), dtype=float)
        for r in sub:
            jt = np.asarray(r.get("_jump_t", []), dtype=float)
            n = min(len(jt), len(rj))
            has = "_jump_t" in r and "_jump_t" in ref and r is not ref
            err = float(np.max(np.abs(jt[:n] - rj[:n]))) if (has and n) else float("nan")
            rows.append(dict(label=key[0], V=key[1], I=key[2], k=key[3], alpha0=key[4], rtol=r["rtol"],
                             outcome=r["outcome"], n_jumps=r["n_jumps"], n_steps=r["n_steps"], wall=r["wall"],
                             err_jump_t=err, n_common=n if has else 0,
                             dn_jumps=(r["n_jumps"] - ref["n_jumps"]) if has else 0, reference=r is ref))
    return rows


EXPLANATIONS: dict[str, str] = {
    "ok": "Reached t_end.",
    "invalid_initial_state": (
        "No consistent start: with the default F0 = 1.01 f(V, V) the level F0 (1 - cos θ) = F0 (1 + sin α0) lies "
        "below f(0+, V) = 130 - 2 V^1.5 (α0 = -1 gives 1 + sin α0 = 0.16), so CONSTR has no root; initial_state "
        "raises ValueError naming F0's valid range."),
    "breakdown:no_root": (
        "On AB the pull side F (1 - cos θ) falls to f(0+, V) (within 1e-10, the model's criterion; v is followed "
        "in ln v down to ~1e-67 m/s), so the peel front would have to stop, a regime the model does not contain.  "
        "Seen (i) at small I with α0 = 1, where FLOW2's angular acceleration "
        "-F R c(α)/I swings α from 1 to ≈ -0.59 within ~0.5 ms and 1 + sin α collapses; (ii) at small V "
        "(0.2-0.5), where the CD→AB jump lands at v = 2e-9 (V=0.2) to 8e-5 m/s (V=0.5), barely above 0; "
        "(iii) for soft tapes (k = 100) after a few s of growing oscillation; (iv) for starts whose level is "
        "barely above f(0+, V) (α0 = -0.5 at V = 0.05); (v) at loose tolerances (atol up to 1), on the "
        "inaccurate orbits such tolerances give."),
    "breakdown:v_floor": "v fell to a v_floor the caller passed (not used by the suite).",
    "breakdown:no_landing": (
        "V below ≈ 0.163, where f_min <= f(0+, V): at the CD fold there is no AB root to jump to (the peel "
        "front would have to stop)."),
    "breakdown:geometry": "1 - cos θ reached 0 (α → -π/2): the peel geometry degenerates.",
    "breakdown:v_ceiling": "v exceeded 1000 m/s on CD: the pull force runs away.",
    "budget:max_steps": "The step budget was used up (budget probes: deliberately tiny budgets).",
    "budget:max_jumps": "The jump budget was used up (budget probes: deliberately tiny budgets).",
    "budget:max_points": "The stored-point budget was used up (budget probes: deliberately tiny budgets).",
    "solver_failure": "The step size collapsed (the integrator could not proceed).",
    "nan": "BUG: a non-finite value in the returned (or partial) arrays.",
    "timeout": "BUG: no answer within the wall-clock timeout (a hang).",
    "crash": "BUG: the worker process died.",
}


def _example(r: dict) -> str:
    s = f"V={r['V']:g}, I={r['I']:g}, k={r['k']:g}, α0={r['alpha0']:g}"
    if r.get("method", "hybrid") != "hybrid":
        s += f", {r['method']}"
    if r.get("geometry", "paper") != "paper":
        s += f", geometry={r['geometry']}"
    if r.get("group") in ("budget", "tol"):
        s += f", rtol={r['rtol']:g}, t_end={r['t_end']:g}"
    if r.get("outcome", "").startswith(("breakdown", "budget", "solver")) and r.get("t_reached") == r.get("t_reached"):
        s += f" (at t={r['t_reached']:.4g} s)"
    return s


_ABBR = {"ok": "ok", "invalid_initial_state": "inv", "breakdown:no_root": "nr", "breakdown:v_floor": "vf",
         "breakdown:no_landing": "nl", "breakdown:geometry": "geo", "breakdown:v_ceiling": "vc",
         "solver_failure": "sf", "nan": "NAN", "timeout": "TIMEOUT", "crash": "CRASH"}


def _abbr(outcome: str) -> str:
    return _ABBR.get(outcome, outcome)


def _count_table(records: list[dict], title: str) -> list[str]:
    c = Counter(r["outcome"] for r in records)
    lines = [f"| {title} | runs |", "|---|---:|"]
    for k, v in sorted(c.items(), key=lambda kv: (-kv[1], kv[0])):
        lines.append(f"| `{k}` | {v} |")
    lines.append(f"| **total** | **{len(records)}** |")
    return lines


def _grid_section(g: list[dict]) -> list[str]:
    """The ``grid`` group: its axes, outcome counts, the cross tables and the residuals."""
    L: list[str] = []
    Is = sorted({r["I"] for r in g})
    Vs = sorted({r["V"] for r in g})
    ks = sorted({r["k"] for r in g})
    a0s = sorted({r["alpha0"] for r in g})
    walls = np.array([r["wall"] for r in g], dtype=float)
    L += ["## Grid", ""]
    L += [f"I ∈ {{{', '.join(f'{x:g}' for x in Is)}}} kg m², V ∈ {{{', '.join(f'{x:g}' for x in Vs)}}} m/s, "
          f"k ∈ {{{', '.join(f'{x:g}' for x in ks)}}} N/m, α0 ∈ {{{', '.join(f'{x:g}' for x in a0s)}}} rad: "
          f"**{len(g)} points**, each {g[0]['t_end']:g} s simulated, hybrid, rtol {g[0]['rtol']:g}, "
          f"`save=\"{g[0]['save']}\"` (every step stored, so the constraint residual and time monotonicity "
          f"are checked at every step), budgets max_steps={g[0]['max_steps']:.0e}, "
          f"max_jumps={g[0]['max_jumps']:.0e}.  Per-point wall time: median {np.nanmedian(walls):.3g} s, "
          f"max {np.nanmax(walls):.3g} s.", ""]
    L += _count_table(g, "outcome (grid)") + [""]
    L += _grid_tables(g, Is, Vs, ks, a0s)
    res = np.array([r["res_max"] for r in g if r["n_points"]], dtype=float)
    jres = np.array([r["jres_max"] for r in g if r["n_jumps"] and r.get("jres_max") == r.get("jres_max")],
                    dtype=float)
    okj = [r["n_jumps"] for r in g if r["outcome"] == "ok"]
    L += [f"Max relative CONSTR residual over all stored steps of all grid runs (complete or partial): "
          f"**{np.nanmax(res) if res.size else float('nan'):.2e}**; at the jumps (level F(1 - cos θ) vs "
          f"f(v_before) and f(v_after)): **{np.nanmax(jres) if jres.size else float('nan'):.2e}**.  "
          f"Jumps per ok run: max {max(okj) if okj else 0}, total {sum(okj)}.", ""]
    return L


def _grid_tables(g: list[dict], Is: list, Vs: list, ks: list, a0s: list) -> list[str]:
    """The grid's outcomes by I × V and by α0 × k."""
    L: list[str] = []
    L += ["Outcomes by I (rows) × V (columns), each cell over k × α0 "
          f"({len(ks) * len(a0s)} runs).  Abbreviations: ok, inv = invalid_initial_state, "
          "nr = breakdown:no_root, nl = breakdown:no_landing, geo = breakdown:geometry, "
          "vc = breakdown:v_ceiling, sf = solver_failure.", ""]
    L += ["| I \\ V | " + " | ".join(f"{v:g}" for v in Vs) + " |", "|---|" + "---|" * len(Vs)]
    for I in Is:
        cells = []
        for V in Vs:
            c = Counter(_abbr(r["outcome"]) for r in g if r["I"] == I and r["V"] == V)
            cells.append(" ".join(f"{k} {v}" for k, v in sorted(c.items(), key=lambda kv: (-kv[1], kv[0]))))
        L += [f"| {I:g} | " + " | ".join(cells) + " |"]
    L += [""]
    L += ["Outcomes by α0 (rows) × k (columns), each cell over I × V:", ""]
    L += ["| α0 \\ k | " + " | ".join(f"{k:g}" for k in ks) + " |", "|---|" + "---|" * len(ks)]
    for a0 in a0s:
        cells = []
        for k in ks:
            c = Counter(_abbr(r["outcome"]) for r in g if r["alpha0"] == a0 and r["k"] == k)
            cells.append(" ".join(f"{kk} {v}" for kk, v in sorted(c.items(), key=lambda kv: (-kv[1], kv[0]))))
        L += [f"| {a0:g} | " + " | ".join(cells) + " |"]
    L += [""]
    return L


def _random_section(rnd: list[dict]) -> list[str]:
    """The ``random`` group: the sample's box and outcomes."""
    L: list[str] = []
    B = RANDOM_BOX
    L += ["## Random sample", ""]
    L += [f"**{len(rnd)} points** drawn with seed {RANDOM_SEED}: I log-uniform in [{B['I'][0]:g}, {B['I'][1]:g}], "
          f"V uniform in [{B['V'][0]:g}, {B['V'][1]:g}], k log-uniform in [{B['k'][0]:g}, {B['k'][1]:g}], "
          f"α0 uniform in [{B['alpha0'][0]:g}, {B['alpha0'][1]:g}], rtol log-uniform in "
          f"[{B['rtol'][0]:g}, {B['rtol'][1]:g}]; {rnd[0]['t_end']:g} s each, `save=\"steps\"`.", ""]
    L += _count_table(rnd, "outcome (random)") + [""]
    res = np.array([r["res_max"] for r in rnd if r["n_points"]], dtype=float)
    okj = [r["n_jumps"] for r in rnd if r["outcome"] == "ok"]
    worst = np.nanmax(res) if res.size else float("nan")
    L += [f"Max relative CONSTR residual over all stored steps: **{worst:.2e}**;"
          f" jumps per ok run: max {max(okj) if okj else 0}, total {sum(okj)}.", ""]
    return L


def _loose_section(loose: list[dict]) -> list[str]:
    """The ``loose`` group: the loose tolerances and their outcomes."""
    L: list[str] = []
    L += ["## Loose tolerances", ""]
    L += [f"**{len(loose)} runs** of {loose[0]['t_end']:g} s (`save=\"jumps\"`): V ∈ "
          f"{{{', '.join(f'{x:g}' for x in sorted({r['V'] for r in loose}))}}} m/s, I ∈ "
          f"{{{', '.join(f'{x:g}' for x in sorted({r['I'] for r in loose}))}}} kg m², α0 ∈ "
          f"{{{', '.join(f'{x:g}' for x in sorted({r['alpha0'] for r in loose}))}}} rad, (rtol, atol) ∈ "
          f"{{{', '.join(f'({rt:g}, {at:g})' if at is not None else f'({rt:g}, None)' for rt, at in LOOSE_TOLS)}}} "
          "(atol None: the default).  At such tolerances the dense output of a step can leave the model's "
          "domain (v ≤ 0) although the step's stages did not; the kernel rejects such steps, so no run "
          "may end with a non-finite or v ≤ 0 state (`nan` counts both).", ""]
    L += _count_table(loose, "outcome (loose tolerances)") + [""]
    return L


def _classes_section(records: list[dict]) -> list[str]:
    """Every non-ok outcome class: its count, explanation and an example."""
    L: list[str] = []
    L += ["## Non-ok outcome classes", ""]
    L += ["| class | runs | explanation | example |", "|---|---:|---|---|"]
    cls = Counter(r["outcome"] for r in records)
    for k in sorted(cls, key=lambda s: (-cls[s], s)):
        if k == "ok":
            continue
        ex = next(r for r in records if r["outcome"] == k)
        expl = EXPLANATIONS.get(k, "BUG: unexpected exception type." if k.startswith("unexpected:") else "")
        L += [f"| `{k}` | {cls[k]} | {expl} | {_example(ex)} |"]
    L += [""]
    return L


def _tolerance_section(tol: list[dict]) -> list[str]:
    """The ``tol`` group: the tolerance sweep against each point's reference."""
    L: list[str] = []
    rows = tolerance_table(tol)
    L += ["## Tolerance sweep", ""]
    L += ["Hybrid, 1 s, `save=\"jumps\"`, every rtol simulate accepts.  err = max |t_j − t_j^ref| over the "
          "common jumps against the same point at the smallest rtol (ref); Δn = jump-count difference.", ""]
    L += ["| point | rtol | outcome | jumps | Δn | steps | wall [s] | err jump t [s] |",
          "|---|---:|---|---:|---:|---:|---:|---:|"]
    for r in rows:
        lab = f"{r['label']} (V={r['V']:g}, I={r['I']:g}, k={r['k']:g}, α0={r['alpha0']:g})"
        L += [f"| {lab} | {r['rtol']:.0e} | `{r['outcome']}` | {r['n_jumps']} | "
              f"{'ref' if r['reference'] else r['dn_jumps']} | {r['n_steps']} | {r['wall']:.3g} | "
              f"{'ref' if r['reference'] else _g(r['err_jump_t'])} |"]
    L += [""]
    return L


def _budget_section(budget: list[dict]) -> list[str]:
    """The ``budget`` group: each probe's outcome against its expectation."""
    L: list[str] = []
    L += ["## Budget probes", ""]
    L += ["| probe | outcome | expected | t reached [s] | steps | jumps | points | partial finite, t monotone |",
          "|---|---|---|---:|---:|---:|---:|---|"]
    for r in budget:
        L += [f"| {r['label']} ({_example(r)}) | `{r['outcome']}` | `{r.get('expect') or 'any allowed'}`"
              f"{'' if r.get('expect_met', True) else ' **NOT MET**'} | {_g(r['t_reached'])} | {r['n_steps']} | "
              f"{r['n_jumps']} | {r['n_points']} | {not r['nonfinite']}, {r['t_monotone']} |"]
    L += [""]
    return L


def _variant_section(variant: list[dict]) -> list[str]:
    """The ``variant`` group: each variant's outcome and residuals."""
    L: list[str] = []
    L += ["## Variants", ""]
    L += ["| variant | point | t_end [s] | outcome | jumps | steps | wall [s] | rel. residual median | max |",
          "|---|---|---:|---|---:|---:|---:|---:|---:|"]
    for r in variant:
        L += [f"| {r['label']} | {_example(r)} | {r['t_end']:g} | `{r['outcome']}` | {r['n_jumps']} | "
              f"{r['n_steps']} | {r['wall']:.3g} | {_g(r.get('res_median'))} | {_g(r['res_max'])} |"]
    L += ["", "The regularised scheme does not enforce CONSTR exactly: its residual is the ε-relaxation, "
          "large during the fast transits of the jumps (where many of its steps, and so stored points, lie).  "
          "The hybrid solver computes F from CONSTR, so its residual is rounding.", ""]
    return L


def _long_section(long: list[dict]) -> list[str]:
    """The ``long`` group: the constraint drift of the long runs."""
    L: list[str] = []
    L += ["## Long runs: constraint drift", ""]
    L += [f"Hybrid, `t_eval` at {LONG_N_EVAL} equispaced times (drift rows) and `save=\"jumps\"` (check rows). "
          f"early/late = max relative CONSTR residual over the first/last {DRIFT_FRACTION:.0%} of the samples "
          "(points) or of the jumps (level vs f(v_before), f(v_after)).", ""]
    L += ["| run | t_end [s] | outcome | jumps | steps | wall [s] | points early | points late | "
          "jumps early | jumps late | jump times = save=jumps run |",
          "|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---|"]
    for r in long:
        same = r.get("jumps_match_save_jumps")
        L += [f"| {r['label']} ({_example(r)}, rtol {r['rtol']:g}) | {r['t_end']:g} | `{r['outcome']}` | "
              f"{r['n_jumps']} | {r['n_steps']} | {r['wall']:.3g} | {_g(r['res_early'])} | "
              f"{_g(r['res_late'])} | {_g(r['jres_early'])} | {_g(r['jres_late'])} | "
              f"{'–' if same is None else ('bitwise' if same else '**differ**')} |"]
    L += [""]
    return L


def _summary_section(records: list[dict], command: str | None, wall_time: float | None) -> list[str]:
    """The command, the counts of bug classes and of unmet expectations, the bug records."""
    L: list[str] = []
    if command:
        L += ["```", command, "```", ""]
    bugs = [r for r in records if is_bug(r)]
    nan_n = sum(r["outcome"] == "nan" for r in records)
    to_n = sum(r["outcome"] == "timeout" for r in records)
    cr_n = sum(r["outcome"] == "crash" for r in records)
    un_n = sum(r["outcome"].startswith("unexpected:") for r in records)
    nm_n = sum(not r.get("t_monotone", True) for r in records)
    unmet = [r for r in records if not r.get("expect_met", True)]
    L += ["## Summary", ""]
    L += [f"- runs: **{len(records)}**" + (f", total wall time **{wall_time:.1f} s**" if wall_time else "")]
    L += [f"- `nan`: **{nan_n}**, `timeout`: **{to_n}**, `crash`: **{cr_n}**, unexpected exceptions: **{un_n}**, "
          f"non-monotone time: **{nm_n}**"]
    L += [f"- runs not matching their expected outcome: **{len(unmet)}**"]
    for r in unmet:
        L += [f"  - {r.get('label') or r['group']}: {_example(r)} → `{r['outcome']}` "
              f"(expected `{r.get('expect') or 'an allowed class'}`) — {r.get('message', '')[:160]}"]
    if bugs:
        L += ["- **bug records:**"]
        for r in bugs:
            L += [f"  - {_example(r)} → `{r['outcome']}`, t_monotone={r.get('t_monotone')} — "
                  f"{r.get('message', '')[:200]}"]
    L += [""]
    return L


def robustness_markdown(records: Sequence[dict], *, command: str | None = None,
                        wall_time: float | None = None) -> str:
    """Render the stress-test report (markdown) from run records.

    Parameters
    ----------
    records : sequence of dict
        Records from :func:`run_point` / :func:`run_points` (any mix of the
        groups "grid", "tol", "budget", "variant", "long"; missing groups
        are skipped).
    command : str, optional
        The command line, shown at the top.
    wall_time : float, optional
        Total wall time of the suite [s].

    Returns
    -------
    str

    Raises
    ------
    ValueError
        If a record lacks the ``outcome`` or ``group`` key.
    """
    records = list(records)
    for i, r in enumerate(records):
        if not isinstance(r, dict) or "outcome" not in r or "group" not in r:
            raise ValueError(f"records[{i}] must be a dict with 'outcome' and 'group' keys (a run_point record)")
    by = {g: [r for r in records if r["group"] == g] for g in ("grid", "random", "tol", "loose", "budget", "variant",
                                                                  "long")}
    L = _summary_section(records, command, wall_time)
    if by["grid"]:
        L += _grid_section(by["grid"])
    if by["random"]:
        L += _random_section(by["random"])
    if by["loose"]:
        L += _loose_section(by["loose"])
    if any(by[x] for x in by) and records:
        L += _classes_section(records)
    for group, write in (("tol", _tolerance_section), ("budget", _budget_section),
                         ("variant", _variant_section), ("long", _long_section)):
        if by[group]:
            L += write(by[group])
    return "\n".join(L)


def pair_long_runs(records: Sequence[dict]) -> None:
    """Set ``jumps_match_save_jumps`` on each long ``t_eval`` record: are its jump times bitwise
    those of the matching ``save="jumps"`` run?  (Output mode must not change the orbit.)"""
    long = [r for r in records if r.get("group") == "long"]
    for r in long:
        if not r.get("n_eval"):
            continue
        mate = next((m for m in long if m is not r and not m.get("n_eval") and m["label"].startswith(r["label"])
                     and (m["V"], m["I"], m["k"], m["alpha0"], m["t_end"], m["rtol"])
                     == (r["V"], r["I"], r["k"], r["alpha0"], r["t_end"], r["rtol"])), None)
        if mate is not None and "_jump_t" in r and "_jump_t" in mate:
            r["jumps_match_save_jumps"] = bool(np.array_equal(np.asarray(r["_jump_t"]), np.asarray(mate["_jump_t"])))


def write_records(records: Sequence[dict], out_dir: str) -> tuple[str, str]:
    """Write ``stress.csv`` and ``stress.json`` (one row per run; private ``_*`` keys dropped).

    Parameters
    ----------
    records : sequence of dict
    out_dir : str
        Directory, created if missing.

    Returns
    -------
    (csv_path, json_path)
    """
    if not isinstance(out_dir, (str, os.PathLike)) or not str(out_dir):
        raise ValueError(f"out_dir must be a non-empty path, got {out_dir!r}")
    os.makedirs(out_dir, exist_ok=True)
    rows = [{k: v for k, v in r.items() if not k.startswith("_")} for r in records]
    keys = list(dict.fromkeys(k for r in rows for k in r))
    cp = write_rows(os.path.join(out_dir, "stress.csv"), rows, fields=keys)
    jp = write_rows(os.path.join(out_dir, "stress.json"), rows)
    return cp, jp

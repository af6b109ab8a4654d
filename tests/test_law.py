"""PeelForce, the peel-force law as data: the four kinds, their folds, value semantics, bad laws.

Oracles: the built-in law's own functions (bitwise, or to rounding for re-written forms), the cubic's folds
and landings in closed form, sympy's derivatives of the same formula, and the data of a table.

``python tests/test_law.py`` prints the convergence table of a tabulated law (the cubic sampled on N points).
"""

from __future__ import annotations

import dataclasses
import functools
import json
import math
import os
import pickle
import subprocess
import sys

import numpy as np
import pytest

import exact
import peelapprox as pa
from peelapprox import PeelForce, PeelParams

V_GRID = np.logspace(-6, 3, 181)  # v [m/s] over the expression laws' domain
PULLS = (0.05, 0.5, 1.0, 2.0, 4.0)  # pull speeds with folds (the cusp is at V ≈ 5.2)
PAPER_TEXT = "400*v**0.35 + 110*v**0.15 + 130*exp(v/11) - 2*V**1.5 - (415 - 45*V**0.4 - 0.35*V**2.15)*v**0.5"
FOLD_FIELDS = ("v_max", "f_max", "v_min", "f_min", "v_land_cd", "v_land_ab")


def _rel(a, b):
    """|a - b| / |b|; 0 when both are None (a landing that does not exist for either)."""
    if a is None or b is None:
        return 0.0 if a is b else math.inf
    return abs(a - b) / abs(b)


# --------------------------------------------------------------------------- the paper's law, four ways
@pytest.mark.parametrize("V", PULLS + (8.0,))
def test_paper_is_peel_force_bitwise(V):
    """Hypothesis: PeelForce.paper() is evaluated by peel_force / peel_force_derivative themselves, so f, f'
    and f'' are bitwise equal on a log grid of v (tolerance 0: the same function on the same input)."""
    law = PeelForce.paper()
    v = np.logspace(-9, 2, 301)
    assert np.array_equal(law(v, V), pa.peel_force(v, V))
    assert np.array_equal(law.f(v, V), pa.peel_force(v, V))
    assert np.array_equal(law.df(v, V), pa.peel_force_derivative(v, V, 1))
    assert np.array_equal(law.d2f(v, V), pa.peel_force_derivative(v, V, 2))
    assert law.f(0.3, V) == pa.peel_force(0.3, V) and np.ndim(law.f(0.3, V)) == 0


@pytest.mark.parametrize("V", PULLS)
def test_paper_folds_are_branch_structure(V):
    """Hypothesis: the paper law's folds are branch_structure's (delegated: equal, tolerance 0)."""
    bs, fo = pa.branch_structure(V), PeelForce.paper().folds(V)
    assert fo.has_folds and all(getattr(fo, n) == getattr(bs, n) for n in FOLD_FIELDS)


def _paper_term_scale(v, V, order):
    """Sum of the magnitudes of fvV's terms in the order-th derivative: the scale of its rounding error."""
    A = 415 - 45 * V**0.4 - 0.35 * V**2.15
    terms = [(400, 0.35), (110, 0.15), (-A, 0.5)]
    s = abs(130 * math.exp(v / 11) / 11**order) + (2 * V**1.5 if order == 0 else 0)
    for c, p in terms:
        k = c * v**p
        for j in range(order):
            k *= (p - j) / v
        s += abs(k)
    return s


@pytest.mark.parametrize("V", PULLS)
def test_paper_family_defaults_match_paper(V):
    """Hypothesis: the paper family with its default 14 numbers is fvV written in v (the built-in one is
    generated in ln v): f agrees to 1e-13 relative; f' and f'' to 1e-13 of the sum of their terms'
    magnitudes (they cancel to zero at the folds and the inflection, so a plain relative test would measure
    the cancellation, not the law).  Measured: 4e-16 and 1e-15."""
    fam = PeelForce.paper_family()
    for v in np.logspace(-6, 2, 97):
        assert _rel(fam.f(v, V), pa.peel_force(v, V)) <= 1e-13
        for order, fn in ((1, fam.df), (2, fam.d2f)):
            assert abs(fn(v, V) - pa.peel_force_derivative(v, V, order)) <= 1e-13 * _paper_term_scale(v, V, order)
    bs, fo = pa.branch_structure(V), fam.folds(V)
    for n in FOLD_FIELDS:
        assert _rel(getattr(fo, n), getattr(bs, n)) <= 1e-9, n


@pytest.mark.parametrize("V", (0.5, 1.0, 3.0))
def test_paper_as_expression(V):
    """Hypothesis: fvV typed as a string is the built-in law: f to 1e-12 relative on a log grid over the
    expression domain [1e-6, 1e3] m/s (both are fvV's formula in double precision: a few ulp apart, measured
    3e-16), its folds and landings to 1e-9 of branch_structure's (both Brent roots to ~4 ulp)."""
    law = PeelForce.expression(PAPER_TEXT)
    assert law.depends_on_V
    assert np.max(np.abs(law.f(V_GRID, V) / pa.peel_force(V_GRID, V) - 1)) <= 1e-12
    bs, fo = pa.branch_structure(V), law.folds(V)
    for n in FOLD_FIELDS:
        assert _rel(getattr(fo, n), getattr(bs, n)) <= 1e-9, n


def test_no_folds_beyond_the_cusp():
    """Hypothesis: above the cusp (V ≈ 5.2) fvV increases in v: every kind reports has_folds=False, as
    branch_structure does (exact booleans)."""
    assert not pa.branch_structure(6.0).has_folds
    for law in (PeelForce.paper(), PeelForce.paper_family(), PeelForce.expression(PAPER_TEXT)):
        fo = law.folds(6.0)
        assert not fo.has_folds and fo.v_max is None and fo.v_land_ab is None


# --------------------------------------------------------------------------- the families
CUBICS = [dict(a=150, b=300, c=300, d=80), dict(a=50, b=2.5, c=3.0, d=1.0), dict(a=1e3, b=2e3, c=400, d=25)]


@pytest.mark.parametrize("coef", CUBICS)
def test_cubic_folds_closed_form(coef):
    """Hypothesis: the cubic's folds are the roots of f' = b - 2 c v + 3 d v² (v = (c ∓ sqrt(c² - 3bd))/(3d))
    and its landings the third roots of f - f_fold = d (v - v_fold)² (v - v_land), v_land = c/d - 2 v_fold
    (Vieta); all to 1e-9 relative (the fold accuracy promised for every law; Brent's roots are ~4 ulp)."""
    a, b, c, d = (float(coef[k]) for k in "abcd")
    law = PeelForce.cubic(**coef)
    disc = math.sqrt(c * c - 3 * b * d)
    v_max, v_min = (c - disc) / (3 * d), (c + disc) / (3 * d)
    cubic = lambda v: a + b * v - c * v**2 + d * v**3  # noqa: E731
    exact_folds = dict(v_max=v_max, f_max=cubic(v_max), v_min=v_min, f_min=cubic(v_min),
                       v_land_cd=c / d - 2 * v_max, v_land_ab=c / d - 2 * v_min)
    fo = law.folds(1.0)
    assert fo.has_folds
    for n, x in exact_folds.items():
        assert _rel(getattr(fo, n), x) <= 1e-9, n
    assert law.folds(7.0) == dataclasses.replace(fo, V=7.0)  # V-independent


def test_cubic_without_folds():
    """Hypothesis: c² < 3 b d makes the cubic increasing: no stick-slip (has_folds False, fields None)."""
    fo = PeelForce.cubic(a=150, b=300, c=100, d=80).folds(1.0)
    assert fo == pa.Folds(1.0, False)


@pytest.mark.parametrize("family, text", [
    ("cubic", "a + b*v - c*v**2 + d*v**3"),
    ("power_branches", "A1*v**n1/(1 + (v/v1)**m) + A2*v**n2"),
    ("paper", "a1*v**p1 + a2*v**p2 + a3*exp(v/v3) - a4*V**q4 - (a5 - a6*V**q6 - a7*V**q7)*v**p5"),
])
def test_family_derivatives_match_sympy(family, text):
    """Hypothesis: each family's hand-written f, f', f'' equal sympy's derivatives of the same formula (an
    expression law with the family's default coefficients): 1e-12 of the magnitude of f, f', f'' summed over
    the grid's neighbourhood scale (both are double-precision forms of one formula; measured ~1e-15)."""
    fam = PeelForce.family(family)
    expr = PeelForce.expression(text, **dict(fam.coefficients))
    v = np.logspace(-4, 1.5, 111)
    for name in ("f", "df", "d2f"):
        x, y = getattr(fam, name)(v, 1.0), getattr(expr, name)(v, 1.0)
        scale = np.abs(fam.f(v, 1.0)) / v ** ("f", "df", "d2f").index(name)
        assert np.all(np.abs(x - y) <= 1e-12 * scale), name


def test_power_branches_defaults_are_calibrated_to_fvV():
    """Hypothesis: the power-law branches' defaults reproduce fvV's folds at V = 1 m/s within 0.2 % (the
    calibration's residual, measured ≤ 0.03 %), as their docstring states."""
    fo, bs = PeelForce.power_branches().folds(1.0), pa.branch_structure(1.0)
    for n in ("v_max", "f_max", "v_min", "f_min"):
        assert _rel(getattr(fo, n), getattr(bs, n)) <= 2e-3, n


# --------------------------------------------------------------------------- tabulated laws
LO, HI = 0.1, 3.0  # the table's range [m/s], around the default cubic's folds (0.691, 1.809)


def convergence_rows(Ns=(20, 40, 80, 160)):
    """The default cubic sampled on N log-spaced points of [0.1, 3] m/s, interpolated: per N the spacing h
    in ln v, the largest |Δf| [N] over 20001 points (all; and farther than 0.3 in ln v from the folds), and
    the relative errors of the folds and landings."""
    cub = PeelForce.cubic()
    fo = cub.folds(1.0)
    fine = np.exp(np.linspace(math.log(LO), math.log(HI), 20001))
    away = (np.abs(np.log(fine / fo.v_max)) > 0.3) & (np.abs(np.log(fine / fo.v_min)) > 0.3)
    rows = []
    for N in Ns:
        v = np.exp(np.linspace(math.log(LO), math.log(HI), N))
        tab = PeelForce.tabulated(v, cub.f(v, 1.0))
        err = np.abs(tab.f(fine, 1.0) - cub.f(fine, 1.0))
        tf = tab.folds(1.0)
        rows.append(dict(N=N, h=math.log(HI / LO) / (N - 1), df_all=float(err.max()), df_away=float(err[away].max()),
                         **{n: _rel(getattr(tf, n), getattr(fo, n)) for n in FOLD_FIELDS}))
    return rows


def test_tabulated_convergence():
    """Hypothesis (measured, stated in peelapprox/law/_table.py): PCHIP in ln v of the cubic converges at
    third order away from the folds (observed order ≥ 2.5 between consecutive N; measured 2.8-2.95); at the
    folds PCHIP puts f' = 0 at the extreme datum, so the fold *positions* are data points, within one
    spacing h (in ln v) of the true ones, and f_max (f_min) is the largest (smallest) datum: below (above)
    the true one by at most ½ max|f''| Δv², Δv = v_fold (e^h - 1) (Taylor); the landings converge with them."""
    cub = PeelForce.cubic()
    fo = cub.folds(1.0)
    rows = convergence_rows()
    for r0, r1 in zip(rows, rows[1:]):
        order = math.log(r0["df_away"] / r1["df_away"]) / math.log(r0["h"] / r1["h"])
        assert order >= 2.5, (r0["N"], r1["N"], order)
    for r in rows:
        h = r["h"]
        for vn, fn in (("v_max", "f_max"), ("v_min", "f_min")):
            vf, ff = getattr(fo, vn), getattr(fo, fn)
            assert r[vn] <= math.expm1(h) + 1e-12
            dv = vf * math.expm1(h)
            assert r[fn] * ff <= 0.5 * abs(cub.d2f(vf, 1.0)) * 1.5 * dv**2  # f'' varies < 50 % within dv
    assert rows[-1]["v_land_cd"] < rows[0]["v_land_cd"] / 50 and rows[-1]["v_land_ab"] < rows[0]["v_land_ab"] / 10


def test_tabulated_folds_are_data_points():
    """Hypothesis: f_max and f_min of a table are its largest and smallest interior data (PCHIP adds no
    extremum), to 1e-12 relative (the Brent root of f' lands within 1e-15 in ln v of the datum)."""
    v = np.exp(np.linspace(math.log(LO), math.log(HI), 30))
    f = PeelForce.cubic().f(v, 1.0)
    fo = PeelForce.tabulated(v, f).folds(1.0)
    turns = np.flatnonzero(np.diff(np.sign(np.diff(f)))) + 1  # the interior extrema of the data
    i, j = int(turns[0]), int(turns[1])
    assert _rel(fo.v_max, v[i]) <= 1e-12 and _rel(fo.f_max, f[i]) <= 1e-12
    assert _rel(fo.v_min, v[j]) <= 1e-12 and _rel(fo.f_min, f[j]) <= 1e-12


def test_tabulated_several_pull_speeds():
    """Hypothesis: tables at V = 0.5, 1, 2 m/s (fvV sampled) give, at a table's V, that table's interpolant
    and between two, the linear blend ((1 - t) f_i + t f_j, t = (V - V_i)/(V_j - V_i)), to 1e-14 relative
    (one multiply-add); outside [0.5, 2] m/s V is refused, and v outside the tables too."""
    v = np.exp(np.linspace(math.log(1e-3), math.log(30.0), 60))
    tabs = [(V, v, pa.peel_force(v, V)) for V in (0.5, 1.0, 2.0)]
    law = PeelForce.tabulated(tables=tabs)
    singles = [PeelForce.tabulated(v, f) for _, _, f in tabs]
    x = np.logspace(-2.9, 1.4, 50)
    assert np.allclose(law.f(x, 1.0), singles[1].f(x, 1.0), rtol=1e-14, atol=0)
    t = (1.5 - 1.0) / (2.0 - 1.0)
    assert np.allclose(law.f(x, 1.5), (1 - t) * singles[1].f(x, 7.0) + t * singles[2].f(x, 7.0), rtol=1e-14, atol=0)
    assert law.depends_on_V and not singles[0].depends_on_V
    with pytest.raises(ValueError, match="outside the tables' pull speeds"):
        law.f(1.0, 3.0)
    with pytest.raises(ValueError, match="not extrapolated"):
        law.f(40.0, 1.0)
    at_one = PeelForce.tabulated(v, tabs[1][2], V=1.0)
    assert at_one.f(1.0, 1.0) == singles[1].f(1.0, 5.0)
    with pytest.raises(ValueError, match="measured at V=1.0"):
        at_one.f(1.0, 2.0)


# --------------------------------------------------------------------------- value semantics
def _one_of_each():
    v = np.exp(np.linspace(math.log(LO), math.log(HI), 25))
    return [PeelForce.paper(), PeelForce.paper_family(a1=401), PeelForce.cubic(), PeelForce.power_branches(),
            PeelForce.expression("a + b*v - c*v**2 + d*v**3", a=150, b=300, c=300, d=80),
            PeelForce.tabulated(v, PeelForce.cubic().f(v, 1.0))]


def test_equality_hash_pickle_json_each_kind():
    """Hypothesis: every kind is equal by value to a rebuilt copy (from pickle, from its asdict JSON), with
    the same hash and key; distinct laws are unequal; a pickle holds no compiled object (it loads in a
    process that never built the law); evaluation after the round trip is bitwise the same."""
    laws = _one_of_each()
    assert len(set(laws)) == len(laws)
    for law in laws:
        law.f(1.0, 1.0)  # build the evaluator, which must not be pickled
        for copy in (pickle.loads(pickle.dumps(law)),
                     PeelForce.from_dict(json.loads(json.dumps(dataclasses.asdict(law))))):
            assert copy == law and hash(copy) == hash(law) and copy.key == law.key and repr(copy) == repr(law)
            assert copy.f(1.0, 1.0) == law.f(1.0, 1.0)
        with pytest.raises(dataclasses.FrozenInstanceError):
            law.kind = "paper"  # type: ignore[misc]
    assert PeelForce.cubic(a=150) == PeelForce.cubic(a=150.0) == PeelForce.family("cubic")
    assert PeelForce.expression("2*v + 1") == PeelForce.expression("v + v + a", a=1)
    assert PeelForce.cubic(a=151) != PeelForce.cubic()
    assert repr(PeelForce.cubic()) == "PeelForce.cubic(a=150, b=300, c=300, d=80)"
    assert eval(repr(PeelForce.power_branches()), {"PeelForce": PeelForce}) == PeelForce.power_branches()


def test_expression_from_sympy_and_text_agree():
    """Hypothesis: a sympy expression (its own symbols v, V, without assumptions) and the same text give one
    law (equal, same key), and an expression law's derivatives are sympy's: f' of the cubic text equals
    b - 2 c v + 3 d v² to 1e-13 relative (a few roundings of a short polynomial)."""
    import sympy as sp

    v, a = sp.symbols("v a")
    law = PeelForce.expression(a + 300 * v - 300 * v**2 + 80 * v**3, a=150)
    assert law == PeelForce.expression("a + 300*v - 300*v^2 + 80*v^3", a=150) and law.key == law.key
    x = np.linspace(0.01, 5, 50)
    assert np.allclose(law.df(x, 1.0), 300 - 600 * x + 240 * x**2, rtol=1e-13, atol=1e-13 * 300)
    assert not law.depends_on_V and law.v_range == (1e-6, 1e3)


def test_keys_are_stable_across_processes():
    """Hypothesis: a law's key (SHA-256 of its canonical content) is the same in another process with another
    hash seed (exact string equality): it can name a cache on disk."""
    laws = _one_of_each()
    code = ("import math, numpy as np, peelapprox as pa\n"
            "from peelapprox import PeelForce\n"
            "import tests.test_law as t\n"
            "print(' '.join(law.key for law in t._one_of_each()))")
    env = dict(os.environ, PYTHONHASHSEED="12345")
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    env["PYTHONPATH"] = root + os.pathsep + env.get("PYTHONPATH", "")
    out = subprocess.run([sys.executable, "-c", code], env=env, cwd=root, capture_output=True, text=True,
                         check=True).stdout.split()
    assert out == [law.key for law in laws]


def test_peelparams_default_unchanged():
    """Hypothesis: the default force leaves PeelParams as before the field: repr, equality and hash are those
    of the six earlier fields (exact), and a non-default law shows, compares and pickles."""
    p = PeelParams(V=1, I=1e-5)
    assert repr(p) == "PeelParams(V=1.0, I=1e-05, k=1000.0, R=0.1, l=1.0, geometry='paper')"
    assert hash(p) == hash((1.0, 1e-5, 1000.0, 0.1, 1.0, "paper")) and p == PeelParams(V=1.0, I=1e-5)
    q = p.replace(force=PeelForce.cubic())
    assert q != p and "force=PeelForce.cubic(a=150" in repr(q)
    assert pickle.loads(pickle.dumps(q)) == q and hash(pickle.loads(pickle.dumps(q))) == hash(q)
    assert PeelParams(**json.loads(json.dumps(dataclasses.asdict(q)))) == q
    with pytest.raises(TypeError, match="force must be a PeelForce"):
        PeelParams(V=1, I=1e-5, force="cubic")  # type: ignore[arg-type]


def test_saved_trajectory_records_the_law(tmp_path):
    """Hypothesis: a trajectory saved with to_npz records its law in the meta JSON (dataclasses.asdict of
    PeelParams) and loads back to equal params (exact equality); a file from before the field (no "force")
    loads with the paper's law."""
    p = PeelParams(V=1.0, I=1e-5)
    tr = exact.simulate(p, 0.01, save="jumps")
    tr.to_npz(tmp_path / "t.npz")
    with np.load(tmp_path / "t.npz") as z:
        meta = json.loads(str(z["meta"]))
    assert meta["params"]["force"]["kind"] == "paper"
    assert exact.Trajectory.from_npz(tmp_path / "t.npz").params == p
    old = {k: x for k, x in meta["params"].items() if k != "force"}
    assert PeelParams(**old) == p and PeelParams(**old).force is PeelForce.paper()


#: fvV as each kind of law, made when a test first asks (:func:`_law_of_kind`), not at import: every pytest-xdist
#: worker imports this module to collect it, and the expression law's parse and derivatives alone cost ~0.85 s of CPU.
LAW_KINDS = {
    "power_branches": PeelForce.power_branches,
    "expression": lambda: PeelForce.expression(PAPER_TEXT),
    "tabulated": lambda: PeelForce.tabulated(np.logspace(-8, 2, 300),
                                             PeelForce.paper().f(np.logspace(-8, 2, 300), 1.0)),
    "smoothed": lambda: PeelForce.smoothed(np.logspace(-8, 2, 300), PeelForce.paper().f(np.logspace(-8, 2, 300), 1.0)),
}


@functools.cache
def _law_of_kind(kind: str) -> PeelForce:
    return LAW_KINDS[kind]()

CONSUMERS = {
    "estimate": lambda p: pa.estimate(p).v_max,
    "reduced_segment": lambda p: pa.reduced_segment(p, "AB", F_in=220.0, alpha_in=0.0, alphadot_in=0.0).dt,
    "initial_state": lambda p: exact.initial_state(p).v,
    "hybrid_field": lambda p: exact.hybrid_field(p)[0],
    "branch_structure": lambda p: pa.branch_structure(p.V, force=p.force).f_max,
}


@pytest.mark.parametrize("kind", sorted(LAW_KINDS))
@pytest.mark.parametrize("name", sorted(CONSUMERS))
def test_consumers_honour_every_kind_of_law(name, kind):
    """Hypothesis: every consumer of params takes every kind of law (any tape's law runs everywhere; the refusals of the
    transition are gone): with fvV written as each kind (the power branches calibrated to it), each returns a
    value, never a ValueError refusing the law."""
    p = PeelParams(V=1.0, I=1e-5, force=_law_of_kind(kind))
    assert CONSUMERS[name](p) is not None


# --------------------------------------------------------------------------- bad laws
def _table(f=None, v=None):
    v = np.exp(np.linspace(math.log(LO), math.log(HI), 12)) if v is None else v
    return v, (PeelForce.cubic().f(v, 1.0) if f is None else f)


def _bad_tables():
    v, f = _table()
    nan = f.copy()
    nan[4] = np.nan
    neg = f - 200.0
    wavy = 200 + 30 * np.sin(np.linspace(0.2, 3.0 * np.pi, 12))  # up, down, up, down
    return {
        "NaN in f": (lambda: PeelForce.tabulated(v, nan), r"f\[4\] = nan"),
        "unsorted v": (lambda: PeelForce.tabulated(v[[0, 1, 3, 2, *range(4, 12)]], f), r"strictly increasing: v\[2\]"),
        "f <= 0": (lambda: PeelForce.tabulated(v, neg), r"f must be > 0 .*f\[\d+\] = -"),
        "too few points": (lambda: PeelForce.tabulated(v[:4], f[:4]), "at least 5 points.*got 4"),
        "no folds in a table": (lambda: PeelForce.tabulated(v, 100 + v), "found none .*no folds"),
        "three extrema in a table": (lambda: PeelForce.tabulated(v, wavy),
                                     "local max at index .*local min .*local max"),
        "lengths differ": (lambda: PeelForce.tabulated(v, f[:-1]), "same length"),
        "2-D": (lambda: PeelForce.tabulated(np.vstack([v, v]), np.vstack([f, f])), "1-D"),
    }


def _bad_analytic():
    return {
        "unknown symbol": (lambda: PeelForce.expression("a + q*v", a=1), "unknown symbol.*q"),
        "complex on the probe": (lambda: PeelForce.expression("200 + (-v)**0.5"), "complex at v=1e-06"),
        "NaN on the probe": (lambda: PeelForce.expression("sqrt(v - 2) + 200"), r"f is nan at v=1e-06"),
        "unused constant": (lambda: PeelForce.expression("v + 200", a=1), "a do not occur"),
        "no v": (lambda: PeelForce.expression("200 + V"), "does not depend on v"),
        "unknown family": (lambda: PeelForce.family("hong_yue"), "unknown peel-force family 'hong_yue'"),
        "unknown coefficient": (lambda: PeelForce.family("cubic", e=1), "unknown coefficient.*'e' of the 'cubic'"),
        "three extrema": (lambda: PeelForce.expression("200 + 30*sin(2*log(v))").folds(1.0),
                          "exactly one local maximum .*found a local m"),
        "min before max": (lambda: PeelForce.cubic(a=500, b=-300, c=-300, d=-80).folds(1.0),
                           "found a local min at v=0.69.*local max at v=1.8"),
        "decreasing": (lambda: PeelForce.expression("300 - v").folds(1.0), "decreases in v throughout"),
        "a paper law with coefficients": (lambda: PeelForce("paper", coefficients=(("a", 1.0),)),
                                         "'paper' law takes no coefficients"),
        "unknown kind": (lambda: PeelForce.from_dict({"kind": "spline"}), "kind must be one of paper, family"),
        "v outside an expression's domain": (lambda: PeelForce.expression("v + 1").f(1e-7, 1.0),
                                             "outside the domain"),
    }


@pytest.mark.parametrize("case", sorted(_bad_tables()) + sorted(_bad_analytic()))
def test_bad_laws_raise_naming_the_problem(case):
    """Hypothesis: every bad law raises a ValueError (TypeError only for wrong types) whose message names
    what is wrong and where (index, value, symbol or extrema: regex on the message)."""
    call, pattern = {**_bad_tables(), **_bad_analytic()}[case]
    with pytest.raises(ValueError, match=pattern):
        call()


if __name__ == "__main__":
    print(f"{'N':>4} {'h':>7} {'max|df| all':>12} {'away':>10} " + " ".join(f"{n:>10}" for n in FOLD_FIELDS))
    for r in convergence_rows((20, 40, 80, 160, 320)):
        print(f"{r['N']:>4} {r['h']:7.4f} {r['df_all']:12.3e} {r['df_away']:10.3e} "
              + " ".join(f"{r[n]:10.2e}" for n in FOLD_FIELDS))

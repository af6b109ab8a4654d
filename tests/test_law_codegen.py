"""Compiled peel-force laws generated from one symbolic source: peelapprox._compiled._render, law._kernels and
law.codegen.

Oracles: the families' formulas written a second time here by hand (f, f', f'' in closed form, as the numpy
evaluators of ``_law_families`` were before they were generated) and evaluated at 30 digits (mpmath); the
built-in paper law (``paper_law``, generated independently in ``w = ln v`` by ``peelapprox._compiled._symbolic``);
sympy's
own lambdified derivatives of an expression law (``PeelForce.f/df/d2f``).

The tolerance of most comparisons, ``1e-13 * scale``, with ``scale`` the sum of the magnitudes of the terms of
the quantity compared (f, f' or f'' expanded into its terms, each evaluated at 30 digits): a double evaluation
of a sum of a few terms is accurate to a few ulp of its largest term, not of the sum (f' cancels near a fold),
and ``exp(p u)`` with ``u = ln v`` carries the error of u amplified by ``p |u|`` (< 15 on v in [1e-6, 1e3]),
so errors are ~1e-15 * scale; 1e-13 leaves a factor ~50, while a wrong coefficient, exponent or derivative
(``p`` for ``p - 1``) is an O(1) relative error.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
import warnings
from pathlib import Path

import mpmath
import numpy as np
import pytest
import sympy as sp
from _parse import parse

import peelapprox._compiled._render as R
import peelapprox._compiled._symbolic as S
import peelapprox.law._cache as LC
import peelapprox.law._kernels as C
import peelapprox.law.codegen as CG
from peelapprox import PeelForce
from peelapprox.errors import KernelCacheWarning
from peelapprox.law._abi import LAW_FP, LAW_FPP, LAW_LNV, paper_coefficients, paper_law
from peelapprox.law._families import FAMILIES
from peelapprox.law._symbolic import V, family_expression, law_expression, v

ROOT = Path(__file__).resolve().parent.parent
VGRID = np.logspace(-6, 3, 37)  # 9 decades: the domain of an expression law, beyond the families' physical range
PULLS = (0.05, 1.0, 8.0)  # the paper's range of V
TOL = 1e-13


# ------------------------------------------------------------------ the oracles
def _hand(name: str, vv, VV, c):
    """f, f', f'' of the family written by hand (mpmath numbers): the independent second writing."""
    e = mpmath.exp
    if name == "paper":
        a1, p1, a2, p2, a3, v3, a4, q4, a5, a6, q6, a7, q7, p5 = c
        A = a5 - a6 * VV**q6 - a7 * VV**q7
        terms = [[a1 * vv**p1, a2 * vv**p2, a3 * e(vv / v3), -a4 * VV**q4, -A * vv**p5],
                 [a1 * p1 * vv ** (p1 - 1), a2 * p2 * vv ** (p2 - 1), a3 * e(vv / v3) / v3, -A * p5 * vv ** (p5 - 1)],
                 [a1 * p1 * (p1 - 1) * vv ** (p1 - 2), a2 * p2 * (p2 - 1) * vv ** (p2 - 2), a3 * e(vv / v3) / v3**2,
                  -A * p5 * (p5 - 1) * vv ** (p5 - 2)]]
    elif name == "cubic":
        a, b, cc, d = c
        terms = [[a, b * vv, -cc * vv**2, d * vv**3], [b, -2 * cc * vv, 3 * d * vv**2], [-2 * cc, 6 * d * vv]]
    else:  # f = A1 v^n1 / g + A2 v^n2, g = 1 + x, x = (v/v1)^m; with s = m x / g:
        A1, n1, v1, m, A2, n2 = c  # v (v^n1/g)' = (n1 - s) v^n1/g,  v^2 (v^n1/g)'' = [(n1-s)(n1-s-1) - m s/g] v^n1/g
        x = (vv / v1) ** m
        g = 1 + x
        t = A1 * vv**n1 / g
        s = m * x / g
        terms = [[t, A2 * vv**n2], [t * n1 / vv, -t * s / vv, A2 * n2 * vv ** (n2 - 1)],
                 [t * ((n1 - s) * (n1 - s - 1) - m * s / g) / vv**2, A2 * n2 * (n2 - 1) * vv ** (n2 - 2)]]
    return [(sum(ts), sum(abs(x) for x in ts)) for ts in terms]


def _oracle_mp(name: str, c, VV: float):
    """[(value, scale) of f, f', f''] at each point of VGRID, mpmath numbers at 30 digits."""
    with mpmath.workdps(30):
        return [_hand(name, mpmath.mpf(float(x)), mpmath.mpf(VV), [mpmath.mpf(y) for y in c]) for x in VGRID]


def _oracle(name: str, c, VV: float):
    """(value, scale) arrays of f, f', f'' on VGRID (30-digit values rounded to doubles)."""
    rows = _oracle_mp(name, c, VV)
    return [(np.array([float(r[k][0]) for r in rows]), np.array([float(r[k][1]) for r in rows])) for k in range(3)]


def _term_scale(expr, order: int):
    """numpy function (v, V) -> the sum of |terms| of d^order expr / dv^order (the scale of the docstring)."""
    d = sp.expand(sp.diff(expr, v, order))
    return sp.lambdify((v, V), sp.Add(*[sp.Abs(t) for t in sp.Add.make_args(d)]), modules="numpy")


CASES = [("paper", None), ("paper", dict(a1=350.0, p1=0.4, v3=9.0, q6=0.5, p5=0.45)),
         ("cubic", None), ("cubic", dict(a=120.0, b=250.0, c=280.0, d=90.0)),
         ("power_branches", None), ("power_branches", dict(A1=300.0, n1=0.2, v1=2.0, m=1.5, A2=20.0, n2=0.7))]


def _coef(name, given):
    values = dict(FAMILIES[name].defaults, **(given or {}))
    return tuple(values[n] for n in FAMILIES[name].names)


def _pulls(name):
    return PULLS if FAMILIES[name].depends_on_V else (1.0,)


# ------------------------------------------------------------------ the generated module
def test_generated_laws_module_is_fresh():
    """Hypothesis: peelapprox/law/_generated.py is exactly what render_module() produces now (exact string
    equality, as tests/test_symbolic.py for _generated.py): regenerate with ``python -m peelapprox.law.codegen``."""
    assert CG.render_module() == (ROOT / "peelapprox" / "law" / "_generated.py").read_text()


def test_one_command_writes_both_generated_modules(tmp_path, monkeypatch):
    """Hypothesis: ``write_modules`` (the command ``python -m peelapprox.law.codegen``) writes the model's kernels
    and the families' laws, each exactly its renderer's text (string equality), through the one renderer."""
    written = {}
    monkeypatch.setattr(R, "write_module", lambda path, text: written.setdefault(Path(path), text))
    CG.write_modules()
    assert written == {Path(S.__file__).with_name("_generated.py"): S.render_module(),
                       Path(CG.__file__).with_name("_generated.py"): CG.render_module()}


def test_the_renderers_forms_are_the_abis():
    """Hypothesis: the forms the renderer hard-codes (it imports nothing of the law, which sits above it) are
    the ABI's ``LAW_LNV``, ``LAW_FP``, ``LAW_FPP`` (exact tuple equality)."""
    assert R.FORMS == (LAW_LNV, LAW_FP, LAW_FPP)


def test_rendering_does_not_depend_on_the_hash_seed():
    """Hypothesis: the rendering is deterministic (the coef entries are numbered in sympy's canonical order, not
    in set order), so the committed file does not flap between runs: exact equality under another PYTHONHASHSEED."""
    code = "import sys; from peelapprox.law.codegen import render_module; sys.stdout.write(render_module())"
    env = dict(os.environ, PYTHONHASHSEED="12345", PYTHONPATH=str(ROOT))
    r = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr[-2000:]
    assert r.stdout == CG.render_module()


# ------------------------------------------------------------------ the symbolic form and the numpy evaluators
@pytest.mark.parametrize("name,given", CASES)
def test_symbolic_form_is_the_hand_written_family(name, given):
    """Hypothesis: the sympy form of the family (``family_expression``) and its sympy derivatives equal the
    hand-written f, f', f'' of the module docstring's oracle, evaluated at 30 digits (both exact there):
    agreement to 1e-25 * scale (30-digit rounding of a handful of operations)."""
    expr, syms = family_expression(name)
    assert [s.name for s in syms] == list(FAMILIES[name].names)
    c = _coef(name, given)
    e = expr.xreplace(dict(zip(syms, [sp.Float(x, 30) for x in c])))
    derivs = [e, sp.diff(e, v), sp.diff(e, v, 2)]
    for VV in _pulls(name):
        ref = _oracle_mp(name, c, VV)
        fns = [sp.lambdify((v, V), d, modules="mpmath") for d in derivs]
        with mpmath.workdps(30):
            for i, x in enumerate(VGRID):
                for k in range(3):
                    val, scale = ref[i][k]
                    assert abs(fns[k](mpmath.mpf(float(x)), mpmath.mpf(VV)) - val) <= 1e-25 * scale, (name, VV, x, k)


@pytest.mark.parametrize("name,given", CASES)
def test_family_numpy_evaluator_matches_30_digits(name, given):
    """Hypothesis: the families' numpy evaluators (now the generated code) give f, f', f'' to rounding:
    1e-13 * scale against the 30-digit hand-written oracle (module docstring)."""
    c = _coef(name, given)
    for VV in _pulls(name):
        ref = _oracle(name, c, VV)
        for k in range(3):
            got = FAMILIES[name].evaluate(VGRID, VV, c, k)
            assert got.shape == VGRID.shape
            err = np.abs(got - ref[k][0])
            assert np.all(err <= TOL * ref[k][1]), (name, VV, k, float(np.max(err / ref[k][1])))


# ------------------------------------------------------------------ the compiled family laws
@pytest.mark.parametrize("name,given", CASES)
def test_family_kernel_all_forms(name, given):
    """Hypothesis: the compiled law of each family, in the three forms of the ABI (LAW_LNV at u = ln v: v, f,
    v f'; LAW_FP: f, f', NaN; LAW_FPP: f, f', f''), equals the family's numpy evaluator and the 30-digit oracle
    to 1e-13 * scale (module docstring; numba and numpy differ only in the last ulp of exp/log).  v of LAW_LNV is
    exp(u), to 1 ulp times |u| (4e-15 relative)."""
    law, pack = C.family_kernel(name)
    c = _coef(name, given)
    for VV in _pulls(name):
        coef = pack(VV, c)
        assert coef.dtype == np.float64 and coef.flags.c_contiguous
        ref = _oracle(name, c, VV)
        ev = [FAMILIES[name].evaluate(VGRID, VV, c, k) for k in range(3)]
        fp = np.array([law(x, coef, LAW_FP) for x in VGRID])
        fpp = np.array([law(x, coef, LAW_FPP) for x in VGRID])
        lnv = np.array([law(math.log(x), coef, LAW_LNV) for x in VGRID])
        assert np.all(np.isnan(fp[:, 2]))
        assert np.all(np.abs(lnv[:, 0] - VGRID) <= 4e-15 * VGRID)
        pairs = [(fp[:, 0], 0), (fp[:, 1], 1), (fpp[:, 0], 0), (fpp[:, 1], 1), (fpp[:, 2], 2), (lnv[:, 1], 0)]
        for got, k in pairs:
            for want in (ev[k], ref[k][0]):
                assert np.all(np.abs(got - want) <= TOL * ref[k][1]), (name, VV, k)
        assert np.all(np.abs(lnv[:, 2] - VGRID * ref[1][0]) <= TOL * VGRID * ref[1][1]), (name, VV)


def test_paper_family_at_defaults_is_the_built_in_law():
    """Hypothesis: the generated paper family at the paper's coefficients equals ``paper_law`` (the built-in fvV,
    generated in w = ln v with exact rational exponents) in all three forms to rounding: 1e-13 * scale (module
    docstring; the float exponents 0.35, 0.15 differ from 7/20, 3/20 by < 1e-17, i.e. < 1e-15 relative in
    v^p at |ln v| < 14)."""
    law, pack = C.family_kernel("paper")
    c = _coef("paper", None)
    for VV in PULLS:
        coef, pc = pack(VV, c), paper_coefficients(VV)
        ref = _oracle("paper", c, VV)
        for i, x in enumerate(VGRID):
            a, b = law(x, coef, LAW_FPP), paper_law(x, pc, LAW_FPP)
            for k in range(3):
                assert abs(a[k] - b[k]) <= TOL * ref[k][1][i], (VV, x, k)
            a, b = law(math.log(x), coef, LAW_LNV), paper_law(math.log(x), pc, LAW_LNV)
            assert abs(a[0] - b[0]) <= 4e-15 * x and abs(a[1] - b[1]) <= TOL * ref[0][1][i]
            assert abs(a[2] - b[2]) <= TOL * x * ref[1][1][i]


def test_kernel_does_no_V_arithmetic():
    """Hypothesis: the V-dependence of the paper family is hoisted into coef (b = -a4 V^q4 and the prefactor
    A = a5 - a6 V^q6 - a7 V^q7 of -v^p5 are entries, computed by pack): the names the law's code uses are its
    arguments, v, u, the coef entries k<i>, CSE temporaries w<i>, its outputs and numpy; never V or a
    coefficient (exact: the set of names in its syntax tree)."""
    import ast
    import inspect
    import re

    from peelapprox.law import _generated as G

    for name in FAMILIES:
        tree = parse(inspect.getsource(G.LAWS[name][0]))
        names = {n.id for n in ast.walk(tree) if isinstance(n, ast.Name)}
        plain = {n for n in names if not re.fullmatch(r"[kw]\d+", n)}
        assert plain <= {"x", "coef", "form", "u", "v", "s", "numpy", "f", "fp", "fpp", "vfp"}, (name, plain)
    doc = G.law_paper.__doc__
    assert "-V**q4*a4" in doc and "V**q6*a6 + V**q7*a7 - a5" in doc  # b and -A are coef entries


# ------------------------------------------------------------------ law_expression
def test_law_expression_of_each_kind():
    """Hypothesis: law_expression gives the law of each kind: the paper's fvV (exact rationals: equal to
    _symbolic.peel_force_expr symbolically), the paper family at defaults equal to it at 30 digits to 1e-15
    relative (floats 0.35, ... vs rationals 7/20, ...: < 1e-17 relative in the exponents), a family with its
    coefficients, an expression rebuilt from its text (exactly equal), and ValueError for a table."""
    from peelapprox._compiled import _symbolic as S

    paper = law_expression(PeelForce.paper())
    assert sp.simplify(paper - S.peel_force_expr(v, V)) == 0
    fam = law_expression(PeelForce.paper_family())
    for vv, VV in ((1e-4, 0.05), (0.3, 1.0), (20.0, 8.0)):
        a, b = (sp.N(x.subs({v: vv, V: VV}), 30) for x in (fam, paper))
        assert abs(a - b) <= 1e-15 * abs(b)
    cub = law_expression(PeelForce.cubic(a=1.0, b=2.0, c=3.0, d=4.0))
    assert sp.expand(cub - (1 + 2 * v - 3 * v**2 + 4 * v**3)) == 0
    force = PeelForce.expression("a*v**0.3 + b*exp(-v/V)", a=2.0, b=3.0)
    assert law_expression(force) == 2 * v**sp.Float(0.3) + 3 * sp.exp(-v / V)  # built by hand: an independent oracle
    vt = np.linspace(0.1, 3.0, 30)
    table = PeelForce.tabulated(v=vt, f=150 + 300 * vt - 300 * vt**2 + 80 * vt**3)
    with pytest.raises(ValueError, match="tabulated.*no closed form"):
        law_expression(table)


# ------------------------------------------------------------------ expression laws
EXPRESSIONS = [(("a + b*v - c*v**2 + d*v**3",), dict(a=150, b=300, c=300, d=80)),
               (("a*v**0.35 + b*exp(-v/V) - c*V**0.4*sqrt(v) + log(v)",), dict(a=400.0, b=130.0, c=45.0))]


@pytest.fixture
def law_cache(tmp_path, monkeypatch):
    """A fresh expression-law cache directory and an empty per-process memo."""
    monkeypatch.setenv("PEELAPPROX_CACHE_DIR", str(tmp_path / "laws"))
    monkeypatch.setattr(C, "_EXPRESSION_KERNELS", {})
    monkeypatch.setattr(LC, "_FALLBACK", {})
    return tmp_path / "laws"


@pytest.mark.parametrize("args,constants", EXPRESSIONS)
def test_expression_kernel_matches_peel_force(law_cache, args, constants):
    """Hypothesis: the compiled expression law gives PeelForce.f, .df, .d2f (sympy's derivatives through numpy,
    an independent rendering) in all three forms, at each pull speed, to 1e-13 * scale (module docstring; the
    scale of each quantity is the sum of the magnitudes of its sympy terms)."""
    force = PeelForce.expression(*args, **constants)
    law, pack = C.expression_kernel(force.source)
    assert len(list(law_cache.glob("law_*.py"))) == 1
    expr = law_expression(force)
    scales = [_term_scale(expr, k) for k in range(3)]
    for VV in (PULLS if force.depends_on_V else (1.0,)):
        coef = pack(VV)
        ref = [force.f(VGRID, VV), force.df(VGRID, VV), force.d2f(VGRID, VV)]
        sc = [TOL * np.broadcast_to(np.asarray(fn(VGRID, VV), dtype=float), VGRID.shape) for fn in scales]
        fpp = np.array([law(x, coef, LAW_FPP) for x in VGRID])
        fp = np.array([law(x, coef, LAW_FP) for x in VGRID])
        lnv = np.array([law(math.log(x), coef, LAW_LNV) for x in VGRID])
        for k in range(3):
            assert np.all(np.abs(fpp[:, k] - ref[k]) <= sc[k]), (VV, k)
        for k in range(2):
            assert np.all(np.abs(fp[:, k] - ref[k]) <= sc[k]), (VV, k)
        assert np.all(np.isnan(fp[:, 2]))
        assert np.all(np.abs(lnv[:, 0] - VGRID) <= 4e-15 * VGRID)
        assert np.all(np.abs(lnv[:, 1] - ref[0]) <= sc[0])
        assert np.all(np.abs(lnv[:, 2] - VGRID * ref[1]) <= VGRID * sc[1])


def test_changed_expression_is_a_new_file(law_cache, monkeypatch):
    """Hypothesis: the file of an expression law is named by its text and the code generator's version, so a
    changed expression (or generator) gets a new file and its own numbers, never a stale kernel.  Exact: file
    counts and names; the numbers to 1e-13 relative (positive terms, no cancellation at v = 0.5)."""
    f1 = PeelForce.expression("a + b*v - c*v**2 + d*v**3", a=150, b=300, c=300, d=80)
    f2 = PeelForce.expression("a + b*v - c*v**2 + d*v**3", a=150, b=300, c=300, d=81)
    l1, p1 = C.expression_kernel(f1.source)
    l2, p2 = C.expression_kernel(f2.source)
    files = sorted(law_cache.glob("law_*.py"))
    assert len(files) == 2
    for law, pack, force in ((l1, p1, f1), (l2, p2, f2)):
        assert abs(law(0.5, pack(1.0), LAW_FP)[0] - float(force.f(0.5, 1.0))) <= 1e-13 * float(force.f(0.5, 1.0))
    assert abs(l2(0.5, p2(1.0), LAW_FP)[0] - l1(0.5, p1(1.0), LAW_FP)[0] - 0.125) <= 1e-12
    assert C.expression_kernel(f1.source)[0] is l1  # memoised
    monkeypatch.setattr(C, "CODEGEN_VERSION", "law-codegen-test")
    monkeypatch.setattr(C, "_EXPRESSION_KERNELS", {})
    C.expression_kernel(f1.source)
    assert len(list(law_cache.glob("law_*.py"))) == 3  # a new generator version: a new file
    assert not list(law_cache.glob("*.tmp"))  # the atomic write left no temporary file


def test_unwritable_cache_dir_falls_back_with_a_warning(law_cache, monkeypatch):
    """Hypothesis: with an unwritable cache directory (a path under /proc cannot be created, even as root) the
    law is written to a temporary directory with one KernelCacheWarning and works (its f to 1e-13 relative:
    positive terms at v = 0.5)."""
    if not Path("/proc").is_dir():
        pytest.skip("needs procfs for an uncreatable path")
    monkeypatch.setenv("PEELAPPROX_CACHE_DIR", "/proc/peelapprox-no-such-dir/laws")
    force = PeelForce.expression("a + b*v**2", a=1.0, b=2.0)
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        law, pack = C.expression_kernel(force.source)
    assert [type(x.message) for x in w].count(KernelCacheWarning) == 1
    assert abs(law(0.5, pack(1.0), LAW_FP)[0] - 1.5) <= 1e-13 * 1.5


PROBE = """
import json, sys
from peelapprox import PeelForce
from peelapprox.law._kernels import expression_kernel
force = PeelForce.expression("a*v**0.35 + b*exp(-v/V) - c*V**0.4*sqrt(v)", a=400.0, b=130.0, c=45.0)
law, pack = expression_kernel(force.source)
print(json.dumps(dict(hits=sum(law.stats.cache_hits.values()), misses=sum(law.stats.cache_misses.values()),
                      n=len(law.signatures), r=law(0.3, pack(1.5), 2))))
"""


def test_second_process_loads_the_compiled_law(tmp_path):
    """Hypothesis: an expression law compiled by one process is loaded from numba's on-disk cache by the next
    (fresh PEELAPPROX_CACHE_DIR and NUMBA_CACHE_DIR): the first run compiles (one cache miss, no hit), the
    second compiles nothing (one hit, no miss; numba's dispatcher statistics, as tests/test_kernel_cache.py)
    and gives bitwise the same numbers (the same machine code)."""
    env = {k: x for k, x in os.environ.items() if not k.startswith("NUMBA_")}
    env.update(PYTHONPATH=str(ROOT), PEELAPPROX_CACHE_DIR=str(tmp_path / "laws"),
               NUMBA_CACHE_DIR=str(tmp_path / "numba"), PYTHONDONTWRITEBYTECODE="1")
    outs = []
    for _ in range(2):
        r = subprocess.run([sys.executable, "-c", PROBE], cwd=tmp_path, env=env, capture_output=True, text=True,
                           timeout=600)
        assert r.returncode == 0, r.stderr[-3000:]
        outs.append(json.loads(r.stdout.strip().splitlines()[-1]))
    first, second = outs
    assert (first["hits"], first["misses"], first["n"]) == (0, 1, 1)
    assert (second["hits"], second["misses"], second["n"]) == (1, 0, 1)
    assert second["r"] == first["r"]
    assert len(list((tmp_path / "laws").glob("law_*.py"))) == 1


# ------------------------------------------------------------------ bad input
def test_bad_input():
    """Hypothesis: unusable names and unknown families or symbols are ValueErrors naming them; a non-string
    source a TypeError (exact messages matched)."""
    a = sp.Symbol("coef", real=True)
    with pytest.raises(ValueError, match="coefficient name 'coef'"):
        R.render_law("law", a * v, (a,))
    with pytest.raises(ValueError, match="symbols q other than"):
        R.render_law("law", sp.Symbol("q") * v, ())
    with pytest.raises(ValueError, match="unknown peel-force family 'nope'"):
        C.family_kernel("nope")
    with pytest.raises(ValueError, match="unknown peel-force family 'nope'"):
        family_expression("nope")
    with pytest.raises(TypeError, match="source must be"):
        C.expression_kernel(1.0)  # type: ignore[arg-type]

"""The one renderer of generated code: sympy expressions into plain Python on numpy functions.

Both generated modules and every expression law come from here: the model's kernels
(:func:`render_function`, into ``peelapprox/_compiled/_generated.py`` from :mod:`peelapprox._compiled._symbolic`), the
families'
laws (:func:`render_law`, into ``peelapprox/law/_generated.py``) and a user's expression law (compiled at run
time by ``peelapprox/law/_kernels.py``); :func:`render_module` joins a header and functions into a module's
text and :func:`write_module` writes it.  ``python -m peelapprox.law.codegen`` regenerates both modules.

:func:`render_law` turns a law ``f(v, V; c)`` (sympy, in the symbols ``v``, ``V`` of
:mod:`peelapprox.law._symbolic`) into the Python source of a law of the compiled laws' ABI
(``peelapprox/law/_abi.py``) — ``law(x, coef, form) -> (f8, f8, f8)`` — and of its packing ``pack(V, c) -> coef``.
The rendering:

* **u = ln v.**  Every power of v with a non-integer exponent becomes ``exp(p u)`` (a half-integer one
  ``v^k s`` with ``s = sqrt v``, cheaper) and ``ln v`` becomes ``u`` (integer powers stay products).  The law
  is then ``F(v, u, s)``, so ``f' = D F`` with ``D = d/dv + (d/du + s/2 d/ds) / v`` and
  ``v f' = v F_v + F_u + s F_s / 2``: the derivatives keep the exponentials of f (no new ``pow``), the form
  ``LAW_LNV`` (x = u) needs no ``log`` and ``LAW_FP``/``LAW_FPP`` (x = v) one ``log`` (only if u occurs).
* **The V-dependence is hoisted.**  Each output is expanded into a sum of terms, terms with the same
  v-dependent factor are collected, and every maximal subexpression free of v and u (of V and the
  coefficients only: ``-a4 V^q4``, ``-(a5 - a6 V^q6 - a7 V^q7)``, ``a1 p1``, ``1/v3`` ...) becomes one entry
  of ``coef``, computed once by ``pack`` when a run is packed.  The kernel does no arithmetic on V or the
  coefficients alone; numbers stay literals.  The entries are numbered in sympy's canonical order, and each
  law's docstring lists them (``coef = pack(V, c) = [...]``): that is the coef layout.
* **One code path, CSE** over f, v f', f', f'' (as :func:`render_function` does for the model): f, then the
  return of ``LAW_LNV`` with v f', then f' and the return of ``LAW_FP``, then f''; floats are printed exactly
  (``repr``).

This module imports nothing of the package (it sits below the law, which compiles expression laws with it);
the forms it hard-codes are the ABI's (a test checks :data:`FORMS` against ``peelapprox/law/_abi.py``).
sympy is imported when something is rendered, not with this module.
"""

from __future__ import annotations

import os
import re
from collections.abc import Sequence
from pathlib import Path
from typing import Any

__all__ = ["CODEGEN_VERSION", "FORMS", "render_function", "render_law", "render_module", "write_module"]

#: Bump when the rendering changes what a law computes (the file's own hash is in
#: :func:`peelapprox.law._kernels.codegen_version` too).
CODEGEN_VERSION = "law-codegen-1"
#: The forms hard-coded in the rendered laws: ``LAW_LNV``, ``LAW_FP``, ``LAW_FPP`` of the ABI.
FORMS = (0, 1, 2)
#: Names a coefficient may not take (the kernel's and pack's own).
_RESERVED = {"x", "coef", "form", "v", "u", "s", "V", "numpy", "cs"}
_GENERATED_NAME = re.compile(r"^[wt]\d+$")


# ---------------------------------------------------------------------------------------------- rendering
def _printer(exact: bool = True) -> Any:
    """sympy's numpy printer; ``exact``: floats as ``repr`` and negative integer powers as ``1.0/...`` (the laws)."""
    from sympy.printing.numpy import NumPyPrinter

    class _Printer(NumPyPrinter):
        """numpy printer with exact floats and integer powers as products (numba: no ``pow`` call)."""

        def _print_Float(self, expr: Any) -> str:
            return repr(float(expr))

        def _print_Pow(self, expr: Any, rational: bool = False) -> str:
            if expr.exp.is_Integer and expr.exp < 0:
                base = expr.base ** (-expr.exp)
                return f"(1.0/{self.parenthesize(base, 1000)})" if base.is_Pow else f"(1.0/{self._print(base)})"
            return super()._print_Pow(expr, rational=rational)

    return (_Printer if exact else NumPyPrinter)({"fully_qualified_modules": True, "inline": True})


# ------------------------------------------------------------------------------------------ the model's kernels
def render_function(name: str, args: Sequence[str], exprs: Sequence[Any], doc: str,
                    out_names: Sequence[str] | None = None, prelude: Sequence[tuple[Any, Any]] = (),
                    extra_outs: Sequence[str] = ()) -> str:
    """Python source of ``def name(*args)`` returning ``exprs`` after common-subexpression elimination.

    ``prelude`` lines ``sym = expr`` come first (the CSE symbols are ``x0, x1, ...``); the outputs are named
    ``out_names`` (default ``r0, r1, ...``) and returned after ``extra_outs`` (names the prelude defines).  A
    numeric output is printed as a float (numba then types the tuple homogeneously).  sympy's numpy printer.
    """
    import sympy as sp

    printer = _printer(exact=False)
    repl, red = sp.cse(list(exprs), symbols=sp.numbered_symbols("x"), optimizations="basic")
    lines = [f"def {name}({', '.join(args)}):", f'    """{doc}"""']
    lines += [f"    {sym} = {printer.doprint(e)}" for sym, e in prelude]
    for sym, e in repl:
        lines.append(f"    {sym} = {printer.doprint(e)}")
    outs = list(out_names or [f"r{i}" for i in range(len(red))])
    for o, e in zip(outs, red):
        e = sp.Float(e) if e.is_Number else e  # homogeneous float tuples for numba
        lines.append(f"    {o} = {printer.doprint(e)}")
    ret = ", ".join(list(extra_outs) + outs)
    lines.append(f"    return {ret}" + ("," if len(outs) + len(extra_outs) == 1 else ""))
    return "\n".join(lines) + "\n"


def render_module(header: str, functions: Sequence[str]) -> str:
    """A generated module's text: its ``header`` (docstring and imports) and the rendered functions."""
    return "\n\n".join([header, *functions])


def write_module(path: str | os.PathLike, text: str) -> str:
    """Write a generated module's ``text`` to ``path``; return the path."""
    Path(path).write_text(text)
    return str(path)


# ---------------------------------------------------------------------------------------------- the laws
def _in_u(expr: Any, v: Any, u: Any, s: Any) -> Any:
    """``expr`` with ``ln v -> u``, ``v^(n/2) -> v^((n-1)/2) s`` (s = sqrt v, cheaper than exp) and
    ``v^p -> exp(p u)`` for other non-integer p (powers of products split first)."""
    import sympy as sp

    def half(a: Any) -> bool:
        return bool(a.is_Pow and a.base == v and a.exp.is_Rational and a.exp.q == 2)

    e = sp.expand_power_base(expr)  # (v/v1)^m -> v^m v1^-m (v and the scales are positive)
    # a float exponent that is a multiple of 1/2 (v**0.5, v**2.0) is that exact rational: the same number
    e = e.replace(lambda a: a.is_Pow and a.base == v and a.exp.is_Float and float(a.exp * 2).is_integer(),
                  lambda a: v ** sp.Rational(int(float(a.exp * 2)), 2))
    e = e.replace(lambda a: isinstance(a, sp.log) and a.args[0] == v, lambda a: u)
    e = e.replace(half, lambda a: v ** (a.exp - sp.Rational(1, 2)) * s)
    return e.replace(lambda a: a.is_Pow and a.base == v and not a.exp.is_Integer, lambda a: sp.exp(a.exp * u))


def _expand(e: Any) -> Any:
    import sympy as sp

    return sp.expand(e, deep=True, mul=True, multinomial=False, power_exp=False, power_base=False, log=False)


class _Hoister:
    """Replaces every maximal subexpression free of v and u by a placeholder (one per distinct expression)."""

    def __init__(self, variables: tuple) -> None:
        self.vars = set(variables)
        self.table: dict[Any, Any] = {}

    def _free(self, e: Any) -> Any:
        import sympy as sp

        if e.is_Number:
            return e
        if e not in self.table:
            self.table[e] = sp.Symbol(f"_h{len(self.table)}", real=True)
        return self.table[e]

    def __call__(self, e: Any) -> Any:
        import sympy as sp

        if not (e.free_symbols & self.vars):
            # factor sums of symbols (a5 p5 - a5 -> a5 (p5 - 1)); not floats, which factor would rescale
            return self._free(sp.factor(e) if e.is_Add and not e.has(sp.Float) else sp.factor_terms(e))
        if e.is_Atom:
            return e
        if e.is_Add:
            groups: dict[Any, list] = {}
            const = []
            for a in e.args:
                ind, dep = a.as_independent(*self.vars, as_Add=False)
                if dep == 1:
                    const.append(ind)
                else:
                    groups.setdefault(dep, []).append(ind)
            terms = [self(sp.Add(*const))] if const else []
            terms += [self(sp.Add(*inds)) * self(dep) for dep, inds in groups.items()]
            return sp.Add(*terms)
        if e.is_Mul:
            ind, dep = e.as_independent(*self.vars, as_Add=False)
            factors = dep.args if dep.is_Mul else (dep,)
            return self(ind) * sp.Mul(*[self(f) for f in factors])
        return e.func(*[self(a) for a in e.args])


def _check_names(coef_symbols: Sequence[Any]) -> None:
    for s in coef_symbols:
        n = s.name
        if not n.isidentifier() or n in _RESERVED or _GENERATED_NAME.match(n) or n.startswith("_"):
            raise ValueError(f"coefficient name {n!r} is not usable in generated code: it must be a Python name "
                             f"other than {', '.join(sorted(_RESERVED))}, w<i>, t<i> or one starting with _")


def render_law(name: str, expr: Any, coef_symbols: Sequence[Any] = (), pack_name: str | None = None,
               doc: str = "") -> str:
    """Python source of the law ``name(x, coef, form)`` of the ABI and of ``pack_name(V, c)`` (module doc).

    Parameters
    ----------
    name : str
        The law function's name; ``pack_name`` (default ``name + "_pack"``) is its packing.
    expr : sympy expression
        ``f`` in the positive symbols ``v`` and ``V`` (those of :mod:`peelapprox.law._symbolic`) and
        ``coef_symbols``.
    coef_symbols : sequence of sympy symbols
        The coefficients, in the order ``pack``'s ``c`` gives them.
    doc : str
        First line of the law's docstring.

    Returns
    -------
    str
        Two functions: ``name(x, coef, form)`` returning ``(v, f, v f')`` for ``form == 0`` (x = ln v),
        ``(f, f', nan)`` for 1 and ``(f, f', f'')`` for 2 (x = v), plain Python on numpy functions (numba
        compiles it, numpy evaluates it on arrays); ``pack_name(V, c)`` returning ``coef`` (float64 array).

    Raises
    ------
    ValueError
        A coefficient name unusable in code, or a symbol other than v, V and the coefficients.
    """
    import sympy as sp

    v, V = sp.Symbol("v", positive=True), sp.Symbol("V", positive=True)
    _check_names(coef_symbols)
    unknown = sorted(s.name for s in expr.free_symbols - {v, V, *coef_symbols})
    if unknown:
        raise ValueError(f"expr has symbols {', '.join(unknown)} other than v, V and the coefficients")
    derived, repl, red, used = _law_outputs(expr, v)
    pack_name = pack_name or f"{name}_pack"
    return (_law_source(name, pack_name, doc, derived, repl, red, used) + "\n\n"
            + _pack_source(name, pack_name, [s.name for s in coef_symbols], derived))


#: The law's outputs in the order they are computed: f, then v f' (LAW_LNV), f' (LAW_FP) and f'' (LAW_FPP).
_OUTS = ("f", "vfp", "fp", "fpp")


def _law_outputs(expr: Any, v: Any) -> tuple[list, list, list, set]:
    """f, v f', f', f'' of ``expr`` in u = ln v and s = sqrt v with the V-dependence hoisted into ``coef``.

    Returns the hoisted subexpressions (the coef layout, canonical order), the CSE definitions ``(w_i, rhs)``,
    the reduced outputs (in :data:`_OUTS` order) and the symbols they use.
    """
    import sympy as sp

    u, sq = sp.Symbol("u", real=True), sp.Symbol("s", positive=True)
    F = _in_u(expr, v, u, sq)

    def D(g: Any) -> Any:  # d/dv with u = ln v and s = sqrt(v)
        return sp.diff(g, v) + (sp.diff(g, u) + sq * sp.diff(g, sq) / 2) / v

    f1 = D(F)
    outputs = {"f": F, "fp": f1, "fpp": D(f1),
               "vfp": v * sp.diff(F, v) + sp.diff(F, u) + sq * sp.diff(F, sq) / 2}
    hoist = _Hoister((v, u, sq))
    hoisted = {k: hoist(_expand(e)) for k, e in outputs.items()}
    # number the coef entries in canonical order (deterministic text), then rename the placeholders
    derived = list(sp.ordered(hoist.table))
    ks = [sp.Symbol(f"coef[{i}]", real=True) for i in range(len(derived))]  # read in place
    rename = {hoist.table[d]: ks[i] for i, d in enumerate(derived)}
    repl, red = sp.cse([hoisted[k].xreplace(rename) for k in _OUTS], symbols=sp.numbered_symbols("w"),
                       optimizations="basic")
    red = [sp.Float(e) if e.is_Number else e for e in red]  # homogeneous float tuples for numba
    used = set().union(*(e.free_symbols for e in red), *(e.free_symbols for _, e in repl))
    return derived, repl, red, used


def _law_source(name: str, pack_name: str, doc: str, derived: list, repl: list, red: list, used: set) -> str:
    """The law function's text: each form returns as soon as its outputs are computed."""
    import sympy as sp

    p = _printer()
    defs = dict(repl)

    def stage(out: str, done: set, indent: str) -> list[str]:
        """The CSE lines ``out`` needs that ``done`` does not hold (in order), then ``out`` itself."""
        e = red[_OUTS.index(out)]
        need, stack = set(), list(e.free_symbols)
        while stack:
            sym = stack.pop()
            if sym in defs and sym not in need and sym not in done:
                need.add(sym)
                stack.extend(defs[sym].free_symbols)
        done |= need
        return [f"{indent}{sym} = {p.doprint(rhs)}" for sym, rhs in repl if sym in need] + [
            f"{indent}{out} = {p.doprint(e)}"]

    layout = ", ".join(p.doprint(d) for d in derived)
    lines = [f"def {name}(x, coef, form):",
             f'    """{doc or "A peel-force law"} in the ABI of peelapprox.law._abi.',
             "",
             f"    coef = {pack_name}(V, c) = [{layout}]",
             '    """',
             "    v = numpy.exp(x) if form == 0 else x  # LAW_LNV: x = ln v -> (v, f, v f'); else x = v"]
    lines += ["    u = x if form == 0 else numpy.log(v)"] if sp.Symbol("u", real=True) in used else []
    lines += ["    s = numpy.sqrt(v)"] if sp.Symbol("s", positive=True) in used else []
    done: set = set()
    lines += stage("f", done, "    ")
    lines.append("    if form == 0:")
    lines += stage("vfp", set(done), "        ")
    lines.append("        return v, f, vfp")
    lines += stage("fp", done, "    ")
    lines.append("    if form == 1:")
    lines.append("        return f, fp, numpy.nan")
    lines += stage("fpp", done, "    ")
    lines.append("    return f, fp, fpp")
    return "\n".join(lines) + "\n"


def _pack_source(name: str, pack_name: str, names: list[str], derived: list) -> str:
    """The packing's text: ``coef`` (the hoisted subexpressions, after CSE) from V and the coefficients."""
    import sympy as sp

    p = _printer()
    plines = [f"def {pack_name}(V, cs=()):",
              f'    """coef of {name} at the pull speed V from the coefficients cs = ({", ".join(names)})."""']
    if names:
        plines.append(f"    {', '.join(names)}{',' if len(names) == 1 else ''} = cs")
    if derived:
        repl, red = sp.cse(derived, symbols=sp.numbered_symbols("t"), optimizations="basic")
        plines += [f"    {sym} = {p.doprint(rhs)}" for sym, rhs in repl]
        plines.append(f"    return numpy.array([{', '.join(p.doprint(e) for e in red)}], dtype=numpy.float64)")
    else:
        plines.append("    return numpy.zeros(0, dtype=numpy.float64)")
    return "\n".join(plines) + "\n"

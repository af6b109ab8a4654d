"""Expression peel-force laws: a sympy expression in ``v`` (and ``V``), canonical form, numpy evaluation.

:func:`canonical` turns what the user typed (a string or a sympy expression, with named constants) into
the canonical text of the law -- the expression with the constants substituted, printed in the grammar of
:mod:`peelapprox.law._grammar` (floats exact), in the symbols ``v`` and ``V`` (both positive) -- and checks
it; :class:`ExpressionLaw` rebuilds the expression from that text by the same grammar (parsed, never
evaluated) and evaluates f, f' and f'' (derivatives by sympy) through ``sympy.lambdify`` to numpy (lambdify
prints the checked sympy tree as numpy code: only whitelisted nodes reach it).  The canonical text is plain
data: it is what a :class:`peelapprox.PeelForce` keeps, shows, stores and hashes (its SHA-256 is the law's
``key``, for caches of compiled code); :func:`from_stored` reads it back from a file, whatever wrote it.

sympy is imported inside the functions only: ``import peelapprox`` does not import it.

The probe: at construction f, f' and f'' are evaluated on :data:`PROBE_V` (241 points, log-spaced over
:data:`V_DOMAIN` = [1e-6, 1e3] m/s) at each pull speed of :data:`PROBE_PULL` (if the law depends on V); a
non-finite or complex value there is a ValueError naming the point.  An expression law is evaluated on
``V_DOMAIN`` only (outside it, a ValueError), since the probe vouches for nothing else.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .._checks import shown
from .._deadline import LAW_BUILD_SECONDS, Expired, time_limit
from . import _grammar

__all__ = ["MAX_DERIVATIVE_NODES", "PROBE_PULL", "PROBE_V", "V_DOMAIN", "ExpressionLaw", "canonical", "from_stored",
           "from_text"]

#: The peel velocities [m/s] on which an expression law is probed and may be evaluated.
V_DOMAIN = (1e-6, 1e3)
#: The probe grid of v: 241 points log-spaced over V_DOMAIN (9 decades, neighbours ≈ 9 % apart).
PROBE_V = np.logspace(math.log10(V_DOMAIN[0]), math.log10(V_DOMAIN[1]), 241)
#: The largest f' and f'' (first and second derivatives in v) an expression law may have [sympy tree nodes], f'
#: checked before f'' is formed (f'' grows about as f' squared over f).  The kernel is rendered from f, f', f''
#: (sympy's expansion, a time growing with their size) and compiled by numba (LLVM passes, which no timer
#: interrupts): a product of 65 factors ran 54 s under ``simulate --max-wall 10``, one of 60 took 33 s to build
#: and 62 s to find its folds.  Measured (2 loaded cores, ``expression_source`` of a product of n linear
#: factors): n = 12, f'' 2,049 nodes, 12 s; n = 16, 5,163, 29 s; n = 20, 10,453, 64 s.  The paper's law has 34
#: nodes in f'', the families at most 48: a law over the limit is refused, named, in about a second.
MAX_DERIVATIVE_NODES = (1_000, 2_500)
#: Pull speeds [m/s] of the probe when the law depends on V (the paper's range is 0.05-8 m/s).
PROBE_PULL = (0.01, 0.1, 1.0, 10.0)


def _symbols():
    import sympy as sp

    return sp.Symbol("v", positive=True), sp.Symbol("V", positive=True)


MAX_EXACT_INTEGER = _grammar.MAX_EXACT_INTEGER  # beyond: a float (the grammar module's docstring of it)


def _number(x: float) -> Any:
    """A constant as sympy number: an integral float is the integer (a=150 and a=150.0 are one law), up to
    :data:`MAX_EXACT_INTEGER`; beyond, the float."""
    import sympy as sp

    x = float(x)
    return sp.Integer(int(x)) if x.is_integer() and abs(x) < MAX_EXACT_INTEGER else sp.Float(x)


def _integral_floats(e: Any) -> Any:
    """``e`` with machine numbers only (:data:`MAX_EXACT_INTEGER`): integral floats below it as integers, integers
    and fractions of integers beyond it as floats (``2**70``, ``1/2**70``; ValueError if beyond the float range)."""
    import sympy as sp

    swap = {x: sp.Integer(int(x)) for x in e.atoms(sp.Float) if float(x).is_integer()
            and abs(float(x)) < MAX_EXACT_INTEGER}
    for r in e.atoms(sp.Rational):
        if abs(r.p) >= MAX_EXACT_INTEGER or r.q >= MAX_EXACT_INTEGER:
            try:
                x = float(r)
            except OverflowError:
                x = math.inf
            if not math.isfinite(x):
                raise ValueError(f"the number {shown(str(r), 40)} exceeds the float range (about 1.8e308)")
            swap[r] = sp.Float(x)
    return e.xreplace(swap) if swap else e


def _grammar_round_trip(e: Any, label: str) -> str:
    """The canonical text of ``e``, checked to parse back to ``e`` itself (at most two printings)."""
    v, V = _symbols()
    for _ in range(3):
        text = _grammar.canonical_text(e)
        back, _used = _grammar.parse(text, {"v": v, "V": V})
        back = _integral_floats(back)
        if back == e:
            return text
        e = back
    raise ValueError(f"expression {label}: its canonical text {shown(text)} does not read back as "
                     "the same expression; write it differently (e.g. expanded)")


def canonical(expr: Any, constants: dict[str, Any]) -> str:
    """The canonical text of ``expr`` with ``constants`` substituted; checked.

    The text is ``expr`` printed in the grammar of :mod:`peelapprox.law._grammar` (sympy's string form, floats
    exact), which :func:`from_text` parses back to the same expression: what a law stores and hashes.  A string
    is parsed by that grammar, never evaluated; a sympy expression is printed and parsed the same way, so
    both meet the same whitelist.

    Raises
    ------
    TypeError
        ``expr`` is neither a string nor a sympy expression, or a constant is not a real number.
    ValueError
        The text is outside the grammar (too long, a forbidden node, name or function: named, with what is
        allowed); a constant is named ``v`` or ``V``, is not finite, or does not occur in the expression; the
        expression does not depend on ``v``; or f, f' or f'' is non-finite or complex at a point of the probe
        (named).
    """
    import sympy as sp

    from .._checks import real

    v, V = _symbols()
    values: dict[str, Any] = {}
    for name, value in constants.items():
        if name in ("v", "V"):
            raise ValueError(f"constant {name!r} clashes with the law's variable {name} (v: peel velocity, "
                             "V: pull speed, m/s)")
        if not (isinstance(name, str) and name.isidentifier()) or name in _grammar.FUNCTIONS:
            raise ValueError(f"constant name {shown(str(name), 40)} must be an identifier other than "
                             "a function's name")
        x = real(name, value)
        if not math.isfinite(x) or abs(x) > _grammar.MAX_LITERAL:
            raise ValueError(f"constant {name} must be finite and at most {_grammar.MAX_LITERAL:g} in "
                             f"magnitude, got {value!r}")
        values[name] = _number(x)
    if isinstance(expr, str):
        label = shown(expr)
        text = expr
    elif isinstance(expr, sp.Basic):
        label = shown(str(expr))
        text = _grammar.canonical_text(expr)
    else:
        raise TypeError(f"expression must be a string or a sympy expression, got {type(expr).__name__}")
    try:
        with time_limit(LAW_BUILD_SECONDS):
            return _checked_text(text, values, label)
    except Expired as exc:
        if exc.caller:  # the caller's budget (caller_budget) was nearer: its own budget exception
            raise
        raise ValueError(f"expression {label}: building it (sympy's derivatives f' and f'' and the probe) took "
                         f"more than {LAW_BUILD_SECONDS:g} s; write it in a simpler form (expanded, fewer factors)"
                         ) from None


def _checked_text(text: str, values: dict[str, Any], label: str) -> str:
    """:func:`canonical`'s work on the text, once the constants are checked."""
    import sympy as sp

    v, V = _symbols()
    e, used = _grammar.parse(text, {"v": v, "V": V, **values})
    unused = sorted(set(values) - used)
    if unused:
        raise ValueError(f"constant(s) {', '.join(unused)} do not occur in the expression {label}")
    if not isinstance(e, sp.Expr):
        raise ValueError(f"expression {label} is not a scalar expression (got {type(e).__name__})")
    e = _integral_floats(e)
    if v not in e.free_symbols:
        raise ValueError(f"expression {label} does not depend on v (it is {shown(str(e), 60)}): a peel "
                         "force must vary with the peel velocity")
    ExpressionLaw(e, label).probe(label)  # before printing: a complex law is named by the point where it is complex
    return _grammar_round_trip(e, label)


def from_stored(text: Any) -> str:
    """The canonical text of a stored expression law (a manifest, an ``.npz``): parsed by the grammar, never
    evaluated; the ``srepr`` text peelapprox 0.2 stored is read too (``legacy=True``).  Checked as
    :func:`canonical` checks a new law.

    Raises
    ------
    TypeError
        ``text`` is not a string.
    ValueError
        As :func:`canonical`.
    """
    import sympy as sp

    if not isinstance(text, str):
        raise TypeError(f"source of an expression law must be a string, got {type(text).__name__}")
    v, V = _symbols()
    e, _used = _grammar.parse(text, {"v": v, "V": V}, legacy=True)
    if not isinstance(e, sp.Expr):
        raise ValueError(f"stored expression {shown(text)} is not a scalar expression")
    return canonical(e, {})


def from_text(text: str) -> Any:
    """The sympy expression of a canonical text (:func:`canonical`), by the grammar: never evaluated."""
    v, V = _symbols()
    return _integral_floats(_grammar.parse(text, {"v": v, "V": V})[0])  # 1e+20 reads as an integer: a float again


def _exact_float_printer() -> Any:
    """lambdify's numpy printer (its own settings), floats printed exactly (``repr``) as the compiled kernel prints
    them: sympy's prints 15 digits (2**70 read 1.18059162071741e+21, 1.1e-15 off)."""
    from sympy.printing.numpy import NumPyPrinter

    class _Printer(NumPyPrinter):
        def _print_Float(self, expr: Any) -> str:
            return repr(float(expr))

    return _Printer({"fully_qualified_modules": False, "inline": True, "allow_unknown_functions": True,
                     "user_functions": {}})


def _check_size(e: Any, what: str, limit: int, label: str) -> None:
    """ValueError if the tree of ``e`` has more than ``limit`` nodes (counted up to limit + 1: linear, bounded)."""
    import sympy as sp

    n = 0
    for _ in sp.preorder_traversal(e):
        n += 1
        if n > limit:
            raise ValueError(f"expression {label}: its derivative {what} has more than {limit} terms and factors "
                             f"(MAX_DERIVATIVE_NODES, {MAX_DERIVATIVE_NODES[0]} for f' and {MAX_DERIVATIVE_NODES[1]} "
                             "for f''): compiling it would take minutes; write the law expanded or with fewer "
                             "factors")


class ExpressionLaw:
    """The evaluator of an expression law, rebuilt from its canonical text."""

    def __init__(self, text: Any, label: str = "law"):
        """From the canonical text (or the checked sympy expression itself, at construction); ValueError if f'
        or f'' exceeds :data:`MAX_DERIVATIVE_NODES`."""
        import sympy as sp

        v, V = _symbols()
        e = from_text(text) if isinstance(text, str) else text
        self.depends_on_V = V in e.free_symbols
        d1 = sp.diff(e, v)
        _check_size(d1, "f'", MAX_DERIVATIVE_NODES[0], label)
        d2 = sp.diff(d1, v)
        _check_size(d2, "f''", MAX_DERIVATIVE_NODES[1], label)
        self.exprs = (e, d1, d2)
        printer = _exact_float_printer()
        self.funcs = [sp.lambdify((v, V), x, modules="numpy", printer=printer) for x in self.exprs]

    def raw(self, v: np.ndarray, V: float, order: int) -> np.ndarray:
        with np.errstate(all="ignore"):
            out = np.asarray(self.funcs[order](v, V))
        if out.dtype.kind in "biu":  # a constant derivative (lambdify returns the number itself)
            out = out.astype(float)
        return np.broadcast_to(out, v.shape).copy() if out.shape != v.shape else out

    def __call__(self, v: np.ndarray, V: float, order: int) -> np.ndarray:
        lo, hi = V_DOMAIN
        if v.size and (v.min() < lo or v.max() > hi):
            bad = v.ravel()[np.flatnonzero(((v < lo) | (v > hi)).ravel())[0]]
            raise ValueError(f"v={float(bad)!r} m/s is outside the domain [{lo:g}, {hi:g}] m/s of an expression "
                             "law (the range its construction probed)")
        return self.raw(v, V, order)

    def probe(self, label: str) -> None:
        """ValueError naming the first point of the probe where f, f' or f'' is complex or not finite."""
        for Vp in (PROBE_PULL if self.depends_on_V else (1.0,)):
            for order, what in enumerate(("f", "f'", "f''")):
                try:
                    y = self.raw(PROBE_V, Vp, order)
                except (ArithmeticError, TypeError, ValueError) as exc:  # an overflow in numpy's scalar code, ...
                    raise ValueError(f"expression {label}: {what} cannot be evaluated on v in [{V_DOMAIN[0]:g}, "
                                     f"{V_DOMAIN[1]:g}] m/s, V={Vp:g} m/s ({type(exc).__name__}: {exc})") from None
                if np.iscomplexobj(y) and np.any(y.imag != 0):
                    i = int(np.flatnonzero(y.imag != 0)[0])
                    raise ValueError(f"expression {label}: {what} is complex at v={PROBE_V[i]:.6g} m/s, "
                                     f"V={Vp:g} m/s ({what} = {complex(y[i])}); a law must be real on v in "
                                     f"[{V_DOMAIN[0]:g}, {V_DOMAIN[1]:g}] m/s")
                y = np.real(y)
                bad = np.flatnonzero(~np.isfinite(y))
                if bad.size:
                    i = int(bad[0])
                    raise ValueError(f"expression {label}: {what} is {y[i]} at v={PROBE_V[i]:.6g} m/s, V={Vp:g} "
                                     f"m/s; a law must be finite on v in [{V_DOMAIN[0]:g}, {V_DOMAIN[1]:g}] m/s")

"""The grammar of a peel-force expression: text parsed by Python's :mod:`ast`, never evaluated.

:func:`parse` turns what a user typed (``"a + b*v - c*v**2 + d*v^3"``), or a law stored in a sweep manifest or
an ``.npz`` file, into a sympy expression by walking the syntax tree node by node: each node kind is on a
whitelist and is built into sympy by hand (``Add``, ``Mul``, ``Pow``, the functions of :data:`FUNCTIONS`).
Nothing of the text reaches ``eval``, ``exec`` or ``sympify``, so ``__import__('os').system(...)`` is a
``ValueError`` naming the forbidden piece, not a command run.

The grammar:

* numbers: integer and decimal literals (``300``, ``2.5e-3``), at most :data:`MAX_LITERAL` in magnitude;
* names: ``v`` (peel velocity) and ``V`` (pull speed) [m/s], the caller's constants, ``E`` and ``pi``;
* ``+ - * /``, powers ``**`` or ``^``, unary ``+`` and ``-``, parentheses;
* calls of the smooth functions of :data:`FUNCTIONS`, one positional argument each.

Refused, with the reason: every other node (attributes, subscripts, strings, keywords, comparisons,
lambdas, ...); the non-smooth functions of :data:`NON_SMOOTH` (the solver needs f, f' and f'' continuous
along a branch); any other name; text longer than :data:`MAX_CHARS`, more than :data:`MAX_NODES` nodes or
calls nested deeper than :data:`MAX_CALL_DEPTH` (each bounds the size of f'' that sympy differentiates and
numba compiles: a 12-deep nested ``log(1 + ...)`` took minutes); a power of two numbers whose value exceeds
:data:`MAX_LITERAL` (an exponent tower ``9**9**9`` would make sympy compute a 370-million-digit integer)
and a numeric exponent above :data:`MAX_EXPONENT` in magnitude.

:func:`canonical_text` prints an expression back into this grammar (floats exactly, by ``repr``); parsing it
gives the same expression (:func:`parse` of :func:`canonical_text` is checked at every law's construction).
A law is stored as that text.  Laws stored by peelapprox 0.2 as sympy's ``srepr`` text are read by the same
walk with ``legacy=True``, which adds the constructors ``srepr`` writes (``Add``, ``Mul``, ``Integer``,
``Float``, ``Symbol``, ...) to the whitelist: still a tree of whitelisted calls, never evaluated.
"""

from __future__ import annotations

import ast
import math
from collections.abc import Mapping
from typing import Any

from .._checks import shown

__all__ = ["FUNCTIONS", "MAX_CALL_DEPTH", "MAX_CHARS", "MAX_EXPONENT", "MAX_LITERAL", "MAX_NODES", "NON_SMOOTH",
           "canonical_text", "parse"]

#: The longest expression text accepted [characters].
MAX_CHARS = 2000
#: The most syntax-tree nodes an expression may have (the paper's fvV written out has 67).
MAX_NODES = 400
#: The deepest nesting of function calls (``exp(sin(log(v)))`` is 3).
MAX_CALL_DEPTH = 6
#: The largest magnitude of a number in a law (a literal, or a power of two numbers).
MAX_LITERAL = 1e300
#: The largest integer kept as an integer [magnitude]: 2**53, below which every integer is a float exactly.  A
#: number beyond (``1e20``, ``2**70``) is a float: as a Python integer it made numpy's evaluator an object array
#: (``ufunc 'isfinite' not supported``) and numba's kernel an integer literal over 64 bits (``TypingError``).
MAX_EXACT_INTEGER = 2**53
#: The largest magnitude of a numeric exponent.
MAX_EXPONENT = 1000

#: The smooth functions a law may call: the name a user writes -> the sympy function's name.  Each is
#: real-analytic where it is real and is compiled by numba (numpy's ufunc of the same meaning).
FUNCTIONS: dict[str, str] = {
    "exp": "exp", "log": "log", "ln": "log", "sqrt": "sqrt",
    "sin": "sin", "cos": "cos", "tan": "tan",
    "sinh": "sinh", "cosh": "cosh", "tanh": "tanh",
    "atan": "atan", "arctan": "atan", "asinh": "asinh", "arcsinh": "asinh",
}
#: Functions refused because they are not smooth (the message says why and lists :data:`FUNCTIONS`).
NON_SMOOTH = frozenset({"Abs", "abs", "sign", "sgn", "Max", "Min", "max", "min", "floor", "ceiling", "ceil",
                        "round", "Piecewise", "Heaviside", "DiracDelta", "Mod", "mod", "frac", "step"})
#: Constants a law may name.
_CONSTANTS = ("E", "pi")

#: The constructors of sympy's ``srepr`` that a stored law of peelapprox 0.2 uses (``legacy=True``).
_LEGACY_CALLS = frozenset({"Add", "Mul", "Pow", "Integer", "Float", "Rational", "Symbol", "Half", "One", "Zero",
                           "NegativeOne", "Exp1", "Pi"})


def _supported() -> str:
    return ", ".join(sorted(set(FUNCTIONS)))


def _number(x: float) -> Any:
    """A float as a sympy number: the integer if it is one below :data:`MAX_EXACT_INTEGER`, else the float."""
    import sympy as sp

    return sp.Integer(int(x)) if x.is_integer() and abs(x) < MAX_EXACT_INTEGER else sp.Float(x)


class _Builder:
    """One walk of a syntax tree into sympy (see the module docstring for what each node may be)."""

    def __init__(self, text: str, names: Mapping[str, Any], legacy: bool) -> None:
        import sympy as sp

        self.sp = sp
        self.text = text
        self.names = dict(names)
        self.used: set[str] = set()
        self.legacy = legacy
        self.nodes = 0

    def fail(self, why: str) -> ValueError:
        return ValueError(f"expression {shown(self.text)}: {why}")

    def number(self, x: Any) -> Any:
        """A numeric result, checked against :data:`MAX_LITERAL` (and finite)."""
        sp = self.sp
        if x.has(sp.zoo, sp.nan, sp.oo, -sp.oo):
            raise self.fail(f"{_num_text(x)} is not finite (a division by zero, a log of 0, ...)")
        if x.is_Number and abs(float(x)) > MAX_LITERAL:
            raise self.fail(f"the number {_num_text(x)} exceeds {MAX_LITERAL:g} in magnitude")
        return x

    def build(self, node: ast.AST, depth: int = 0) -> Any:
        self.nodes += 1
        if self.nodes > MAX_NODES:
            raise self.fail(f"more than {MAX_NODES} syntax nodes (the derivatives f' and f'' are compiled: "
                            "the size is bounded to keep that bounded)")
        sp = self.sp
        if isinstance(node, ast.Expression):
            return self.build(node.body, depth)
        if isinstance(node, ast.Constant):
            value = node.value
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise self.fail(f"{type(value).__name__} literal {shown(value, 40)} is not a number")
            if isinstance(value, int):
                if abs(value) > MAX_LITERAL:
                    raise self.fail(f"the integer literal has {len(str(abs(value)))} digits: numbers are bounded "
                                    f"by {MAX_LITERAL:g} in magnitude")
                return sp.Integer(value) if abs(value) < MAX_EXACT_INTEGER else sp.Float(float(value))
            if not math.isfinite(value) or abs(value) > MAX_LITERAL:
                raise self.fail(f"the literal {value!r} is not finite or exceeds {MAX_LITERAL:g} in magnitude")
            return _number(value)
        if isinstance(node, ast.Name):
            return self.name(node.id)
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.UAdd, ast.USub)):
            x = self.build(node.operand, depth)
            return self.number(-x) if isinstance(node.op, ast.USub) else x
        if isinstance(node, ast.BinOp) and isinstance(node.op, (ast.Add, ast.Sub, ast.Mult, ast.Div, ast.Pow)):
            a, b = self.build(node.left, depth), self.build(node.right, depth)
            if isinstance(node.op, ast.Pow):
                return self.power(a, b)
            if isinstance(node.op, ast.Div) and b.is_zero:
                raise self.fail("division by zero")
            op = {ast.Add: lambda: a + b, ast.Sub: lambda: a - b, ast.Mult: lambda: a * b,
                  ast.Div: lambda: a / b}[type(node.op)]
            return self.number(op())
        if isinstance(node, ast.Call):
            return self.call(node, depth)
        raise self.fail(f"{_describe(node)} is not allowed in a peel-force law (only numbers, v, V, constants, "
                        f"+ - * / ** ^ and the functions {_supported()})")

    def name(self, name: str) -> Any:
        sp = self.sp
        if name in self.names:
            self.used.add(name)
            return self.names[name]
        if name == "E":
            return sp.E
        if name == "pi":
            return sp.pi
        if name in FUNCTIONS or name in NON_SMOOTH:
            raise self.fail(f"{name} is a function: call it, e.g. {name}(v)")
        if name.lower() in ("nan", "inf", "infinity", "oo", "zoo"):
            raise self.fail(f"{name} is not a number a law can hold: a peel force is finite")
        known = ", ".join(["v", "V", *sorted(n for n in self.names if n not in ("v", "V")), *_CONSTANTS])
        raise self.fail(f"unknown symbol {shown(name, 40)}: a law may use {known}; give other constants as "
                        f"keywords, e.g. {name if name.isidentifier() and len(name) < 20 else 'a'}=1.0")

    def power(self, a: Any, b: Any) -> Any:
        if b.is_Number and abs(float(b)) > MAX_EXPONENT:
            raise self.fail(f"the exponent {_num_text(b)} exceeds {MAX_EXPONENT} in magnitude")
        if a.is_Number and b.is_Number:
            fa, fb = float(a), float(b)
            if fa == 0.0 and fb < 0:
                raise self.fail("division by zero (0 to a negative power)")
            if fa != 0.0 and fb * math.log10(abs(fa)) > math.log10(MAX_LITERAL):
                raise self.fail(f"the power {_num_text(a)}**{_num_text(b)} exceeds {MAX_LITERAL:g} (numbers are "
                                "bounded; exponent towers are refused)")
        r = self.number(a ** b)
        if r.is_Pow and r.exp.is_Number and abs(float(r.exp)) > MAX_EXPONENT:  # (v**1000)**1000 = v**1000000
            raise self.fail(f"the exponent {_num_text(r.exp)} of {_num_text(r.base)} exceeds {MAX_EXPONENT} in "
                            "magnitude")
        if not r.free_symbols and not r.is_Number:  # pi**1000, 2**0.5: one float, bounded
            return self.constant(r, f"{_num_text(a)}**{_num_text(b)}")
        return r

    def call(self, node: ast.Call, depth: int) -> Any:
        sp = self.sp
        if not isinstance(node.func, ast.Name):
            raise self.fail(f"{_describe(node.func)} cannot be called: only the functions {_supported()}")
        fname = node.func.id
        if self.legacy and fname in _LEGACY_CALLS:
            return self.legacy_call(fname, node, depth)
        if fname in NON_SMOOTH:
            raise self.fail(f"{fname} is not smooth: the solver needs f, f' and f'' continuous along a branch "
                            f"(its Newton steps, the fold conditions f' = 0 and the Jacobians); the smooth "
                            f"functions are {_supported()} (write a smooth law, e.g. sqrt(x**2 + d**2) for |x|)")
        if fname not in FUNCTIONS:
            raise self.fail(f"unknown function {shown(fname, 40)}: the functions a law may call are {_supported()}")
        if node.keywords or len(node.args) != 1 or isinstance(node.args[0], ast.Starred):
            raise self.fail(f"{fname} takes one positional argument, e.g. {fname}(v)")
        if depth + 1 > MAX_CALL_DEPTH:
            raise self.fail(f"function calls nested more than {MAX_CALL_DEPTH} deep (f'' grows with each level and "
                            "is compiled: the depth is bounded to keep that bounded)")
        arg = self.build(node.args[0], depth + 1)
        value = self.number(getattr(sp, FUNCTIONS[fname])(arg))
        if not value.free_symbols and not value.is_Number:  # sin(2**70), exp(3): one float, bounded and real
            return self.constant(value, f"{fname}({_num_text(arg)})")
        return value

    def constant(self, value: Any, text: str) -> Any:
        """A number-valued subexpression as one float, checked finite, real and at most :data:`MAX_LITERAL`."""
        sp = self.sp
        z = complex(sp.N(value, 20))
        if z.imag != 0.0:
            raise self.fail(f"{text} is not real (it is {z}): a peel force is real")
        if not math.isfinite(z.real) or abs(z.real) > MAX_LITERAL:
            raise self.fail(f"{text} is not finite or exceeds {MAX_LITERAL:g} in magnitude")
        return _number(z.real)

    def legacy_call(self, fname: str, node: ast.Call, depth: int) -> Any:
        """A constructor of sympy's ``srepr`` (a stored law of peelapprox 0.2), built from checked arguments."""
        sp = self.sp
        if depth + 1 > 4 * MAX_CALL_DEPTH + 8:
            raise self.fail("stored expression nested too deep")
        kw = {k.arg: k.value for k in node.keywords}
        for key, val in kw.items():
            if not (isinstance(val, ast.Constant) and isinstance(val.value, (bool, int))):
                raise self.fail(f"stored {fname}: keyword {shown(key, 40)} must be a literal")
        if fname == "Symbol":
            if (len(node.args) != 1 or not isinstance(node.args[0], ast.Constant)
                    or node.args[0].value not in ("v", "V") or set(kw) - {"positive", "real"}):
                raise self.fail("a stored law may hold the symbols v and V only")
            return self.name(str(node.args[0].value))
        if fname == "Float":
            if not node.args or not isinstance(node.args[0], ast.Constant) or set(kw) - {"precision"}:
                raise self.fail("malformed stored Float")
            try:
                x = float(str(node.args[0].value))
            except ValueError:
                raise self.fail("malformed stored Float") from None
            if not math.isfinite(x) or abs(x) > MAX_LITERAL:
                raise self.fail(f"the stored number {x!r} is not finite or exceeds {MAX_LITERAL:g}")
            return sp.Float(x)
        if kw:
            raise self.fail(f"{fname} takes no keywords in a stored law")
        args = [self.build(a, depth + 1) for a in node.args]
        if fname in ("Integer", "Rational"):
            if not all(a.is_Integer for a in args) or len(args) != (1 if fname == "Integer" else 2):
                raise self.fail(f"malformed stored {fname}")
            if fname == "Rational" and args[1].is_zero:
                raise self.fail("division by zero")
            return self.number(sp.Integer(args[0]) if fname == "Integer" else sp.Rational(args[0], args[1]))
        consts = {"Half": sp.S.Half, "One": sp.S.One, "Zero": sp.S.Zero, "NegativeOne": sp.S.NegativeOne,
                  "Exp1": sp.E, "Pi": sp.pi}
        if fname in consts:
            if args:
                raise self.fail(f"{fname} takes no arguments")
            return consts[fname]
        if fname == "Pow":
            if len(args) != 2:
                raise self.fail("Pow takes two arguments")
            return self.power(args[0], args[1])
        if not args:
            raise self.fail(f"{fname} needs arguments")
        return self.number(sp.Add(*args) if fname == "Add" else sp.Mul(*args))


def _describe(node: ast.AST) -> str:
    kinds = {ast.Attribute: "attribute access", ast.Subscript: "indexing", ast.Lambda: "a lambda",
             ast.Compare: "a comparison", ast.BoolOp: "a boolean operation", ast.IfExp: "a conditional",
             ast.JoinedStr: "an f-string", ast.List: "a list", ast.Tuple: "a tuple", ast.Dict: "a dict",
             ast.Set: "a set", ast.Starred: "unpacking", ast.NamedExpr: "an assignment expression"}
    for cls, text in kinds.items():
        if isinstance(node, cls):
            return text
    if isinstance(node, ast.BinOp):
        return f"the operator {type(node.op).__name__}"
    if isinstance(node, ast.UnaryOp):
        return f"the operator {type(node.op).__name__}"
    return f"a {type(node).__name__} node"


def _num_text(x: Any) -> str:
    s = str(x)
    return s if len(s) <= 30 else f"{s[:12]}...({len(s)} digits)"


def parse(text: str, names: Mapping[str, Any] | None = None, *, legacy: bool = False) -> tuple[Any, set[str]]:
    """The sympy expression of ``text`` and the set of ``names`` it used, by the grammar of the module docstring.

    Parameters
    ----------
    text : str
        The expression, e.g. ``"a + b*v - c*v**2 + d*v^3"``.
    names : mapping of str to sympy expression, optional
        What each allowed name stands for: ``v`` and ``V`` (the law's symbols) and the caller's constants.
    legacy : bool
        Also read sympy's ``srepr`` constructors (a law stored by peelapprox 0.2).

    Raises
    ------
    TypeError
        ``text`` is not a string.
    ValueError
        The text is too long, does not parse as an expression, or holds anything outside the grammar (the
        message names it and what is allowed).
    """
    if not isinstance(text, str):
        raise TypeError(f"expression must be a string, got {type(text).__name__}")
    if len(text) > MAX_CHARS:
        raise ValueError(f"expression {shown(text)} is longer than {MAX_CHARS} characters (a law's text is "
                         "bounded so that parsing, differentiating and compiling it stay bounded)")
    if not text.strip():
        raise ValueError("expression is empty: write a law in v, e.g. '300 - 100*v + 20*v**2'")
    try:
        # ``^`` is a power, as in sympy's convert_xor: replaced before parsing, where Python's precedence of ``**``
        # applies (``a + b*v^2`` is a + b v², not (a + b v) xor 2); ``^`` inside a string changes a string, refused
        tree = ast.parse(text.strip().replace("^", "**"), mode="eval")
    except SyntaxError as exc:
        raise ValueError(f"expression {shown(text)} does not parse: {exc.msg}"
                         + (f" at column {exc.offset}" if exc.offset else "")) from None
    except (RecursionError, MemoryError):
        raise ValueError(f"expression {shown(text)} does not parse: nested too deeply") from None
    except ValueError as exc:  # a null byte, a lone surrogate, ...
        raise ValueError(f"expression {shown(text)} does not parse: {exc}") from None
    b = _Builder(text, names or {}, legacy)
    try:
        e = b.build(tree)
    except RecursionError:
        raise b.fail("nested too deeply") from None
    for p in e.atoms(b.sp.Pow):  # products combine powers: v**600*v**600 = v**1200
        if p.exp.is_Number and abs(float(p.exp)) > MAX_EXPONENT:
            raise b.fail(f"the exponent {_num_text(p.exp)} exceeds {MAX_EXPONENT} in magnitude")
    return e, b.used


def canonical_text(expr: Any) -> str:
    """``expr`` printed in the grammar of :func:`parse`: sympy's string form with every float exact (``repr``)."""
    from sympy.printing.str import StrPrinter

    class _Printer(StrPrinter):
        def _print_Float(self, e: Any) -> str:
            r = repr(float(e))
            return f"({r})" if r.startswith("-") else r

    return str(_Printer({"order": None}).doprint(expr))

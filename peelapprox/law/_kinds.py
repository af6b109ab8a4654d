"""What each kind of peel-force law does: one implementation object per kind, behind :class:`peelapprox.PeelForce`.

A law's data says which kind it is (``PeelForce.kind``); :data:`KIND_IMPLS` maps that name to its
:class:`LawKind`, which knows how the kind checks its fields, shows and hashes itself, is evaluated by numpy,
finds its folds, becomes a compiled kernel and a sympy expression.  The base class holds what the kinds share
(the evaluation checks, the fold search, the structure from a compiled kernel); each kind overrides what differs:

* :class:`PaperKind` — the built-in fvV, through :mod:`peelapprox.law._paper` (bitwise), inlined by the drivers;
* :class:`FamilyKind` — a formula of :mod:`peelapprox.law._families` with its coefficients as data;
* :class:`ExpressionKind` — a sympy expression kept as canonical text (:mod:`peelapprox.law._expression`);
* :class:`TabulatedKind` — measured curves, PCHIP in ln v (:mod:`peelapprox.law._table`);
* :class:`SplineKind` — noisy measured points smoothed by a C⁴ spline in ln v (:mod:`peelapprox.law._spline`).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from typing import Any

import numpy as np

from .._checks import in_range, reals, shown
from .._ranges import PARAM_RANGES, STATE_RANGES
from . import _expression, _families, _spline, _table
from ._abi import LAWS, paper_coefficients
from ._compiled import law_structure
from ._folds import BranchStructure, find_folds
from ._kernels import expression_kernel, family_kernel
from ._paper import paper_structure, paper_value_slope, peel_force, peel_force_derivative
from ._table_jit import quintic_law, table_coefficients, table_law

__all__ = ["FOLD_GRID_DENSITY", "KIND_IMPLS", "LawKind", "shown_law"]

#: Points per unit of ln v of the grid on which a law's folds are bracketed by the sign changes of f'
#: (neighbours 0.5 % apart in v; at least 2001 points).
FOLD_GRID_DENSITY = 200
#: Lower end [m/s] of the fold search of the families (the built-in law searches from the same 1e-12).
_FAMILY_FOLD_LO = 1e-12

#: An evaluator: ``(v array, V, order 0|1|2) -> array`` of f, f' or f''.
Evaluator = Callable[[np.ndarray, float, int], np.ndarray]


def shown_law(force: Any, limit: int = 300) -> str:
    """``repr(force)`` for a message, cut after ``limit`` characters (an expression law's text may be long)."""
    r = repr(force)
    return r if len(r) <= limit else f"{r[:limit]}... ({len(r)} characters)"


def _num(x: float) -> str:
    """A coefficient as a physicist writes it, exact (shortest repr, ``150`` for ``150.0``)."""
    r = repr(float(x))
    return r[:-2] if r.endswith(".0") else r


class LawKind:
    """The behaviour of one kind of law (module docstring); ``force`` is the :class:`PeelForce` at hand."""

    #: The kind's name (``PeelForce.kind``) and the fields its data needs.
    name = ""
    needs: tuple[str, ...] = ()
    #: True if the compiled drivers inline this law (fvV) instead of calling it through the ABI.
    inlined = False

    # ------------------------------------------------------------------ data
    def canonical(self, force: Any) -> dict[str, Any]:
        """The canonical values of the fields this kind checks (ValueError/TypeError for bad data)."""
        return {}

    def display(self, force: Any) -> str:
        """What ``repr`` shows of the law's content, derived from the canonical data."""
        return ""

    def show(self, force: Any) -> str:
        """``repr(force)``."""
        return f"PeelForce.{self.name}(<{force.display}>)"

    def key_text(self, force: Any) -> str:
        """The text whose SHA-256 is the law's key: kind, family, exact coefficients and tables."""
        parts = [force.kind, str(force.name)] + [f"{n}={float(x).hex()}" for n, x in force.coefficients]
        for V, v, f in force.tables:
            parts.append(f"V={'None' if V is None else float(V).hex()}")
            parts.append(":".join(np.asarray(x, dtype="<f8").tobytes().hex() for x in (v, f)))
        return "|".join(parts)

    def label(self, force: Any) -> str:
        """The name by which a consumer lists the laws it honours (:func:`peelapprox.law.law_label`)."""
        return self.name

    # ------------------------------------------------------------------ evaluation
    def depends_on_V(self, force: Any) -> bool:
        raise NotImplementedError

    def v_range(self, force: Any) -> tuple[float, float]:
        raise NotImplementedError

    def evaluator(self, force: Any) -> Evaluator:
        """The numpy evaluator of f, f', f'' (built once per law: :meth:`PeelForce._evaluator`)."""
        raise NotImplementedError

    def check_v(self, force: Any, v: Any) -> np.ndarray:
        """The peel velocities as a float array (a law's own evaluator refuses what is outside its domain)."""
        return reals("v", v)

    def evaluate(self, force: Any, v: Any, V: Any, order: int) -> Any:
        """f (order 0), f' or f'' at v [m/s] and V: V in ``PARAM_RANGES["V"]``, a finite result or a ValueError."""
        V = in_range("V", V, *PARAM_RANGES["V"])
        va = self.check_v(force, v)
        with np.errstate(all="ignore"):
            out = np.asarray(force._evaluator()(va, V, order), dtype=float)
        if not np.all(np.isfinite(out)):
            i = int(np.flatnonzero(~np.isfinite(out).ravel())[0])
            what = ("f", "f'", "f''")[order]
            raise ValueError(f"the peel-force law {force!r} gives {what} = "
                             f"{out.ravel()[i]} at v={float(va.ravel()[i])!r} m/s, V={V!r} m/s")
        return out[()] if out.ndim == 0 else out

    def value_slope(self, force: Any, V: float) -> tuple[float, float]:
        """``(f, f')`` at the steady sliding ``v = V`` (the fixed point)."""
        return float(force.f(V, V)), float(force.df(V, V))

    # ------------------------------------------------------------------ folds
    def fold_window(self, force: Any) -> tuple[tuple[float, float], tuple[float, float]]:
        """``(window, domain)``: where the extrema are looked for, where the landings may lie [m/s]."""
        lo, hi = force.v_range
        return (lo, hi), (lo, hi)

    def folds(self, force: Any, V: float) -> BranchStructure:
        """The folds and landings at V (V checked): the sign changes of f' on a grid, refined by Brent."""
        window, domain = self.fold_window(force)
        impl = force._evaluator()

        def fn(v: np.ndarray, order: int) -> np.ndarray:
            with np.errstate(all="ignore"):
                return np.asarray(impl(v, V, order), dtype=float)

        return find_folds(fn, V, window, domain, shown_law(force), FOLD_GRID_DENSITY)

    # ------------------------------------------------------------------ compiled form
    def domain(self, force: Any) -> tuple[float, float]:
        """``(lo, hi)`` [m/s] where the compiled law may be evaluated."""
        return force.v_range

    def kernel(self, force: Any, V: float) -> tuple[Any, np.ndarray]:
        """``(kernel, coef)``: the law's compiled function of the ABI and its coefficients at V."""
        raise NotImplementedError

    def structure(self, force: Any, V: float, fn: Any, coef: np.ndarray,
                  domain: tuple[float, float]) -> BranchStructure:
        """Every field of the :class:`BranchStructure` at V, from the folds and the compiled kernel."""
        return law_structure(force.folds(V), V, fn, coef, domain)

    # ------------------------------------------------------------------ symbolic form
    def expression(self, force: Any) -> Any:
        """The law as a sympy expression in the symbols of :mod:`peelapprox.law._symbolic`."""
        raise ValueError(f"a {self.name} peel-force law has no closed form: law_expression takes a 'paper', "
                         "'family' or 'expression' law")


class PaperKind(LawKind):
    """The paper's fvV: evaluated by :func:`peelapprox.peel_force` itself and inlined by the drivers."""

    name = "paper"
    inlined = True

    def show(self, force: Any) -> str:
        return "PeelForce.paper()"

    def depends_on_V(self, force: Any) -> bool:
        return True

    def v_range(self, force: Any) -> tuple[float, float]:
        return STATE_RANGES["v"]

    def evaluate(self, force: Any, v: Any, V: Any, order: int) -> Any:
        return peel_force(v, V) if order == 0 else peel_force_derivative(v, V, order)

    def value_slope(self, force: Any, V: float) -> tuple[float, float]:
        return paper_value_slope(V)

    def folds(self, force: Any, V: float) -> BranchStructure:
        return dataclasses.replace(paper_structure(V), v_inflection=math.nan, f_zero=math.nan, v_breakdown=math.nan)

    def domain(self, force: Any) -> tuple[float, float]:
        return (0.0, math.inf)

    def kernel(self, force: Any, V: float) -> tuple[Any, np.ndarray]:
        return LAWS["paper"], paper_coefficients(V)

    def structure(self, force: Any, V: float, fn: Any, coef: np.ndarray,
                  domain: tuple[float, float]) -> BranchStructure:
        return paper_structure(V)

    def expression(self, force: Any) -> Any:
        from .._compiled import _symbolic as S
        from ._symbolic import V, v

        return S.peel_force_expr(v, V)


class FamilyKind(LawKind):
    """A formula of :data:`peelapprox.law._families.FAMILIES` with the law's coefficients."""

    name = "family"
    needs = ("name", "coefficients")

    @staticmethod
    def family(force: Any) -> _families.Family:
        return _families.FAMILIES[str(force.name)]

    def canonical(self, force: Any) -> dict[str, Any]:
        if force.name not in _families.FAMILIES:
            raise ValueError(f"unknown peel-force family {shown(force.name)}: the families are "
                             f"{', '.join(_families.FAMILIES)}")
        return {"coefficients": _families.coefficients(self.family(force), dict(force.coefficients))}

    def show(self, force: Any) -> str:
        coefs = ", ".join(f"{n}={_num(x)}" for n, x in force.coefficients)
        return f"PeelForce.{self.family(force).constructor}({coefs})"

    def label(self, force: Any) -> str:
        return str(self.family(force).constructor)

    def depends_on_V(self, force: Any) -> bool:
        return self.family(force).depends_on_V

    def v_range(self, force: Any) -> tuple[float, float]:
        return STATE_RANGES["v"]

    def evaluator(self, force: Any) -> Evaluator:
        fam = self.family(force)
        c = tuple(x for _, x in force.coefficients)
        return lambda v, V, order: fam.evaluate(v, V, c, order)

    def check_v(self, force: Any, v: Any) -> np.ndarray:
        lo, hi = STATE_RANGES["v"]
        return reals("v", v, lo, hi, lo_open=True)

    def fold_window(self, force: Any) -> tuple[tuple[float, float], tuple[float, float]]:
        lo, hi = force.v_range
        return (_FAMILY_FOLD_LO, hi), (lo * 10.0, hi)  # the families' domain is open at lo

    def domain(self, force: Any) -> tuple[float, float]:
        return (0.0, math.inf)

    def kernel(self, force: Any, V: float) -> tuple[Any, np.ndarray]:
        fn, pack = family_kernel(str(force.name))
        return fn, _families.packed(f"params.force={shown(force)}", pack, V, tuple(x for _, x in force.coefficients))

    def expression(self, force: Any) -> Any:
        import sympy as sp

        from ._symbolic import family_expression

        expr, syms = family_expression(str(force.name))
        values = dict(force.coefficients)
        return expr.xreplace({s: sp.Float(float(values[s.name])) for s in syms})


class ExpressionKind(LawKind):
    """A sympy expression in v (and V), kept as its canonical text."""

    name = "expression"
    needs = ("source",)

    def canonical(self, force: Any) -> dict[str, Any]:
        if not isinstance(force.source, str):
            raise TypeError(f"source of an expression law must be a string, got {type(force.source).__name__}")
        return {"source": _expression.from_stored(force.source)}

    def display(self, force: Any) -> str:
        return repr(force.source)

    def show(self, force: Any) -> str:
        return f"PeelForce.expression({force.display})"

    def key_text(self, force: Any) -> str:
        return str(force.source)

    def depends_on_V(self, force: Any) -> bool:
        return bool(force._evaluator().depends_on_V)

    def v_range(self, force: Any) -> tuple[float, float]:
        return _expression.V_DOMAIN

    def evaluator(self, force: Any) -> Evaluator:
        return _expression.ExpressionLaw(str(force.source))

    def kernel(self, force: Any, V: float) -> tuple[Any, np.ndarray]:
        fn, pack = expression_kernel(str(force.source))
        return fn, _families.packed(f"params.force={shown(force)}", pack, V)

    def expression(self, force: Any) -> Any:
        return _expression.from_text(str(force.source))


class TabulatedKind(LawKind):
    """Measured curves ``(V, v, f)``: PCHIP in ln v, linear in V, never extrapolated."""

    name = "tabulated"
    needs = ("tables",)

    def canonical(self, force: Any) -> dict[str, Any]:
        return {"tables": _table.check_tables(force.tables, PARAM_RANGES["V"])}

    def display(self, force: Any) -> str:
        return "; ".join(f"V={V!r}: {len(v)} points, v in [{v[0]:.6g}, {v[-1]:.6g}] m/s, "
                         f"f in [{min(f):.6g}, {max(f):.6g}] N" for V, v, f in force.tables)

    def depends_on_V(self, force: Any) -> bool:
        return len(force.tables) > 1

    def v_range(self, force: Any) -> tuple[float, float]:
        return force._evaluator().v_range()

    def evaluator(self, force: Any) -> Evaluator:
        return _table.TableLaw(force.tables)

    def kernel(self, force: Any, V: float) -> tuple[Any, np.ndarray]:
        self.check_start(force)
        return table_law, table_coefficients(force.tables, V)

    @staticmethod
    def check_start(force: Any) -> None:
        """ValueError if the data start below ``STATE_RANGES["v"]`` (the compiled f'' would underflow)."""
        lo, v_lo = force.v_range[0], STATE_RANGES["v"][0]
        if lo < v_lo:
            raise ValueError(f"params.force: the table starts at v={lo!r} m/s, below the model's velocities "
                             f"STATE_RANGES['v'] = ({v_lo:g}, {STATE_RANGES['v'][1]:g}] m/s (v^2 underflows in f'' "
                             "there): give the table's v in m/s, within that range")


class SplineKind(TabulatedKind):
    """Points smoothed by a spline in ln v (``PeelForce.smoothed``: C⁴ quintic; C² cubic from older data): its knots
    and B-spline coefficients as data; evaluated by scipy's BSpline, compiled through the quintic kernel (a cubic
    through the table kernel); never extrapolated."""

    name = "smoothed"

    def canonical(self, force: Any) -> dict[str, Any]:
        return {"tables": _spline.check_spline(force.tables, PARAM_RANGES["V"])}

    def display(self, force: Any) -> str:
        V, t, _ = force.tables[0]
        k = _spline.degree(force.tables)
        return f"V={V!r}: C{k - 1} spline in ln v, {len(t) - 2 * k} knots, v in [{t[0]:.6g}, {t[-1]:.6g}] m/s"

    def show(self, force: Any) -> str:
        return f"PeelForce.smoothed(<{force.display}>)"

    def depends_on_V(self, force: Any) -> bool:
        return False

    def evaluator(self, force: Any) -> Evaluator:
        return _spline.SplineLaw(force.tables)

    def kernel(self, force: Any, V: float) -> tuple[Any, np.ndarray]:
        self.check_start(force)
        fn = quintic_law if _spline.degree(force.tables) == _spline.LAW_DEGREE else table_law
        return fn, _spline.spline_coefficients(force.tables, V)


#: The implementation of each kind, by ``PeelForce.kind``, in the order of the module docstring.
KIND_IMPLS: dict[str, LawKind] = {k.name: k for k in (PaperKind(), FamilyKind(), ExpressionKind(), TabulatedKind(),
                                                      SplineKind())}

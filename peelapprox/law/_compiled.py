"""Any :class:`peelapprox.PeelForce` as the compiled solvers take it: kernel, coefficients, branch structure, domain.

:func:`compiled_law` is the one place where a law becomes what a compiled driver calls (the ABI of
:mod:`peelapprox.law._abi`: ``law(x, coef, form)``) at one pull speed V:

=================  ==========================================================================================
kind               kernel and ``coef`` (the law's :meth:`~peelapprox.law._kinds.LawKind.kernel`)
=================  ==========================================================================================
``paper``          :func:`peelapprox.law._abi.paper_law`, ``(b, A)`` of fvV; the drivers inline it instead
                   (``inlined=True``: the default path, bitwise the numbers of 0.2.0)
``family``         the family's kernel compiled once with the package; ``coef`` packed from V and the
                   coefficients (changing a coefficient recompiles nothing)
``expression``     the expression's kernel, generated into the user cache and compiled once per machine
``tabulated``      the table kernel; ``coef`` the packed PCHIP pieces of the table(s) at V
=================  ==========================================================================================

and :func:`law_structure` gives the law's :class:`peelapprox.BranchStructure` — the folds and landings of
:meth:`PeelForce.folds`, plus what the drivers need beyond them: ``f(0+)`` (``f_zero``), the breakdown
velocity and the minimiser of f' (``v_inflection``) — so that every solver reads the same folds for a law.

The law's **domain** ``(lo, hi)`` [m/s] is where it may be evaluated: ``(0, inf)`` for the paper's law and
the families, ``[1e-6, 1e3]`` for an expression (its probed range), the table's range for a tabulated law.
A run that leaves it is stopped (:data:`peelapprox._status.LAW_DOMAIN`), never extrapolated: below ``lo``
the breakdown velocity is ``lo`` itself and ``f_zero = f(lo)``.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, cast

import numpy as np

from .._brentq import brentq
from ._abi import LAW_FP, LAW_FPP, unused_law
from ._folds import BREAKDOWN_LEVEL, BranchStructure

__all__ = ["CompiledLaw", "U_ZERO", "compiled_law", "law_domain", "law_structure"]

#: ``ln v`` standing for ``v = 0+`` where a law's domain reaches 0 (e^-690 ≈ 1e-300 m/s: f(0+) to rounding).
U_ZERO = -690.0
_RTOL = 4 * np.finfo(float).eps


@dataclass(frozen=True, eq=False)
class CompiledLaw:
    """A peel-force law at one pull speed, as the compiled drivers take it (module docstring).

    Attributes
    ----------
    force : PeelForce
        The law.
    V : float
        The pull speed [m/s] the coefficients are packed for.
    fn : numba dispatcher
        The law's kernel, signature ``LAW_SIG``: ``fn(x, coef, form) -> (float, float, float)``.
    coef : numpy.ndarray
        Its coefficient vector (float64, contiguous).
    structure : BranchStructure
        Folds, landings, ``f(0+)``, breakdown velocity of ``f(·, V)`` (:func:`law_structure`).
    domain : (float, float)
        ``(lo, hi)`` [m/s] where the law may be evaluated (module docstring).
    inlined : bool
        True for the paper's law, which the drivers inline (they ignore ``fn`` and ``coef``).
    """

    force: Any
    V: float
    fn: Any
    coef: np.ndarray
    structure: BranchStructure
    domain: tuple[float, float]
    inlined: bool

    @property
    def arg(self) -> Any:
        """The law argument a compiled driver is passed: :attr:`fn`, or for the paper's law, which the drivers
        inline and never call through the argument, a trivial kernel of the law type (so that the default path
        compiles no second copy of fvV)."""
        return unused_law if self.inlined else self.fn

    def f(self, v: float) -> float:
        """f(v) [N] through the compiled kernel."""
        return float(self.fn(float(v), self.coef, LAW_FP)[0])

    def df(self, v: float) -> float:
        """f'(v) [N s/m] through the compiled kernel."""
        return float(self.fn(float(v), self.coef, LAW_FP)[1])

    def branch_root(self, G: float, branch: str) -> float:
        """v on ``branch`` with ``f(v) = G`` (CONSTR): Brent's method in ln v (~4 ulp in v), bracketed by the
        folds -- AB on ``(lo, v_max]`` (``lo`` the domain's start, or ``v = e^-690`` where f = f(0+) to
        rounding), CD on ``[v_min, hi)`` up to where f first exceeds G (doubling, at most to the domain's end).
        ``G`` must be in ``structure.level_range(branch)`` (the caller checks :meth:`BranchStructure.has_root`);
        ValueError if the root lies beyond the domain (CD's, or AB's of a law without folds, which cannot then
        be bracketed)."""
        bs = self.structure

        def g(u: float) -> float:
            f = self.f(math.exp(u))
            if not math.isfinite(f):
                raise ValueError(f"params.force: {self.force!r} at V={self.V!r} m/s is not finite at v = "
                                 f"{math.exp(u):.6g} m/s while the root of f = {G!r} N on {branch} is sought: its "
                                 "coefficients overflow there (a smaller v range or other coefficients)")
            return f - G

        lo_d, hi_d = self.domain
        if branch == "AB":
            lo = math.log(lo_d) if lo_d > 0 else U_ZERO
            hi = math.log(cast(float, bs.v_max)) if bs.has_folds else math.log(min(hi_d, 1e3))
            if not bs.has_folds:
                while g(hi) < 0.0 and hi < math.log(hi_d) and hi < 700.0:
                    hi = min(hi + math.log(2.0), math.log(hi_d))
        else:
            lo = hi = math.log(float(bs.v_min))  # type: ignore[arg-type]  # CD exists: has_folds
            u_end = math.log(hi_d) if math.isfinite(hi_d) else 700.0
            while g(hi) < 0.0:
                if hi >= u_end:
                    raise ValueError(f"the level f = {G!r} N has no CD root within the peel-force law's domain "
                                     f"[{lo_d!r}, {hi_d!r}] m/s ({self.force!r})")
                hi = min(hi + math.log(2.0), u_end)
        g_lo, g_hi = g(lo), g(hi)
        if g_hi == 0.0:
            return math.exp(hi)
        if g_lo == 0.0:
            return math.exp(lo)
        if (g_lo > 0.0) == (g_hi > 0.0):  # no bracket: the root lies outside the domain (no fold bounds AB)
            raise ValueError(f"the level f = {G!r} N has no {branch} root within the peel-force law's domain "
                             f"[{lo_d!r}, {hi_d!r}] m/s ({self.force!r}"
                             f"{'' if bs.has_folds else ', a law without folds: AB rises to the end of the domain'}"
                             f"): f runs from {g_lo + G:.6g} N at v = {math.exp(lo):.6g} m/s to {g_hi + G:.6g} N at "
                             f"v = {math.exp(hi):.6g} m/s, so the branch root cannot be bracketed")
        return math.exp(brentq(g, lo, hi, xtol=1e-15, rtol=_RTOL))


def law_domain(force: Any) -> tuple[float, float]:
    """``(lo, hi)`` [m/s] where the compiled law may be evaluated (module docstring)."""
    return force.impl.domain(force)


def law_structure(fo: BranchStructure, V: float, fn: Callable, coef: np.ndarray,
                  domain: tuple[float, float]) -> BranchStructure:
    """The whole :class:`BranchStructure` at V of a law with the folds ``fo`` (:meth:`PeelForce.folds`) and the
    compiled kernel ``fn``/``coef``: ``f_zero = f(lo)`` (``lo`` the domain's start, or ``v = e^-690`` for a domain
    reaching 0); the breakdown velocity is ``lo`` for a domain starting above 0, else where
    ``f - f_zero = BREAKDOWN_LEVEL max(|f_zero|, 1)`` (Brent in ln v, as for fvV); ``v_inflection`` the root
    of f'' between the folds (Brent), or without folds the minimiser of f' on a grid.
    """
    lo_d, hi_d = domain

    def f(u: float) -> float:
        return float(fn(math.exp(u), coef, LAW_FP)[0])

    def fpp(u: float) -> float:
        return float(fn(math.exp(u), coef, LAW_FPP)[2])

    u_lo = math.log(lo_d) if lo_d > 0 else U_ZERO
    f_zero = f(u_lo)
    u_top = math.log(fo.v_max) if fo.has_folds else math.log(min(hi_d, 1e3))  # type: ignore[arg-type]
    if lo_d > 0:
        v_br = lo_d
    else:
        margin = BREAKDOWN_LEVEL * max(abs(f_zero), 1.0)
        if f(u_top) - f_zero - margin > 0:
            v_br = math.exp(brentq(lambda u: f(u) - f_zero - margin, u_lo, u_top, xtol=1e-12, rtol=_RTOL))
        else:  # f barely rises on AB: the whole branch is within rounding of f(0+)
            v_br = math.exp(u_top)
    if fo.has_folds:
        a, b = math.log(fo.v_max), math.log(fo.v_min)  # type: ignore[arg-type]
        v_infl = math.exp(brentq(fpp, a, b, xtol=1e-15, rtol=_RTOL)) if fpp(a) * fpp(b) < 0 else math.sqrt(
            fo.v_max * fo.v_min)  # type: ignore[operator]
    else:
        w = np.linspace(max(u_lo, math.log(1e-6)), math.log(min(hi_d, 1e3)), 2001)
        d = np.array([float(fn(math.exp(x), coef, LAW_FP)[1]) for x in w])
        v_infl = math.exp(float(w[int(np.argmin(d))]))
    return dataclasses.replace(fo, V=float(V), v_inflection=v_infl, f_zero=f_zero, v_breakdown=v_br)


_CACHE: dict[tuple[Any, float], CompiledLaw] = {}


def compiled_law(force: Any, V: float) -> CompiledLaw:
    """The law ``force`` at pull speed V as the compiled drivers take it (module docstring); cached per (law, V).

    Raises
    ------
    ValueError
        Naming ``params.force``: a law whose folds cannot be found (:meth:`PeelForce.folds`), V outside a
        tabulated law's speeds, or a table starting below ``STATE_RANGES["v"]`` (1e-150 m/s, where the
        compiled f'' would divide by an underflowed v^2).
    """
    key = (force, float(V))
    out = _CACHE.get(key)
    if out is None:
        impl = force.impl
        domain = impl.domain(force)
        fn, coef = impl.kernel(force, V)
        try:
            bs = impl.structure(force, V, fn, coef, domain)
        except ValueError as e:
            raise ValueError(f"params.force: {e}") from None
        out = CompiledLaw(force, float(V), fn, np.ascontiguousarray(coef, dtype=float), bs, domain, impl.inlined)
        if len(_CACHE) >= 512:
            _CACHE.clear()
        _CACHE[key] = out
    return out

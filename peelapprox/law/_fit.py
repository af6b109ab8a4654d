"""Fitting a law to measured points: :meth:`peelapprox.PeelForce.fit` and its record :class:`FitResult`.

Weighted least squares (``scipy.optimize.least_squares``, trust-region reflective, central-difference Jacobian)
of a compiled family's coefficients, or of an expression's named constants, to points ``(v_i, f_i)``: the
residuals are ``(f(v_i; c) - f_i) / sigma_i``.  A family is evaluated by its numpy evaluator
(:meth:`peelapprox.law._families.Family.evaluate`, the generated code run by numpy): a family fit compiles
nothing.  An expression is parsed once by the grammar (never evaluated) with its constants as symbols and
printed to numpy by ``sympy.lambdify``.

The statistics (:class:`FitResult`):

* the covariance of the fitted coefficients is ``(J^T J)^-1`` of the weighted Jacobian J at the solution
  (central differences, computed again there) -- with ``sigma`` given, as is (chi^2 is then meaningful:
  ~ dof for a model that describes the data); without ``sigma`` (unit weights) scaled by the residual variance
  ``chi^2 / dof``, as ``scipy.optimize.curve_fit`` does with ``absolute_sigma=False``;
* **identification**: the columns of J, each scaled to unit norm, must be independent: a singular value of the
  scaled J below :data:`IDENTIFY_RCOND` times the largest (or a column of zeros) means that the points do not
  determine some combination of the coefficients; the fit then raises a ``ValueError`` naming the coefficients
  of that combination (and how to fix them, ``bounds={name: (x, x)}``) instead of returning numbers;
* the folds ``(v_max, f_max, v_min, f_min)`` of the fitted law at V, with their covariance ``G C G^T`` by the
  delta method, G their Jacobian with respect to the fitted coefficients by central finite differences (steps
  of 1e-3 standard errors; each fold found by the law's own fold search, Brent to ~4 ulp).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from .._checks import ArgumentTypeError, in_range, real, reals, shown
from .._ranges import PARAM_RANGES, STATE_RANGES
from . import _families
from ._fit_result import FitResult, FoldEstimate
from ._folds import find_folds

__all__ = ["IDENTIFY_RCOND", "N_SIGNIFICANCE", "FitResult", "FoldEstimate", "check_points", "fit"]

#: Smallest ratio of the smallest to the largest singular value of the column-scaled weighted Jacobian for which
#: the coefficients count as identified (module docstring).  The Jacobian is a central difference (relative error
#: ~1e-10): below 1e-9 the direction of the smallest singular value is numerical noise, and so would be the
#: standard errors along it.
IDENTIFY_RCOND = 1e-9
#: The fitted folds' depth ``f_max - f_min`` must exceed this many of its standard errors (delta method) for the
#: fit to have an N shape; else ``FitResult.folds`` is None, ``folds_note`` says why and the law's ``folds``
#: raise a ValueError saying so.
N_SIGNIFICANCE = 2.0
#: Fold search density (points per unit of ln v) and window of the fits' folds, as the laws' own.
_FOLD_DENSITY = 200
_FOLDS = ("v_max", "f_max", "v_min", "f_min")


def check_points(v: Any, f: Any, *, need: int, what: str) -> tuple[np.ndarray, np.ndarray]:
    """``(v, f)`` as float arrays, or a ValueError/TypeError naming the argument and the first offending index.

    1-D of equal length, at least ``need`` points (``what`` says why), finite, ``v > 0`` and strictly increasing,
    ``f > 0`` (a peel force, as :meth:`peelapprox.PeelForce.tabulated` requires).
    """
    out = []
    for name, x in (("v", v), ("f", f)):
        refused = x is None or isinstance(x, (str, bytes, bool, np.bool_))
        try:
            a = None if refused else np.asarray(x)
        except (TypeError, ValueError):
            a = None
        if a is None or a.dtype.kind not in "iuf":
            raise ArgumentTypeError(f"{name} must be an array of real numbers, got {type(x).__name__}")
        if a.ndim != 1:
            raise ValueError(f"{name} must be a 1-D array, got shape {a.shape}")
        out.append(a.astype(float))
    va, fa = out
    if va.size != fa.size:
        raise ValueError(f"v and f must have the same length, got {va.size} and {fa.size}")
    if va.size < need:
        raise ValueError(f"v, f: {va.size} point(s), fewer than the {need} {what}")
    for name, a in (("v", va), ("f", fa)):
        bad = np.flatnonzero(~np.isfinite(a))
        if bad.size:
            raise ValueError(f"{name} must be finite: {name}[{int(bad[0])}] = {float(a[bad[0]])!r}")
    bad = np.flatnonzero(va <= 0)
    if bad.size:
        raise ValueError(f"v must be > 0 (peel velocities in m/s): v[{int(bad[0])}] = {float(va[bad[0]])!r}")
    bad = np.flatnonzero(np.diff(va) <= 0)
    if bad.size:
        i = int(bad[0])
        why = "a duplicate" if va[i] == va[i + 1] else "unsorted"
        raise ValueError(f"v must be strictly increasing ({why}): v[{i}] = {float(va[i])!r} >= "
                         f"v[{i + 1}] = {float(va[i + 1])!r}")
    bad = np.flatnonzero(fa <= 0)
    if bad.size:
        i = int(bad[0])
        raise ValueError(f"f must be > 0 (a peel force in N): f[{i}] = {float(fa[i])!r} at v = {float(va[i])!r}")
    return va, fa


class _Model:
    """A parametrised law: ``evaluate(theta_all, v, V, order)`` by numpy, its coefficient names, defaults and
    lower bounds, and ``build(coefficients)``, the :class:`PeelForce` of the final values."""

    def __init__(self, cls: Any, family: Any, p0: Any):
        if isinstance(family, cls):
            if family.kind != "family":
                raise ValueError(f"family: a law given as family must be a family law (its coefficients are the "
                                 f"start), got a {family.kind!r} law")
            start = dict(family.coefficients)
            family = family.name
        elif isinstance(family, str):
            start = {}
        else:
            raise TypeError(f"family must be a family's name (e.g. 'cubic'), a family law or an expression's text, "
                            f"got {type(family).__name__}")
        by_constructor = {f.constructor: n for n, f in _families.FAMILIES.items()}
        name = by_constructor.get(family, family)
        self.cls = cls
        if name in _families.FAMILIES:
            fam = _families.FAMILIES[name]
            self.fam: _families.Family | None = fam
            self.label = f"family {fam.constructor}"
            self.names = fam.names
            self.start = {**dict(fam.defaults), **start}
            self.lower = {n: (0.0 if n in fam.positive else -math.inf) for n in self.names}
            self.depends_on_V = fam.depends_on_V
            lo, hi = STATE_RANGES["v"]
            self.window = ((1e-12, hi), (lo * 10.0, hi))  # as FamilyKind.fold_window
        else:
            self.fam = None
            self._expression(family, p0)
        if p0 is not None:
            if not isinstance(p0, Mapping):
                raise TypeError(f"p0 must be a mapping of coefficient names to starting values, got "
                                f"{type(p0).__name__}")
            unknown = sorted(set(p0) - set(self.names))
            if unknown:
                raise ValueError(f"p0: unknown coefficient(s) {', '.join(map(shown, unknown))} of the {self.label}: "
                                 f"its coefficients are {', '.join(self.names)}")
            for n, x in p0.items():
                self.start[n] = in_range(f"p0[{n!r}]", x)  # finite

    def _expression(self, text: str, p0: Any) -> None:
        import sympy as sp

        from . import _grammar
        from ._expression import V_DOMAIN, _symbols

        if not isinstance(p0, Mapping) or not p0:
            raise ValueError(f"family {shown(text)} is not a family ({', '.join(_families.FAMILIES)}); as an "
                             "expression to fit, p0 must name its constants with starting values, e.g. "
                             "p0={'a': 150, 'b': 300}")
        v, V = _symbols()
        syms = {n: sp.Symbol(str(n), real=True) for n in p0}
        for n in syms:
            if n in ("v", "V") or not str(n).isidentifier() or n in _grammar.FUNCTIONS:
                raise ValueError(f"p0: {shown(n)} cannot be a constant's name (an identifier other than v, V or a "
                                 "function's name)")
        e, used = _grammar.parse(text, {"v": v, "V": V, **syms})
        unused = sorted(set(syms) - used)
        if unused:
            raise ValueError(f"p0: constant(s) {', '.join(unused)} do not occur in the expression {shown(text)}")
        if not isinstance(e, sp.Expr) or v not in e.free_symbols:
            raise ValueError(f"family {shown(text)}: an expression to fit must depend on v")
        self.text = text
        self.label = f"expression {shown(text)}"
        self.names = tuple(syms)
        self.start = {}
        self.lower = {n: -math.inf for n in self.names}
        self.depends_on_V = V in e.free_symbols
        args = (v, V, *syms.values())
        d1 = sp.diff(e, v)
        self.funcs = [sp.lambdify(args, x, modules="numpy") for x in (e, d1)]
        self.window = (V_DOMAIN, V_DOMAIN)

    def evaluate(self, theta: tuple, v: np.ndarray, V: float, order: int) -> np.ndarray:
        with np.errstate(all="ignore"):
            if self.fam is not None:
                try:
                    return self.fam.evaluate(v, V, theta, order)
                except ValueError:  # the coefficients overflow at V
                    return np.full(v.shape, np.nan)
            try:
                out = np.asarray(self.funcs[order](v, V, *theta))
            except (ArithmeticError, TypeError, ValueError):
                return np.full(v.shape, np.nan)
            if np.iscomplexobj(out):
                out = np.where(out.imag == 0, out.real, np.nan)
            out = out.astype(float)
            return np.broadcast_to(out, v.shape).copy() if out.shape != v.shape else out

    def build(self, values: dict[str, float]) -> Any:
        if self.fam is not None:
            return self.cls.family(self.fam.name, **values)
        return self.cls.expression(self.text, **values)

    def folds(self, theta: tuple, V: float) -> Any:
        return find_folds(lambda x, order: self.evaluate(theta, x, V, order), V, self.window[0], self.window[1],
                          self.label, _FOLD_DENSITY)


def _bounds(model: _Model, bounds: Any) -> tuple[dict[str, float], dict[str, tuple[float, float]]]:
    """``(fixed values, (lo, hi) of each free coefficient)`` from ``bounds`` (``{name: (lo, hi)}``, lo == hi fixes)."""
    given = {} if bounds is None else bounds
    if not isinstance(given, Mapping):
        raise TypeError(f"bounds must be a mapping {{name: (lo, hi)}}, got {type(bounds).__name__}")
    unknown = sorted(set(given) - set(model.names))
    if unknown:
        raise ValueError(f"bounds: unknown coefficient(s) {', '.join(map(shown, unknown))} of the {model.label}: "
                         f"its coefficients are {', '.join(model.names)}")
    fixed: dict[str, float] = {}
    free: dict[str, tuple[float, float]] = {}
    for n in model.names:
        lo, hi = model.lower[n], math.inf
        if n in given:
            pair = given[n]
            if not isinstance(pair, (tuple, list)) or len(pair) != 2:
                raise ValueError(f"bounds[{n!r}] must be a pair (lo, hi), got {shown(pair)}")
            lo = max(lo, real(f"bounds[{n!r}][0]", pair[0]))
            hi = real(f"bounds[{n!r}][1]", pair[1])
            if math.isnan(lo) or math.isnan(hi) or lo > hi:
                raise ValueError(f"bounds[{n!r}] = {shown(pair)}: lo must be <= hi (and within the coefficient's "
                                 f"range, lower end {model.lower[n]!r})")
            if lo == hi:
                fixed[n] = lo
                continue
        free[n] = (lo, hi)
    if not free:
        raise ValueError(f"bounds fix every coefficient of the {model.label}: nothing to fit")
    return fixed, free


def _jacobian(res: Callable[[np.ndarray], np.ndarray], x: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Central differences of ``res`` at x (one-sided at a bound), step ``eps^(1/3) max(|x|, 1e-8)``."""
    r0 = res(x)
    J = np.empty((r0.size, x.size))
    for i in range(x.size):
        h = np.cbrt(np.finfo(float).eps) * max(abs(x[i]), 1e-8)
        a, b = x.copy(), x.copy()
        a[i] = min(x[i] + h, hi[i])
        b[i] = max(x[i] - h, lo[i])
        J[:, i] = (res(a) - res(b)) / (a[i] - b[i])
    return J


def fit(cls: Any, v: Any, f: Any, family: Any, *, sigma: Any = None, V: Any = None, p0: Any = None,
        bounds: Any = None) -> Any:
    """The fitted law with its :class:`FitResult` (``law.fit_result``): :meth:`peelapprox.PeelForce.fit`."""
    model = _Model(cls, family, p0)
    fixed, free = _bounds(model, bounds)
    names = tuple(free)
    k = len(names)
    va, fa = check_points(v, f, need=k + 1, what=f"a fit of {k} coefficient(s) needs (one more than the fitted "
                                                  "coefficients, for one degree of freedom)")
    w = _weights(sigma, va)
    if model.depends_on_V and V is None:
        raise ValueError(f"V: the {model.label} depends on the pull speed; give the V [m/s] the points were "
                         "measured at")
    pr = _Problem(model, names, {**model.start, **fixed}, va, fa, w,
                  1.0 if V is None else in_range("V", V, *PARAM_RANGES["V"]))
    lo = np.array([free[n][0] for n in names])
    hi = np.array([free[n][1] for n in names])
    sol, x = _solve(pr, lo, hi, _start(pr, lo, hi))
    values = dict(zip(model.names, pr.theta_of(x)))
    law = model.build(values)
    J = _jacobian(pr.res, x, lo, hi)
    cov = _covariance(J, names, model.label)
    r = sol.fun
    chi2 = float(r @ r)
    dof = va.size - k
    if sigma is None:
        cov = cov * (chi2 / dof)
    se = np.sqrt(np.clip(np.diag(cov), 0.0, None))  # (J^T J)^-1 is positive semi-definite: clip rounding
    d = np.where(se > 0, se, 1.0)
    folds, note = _fold_estimate(model, pr.theta_of, x, se, cov, lo, hi, pr.V, (va[0], va[-1]))
    if folds is not None:
        note = _insignificant(folds, fa)
        if note:
            folds = None
    elif _has_folds(model, pr.theta_of(x), pr.V):
        note = (f"no significant N shape: the fitted law has folds at V={pr.V!r} m/s but they vanish when a "
                f"coefficient moves by a thousandth of its standard error ({note})")
    result = FitResult(model.label, names, values, dict(zip(names, se.tolist())), cov,
                       tuple(n for n in model.names if n not in free), r * w, chi2, dof, chi2 / dof,
                       sigma is not None, folds, note, bool(sol.success), str(sol.message), int(sol.nfev),
                       cov / np.outer(d, d))
    object.__setattr__(law, "_fit_result", result)
    if note.startswith("no significant N shape"):
        object.__setattr__(law, "_no_n_shape", f"this law was fitted (PeelForce.fit) to points without a "
                                               f"significant N shape, so its folds are not the data's: {note}")
    return law


def _weights(sigma: Any, va: np.ndarray) -> np.ndarray:
    """The points' standard deviations [N] (ones without ``sigma``), checked: one, or one per point, each > 0."""
    if sigma is None:
        return np.ones_like(va)
    if not (np.ndim(sigma) in (0, 1) and np.size(sigma) in (1, va.size)):
        raise ValueError(f"sigma must be one standard deviation [N] or one per point ({va.size}), got shape "
                         f"{np.shape(sigma)}")
    w = np.broadcast_to(reals("sigma", sigma), va.shape).copy()
    bad = np.flatnonzero(~(w > 0))
    if bad.size:
        raise ValueError(f"sigma must be > 0 (standard deviations of f [N]): sigma[{int(bad[0])}] = "
                         f"{float(w[bad[0]])!r}")
    return w


class _Problem:
    """The least-squares problem of a fit: the free coefficients ``names`` (the others held at ``start``), the
    points ``va, fa`` with their standard deviations ``w``, at the pull speed ``V``."""

    def __init__(self, model: _Model, names: tuple[str, ...], start: dict[str, float], va: np.ndarray,
                 fa: np.ndarray, w: np.ndarray, V: float):
        self.model, self.names, self.start, self.va, self.fa, self.w, self.V = model, names, start, va, fa, w, V

    def theta_of(self, x: np.ndarray) -> tuple:
        """All the law's coefficients, in its order, with the free ones at ``x``."""
        d = dict(self.start)
        d.update(zip(self.names, map(float, x)))
        return tuple(d[n] for n in self.model.names)

    def res(self, x: np.ndarray) -> np.ndarray:
        """The weighted residuals at ``x``."""
        return (self.model.evaluate(self.theta_of(x), self.va, self.V, 0) - self.fa) / self.w


def _start(pr: _Problem, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """The start of the free coefficients, moved just inside their bounds; a ValueError naming ``p0`` where the
    law is not finite at a point there."""
    x0 = np.array([float(pr.start[n]) for n in pr.names])
    span = np.where(np.isfinite(hi - lo), hi - lo, np.inf)
    x0 = np.clip(x0, lo + 1e-12 * np.minimum(span, np.abs(x0) + 1.0), hi - 1e-12 * np.minimum(span, np.abs(x0) + 1.0))
    r0 = pr.res(x0)
    if not np.all(np.isfinite(r0)):
        i = int(np.flatnonzero(~np.isfinite(r0))[0])
        raise ValueError(f"p0: the {pr.model.label} at its start {dict(zip(pr.names, x0.tolist()))} is not finite "
                         f"at v[{i}] = {pr.va[i]!r} m/s; give a start (p0) where it is")
    return x0


def _solve(pr: _Problem, lo: np.ndarray, hi: np.ndarray, x0: np.ndarray) -> tuple[Any, np.ndarray]:
    """scipy's least_squares from ``x0`` within the bounds: its result and the fitted free coefficients; a
    ValueError when it fails (the coefficients not identified, if that is why)."""
    from scipy.optimize import least_squares

    # a coefficient bounded by (0, inf) only (a family's scale) is fitted as its logarithm: positive without the
    # reflections of bounded trust regions, which stall on the paper family; any other finite bound is least_squares'
    logs = (lo == 0.0) & (hi == math.inf)
    blo, bhi = np.where(logs, -math.inf, lo), np.where(logs, math.inf, hi)

    def to_x(y: np.ndarray) -> np.ndarray:
        return np.where(logs, np.exp(np.where(logs, y, 0.0)), y)

    y0 = np.where(logs, np.log(np.where(logs, x0, 1.0)), x0)
    with np.errstate(all="ignore"):  # a trial step may overflow: least_squares rejects it and shrinks the region
        sol = least_squares(lambda y: pr.res(to_x(y)), y0, jac="3-point", bounds=(blo, bhi), method="trf",
                            x_scale="jac", ftol=1e-15, xtol=1e-15, gtol=1e-15, max_nfev=200 * (len(pr.names) + 1))
    x = to_x(np.asarray(sol.x, dtype=float))
    if sol.status <= 0 or not np.all(np.isfinite(sol.fun)):
        if np.all(np.isfinite(sol.fun)):
            _covariance(_jacobian(pr.res, x, lo, hi), pr.names, pr.model.label)  # not identified: say so first
        raise ValueError(f"the {pr.model.label} cannot be fitted to these points: least_squares stopped "
                         f"({sol.message}) after {sol.nfev} evaluations; give a start (p0) nearer the data, bounds, "
                         "or another family")
    return sol, x


def _has_folds(model: _Model, theta: tuple, V: float) -> bool:
    try:
        return bool(model.folds(theta, V).has_folds)
    except ValueError:
        return False


def _insignificant(folds: FoldEstimate, f: np.ndarray) -> str:
    """Why the fitted folds are no N shape of the data (:data:`N_SIGNIFICANCE`), or ``""``: the depth
    ``f_max - f_min`` at most ``N_SIGNIFICANCE`` of its standard errors, or at most 1e-9 of the largest |f|
    (rounding: a flat trace's fit has coefficients of 1e-16 and no residual)."""
    depth = folds.values["f_max"] - folds.values["f_min"]
    C = folds.covariance
    se = math.sqrt(max(float(C[1, 1] + C[3, 3] - 2.0 * C[1, 3]), 0.0))
    if depth > N_SIGNIFICANCE * se and depth > 1e-9 * float(np.max(np.abs(f))):
        return ""
    return (f"no significant N shape: the fitted depth f_max - f_min = {depth:.3g} N at V={folds.V!r} m/s, "
            f"standard error {se:.3g} N (at most {N_SIGNIFICANCE:g} standard errors, or rounding); the points do "
            "not show a maximum followed by a minimum")


def _covariance(J: np.ndarray, names: tuple[str, ...], label: str) -> np.ndarray:
    """``(J^T J)^-1`` by the SVD of the column-scaled J, or a ValueError naming what the points do not identify."""
    norms = np.sqrt(np.sum(J * J, axis=0))
    zero = [n for n, s in zip(names, norms) if not s > 0]
    if zero:
        raise ValueError(f"the points do not identify the coefficient(s) {', '.join(zero)} of the {label}: f does "
                         "not change with them at these points; fix them (bounds={name: (x, x)}) or add data")
    U, s, Vt = np.linalg.svd(J / norms, full_matrices=False)
    small = np.flatnonzero(s < IDENTIFY_RCOND * s[0])
    if small.size:
        parts, involved = [], []
        for j in small:
            row = np.abs(Vt[j])
            big = [names[i] for i in np.argsort(-row) if row[i] >= 0.1 * row.max()]
            parts.append("(" + ", ".join(big) + ")")
            involved += [n for n in big if n not in involved]
        raise ValueError(f"the points do not identify the coefficients of the {label}: a combination of each of "
                         f"{'; '.join(parts)} leaves f unchanged to {s[-1] / s[0]:.3g} of the best-determined "
                         f"(limit {IDENTIFY_RCOND:g}); fix one of each (bounds={{name: (x, x)}}) or add data "
                         f"that tell them apart (a wider v range); involved: {', '.join(involved)}")
    inv = (Vt.T / s**2) @ Vt
    return inv / np.outer(norms, norms)


def _fold_estimate(model: _Model, theta_of: Callable, x: np.ndarray, se: np.ndarray, cov: np.ndarray,
                   lo: np.ndarray, hi: np.ndarray, V: float, data: tuple[float, float]) -> tuple[FoldEstimate | None,
                                                                                                   str]:
    """The folds at V and their covariance by the delta method (module docstring), or ``(None, why)``."""

    def fold_vector(xx: np.ndarray) -> np.ndarray:
        bs = model.folds(theta_of(xx), V)
        if not bs.has_folds:
            raise ValueError(f"the fitted law has no folds at V={V!r} m/s (f' > 0 throughout): no stick-slip")
        return np.array([bs.v_max, bs.f_max, bs.v_min, bs.f_min], dtype=float)

    try:
        y0 = fold_vector(x)
        G = np.empty((4, x.size))
        for i in range(x.size):
            h = max(1e-3 * se[i], 1e-9 * abs(x[i]), 1e-12)
            a, b = x.copy(), x.copy()
            a[i] = min(x[i] + h, hi[i])
            b[i] = max(x[i] - h, lo[i])
            G[:, i] = (fold_vector(a) - fold_vector(b)) / (a[i] - b[i])
    except ValueError as exc:
        return None, str(exc)
    C = G @ cov @ G.T
    sd = np.sqrt(np.clip(np.diag(C), 0.0, None))
    inside = bool(data[0] <= y0[0] <= data[1] and data[0] <= y0[2] <= data[1])
    return FoldEstimate(V, dict(zip(_FOLDS, y0.tolist())), dict(zip(_FOLDS, sd.tolist())), C, inside), ""

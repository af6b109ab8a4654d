"""The peel-force law as data: :class:`PeelForce`, one law ``f(v, V)`` [N] of the peel velocity and the pull speed.

Five kinds (:data:`KINDS`), each plain data (strings and tuples of floats), so a law is immutable, hashable, equal
by value, picklable and JSON-able (``dataclasses.asdict``): ``"paper"`` (the built-in fvV, evaluated bitwise by
:func:`peelapprox.peel_force`), ``"family"`` (a formula of :mod:`peelapprox.law._families` with its coefficients
as data), ``"expression"`` (a sympy expression kept as canonical text), ``"tabulated"`` (measured curves) and
``"smoothed"`` (a C⁴ spline in ln v smoothing noisy points, :mod:`peelapprox.law._spline`).
What a kind does is its implementation object (:mod:`peelapprox.law._kinds`, :attr:`PeelForce.impl`).
"""

from __future__ import annotations

import hashlib
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from .._checks import in_range, shown
from .._ranges import PARAM_RANGES
from . import _expression, _families
from ._folds import BranchStructure
from ._force_checks import _check_field_types, _check_nesting
from ._kinds import FOLD_GRID_DENSITY, KIND_IMPLS, LawKind, shown_law

__all__ = ["ALL_LAWS", "FOLD_GRID_DENSITY", "KINDS", "PeelForce", "law_label", "require_law", "shown_law"]

#: The kinds of law.
KINDS = tuple(KIND_IMPLS)
#: Every law by its :func:`law_label`: what a consumer that honours any law passes as ``laws``.
ALL_LAWS = ("paper", *(f.constructor for f in _families.FAMILIES.values()), "expression", "tabulated",
            "smoothed")


@dataclass(frozen=True, eq=False, repr=False)
class PeelForce:
    """A peel-force law ``f(v, V)`` [N]: the paper's fvV, a family, an expression or a table.

    Build one with :meth:`paper`, :meth:`family` (or :meth:`paper_family`, :meth:`cubic`,
    :meth:`power_branches`), :meth:`expression` or :meth:`tabulated`; the fields below are its plain-data
    state (validated again if the class is called directly, e.g. from a dict by :meth:`from_dict`).

    Attributes
    ----------
    kind : {"paper", "family", "expression", "tabulated", "smoothed"}
    name : str or None
        The family's name (``"paper"``, ``"cubic"``, ``"power_branches"``) of a family law.
    coefficients : tuple of (name, float)
        A family law's coefficients, in the family's order.
    source : str or None
        An expression law's canonical text (sympy ``srepr``, constants substituted).
    tables : tuple of (V or None, v tuple, f tuple)
        A tabulated law's tables; a smoothed law's one ``(V or None, knots [m/s], B-spline coefficients)``.
    display : str
        What ``repr`` shows of an expression or a table, derived from the canonical content (an expression:
        its canonical text, constants substituted); a ``display`` passed in (e.g. by :meth:`from_dict`) is
        ignored; not compared.

    Notes
    -----
    Equal (and equally hashed) by kind and canonical content: family coefficients as floats, an
    expression by its canonical text (``"2*v"`` equals ``"v + v"``), tables by their values.  Pickles as
    its plain-data fields (compiled evaluators are rebuilt lazily in each process).  Evaluation:
    ``law(v, V)`` or :meth:`f`, :meth:`df`, :meth:`d2f`, vectorised over v; V must be in
    ``PARAM_RANGES["V"]`` and is ignored by a V-independent law.
    """

    kind: str
    name: str | None = None
    coefficients: tuple = ()
    source: str | None = None
    tables: tuple = ()
    display: str = ""

    # ------------------------------------------------------------------ construction
    def __post_init__(self) -> None:
        _check_field_types(self)
        if self.kind not in KINDS:
            raise ValueError(f"kind must be one of {', '.join(KINDS)}, got {self.kind!r}")
        impl = KIND_IMPLS[self.kind]
        given = {"name": self.name is not None, "coefficients": bool(self.coefficients),
                 "source": self.source is not None, "tables": bool(self.tables)}
        extra = [name for name, g in given.items() if g and name not in impl.needs]
        fields = impl.canonical(self)
        if extra:
            raise ValueError(f"a {self.kind!r} law takes no {', '.join(extra)}")
        for name, empty in (("coefficients", ()), ("source", None), ("tables", ())):
            object.__setattr__(self, name, fields.get(name, getattr(self, name) or empty))
        # what repr shows is derived from the canonical content, never taken from stored data
        object.__setattr__(self, "display", impl.display(self))

    @classmethod
    def paper(cls) -> PeelForce:
        """The paper's law fvV, evaluated by :func:`peelapprox.peel_force` (bitwise): the default."""
        return _PAPER_LAW

    @classmethod
    def family(cls, name: str, **coefficients: float) -> PeelForce:
        """A law of the named family (:mod:`peelapprox.law._families`), missing coefficients at their defaults.

        ValueError for an unknown family or coefficient name (the message lists the valid ones), a
        non-finite coefficient, or a non-positive scale (``v3``, ``A1``, ``v1``, ``m``).
        """
        return cls("family", name, tuple(coefficients.items()))

    @classmethod
    def paper_family(cls, **params: float) -> PeelForce:
        """fvV with its 14 numbers as coefficients (defaults: the paper's)::

            f = a1 v^p1 + a2 v^p2 + a3 e^(v/v3) - a4 V^q4 - (a5 - a6 V^q6 - a7 V^q7) v^p5

        a1=400, p1=0.35, a2=110, p2=0.15, a3=130, v3=11, a4=2, q4=1.5, a5=415, a6=45, q6=0.4, a7=0.35,
        q7=2.15, p5=0.5 (De, Maybhate & Ananthakrishna 2004, Eq. fvV).  With the defaults it equals
        :meth:`paper` to ~1e-15 relative (not bitwise).  V-dependent, as fvV.
        """
        return cls.family("paper", **params)

    @classmethod
    def cubic(cls, a: float = 150.0, b: float = 300.0, c: float = 300.0, d: float = 80.0) -> PeelForce:
        """The N-shaped cubic ``f = a + b v - c v^2 + d v^3`` [N, v in m/s], V-independent.

        The smooth normal form of the N-shaped (rising-falling-rising) law of Hong & Yue, Phys. Rev. Lett.
        74, 254 (1995) — the generic smooth N, not Hong & Yue's own numbers (which could not be verified).
        Folds at the roots of ``b - 2 c v + 3 d v^2``; the defaults put them at 0.691 and
        1.809 m/s.
        """
        return cls.family("cubic", a=a, b=b, c=c, d=d)

    @classmethod
    def power_branches(cls, A1: float = 338.5, n1: float = 0.1038, v1: float = 3.244, m: float = 1.074,
                       A2: float = 14.36, n2: float = 0.8502) -> PeelForce:
        """Two rising power-law branches joined by a falling one, V-independent::

            f(v) = A1 v^n1 / (1 + (v/v1)^m) + A2 v^n2

        The slow (viscoelastic) and fast (glassy) branches of G(v) = f/b measured on adhesive tapes by
        Maugis & Barquins (1988) and Barquins & Ciccotti (Int. J. Adhes. Adhes. 17, 65, 1997).  The defaults
        are a calibration to the paper's fvV at V = 1 m/s (v_max ≈ 0.506 m/s, f_max ≈ 285.6 N,
        v_min ≈ 8.59 m/s, f_min ≈ 199.4 N), not the measured constants of a 3M tape (unverified here).
        """
        return cls.family("power_branches", A1=A1, n1=n1, v1=v1, m=m, A2=A2, n2=n2)

    @classmethod
    def expression(cls, expr: Any, **constants: float) -> PeelForce:
        """A law written as a sympy expression (or its text) in ``v`` [m/s] and optionally ``V`` [m/s].

        ``constants`` are substituted (``PeelForce.expression("a + b*v - c*v**2 + d*v**3", a=150, b=300,
        c=300, d=80)``); ``^`` means a power.  f' and f'' come from sympy; evaluation is numpy through
        ``sympy.lambdify``, on ``v`` in [1e-6, 1e3] m/s (the probed domain).

        Raises
        ------
        ValueError
            Unknown symbols (named), an undefined function, an unused or ill-named constant, no dependence
            on v, or f, f', f'' complex or non-finite at a point of the probe (v log-spaced over
            [1e-6, 1e3] m/s; V in 0.01, 0.1, 1, 10 m/s if the law depends on V), the point named.
        """
        text = _expression.canonical(expr, constants)
        return _restore("expression", None, (), text, ())  # checked: no second parse and probe

    @classmethod
    def tabulated(cls, v: Any = None, f: Any = None, *, V: float | None = None, tables: Any = None) -> PeelForce:
        """A measured curve: ``tabulated(v, f)`` (optionally ``V=`` its pull speed), or several,
        ``tabulated(tables=[(V1, v1, f1), (V2, v2, f2), ...])`` at increasing V.

        f is interpolated by PCHIP in ln v (shape-preserving: no extremum the data lack; f' continuous);
        between tables, linearly in V.  One table with ``V=None`` is used at every V; with ``V=x``, at x
        only.  v outside the table (or V outside the tables' speeds) is refused, never extrapolated.

        Raises
        ------
        ValueError
            Naming the offending index and value: not 1-D, lengths differ, fewer than 5 points, a NaN or
            inf, v not > 0 or not strictly increasing, f not > 0, a flat step, or not exactly one local
            maximum followed by one local minimum in the data.
        """
        if tables is not None:
            if v is not None or f is not None or V is not None:
                raise ValueError("give either v and f (and V) or tables, not both")
            return cls("tabulated", tables=tables)
        if v is None or f is None:
            raise ValueError("tabulated needs v and f (arrays of peel velocities [m/s] and forces [N])")
        return cls("tabulated", tables=((V, v, f),))

    @classmethod
    def fit(cls, v: Any, f: Any, family: Any, *, sigma: Any = None, V: float | None = None,
            p0: Mapping[str, float] | None = None,
            bounds: Mapping[str, tuple[float, float]] | None = None) -> PeelForce:
        """The law of a family (or an expression) whose coefficients fit the points ``(v, f)`` best, with its
        statistics in ``law.fit_result``.

        Weighted least squares (``scipy.optimize.least_squares``) of ``(f(v_i) - f_i) / sigma_i``; a family is
        evaluated by numpy (nothing is compiled).  Details: :mod:`peelapprox.law._fit`.

        Parameters
        ----------
        v, f : array_like
            The points: peel velocities [m/s] (> 0, strictly increasing) and forces [N] (> 0), finite, more of them
            than fitted coefficients.
        family : str or PeelForce
            A family's name or constructor (``"cubic"``, ``"paper_family"``, ``"power_branches"``; start: its
            defaults), a family law (start: its coefficients), or an expression's text whose constants are the
            keys of ``p0`` (e.g. ``"a + b*v - c*v**2 + d*v**3"``).
        sigma : float or array_like, optional
            Standard deviation [N] of each f (or one for all): chi^2 is then meaningful and the covariance
            absolute.  None: unit weights, the covariance scaled by the residual variance ``chi^2 / dof``.
        V : float, optional
            The pull speed [m/s] of the points: needed by a law that depends on V; where the folds are given
            (default 1.0 for a V-independent law).
        p0 : mapping, optional
            Starting values by name (a family: over its defaults; an expression: required, its constants).
        bounds : mapping, optional
            ``{name: (lo, hi)}``; ``lo == hi`` holds that coefficient fixed at that value (not fitted).  A family's
            positive coefficients are bounded below by 0 anyway.

        Returns
        -------
        PeelForce
            The fitted law, equal to the same law built by hand; ``law.fit_result`` is a
            :class:`~peelapprox.FitResult` (coefficients by name, covariance, standard errors,
            residuals, chi^2, dof, chi^2/dof, the folds at V with their standard errors by the delta method).

        Raises
        ------
        ValueError
            Naming the argument and index: a NaN or inf, v not > 0 or not strictly increasing (unsorted or
            duplicate), fewer points than coefficients + 1, a bad sigma, p0 or bounds; an unknown family; a
            start where the law is not finite; a fit that does not converge; points that do not identify a
            coefficient (the message names the coefficients involved: fix them with ``bounds`` or add data).
        TypeError
            An argument of the wrong type.
        """
        from ._fit import fit

        return fit(cls, v, f, family, sigma=sigma, V=V, p0=p0, bounds=bounds)

    @property
    def fit_result(self) -> Any:
        """What :meth:`fit` measured (:class:`~peelapprox.FitResult`), or None for a law not made by
        :meth:`fit`.  Not part of the law's value: not compared, hashed, keyed, pickled or in ``asdict``."""
        return self.__dict__.get("_fit_result")

    @classmethod
    def smoothed(cls, v: Any, f: Any, *, lam: float | str = "gcv", V: float | None = None) -> PeelForce:
        """Noisy measured points smoothed by a C⁴ spline in ln v: a law of kind ``"smoothed"``.

        scipy's ``make_smoothing_spline`` of f in ``u = ln v`` (knots at the data), projected on quintic
        B-splines with the same knots, then the N shape is checked on the result: exactly one maximum then one
        minimum inside the data range.  f and its first four derivatives are continuous (f'' too, unlike a
        table's PCHIP; f‴ too, unlike a cubic spline, so the solver's steps are not rejected at the knots), the
        folds are the roots of the spline's derivative (between data, not at a datum), and a compiled run
        evaluates it by the quintic kernel at about a table's cost per call.  Details:
        :mod:`peelapprox.law._spline`.

        Parameters
        ----------
        v, f : array_like
            Peel velocities [m/s] (> 0, strictly increasing) and forces [N] (> 0), finite, at least 5 points.
        lam : "gcv" or float
            The smoothing penalty of ``sum (f_i - s(u_i))^2 + lam * integral s''(u)^2 du``: it smooths over a
            length ``(lam * L / n)^(1/4)`` in ln v (L the data's range in ln v, n the points); 0 interpolates (a
            natural cubic spline through the points).  ``"gcv"`` (default): generalised cross-validation's
            penalty if its law is N-shaped, else the least penalty whose law is N-shaped while it follows the
            data as noise would (a shape-constrained choice; :func:`peelapprox.law._spline.smooth`).  More than
            1000 points are averaged in runs of consecutive points first (the work is bounded).
        V : float, optional
            The pull speed [m/s] the points were measured at: the law is then used at that V only; None (default)
            uses it at every V.

        Returns
        -------
        PeelForce
            Kind ``"smoothed"``: its ``tables`` hold ``((V, knots [m/s], B-spline coefficients),)`` (a spline in
            ln v), plain tuples of floats (immutable, hashable, ``dataclasses.asdict``/:meth:`from_dict`
            round-trip).  Refuses v outside the data range (never extrapolated).

        Raises
        ------
        ValueError
            Naming the argument and index: a NaN or inf, v not > 0 or not strictly increasing (unsorted or
            duplicate), f not > 0, fewer than 5 points, lengths differ; a bad ``lam`` or V; a smoothed curve that is not
            N-shaped (the extrema it has are listed: smooth more, with a larger ``lam``).
        TypeError
            v or f not arrays of real numbers.
        """
        from ._spline import smooth

        return cls("smoothed", tables=smooth(v, f, lam, V))

    @classmethod
    def from_csv(cls, path: Any, *, columns: Any = None, delimiter: str | None = None) -> PeelForce:
        """The tabulated law (:meth:`tabulated`) of a CSV file's peel-force curve(s).

        The header names the columns ``v`` and ``f``, or ``V``, ``v`` and ``f`` (one table per pull speed V, the
        rows of a V in file order; at most :data:`peelapprox.law._tablefile.MAX_TABLES` = 1000 tables), in any
        order, each optionally with its unit -- ``v [m/s]``, ``v [mm/s]``, ``f [N]``, ``f (kN)``, ...
        (:data:`peelapprox._csvread.UNITS`): converted to m/s and N; an unknown unit or
        one of another dimension is refused, named.  ``#`` starts a comment; blank lines are skipped.  The file
        must be a regular UTF-8 file of at most 16 MiB (a spreadsheet's byte-order mark is fine).

        Parameters
        ----------
        path : str or os.PathLike
            The file.
        columns : mapping or sequence of str, optional
            The header cells to read instead of ``v``, ``f`` (``V``): ``{"v": "speed", "f": "force [kN]"}`` or
            ``("speed", "force")``; other columns are then ignored.  A unit given here is the unit of a header
            cell that states none (the units are "stated").
        delimiter : str, optional
            The cell separator (default ``,``).

        Returns
        -------
        PeelForce
            A tabulated law (to smooth or fit the same points, read them with
            :func:`peelapprox.law._tablefile.read_points`, or use the CLI's ``--smooth`` and ``--force-fit``).

        Raises
        ------
        ValueError
            Naming the file and the line (and column): not a regular file, too large, empty, binary (not UTF-8),
            a wrong header, an unknown unit, a bad cell or row, or :meth:`tabulated`'s error with the file line
            of the point it names.
        TypeError
            ``path`` is not a path, ``columns`` of the wrong type.
        """
        from ._tablefile import from_csv

        return from_csv(cls, path, columns, delimiter)

    @classmethod
    def from_dict(cls, d: Mapping[str, Any]) -> PeelForce:
        """The law ``dataclasses.asdict(law)`` (or its JSON) describes; validated.

        A field nested deeper than :data:`~peelapprox.law._force_checks.MAX_NESTING` (lists in lists) is a
        TypeError naming it (a coefficient list nested 100,000 deep raised RecursionError)."""
        if not isinstance(d, Mapping):
            raise TypeError(f"d must be a mapping of the law's fields (dataclasses.asdict(law) or its JSON), got "
                            f"{type(d).__name__}")
        unknown = sorted(set(d) - {"kind", "name", "coefficients", "source", "tables", "display"})
        if unknown:
            raise ValueError(f"d has unknown field(s) {shown(', '.join(map(str, unknown)))}: a law's fields are kind, "
                             "name, coefficients, source, tables, display")
        for field, value in d.items():
            _check_nesting(f"d[{field!r}]", value)
        return cls(**dict(d))  # lists for tuples: __post_init__ makes them canonical

    # ------------------------------------------------------------------ value semantics
    def _key(self) -> tuple:
        return (self.kind, self.name, self.coefficients, self.source, self.tables)

    def __eq__(self, other: object) -> bool:
        return isinstance(other, PeelForce) and self._key() == other._key()

    def __hash__(self) -> int:
        h = self.__dict__.get("_hash")
        if h is None:
            h = hash(self._key())
            object.__setattr__(self, "_hash", h)
        return h

    def __reduce__(self):
        return (_restore, (self.kind, self.name, self.coefficients, self.source, self.tables, self.display))

    def __repr__(self) -> str:
        return self.impl.show(self)

    @property
    def impl(self) -> LawKind:
        """What this kind of law does (:mod:`peelapprox.law._kinds`)."""
        return KIND_IMPLS[self.kind]

    @property
    def key(self) -> str:
        """SHA-256 (hex) of the law's canonical content: of an expression's canonical text, else of its
        kind, family, coefficients (exact hex floats) and tables; the same in every process."""
        return hashlib.sha256(self.impl.key_text(self).encode()).hexdigest()

    @property
    def depends_on_V(self) -> bool:
        """True if f changes with the pull speed V."""
        return self.impl.depends_on_V(self)

    @property
    def inlined(self) -> bool:
        """True for the built-in fvV, which the compiled drivers inline (its coefficients in the model block)."""
        return self.impl.inlined

    @property
    def v_range(self) -> tuple[float, float]:
        """``(lo, hi)`` [m/s]: the peel velocities at which the law may be evaluated (the built-in law and the
        families: ``STATE_RANGES["v"]``, open at lo; an expression: [1e-6, 1e3]; a table: its range)."""
        return self.impl.v_range(self)

    # ------------------------------------------------------------------ evaluation
    def _evaluator(self) -> Any:
        """The kind's numpy evaluator of this law, built once (an expression's derivatives, a table's PCHIP)."""
        impl = self.__dict__.get("_evaluate_with")
        if impl is None:
            impl = self.impl.evaluator(self)
            object.__setattr__(self, "_evaluate_with", impl)
        return impl

    def f(self, v: Any, V: float) -> Any:
        """f(v, V) [N], vectorised over v (a float for a scalar v)."""
        return self.impl.evaluate(self, v, V, 0)

    __call__ = f

    def df(self, v: Any, V: float) -> Any:
        """∂f/∂v (v, V) [N s/m]."""
        return self.impl.evaluate(self, v, V, 1)

    def d2f(self, v: Any, V: float) -> Any:
        """∂²f/∂v² (v, V) [N s²/m²]."""
        return self.impl.evaluate(self, v, V, 2)

    def folds(self, V: float) -> BranchStructure:
        """The folds of ``f(·, V)`` (local maximum, then local minimum in v) and where jumps from them land.

        The built-in law's are :func:`peelapprox.branch_structure`'s.  Any other law's are found on its
        own: the sign changes of f' on a grid in ln v (:data:`FOLD_GRID_DENSITY` points per unit) over the
        fold window (a family: [1e-12, 1e3] m/s; an expression: [1e-6, 1e3]; a table: its range), each
        refined by Brent's method in ln v; the landings by Brent's method on the other branch, over the
        law's whole domain (:attr:`v_range`).  Cached per V.

        Returns
        -------
        BranchStructure
            The folds and landings (``v_inflection``, ``f_zero``, ``v_breakdown`` NaN:
            ``branch_structure(V, force=law)`` has every field); ``has_folds=False`` (every fold field None)
            when f' > 0 throughout: no stick-slip at this V.

        Raises
        ------
        ValueError
            If f' < 0 throughout (no stable slow branch), or the extrema are not exactly one maximum
            followed by one minimum (the message lists those found), or V is out of range; or a law made by
            :meth:`fit` from points without a significant N shape (``fit_result.folds_note`` says why).
        """
        refused = self.__dict__.get("_no_n_shape")
        if refused:
            raise ValueError(refused)
        cache = self.__dict__.get("_folds")
        if cache is None:
            cache = {}
            object.__setattr__(self, "_folds", cache)
        V = in_range("V", V, *PARAM_RANGES["V"])
        if V not in cache:
            if len(cache) >= 256:
                cache.clear()
            cache[V] = self.impl.folds(self, V)
        return cache[V]


def _restore(kind: str, name: str | None, coefficients: tuple, source: str | None, tables: tuple,
             display: str = "") -> PeelForce:
    """Unpickle a law (sent between this package's own processes) without validating it again (it was validated
    when first built); what ``repr`` shows is derived again, never taken from the data (``display`` is ignored)."""
    law = object.__new__(PeelForce)
    for field_name, value in (("kind", kind), ("name", name), ("coefficients", coefficients), ("source", source),
                              ("tables", tables)):
        object.__setattr__(law, field_name, value)
    object.__setattr__(law, "display", law.impl.display(law))
    return law


_PAPER_LAW = PeelForce("paper")


def law_label(force: Any) -> str:
    """The name by which a consumer lists the laws it honours: ``"paper"`` (the built-in fvV), a family's
    constructor (``"paper_family"``, ``"cubic"``, ``"power_branches"``), ``"expression"`` or ``"tabulated"``."""
    return force.impl.label(force)


def require_law(params: Any, where: str | None = None, laws: tuple[str, ...] = ALL_LAWS) -> None:
    """ValueError unless ``params.force`` (if any) is one of ``laws`` (:func:`law_label` names; default: every
    law): the one check, at each consumer that runs only some laws (the ε-variational Lyapunov method and the
    diffsol peer need a closed form; a driver with fvV inlined needs the paper's law).  ``where`` names the
    consumer (the public function that validated its ``params``; every caller in the package names itself;
    default ``"this function"``)."""
    force = getattr(params, "force", None)
    if force is None or force.inlined or law_label(force) in laws:
        return
    raise ValueError(f"params.force: {where or 'this function'} runs the laws {', '.join(repr(x) for x in laws)} "
                     f"only, not {shown_law(force)}")

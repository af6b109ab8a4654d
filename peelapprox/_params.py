"""Model parameters of the roller-tape peeling problem (paper Sec. II and IV)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

from ._checks import ArgumentTypeError, _got, choice, in_range, interval
from ._ranges import (
    GEOMETRIES,
    GRAVITY,
    L_OVER_R_MIN,
    LOAD_MASS_RANGE,
    LOAD_RANGE,
    LOADINGS,
    PARAM_RANGES,
    TAPE_MASS_RANGE,
    default_load_masses,
)
from .law import PeelForce

__all__ = ["PeelParams"]

_VARIANT_DEFAULTS = {"tape_mass": None, "loading": "velocity", "load_mass": None, "load": None}


@dataclass(frozen=True, repr=False)
class PeelParams:
    """Physical parameters of the peeling model (SI units).

    Parameters
    ----------
    V : float
        Pull speed of the motor at O' [m/s]; enters the peel force ``f(v, V)``
        (fvV) and the tape elongation rate (flow3).
    I : float
        Moment of inertia of the roller tape [kg m²] (FLOW2).
    k : float, default 1000
        Elastic constant of the tape [N/m] (flow3).
    R : float, default 0.1
        Roller radius [m] (FLOW1, FLOW2).
    l : float, default 1
        Distance O–O' between the roller axis and the motor [m]; must exceed
        ``R``.  Used only by ``geometry="exact"``.
    geometry : {"paper", "exact"}, default "paper"
        Closure of ``cos θ``: the paper's ``-sin α`` or the exact
        ``-l sin α / L(α)``.
    force : PeelForce, default ``PeelForce.paper()``
        The peel-force law f(v, V) (fvV by default).  A mapping (as
        ``dataclasses.asdict`` writes it) is turned back into a law.  Other
        laws than the paper's are refused, naming the law, by the functions
        that cannot run them (``validate.params``); the default leaves ``repr``,
        equality and ``hash`` as they were before the field existed.
    tape_mass : float or None, default None
        Mass m of the peeled ribbon [kg] (docs/tape-mass.md): the
        tape-mass model, LAGRAN plus the ribbon's kinetic energy, a smooth
        ODE whose jumps arise from the dynamics.  None or 0: the paper's
        massless model (the DAE).  Else in ``TAPE_MASS_RANGE`` = [1e-15, 10].
    loading : {"velocity", "load"}, default "velocity"
        ``"velocity"``: the end O' pulled at the constant speed V (the
        paper).  ``"load"``: a constant force ``load`` on a body of mass
        ``load_mass`` at O' (docs/constant-load.md): ``M V̇_p = F_L - F``,
        the pull speed ``V_p`` a state starting at V; the peel-force law is
        still evaluated at the fixed speed V.
    load_mass : float or None
        M [kg], required with ``loading="load"`` (in ``LOAD_MASS_RANGE`` =
        [1e-6, 1e6]), refused otherwise.
    load : float or None
        F_L [N] (``LOAD_RANGE`` = [1e-3, 1e7]); default ``load_mass *
        GRAVITY``: a hanging mass.  Only with ``loading="load"``.

    Raises
    ------
    TypeError
        (:class:`peelapprox.validate.ArgumentTypeError`, also a
        ValueError) If a field is not a real number (None, a string, a
        bool) or ``geometry`` is not a string.
    ValueError
        If a field is not finite, lies outside its range
        (:data:`PARAM_RANGES`), if ``l < 1.001 R``, or if ``geometry`` is
        unknown.  The message names the field and its valid range.

    Notes
    -----
    Valid ranges (:data:`PARAM_RANGES`; the paper's values are V = 0.05-8
    m/s, I = 1e-6-1e-1 kg m², k = 1000 N/m, R = 0.1 m).  Each bound keeps the
    numerics of every function in the package valid, with margin; beyond
    them the runs fail with ZeroDivisionError, OverflowError or bracket
    errors, or take unbounded time.  Measured with ``estimate``,
    ``reduced_segment`` and a 0.2 s ``exact.simulate(..., save="jumps")``
    in both geometries, around V = 2, I = 1e-4:

    * ``V`` in [1e-6, 100] m/s.  The law fvV is fitted to the paper's
      V <= 10; its ``f(0+, V) = 130 - 2 V^1.5`` is negative above 16 m/s.
      Numerically, the fixed point ``f(V, V) ~ 130 e^(V/11)`` overflows at
      V ~ 7800, and the solvers' root bracket (v <= 300 m/s) fails already
      at V = 300 (exact.simulate: "f(a) and f(b) must have different
      signs"); V = 100 and 200 work.  Below 1e-6 m/s nothing fails (V =
      1e-300 ends in a documented breakdown) but the stick phase lasts
      ``(f_max - f_min)/(k V)`` > 1e5 s: not a pull speed.
    * ``I`` in [1e-12, 1e6] kg m².  The inertial period ``2π sqrt(I/(F R))``
      is 1.2e-6 s at I = 1e-12 (a 0.2 s run: 2 s of wall time); at 1e-15 it
      does not finish in 20 s.  1e6 kg m² (a 10 t flywheel) is used by the
      tests as the inertia-free limit; 1e9 also works.
    * ``k`` in [1e-3, 1e7] N/m.  The stiff time ``sqrt(I/(k R²))`` sets the
      step: 0.2 s take 1.1 s at k = 1e7, 16 s at 1e8, over 20 s at 1e9;
      ``k = 1e300`` divides by zero (the default absolute tolerances).  Down to
      k = 1e-6 every run returns (the reduced segment then exhausts its step
      budget, a documented SolverBudgetExceeded).
    * ``R`` in [1e-4, 10] m.  ``V/R`` and ``F R/I`` set the fast scales:
      R = 1e-4 takes 0.3 s, 1e-5 5 s, 1e-6 over 20 s; ``R = 1e-300`` divides
      by zero.  R = 100 (with l = 1000) still works; 10 m is a generous roller.
    * ``l`` in [1.001 R, 1e3] m (``l`` is read only by ``geometry="exact"``).
      At ``l = R (1 + 1e-12)`` the closure is NaN at α = 0 and at
      ``R (1 + 1e-6)`` a 0.2 s run does not finish in 20 s; from 1.001 R
      (closure slope ``l/(l - R)`` <= 1001) runs are ordinary.  l = 1e6 works;
      beyond 1 km the exact geometry is the paper's to 1e-4.

    Examples
    --------
    >>> p = PeelParams(V=1.0, I=1e-5)
    >>> p.k, p.R, p.l
    (1000.0, 0.1, 1.0)
    """

    V: float
    I: float
    k: float = 1000.0
    R: float = 0.1
    l: float = 1.0
    geometry: str = field(default="paper")
    force: PeelForce = field(default=PeelForce.paper())
    tape_mass: float | None = None
    loading: str = "velocity"
    load_mass: float | None = None
    load: float | None = None

    def __post_init__(self) -> None:
        for name, (lo, hi) in PARAM_RANGES.items():
            object.__setattr__(self, name, in_range(name, getattr(self, name), lo, hi))
        if self.l < L_OVER_R_MIN * self.R:
            raise ValueError(
                f"l must be greater than R: l must be finite and in [{L_OVER_R_MIN} R, {PARAM_RANGES['l'][1]:g}] = "
                f"[{L_OVER_R_MIN * self.R:g}, {PARAM_RANGES['l'][1]:g}], got l={self.l!r} with R={self.R!r}"
            )
        object.__setattr__(self, "geometry", choice("geometry", self.geometry, GEOMETRIES))
        if isinstance(self.force, Mapping):  # as dataclasses.asdict (a saved trajectory's JSON) wrote it
            object.__setattr__(self, "force", PeelForce.from_dict(self.force))
        if not isinstance(self.force, PeelForce):
            raise ArgumentTypeError(f"force must be a PeelForce (e.g. PeelForce.paper()), got {_got(self.force)}")
        self._check_variant()

    def _check_variant(self) -> None:
        """Validate and normalise the variant fields (tape mass, load): ``tape_mass`` 0 -> None, the default load."""
        if self.tape_mass is not None:
            m = self.tape_mass
            if not isinstance(m, bool) and isinstance(m, (int, float)) and m == 0:
                object.__setattr__(self, "tape_mass", None)
            else:
                object.__setattr__(self, "tape_mass", in_range("tape_mass", m, *TAPE_MASS_RANGE))
        object.__setattr__(self, "loading", choice("loading", self.loading, LOADINGS))
        if self.loading == "velocity":
            for name in ("load_mass", "load"):
                if getattr(self, name) is not None:
                    raise ValueError(f"{name} is used only with loading='load' (a constant load); got {name}="
                                     f"{getattr(self, name)!r} with loading='velocity'")
            return
        if self.load_mass is None:
            raise ValueError(f"load_mass is required with loading='load': the mass M [kg] at the pulled end, in "
                             f"[{LOAD_MASS_RANGE[0]:g}, {LOAD_MASS_RANGE[1]:g}]")
        object.__setattr__(self, "load_mass", in_range("load_mass", self.load_mass, *LOAD_MASS_RANGE))
        if self.load is not None:
            object.__setattr__(self, "load", in_range("load", self.load, *LOAD_RANGE))
            return
        load = self.load_mass * GRAVITY  # the default: a hanging mass
        lo, hi = LOAD_RANGE
        if not lo <= load <= hi:
            raise ValueError(
                f"load was not given, so its default load_mass * g = {self.load_mass!r} kg * {GRAVITY} m/s^2 = "
                f"{load:.6g} N was used, outside LOAD_RANGE = {interval(lo, hi)} N: give load, or a load_mass in "
                f"{interval(*default_load_masses())} kg")
        object.__setattr__(self, "load", load)

    @property
    def variant(self) -> str | None:
        """The model variant's field name (``peelapprox.kernels.variant_field``): None for the paper's
        massless model under velocity control, ``"tape"``, ``"tape_load"`` or ``"eps_load"``."""
        if self.loading == "load":
            return "tape_load" if self.tape_mass else "eps_load"
        return "tape" if self.tape_mass else None

    def _fields(self) -> tuple:
        """The fields as before ``force`` existed, then ``force`` if it is not the paper's law, then the variant
        fields that are not at their defaults (so the default's ``repr`` and ``hash`` are as before)."""
        base = (self.V, self.I, self.k, self.R, self.l, self.geometry)
        return base if self.force == PeelForce.paper() else base + (self.force,)

    def _variant_items(self) -> tuple:
        return tuple((n, getattr(self, n)) for n in ("tape_mass", "loading", "load_mass", "load")
                     if getattr(self, n) != _VARIANT_DEFAULTS[n])

    def __hash__(self) -> int:
        return hash(self._fields() + self._variant_items())

    def __repr__(self) -> str:
        names = ("V", "I", "k", "R", "l", "geometry", "force")
        items = [f"{n}={x!r}" for n, x in zip(names, self._fields())]
        items += [f"{n}={x!r}" for n, x in self._variant_items()]
        return f"PeelParams({', '.join(items)})"

    def closure(self, alpha):
        """``(c, dc/dα)`` with ``c = -cos θ`` for this geometry; scalar or array ``alpha``."""
        from . import _generated

        fun = _generated.closure_paper if self.geometry == "paper" else _generated.closure_exact
        return fun(alpha, self.R, self.l)

    def replace(self, **changes) -> PeelParams:
        """Return a copy with some fields changed (validated again)."""
        import dataclasses

        return dataclasses.replace(self, **changes)

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
        Pull speed of the motor at O' [m/s]: the peel force ``f(v, V)`` (fvV) and the tape's elongation (flow3).
    I : float
        Moment of inertia of the roller tape [kg m²] (FLOW2).
    k, R : float, default 1000, 0.1
        Elastic constant of the tape [N/m] (flow3); roller radius [m] (FLOW1, FLOW2).
    l : float, default 1
        Distance O–O' from the roller axis to the motor [m], at least ``1.001 R``; read by ``geometry="exact"``.
    geometry : {"paper", "exact"}, default "paper"
        Closure of ``cos θ``: the paper's ``-sin α`` or the exact ``-l sin α / L(α)``.
    force : PeelForce, default ``PeelForce.paper()``
        The peel-force law f(v, V); a mapping (``dataclasses.asdict``'s) is turned back into a law.
    tape_mass : float or None, default None
        Mass m of the peeled ribbon [kg], in ``TAPE_MASS_RANGE``: the tape-mass model, a smooth ODE whose jumps
        arise from the dynamics (docs/tape-mass.md).  None or 0: the paper's massless DAE.
    loading : {"velocity", "load"}, default "velocity"
        The end O' pulled at the constant speed V (the paper), or by a constant force ``load`` on a body of mass
        ``load_mass``: ``M V̇_p = F_L - F``, the pull speed a state starting at V (docs/constant-load.md).
    load_mass, load : float or None
        M [kg] (``LOAD_MASS_RANGE``), required with ``loading="load"`` and refused otherwise; F_L [N]
        (``LOAD_RANGE``), default ``load_mass * GRAVITY``, a hanging mass.

    Raises
    ------
    TypeError
        (:class:`~peelapprox.validate.ArgumentTypeError`, also a ValueError) A field of the wrong kind.
    ValueError
        A field not finite or outside its range (:data:`PARAM_RANGES`, where the bounds are explained), or
        ``l < 1.001 R``; the message names the field and its range.

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
        from ._compiled import _generated

        fun = _generated.closure_paper if self.geometry == "paper" else _generated.closure_exact
        return fun(alpha, self.R, self.l)

    def replace(self, **changes) -> PeelParams:
        """Return a copy with some fields changed (validated again)."""
        import dataclasses

        return dataclasses.replace(self, **changes)

"""Model parameters of the roller-tape peeling problem (paper Sec. II and IV)."""

from __future__ import annotations

from dataclasses import dataclass, field

from ._validate import positive

__all__ = ["PeelParams", "GEOMETRIES"]

#: Closures of ``cos θ`` available to the model.  ``"paper"`` is the paper's
#: numerics, ``cos θ = -sin α`` (used in FLOW2, flow3 and CONSTR);  ``"exact"``
#: is the full geometry ``cos θ = -l sin α / L``, ``L² = l² + R² - 2 l R cos α``.
GEOMETRIES = ("paper", "exact")



@dataclass(frozen=True)
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

    Raises
    ------
    ValueError
        If a field is not finite and positive, if ``l <= R``, or if
        ``geometry`` is unknown.  The message names the field and its valid
        range.

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

    def __post_init__(self) -> None:
        for name in ("V", "I", "k", "R", "l"):
            object.__setattr__(self, name, positive(name, getattr(self, name)))
        if self.l <= self.R:
            raise ValueError(
                f"l must be greater than R (valid range: l in (R, inf) = ({self.R}, inf)), got l={self.l}"
            )
        if self.geometry not in GEOMETRIES:
            raise ValueError(f"geometry must be one of {GEOMETRIES}, got {self.geometry!r}")

    def closure(self, alpha):
        """``(c, dc/dα)`` with ``c = -cos θ`` for this geometry; scalar or array ``alpha``."""
        from . import _generated

        fun = _generated.closure_paper if self.geometry == "paper" else _generated.closure_exact
        return fun(alpha, self.R, self.l)

    def replace(self, **changes) -> "PeelParams":
        """Return a copy with some fields changed (validated again)."""
        import dataclasses

        return dataclasses.replace(self, **changes)

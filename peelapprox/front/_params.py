"""Parameters of the peel front: N strips across the tape's width sharing the roller (docs/peel-front.md)."""

from __future__ import annotations

from dataclasses import dataclass

from .._checks import ArgumentTypeError, _got, choice, in_range, integer
from .._params import PeelParams
from ..law import PeelForce  # noqa: F401 - the type of PeelParams.force, named in the docstrings

__all__ = ["FrontParams", "FRONT_N_RANGE", "FRONT_ENDS", "FRONT_GAMMA_RANGE", "FRONT_KAPPA_RANGE",
           "FRONT_DELTA0_RANGE"]

#: Numbers of strips N: 1 (the tape-mass model itself) to 1e5 (a state of 2e5 numbers; the cost per step is O(N)).
FRONT_N_RANGE = (1, 100_000)
#: The ends of the front: "free" (no bond beyond the edges, the tape's real edges) or "periodic" (a ring).
FRONT_ENDS = ("free", "periodic")
#: γ = 4NΓ/|f'_u|, the AE dissipation against the steepest unstable slope of f (0: no AE, no damping).
FRONT_GAMMA_RANGE = (0.0, 1e6)
#: κ = 4N k_c/k, the front's bond stiffness against the tape's (0: independent strips but for the roller).
FRONT_KAPPA_RANGE = (0.0, 1e6)
#: δ₀, the relative spread of the initial local stretches (0: a uniform front, the tape-mass model exactly).
FRONT_DELTA0_RANGE = (0.0, 0.5)


@dataclass(frozen=True, kw_only=True)
class FrontParams:
    """The peel front as a line of N strips (a reconstruction of De & Ananthakrishna, PRL 97, 165503 (2006)).

    The tape's width is split into N strips.  They share the roller (the angle α and its rate ω, FLOW1 and
    FLOW2 with the mean peel force) and each has its own stretch u_j and local peel velocity v_j; neighbours are
    coupled by a bond spring ``k_c`` and a bond dissipation ``Γ`` of the local strain rate, whose dissipated
    power ``R_AE = Γ Σ (v_{j+1} - v_j)²`` is the model's acoustic emission.  The mean of the strips obeys the
    tape-mass model's equations (docs/tape-mass.md) with ``f -> f̄``; N = 1 *is* the tape-mass model.
    Equations, energy balance and the transverse stability relation: docs/peel-front.md.

    Parameters
    ----------
    base : PeelParams
        The point model: V, I, k, R, l, geometry, the peel-force law ``force`` (which must have folds) and the
        tape mass ``tape_mass`` m [kg] (required: the strips' inertia; the whole ribbon's mass, split equally).
        Velocity control only (``loading="velocity"``).
    N : int
        Number of strips, in ``FRONT_N_RANGE`` = [1, 100000].
    gamma : float, optional
        Dimensionless AE dissipation ``γ = 4NΓ/|f'_u|`` with ``|f'_u| = -f'(v_infl, V)``, the steepest slope of
        f's unstable branch: transverse modes of wavenumber q grow on the unstable branch iff ``γ sin²(q/2) <
        |f'|/|f'_u|``, so ``γ < 1`` lets the shortest waves grow there (docs/peel-front.md, "Transverse
        modes").  In ``FRONT_GAMMA_RANGE`` = [0, 1e6]; default 1.  Give ``gamma`` or ``Gamma``, not both.
    Gamma : float, optional
        The same as a per-bond coefficient Γ [N s/m] (``gamma = 4 N Gamma / |f'_u|``), ≥ 0.
    kappa : float, optional
        Dimensionless bond stiffness ``κ = 4 N k_c / k``, in ``FRONT_KAPPA_RANGE`` = [0, 1e6]; default 1.
        Give ``kappa`` or ``k_c``, not both.
    k_c : float, optional
        The same as a per-bond spring constant [N/m], ≥ 0.
    ends : {"free", "periodic"}
        The front's ends: the tape's free edges (default) or a ring.
    delta0 : float
        Initial heterogeneity: the local stretches start at ``u (1 + δ₀ ξ_j)`` with ξ_j uniform in [-1, 1],
        shifted to mean zero (the mean state is the tape-mass model's start), in ``FRONT_DELTA0_RANGE`` =
        [0, 0.5]; default 0, a uniform front.
    seed : int
        Seed of ξ (``numpy.random.default_rng``), in [0, 2**63 - 1]; default 0.

    Raises
    ------
    TypeError
        A field of the wrong kind (``base`` not a PeelParams, N not an integer).
    ValueError
        A field out of its range, named with the range; a base without a tape mass, under a load, or whose law
        has no folds (no unstable branch: no stick-slip, no γ).

    Examples
    --------
    >>> from peelapprox import PeelParams
    >>> fp = FrontParams(base=PeelParams(V=1.0, I=1e-5, tape_mass=1e-3), N=16, gamma=0.1)
    >>> round(fp.f_slope_unstable, 3), round(fp.Gamma, 6)
    (18.287, 0.028574)
    """

    base: PeelParams
    N: int
    gamma: float | None = None
    Gamma: float | None = None
    kappa: float | None = None
    k_c: float | None = None
    ends: str = "free"
    delta0: float = 0.0
    seed: int = 0

    def __post_init__(self) -> None:
        if not isinstance(self.base, PeelParams):
            raise ArgumentTypeError(f"base must be a PeelParams (with tape_mass set), got {_got(self.base)}")
        if self.base.tape_mass is None:
            raise ValueError("base.tape_mass must be set: the front's strips need the ribbon's mass m [kg] (in "
                             "TAPE_MASS_RANGE = [1e-15, 10]); got base.tape_mass=None (the massless model)")
        if self.base.loading != "velocity":
            raise ValueError(f"base.loading must be 'velocity' (the front is built under velocity control), got "
                             f"{self.base.loading!r}")
        object.__setattr__(self, "N", integer("N", self.N, *FRONT_N_RANGE))
        object.__setattr__(self, "ends", choice("ends", self.ends, FRONT_ENDS))
        object.__setattr__(self, "delta0", in_range("delta0", self.delta0, *FRONT_DELTA0_RANGE))
        object.__setattr__(self, "seed", integer("seed", self.seed, 0, 2**63 - 1))
        slope = self.f_slope_unstable  # raises for a law without folds
        scale = 4.0 * self.N / slope  # gamma = scale * Gamma
        self._pair("gamma", "Gamma", 1.0, scale, FRONT_GAMMA_RANGE)
        self._pair("kappa", "k_c", 1.0, 4.0 * self.N / self.base.k, FRONT_KAPPA_RANGE)

    def _pair(self, dimless: str, bond: str, default: float, scale: float, rng: tuple[float, float]) -> None:
        """Fill the dimensionless field and its per-bond twin (``dimless = scale * bond``) from the one given."""
        a, b = getattr(self, dimless), getattr(self, bond)
        if a is not None and b is not None:
            raise ValueError(f"give {dimless} or {bond}, not both (got {dimless}={a!r}, {bond}={b!r})")
        if b is not None:
            b = in_range(bond, b, rng[0] / scale, rng[1] / scale)
            a = b * scale
        else:
            a = in_range(dimless, default if a is None else a, *rng)
        object.__setattr__(self, dimless, float(a))
        object.__setattr__(self, bond, float(a) / scale)

    @property
    def m(self) -> float:
        """The ribbon's mass m [kg] (``base.tape_mass``), m/N per strip."""
        return float(self.base.tape_mass)  # type: ignore[arg-type]

    @property
    def f_slope_unstable(self) -> float:
        """``|f'_u| = -f'(v_infl, V)`` [N s/m]: the steepest slope of the law's unstable branch, the scale of γ."""
        from ..law import branch_structure

        bs = branch_structure(self.base.V, force=self.base.force)
        if not bs.has_folds:
            raise ValueError(f"base.force must have folds (a decreasing, unstable branch between v_max and v_min): "
                             f"{self.base.force!r} at V={self.base.V!r} has none, so there is no stick-slip and no "
                             "transverse instability to scale gamma by")
        fp = float(self.base.force.df(bs.v_inflection, self.base.V))
        if not fp < 0.0:
            raise ValueError(f"base.force has f'(v_infl) = {fp!r} >= 0 at V={self.base.V!r}: no unstable branch")
        return -fp

    def as_dict(self) -> dict:
        """The front's own fields (the base as its ``repr``), for tables and files."""
        return {"base": repr(self.base), "N": self.N, "gamma": self.gamma, "Gamma": self.Gamma, "kappa": self.kappa,
                "k_c": self.k_c, "ends": self.ends, "delta0": self.delta0, "seed": self.seed}

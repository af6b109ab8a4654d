"""The records of a fit to measured points (:meth:`peelapprox.PeelForce.fit`): :class:`FitResult` and the folds
with their uncertainties, :class:`FoldEstimate`.  How each figure is measured (the covariance with or without
``sigma``, the identification, the delta method of the folds) is the module docstring of
``peelapprox/law/_fit.py``, which fills them in."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["FitResult", "FoldEstimate"]


@dataclass(frozen=True, eq=False)
class FoldEstimate:
    """The folds of a fitted law at V with their uncertainties (delta method: module docstring).

    Attributes
    ----------
    V : float
        The pull speed [m/s] of the folds.
    values : dict
        ``v_max`` [m/s], ``f_max`` [N], ``v_min`` [m/s], ``f_min`` [N].
    stderr : dict
        Their standard errors, same keys.
    covariance : numpy.ndarray
        4x4, in the order v_max, f_max, v_min, f_min.
    inside_data : bool
        True if both folds lie within the range of the fitted v (else they are extrapolated by the law).
    """

    V: float
    values: dict[str, float]
    stderr: dict[str, float]
    covariance: np.ndarray
    inside_data: bool


@dataclass(frozen=True, eq=False)
class FitResult:
    """What :meth:`peelapprox.PeelForce.fit` measured, attached to the fitted law as ``law.fit_result``.

    Attributes
    ----------
    model : str
        ``"family <name>"`` or ``"expression <text>"``.
    names : tuple of str
        The fitted coefficients, in the order of :attr:`covariance`.
    coefficients : dict
        Every coefficient of the law by name, the fitted ones at their estimates (fixed ones included).
    stderr : dict
        The standard error of each fitted coefficient.
    covariance : numpy.ndarray
        Their covariance, ``len(names)`` square (module docstring: with or without ``sigma``).
    fixed : tuple of str
        The coefficients held at a value (``bounds={name: (x, x)}``, or a family's not fitted).
    residuals : numpy.ndarray
        ``f(v_i) - f_i`` [N] at the solution (unweighted).
    chi2 : float
        ``sum(((f(v_i) - f_i) / sigma_i)^2)`` (sigma 1 without ``sigma``).
    dof : int
        Points minus fitted coefficients (at least 1).
    chi2_dof : float
        ``chi2 / dof``: with ``sigma``, ~1 for a law that describes the data; without, the residual variance [N^2].
    absolute_sigma : bool
        True if ``sigma`` was given (the covariance is not rescaled).
    folds : FoldEstimate or None
        The folds at V with their uncertainties; None if the fitted law has no folds there (see ``folds_note``).
    folds_note : str
        Why ``folds`` is None, else empty.
    success : bool
        least_squares converged (a tolerance was met).
    message : str
        least_squares' message.
    nfev : int
        Evaluations of the residuals.
    """

    model: str
    names: tuple[str, ...]
    coefficients: dict[str, float]
    stderr: dict[str, float]
    covariance: np.ndarray
    fixed: tuple[str, ...]
    residuals: np.ndarray
    chi2: float
    dof: int
    chi2_dof: float
    absolute_sigma: bool
    folds: FoldEstimate | None
    folds_note: str = ""
    success: bool = True
    message: str = ""
    nfev: int = 0
    correlation: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))

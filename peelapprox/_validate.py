"""Small named validators shared by the public functions (clear ``ValueError`` messages)."""

from __future__ import annotations

import math
from typing import Optional

__all__ = ["finite", "positive", "nonnegative", "optional_finite"]


def finite(name: str, x) -> float:
    """``float(x)``, or ValueError naming ``name`` if x is not a finite real number."""
    try:
        y = float(x)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a finite real number, got {x!r}") from None
    if not math.isfinite(y):
        raise ValueError(f"{name} must be finite, got {x!r}")
    return y


def positive(name: str, x) -> float:
    """``float(x)`` if it is a finite number in (0, inf), else ValueError naming ``name`` and the range."""
    try:
        y = float(x)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a real number in (0, inf), got {x!r}") from None
    if not (math.isfinite(y) and y > 0.0):
        raise ValueError(f"{name} must be finite and in (0, inf), got {x!r}")
    return y


def nonnegative(name: str, x) -> float:
    """``float(x)`` if it is a finite number in [0, inf), else ValueError naming ``name`` and the range."""
    try:
        y = float(x)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a real number in [0, inf), got {x!r}") from None
    if not (math.isfinite(y) and y >= 0.0):
        raise ValueError(f"{name} must be finite and in [0, inf), got {x!r}")
    return y


def optional_finite(name: str, x) -> Optional[float]:
    """None stays None; anything else goes through :func:`finite`."""
    return None if x is None else finite(name, x)

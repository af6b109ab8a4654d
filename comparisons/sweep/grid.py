"""Grid axes of a sweep from the command line's ``start:stop:num[:log]`` or comma-list specs."""

from __future__ import annotations

import numpy as np

__all__ = ["parse_grid"]


def parse_grid(spec: str, *, name: str = "values") -> np.ndarray:
    """Grid values from ``"start:stop:num"`` (linspace), ``"start:stop:num:log"`` (geometric, exact endpoints)
    or a comma list ``"0.4,1,2"``.

    Raises ValueError naming ``name`` on a malformed spec.
    """
    s = str(spec).strip()
    try:
        if ":" in s:
            parts = s.split(":")
            if len(parts) not in (3, 4) or (len(parts) == 4 and parts[3] not in ("log", "lin")):
                raise ValueError("expected start:stop:num or start:stop:num:log")
            a, b = float(parts[0]), float(parts[1])
            n = int(parts[2])
            if n < 1:
                raise ValueError(f"num must be >= 1, got {n}")
            if len(parts) == 4 and parts[3] == "log":
                if not (a > 0 and b > 0):
                    raise ValueError("a log range needs start > 0 and stop > 0")
                return np.geomspace(a, b, n)
            return np.linspace(a, b, n)
        vals = [float(x) for x in s.split(",") if x.strip()]
        if not vals:
            raise ValueError("empty list")
        return np.asarray(vals)
    except ValueError as exc:
        raise ValueError(f"{name}: cannot parse {spec!r} ({exc}); use start:stop:num[:log] or a comma list") \
            from None

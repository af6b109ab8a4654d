"""The peel-force law of a sweep: one law at every point, or a family coefficient as a third axis.

A sweep runs the law ``force`` (a :class:`peelapprox.PeelForce`; default the paper's fvV) at every point.  With
``coef=(name, values)`` the coefficient ``name`` of a family law (``PeelForce.family``, e.g. ``c`` of
``PeelForce.cubic()``) is a third grid axis: the point ``(I, V, c)`` runs ``force`` with that coefficient set to
``c`` (a family is compiled once: a coefficient is data, nothing recompiles from point to point).  Use one
value of I or V to sweep the coefficient instead of it.

What travels and what is recorded:

* to the workers: the law itself, pickled as its plain data (:class:`PeelForce` pickles as strings and tuples of
  floats), and the coefficient value of the point;
* in the manifest (``sweep.json``), for a law other than the paper's: ``force`` (``dataclasses.asdict(law)``,
  which :meth:`PeelForce.from_dict` rebuilds), ``law`` (its ``repr``) and ``law_key`` (:attr:`PeelForce.key`);
  with a coefficient axis, ``coef`` = ``{"name": ..., "values": [...]}``;
* in every record of such a sweep: ``law`` and ``law_key`` of the point's own law, and ``coef`` (the point's
  coefficient value) with a coefficient axis.

A sweep of the paper's law without a coefficient axis writes none of these: its files are those of before.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from typing import Any

from peelapprox import PeelForce
from peelapprox.validate import ArgumentTypeError, reals

__all__ = ["LAW_KEYS", "check_coef", "check_force", "describe", "law_fields", "manifest_fields", "manifest_law",
           "point_law"]

#: Record keys the engine writes for a law sweep (besides :data:`comparisons.sweep.RESERVED`).
LAW_KEYS = ("coef", "law", "law_key")


def check_force(force: Any) -> PeelForce:
    """``force`` as the sweep's law: a :class:`peelapprox.PeelForce` (None: the paper's); TypeError otherwise."""
    if force is None:
        return PeelForce.paper()
    if not isinstance(force, PeelForce):
        raise ArgumentTypeError(f"force must be a peelapprox.PeelForce (or None: the paper's law), got "
                                f"{type(force).__name__}: {force!r}")
    return force


def check_coef(force: PeelForce, coef: Any) -> tuple[str, list[float]] | None:
    """The coefficient axis ``(name, values)`` checked against the family law ``force``: ``name`` one of its
    coefficients, ``values`` finite, non-empty, no repeats, and each a valid law (a scale must stay > 0).

    Raises
    ------
    ValueError
        Naming ``coef``: ``force`` is not a family law, an unknown coefficient (the valid ones listed), a repeated
        or non-finite value, or a value the family refuses (the value and the family's message).
    """
    if coef is None:
        return None
    if not (isinstance(coef, (tuple, list)) and len(coef) == 2 and isinstance(coef[0], str)):
        raise ArgumentTypeError(f"coef must be a pair (name, values), e.g. ('c', [250, 300, 350]), got {coef!r}")
    name, values = coef
    if force.kind != "family":
        raise ValueError(f"coef: a coefficient axis sweeps a coefficient of a family law (PeelForce.family, "
                         f"PeelForce.cubic, ...); force is {force!r}")
    names = [n for n, _ in force.coefficients]
    if name not in names:
        raise ValueError(f"coef: {name!r} is not a coefficient of {force!r}; its coefficients are {', '.join(names)}")
    vals = [float(x) for x in reals(f"coef: the values of {name!r}", values).ravel()]
    if len(set(vals)) != len(vals):
        raise ValueError(f"coef: the values of {name!r} must not repeat, got {vals}")
    for x in vals:
        try:
            point_law(force, name, x)
        except (TypeError, ValueError) as exc:
            raise ValueError(f"coef: {name}={x!r} is not a valid coefficient of {force!r}: {exc}") from None
    return name, vals


def point_law(force: PeelForce, name: str | None, value: float | None) -> PeelForce:
    """The law of one point: ``force`` itself, or with its coefficient ``name`` set to ``value``."""
    if name is None:
        return force
    coefs = dict(force.coefficients)
    coefs[name] = value
    return PeelForce.family(str(force.name), **coefs)


def law_fields(law: PeelForce) -> dict[str, str]:
    """``{"law": repr(law), "law_key": law.key}``: what a record says of its law."""
    return {"law": repr(law), "law_key": law.key}


def manifest_fields(force: PeelForce, coef: tuple[str, list[float]] | None) -> dict[str, Any]:
    """The manifest's law entries (module docstring); empty for the paper's law without a coefficient axis."""
    out: dict[str, Any] = {}
    if force.kind != "paper":
        out.update(force=dataclasses.asdict(force), **law_fields(force))
    if coef is not None:
        out["coef"] = {"name": coef[0], "values": list(coef[1])}
    return out


def manifest_law(m: dict) -> tuple[PeelForce, tuple[str, list[float]] | None]:
    """``(force, coef)`` of a manifest (absent entries: the paper's law, no coefficient axis).

    Raises ValueError (the reason, for the caller to name the file) when an entry is malformed or its law is
    invalid."""
    spec = m.get("force")
    if spec is None:
        force = PeelForce.paper()
    else:
        if not isinstance(spec, dict):
            raise ValueError(f"force must be a JSON object (dataclasses.asdict of a PeelForce), got {spec!r:.60}")
        try:
            force = PeelForce.from_dict(spec)
        except (TypeError, ValueError) as exc:
            raise ValueError(f"force does not describe a valid law: {exc}") from None
        if m.get("law_key") not in (None, force.key):
            raise ValueError(f"law_key {m.get('law_key')!r} is not the key of the law in force ({force.key})")
    c = m.get("coef")
    if c is None:
        return force, None
    if not isinstance(c, dict) or set(c) != {"name", "values"} or not isinstance(c["values"], list):
        raise ValueError(f"coef must be a JSON object {{'name': ..., 'values': [...]}}, got {c!r:.60}")
    return force, check_coef(force, (c["name"], c["values"]))


def describe(coef: tuple[str, Sequence[float]] | None) -> str:
    """``"c=[250.0, 300.0]"`` or ``"none"`` (for messages)."""
    return "none" if coef is None else f"{coef[0]}={list(coef[1])}"

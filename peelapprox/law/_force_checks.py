"""The checks of a law's fields, before any kind uses them (:class:`peelapprox.law._force.PeelForce`): their types
(``__post_init__``) and how deep a mapping's fields nest (:meth:`PeelForce.from_dict`)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from .._checks import shown

#: The deepest nesting of lists (or tuples, mappings) in a field of :meth:`PeelForce.from_dict`'s mapping: a law's
#: fields nest at most 3 deep (tables: a list of (V, v, f) triples of lists).
MAX_NESTING = 8


def _check_field_types(force: Any) -> None:
    """TypeError naming the field whose type is wrong (a list as a family's name, coefficients as a flat list),
    before any kind uses it; coefficients given as a mapping or as JSON's ``[name, value]`` lists become pairs."""
    for field in ("kind", "name", "source"):
        value = getattr(force, field)
        if not (isinstance(value, str) or (value is None and field != "kind")):
            raise TypeError(f"{field} must be a string{'' if field == 'kind' else ' or None'}, got "
                            f"{type(value).__name__} {shown(value)}")
    coefs = force.coefficients
    if isinstance(coefs, Mapping):
        coefs = tuple(coefs.items())
    if (isinstance(coefs, (str, bytes)) or not isinstance(coefs, (tuple, list))
            or not all(isinstance(p, (tuple, list)) and len(p) == 2 and isinstance(p[0], str) for p in coefs)):
        raise TypeError(f"coefficients must be (name, value) pairs or a mapping of name to value, got "
                        f"{shown(force.coefficients)}")
    object.__setattr__(force, "coefficients", tuple(tuple(p) for p in coefs))


def _check_nesting(name: str, value: Any) -> None:
    """TypeError if ``value`` nests lists, tuples or mappings deeper than :data:`MAX_NESTING` (an iterative walk:
    no recursion to exhaust)."""
    stack = [(value, 0)]
    while stack:
        x, depth = stack.pop()
        if isinstance(x, Mapping):
            children: Any = x.values()
        elif isinstance(x, (list, tuple)):
            children = x
        else:
            continue
        if depth >= MAX_NESTING:
            raise TypeError(f"{name} is nested more than MAX_NESTING = {MAX_NESTING} deep (lists in lists): a law's "
                            "fields nest at most 3 deep (tables: a list of (V, v, f) triples of lists)")
        stack.extend((c, depth + 1) for c in children)

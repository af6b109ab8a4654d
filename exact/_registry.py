"""The registry of models, :data:`MODELS` (name -> model) and :func:`model_of`, apart from the base class
(:mod:`exact._model`, which re-exports both typed): a model's start imports the trajectory module, which asks the
registry which fields of the parameters its model reads, so the registry imports nothing of ``exact``."""

from __future__ import annotations

from typing import Any

__all__ = ["MODELS", "model_of"]

#: The models of :func:`exact.simulate` by name (instances of :class:`exact.Model`, entered by
#: :func:`exact.register_model`), in the order :func:`model_of` tries them.
MODELS: dict[str, Any] = {}


def model_of(params: Any) -> Any:
    """The model ``params`` describe: the first of :data:`MODELS` that accepts them."""
    return next(m for m in MODELS.values() if m.accepts(params))

"""One grid point of a sweep, as it runs in a worker, and how the measures reach the workers.

:func:`run_point` evaluates the measures at one (I, V) and returns its record; it never raises for a
measure's failure (the point's status says it).  Under the sweep's wall-clock budget (a deadline, a
``time.time()``) the measures get what is left of it as the option ``max_wall`` [s]; a point that begins after
the deadline, or whose measure the deadline cut (``SolverBudgetExceeded``, ``budget="max_wall"``, once the
deadline has passed), returns the status :data:`NOT_RUN`, which the engine does not record: the point is
computed when the sweep is resumed.  Workers get each measure by its import reference
``module:qualname``, or by value (cloudpickle bytes) if they could not import it (:func:`worker_refs`).
"""

from __future__ import annotations

import dataclasses
import importlib
import time
from collections.abc import Callable, Mapping, Sequence
from types import MappingProxyType, ModuleType
from typing import Any, cast

from exact import MODELS
from peelapprox import PeelForce, PeelParams, SolverBudgetExceeded
from peelapprox.io import jsonable

from .._worker import error_text
from .law import LAW_KEYS, law_fields, point_law
from .measures import MEASURES, Measure, measure_ref, record_key
from .store import RESERVED

__all__ = ["NOT_RUN", "PARAM_OPTIONS", "import_ref", "run_point", "make_params", "worker_refs"]

#: The status of a point the sweep's wall-clock budget left out or cut (module docstring): never recorded.
NOT_RUN = "not run: max_wall"

#: Options the engine turns into :class:`peelapprox.PeelParams` fields.
#: The PeelParams fields a sweep's options set (besides I, V and the law): the models' own too (``Model.parameters``
#: of ``exact.MODELS``: a tape mass, a constant load), so a sweep of (I, V) runs for a given model; one sweep per
#: tape mass sweeps m.
PARAM_OPTIONS = ("k", "R", "l", "geometry") + tuple(
    f.name for f in dataclasses.fields(PeelParams) if any(f.name in dict(m.parameters) for m in MODELS.values()))


def import_ref(ref: str) -> Any:
    """The object an import reference ``"module:qualname"`` names (a module-level function the workers import;
    the reference comes from this process's registries, never from a file)."""
    mod, _, qual = ref.partition(":")
    obj: Any = importlib.import_module(mod)
    for part in qual.split("."):
        obj = getattr(obj, part)
    return obj


def _resolve(name: str, ref: None | str | bytes) -> Measure:
    """The measure function in this (worker) process: unpickled if shipped by value (bytes), else by import
    reference, else by registry name."""
    if isinstance(ref, bytes):
        import pickle

        try:
            return pickle.loads(ref)
        except Exception as exc:
            raise LookupError(f"measure {name!r} was shipped by value (cloudpickle) but cannot be unpickled in this "
                              f"process ({type(exc).__name__}: {exc}); install cloudpickle where the workers run, "
                              "or define the measure in an importable module") from None
    if ref is not None:
        fn = MEASURES.get(name)
        if fn is not None and measure_ref(fn) == ref:
            return fn
        try:
            return import_ref(ref)
        except Exception:
            pass
    if name in MEASURES:
        return MEASURES[name]
    raise LookupError(f"measure {name!r} cannot be resolved in this process (import reference {ref!r}); "
                      "define it at module level in a module the workers can import")


def _value(val: Any, depth: int = 2) -> Any:
    """A measure's value as JSON: a scalar, or a list or tuple of them (of lists, ``depth`` levels at most)."""
    if depth and isinstance(val, (list, tuple)):
        return [_value(x, depth - 1) for x in val]
    return jsonable(val, keep_nonfinite=True, scalar=True)


def _prefixed(name: str, out: Any) -> dict:
    if not isinstance(out, Mapping):
        raise TypeError(f"measure {name!r} must return a dict, got {type(out).__name__}")
    rec = {}
    for key, val in out.items():
        if not isinstance(key, str) or not key:
            raise TypeError(f"measure {name!r} returned a non-string key {key!r}")
        full = record_key(name, key)
        try:
            rec[full] = _value(val)
        except TypeError as exc:
            raise TypeError(f"measure {name!r}, key {key!r}: {exc}") from None
    return rec


def make_params(I: float, V: float, options: Mapping, force: PeelForce | None = None) -> PeelParams:
    """The point's :class:`peelapprox.PeelParams`: ``I``, ``V``, the options :data:`PARAM_OPTIONS` and the law
    ``force`` (None: the paper's)."""
    fields: dict[str, Any] = {k: options[k] for k in PARAM_OPTIONS if k in options}
    if force is not None:
        fields["force"] = force
    return PeelParams(V=V, I=I, **fields)


def run_point(I: float, V: float, measures: Sequence[str], options: Mapping,
              refs: Mapping[str, str | bytes] | None = None, force: PeelForce | None = None,
              coef: tuple[str, float] | None = None, deadline: float | None = None) -> dict:
    """Evaluate ``measures`` at one grid point; never raises for a measure's failure.

    Module level and plain-data in/out, so any executor can ship it.  ``refs``
    maps a measure's name to its import reference, or to its cloudpickle bytes.
    ``force`` is the sweep's law (a :class:`peelapprox.PeelForce`, pickled as
    plain data; None: the paper's) and ``coef`` = ``(name, value)`` the point's
    value of a coefficient axis (:mod:`comparisons.sweep.law`).  ``deadline``:
    the sweep's, a ``time.time()`` (module docstring; None: unbounded).
    Returns the record ``{"I", "V", "status", <measure keys>...}``; ``status``
    as in the docstring of :mod:`comparisons.sweep`; for a law other than the
    paper's or a coefficient axis, ``{"I", "V", ["coef",] "status", "law",
    "law_key", ...}``.
    """
    refs = refs or {}
    body: dict = {}
    error = reported = None
    head: dict = {"I": I, "V": V} if coef is None else {"I": I, "V": V, "coef": coef[1]}
    left = None if deadline is None else deadline - time.time()
    if left is not None and left <= 0:
        return {**head, "status": NOT_RUN}
    try:
        law = None if force is None else point_law(force, *(coef or (None, None)))
        params = make_params(I, V, options, law)
    except Exception as exc:
        return {**head, "status": error_text(exc)}
    if law is not None and (coef is not None or law.kind != "paper"):
        body.update(law_fields(law))
    opts = MappingProxyType(dict(options) if left is None else {**options, "max_wall": left})
    for name in measures:
        try:
            out = _prefixed(name, _resolve(name, refs.get(name))(params, opts))
            clash = (set(out) & set(body)) | (set(out) & {*RESERVED, *LAW_KEYS})
            if clash:
                raise ValueError(f"measure {name!r} returned keys that are already taken: {sorted(clash)}")
            body.update(out)
            own = out.get(f"{name}_status")
            if reported is None and isinstance(own, str) and own != "ok":
                reported = own
        except Exception as exc:
            if (deadline is not None and isinstance(exc, SolverBudgetExceeded) and exc.budget == "max_wall"
                    and time.time() >= deadline):  # the sweep's budget, not the point's: computed on resume
                return {**head, "status": NOT_RUN}
            err = error_text(exc)
            body[f"{name}_status"] = err
            error = error or err
    return {**head, "status": error or reported or "ok", **body}


def _cloudpickle() -> ModuleType | None:
    """The cloudpickle module, or None if it is not installed."""
    try:
        import cloudpickle
    except ImportError:
        return None
    return cloudpickle


def _importable(fn: Callable) -> bool:
    """Whether a worker process can import ``fn`` by its ``module:qualname`` (as this process resolves it)."""
    mod, _, qual = measure_ref(fn).partition(":")
    if mod in ("__main__", "__mp_main__", "?") or "<" in qual:
        return False
    try:
        return import_ref(measure_ref(fn)) is fn
    except Exception:
        return False


def worker_refs(measures: Sequence[str]) -> dict[str, str | bytes]:
    """What the workers get for each measure: its import reference, or its cloudpickle bytes if they could not
    import it.  ValueError (before any point runs) if such a measure cannot be shipped."""
    refs: dict[str, str | bytes] = {name: measure_ref(MEASURES[name]) for name in measures}
    lone = [name for name in measures if not _importable(MEASURES[name])]
    if not lone:
        return refs
    cp = _cloudpickle()
    if cp is None:
        raise ValueError(f"measure(s) {lone} ({[refs[n] for n in lone]}) cannot be imported by worker processes "
                         "(defined in a notebook or __main__, a lambda or a local function) and cloudpickle, which "
                         "would ship them, is not installed: define them in an importable module, "
                         "pip install cloudpickle, or run in this process with max_workers=0 (--workers 0)")
    for name in lone:
        try:
            refs[name] = cp.dumps(MEASURES[name])
        except Exception as exc:
            ref = cast(str, refs[name])  # still its import reference: dumps raised before the assignment
            raise ValueError(f"measure {name!r} ({ref}) cannot be pickled to ship it to the workers "
                             f"({type(exc).__name__}: {exc}): define it in an importable module, or run in this "
                             "process with max_workers=0 (--workers 0)") from None
    return refs

"""The approximations an atlas measures: a registry of predictions of a stick-slip attractor's observables.

An *approximation* is ``fn(params) -> StickSlipObservables`` (or a dict of the same fields: ``status``,
``reason``, ``method``, the observables, ``period``), computed from the reduced equations or closed forms,
never from the full DAE.  :data:`APPROXIMATIONS` maps a name to one of

* a callable ``fn(params)``;
* an import reference ``"module:attribute"`` of such a callable, resolved when an atlas starts: an entry whose
  reference does not resolve (its module or function is not installed) is *skipped*, and the atlas says so;
* a pair ``("module:attribute", {keyword: value})``: the same, called as ``fn(params, **keywords)`` (a variant
  of one function, e.g. another alpha model).

Adding an approximation is one line in :data:`APPROXIMATIONS` (or :func:`register_approximation`).  The
built-ins: ``"estimate"`` (:func:`estimate_observables`: what :func:`peelapprox.estimate` predicts, the
quasi-static cycle) and ``"approx:default"`` (``peelapprox.approximate_attractor`` with its defaults, the
reduced return map iterated to its attractor).
"""

from __future__ import annotations

import numbers
import re
import threading
from collections.abc import Callable, Mapping
from typing import Any

from peelapprox import PeelParams, StickSlipObservables, estimate
from peelapprox.io import fmt_number

from ..sweep.task import import_ref

__all__ = ["APPROXIMATIONS", "OBSERVABLES", "UNITS", "TOLERANCE", "Entry", "register_approximation",
           "estimate_observables", "resolve", "available", "key_of", "predict", "last_output"]

#: The observables an atlas compares: :class:`peelapprox.StickSlipObservables`' own list
#: (``StickSlipObservables.OBSERVABLES``, the very object; their definitions are its docstring's): the mean time
#: between slips, the mean force drop of a slip, the mean CD and AB stays, and the force range at the jumps.
#: ``period`` is recorded too but compared as a class, not as a relative error.
OBSERVABLES = StickSlipObservables.OBSERVABLES
#: The unit of each observable (times in s, forces in N), from the same fields.
UNITS = {name: StickSlipObservables.UNITS[name] for name in OBSERVABLES}

#: The paper's claim for its approximations, "reasonably accurate values", read as within 10 %: the outline of
#: the atlas's maps and the criterion of its summary.
TOLERANCE = 0.10

#: A registry entry: a callable, an import reference ``"module:attribute"``, or ``(reference, keywords)``.
Entry = Callable[[PeelParams], Any] | str | tuple


def estimate_observables(params: PeelParams) -> dict:
    """What :func:`peelapprox.estimate` predicts of the attractor: the quasi-static cycle (α frozen at 0).

    The front sticks on AB from the landing of a CD→AB jump to the fold ``v_max`` in the quasi-static time
    ``t_ab_quasi_static`` (approxvdot with α̇ = 0), slips on CD to ``v_min`` in ``t_cd_quasi_static``, and the
    force moves between the folds' ``f_max`` and ``f_min`` (``F = f`` at α = 0).  So ``stick_time`` = t_AB,
    ``slip_time`` = t_CD, ``slip_interval`` = t_AB + t_CD (the jumps take no time), ``force_drop`` = f_max -
    f_min, ``F_max`` = f_max, ``F_min`` = f_min, ``period`` 1.  A stable fixed point (or no folds at V) is
    ``status="steady"``.

    Parameters
    ----------
    params : PeelParams
        The paper's massless model under velocity control, any law whose folds can be found.

    Returns
    -------
    dict
        The fields of :class:`peelapprox.StickSlipObservables` it predicts (the spreads are not predicted).

    Raises
    ------
    ValueError
        As :func:`peelapprox.estimate` (a model variant, a law whose folds cannot be found).
    """
    e = _estimate_of(params)
    method = "estimate: quasi-static cycle (alpha = 0, approxvdot between the folds)"
    if e.velocity == "stable" or not e.has_folds:
        why = (f"the law has no folds at V = {fmt_number(e.V, 4)} m/s" if not e.has_folds else
               f"the fixed point v = V is stable (f'(V, V) = {fmt_number(e.fixed_point_fprime, 4)} N s/m > 0)")
        return {"status": "steady", "reason": f"{why}: steady peeling", "method": method, "period": None}
    if e.t_ab_quasi_static is None or e.t_cd_quasi_static is None:
        return {"status": "no prediction", "reason": "a quasi-static passage does not reach its fold (v_max >= V "
                "or v_min <= V)", "method": method, "period": None}
    assert e.f_max is not None and e.f_min is not None  # has_folds
    t_ab, t_cd = e.t_ab_quasi_static, e.t_cd_quasi_static
    return {"status": "stick-slip", "reason": f"{e.label}: the quasi-static cycle between the folds",
            "method": method, "period": 1, "slip_interval": t_ab + t_cd, "force_drop": e.f_max - e.f_min,
            "slip_time": t_cd, "stick_time": t_ab, "F_max": e.f_max, "F_min": e.f_min}


_LAST = threading.local()


def _estimate_of(params: PeelParams) -> Any:
    """:func:`peelapprox.estimate` of ``params``, this thread's last one reused for the very same object: an atlas
    point asks for it twice (the ``regime`` label and the ``"estimate"`` approximation), and its quadratures call
    Python functions (under the GIL) ~10 ms a time.  The object is held, so its ``id`` is not reused."""
    last = getattr(_LAST, "pair", None)
    if last is None or last[0] is not params:
        last = _LAST.pair = (params, estimate(params))
    return last[1]


#: name -> approximation (module docstring).  One line adds one; an entry whose import reference does not
#: resolve is skipped by an atlas (and listed in its ``skipped``).
APPROXIMATIONS: dict[str, Entry] = {
    "estimate": estimate_observables,
    "approx:default": "peelapprox:approximate_attractor",
    # the same reductions from the exact solver's start only: what the default's second start buys
    "approx:solver": ("peelapprox:approximate_attractor", {"start": "solver"}),
    # the paper's Case I (approxalpha on AB, airy2 on CD) everywhere
    "approx:caseI": ("peelapprox:approximate_attractor", {"alpha_model": "approxalpha", "cd_alpha_model": "airy2"}),
    # the full branch dynamics linearised in alpha: the chain's check, not a prediction
    "approx:check": ("peelapprox:approximate_attractor", {"alpha_model": "genalpha", "v_equation": "fullvdot",
                                                          "cd_alpha_model": "genalpha", "cd_v_equation": "fullvdot"}),
}

_NAME = re.compile(r"^[A-Za-z][A-Za-z0-9_:.+-]*$")
_REF = re.compile(r"^[A-Za-z_][\w.]*:[A-Za-z_][\w.]*$")


def key_of(name: str) -> str:
    """An approximation's name in a file name (the maps'): every character other than a letter, digit or ``_``
    becomes ``_`` (``"approx:default"`` -> ``"approx_default"``)."""
    return re.sub(r"\W", "_", name)


def _check_entry(name: str, entry: Any) -> None:
    """ValueError naming the approximation unless ``entry`` is a registry entry (module docstring)."""
    if callable(entry):
        return
    ref, kwargs = (entry, {}) if isinstance(entry, str) else (entry if isinstance(entry, tuple) and len(entry) == 2
                                                                  else (None, None))
    if not (isinstance(ref, str) and _REF.match(ref)) or not isinstance(kwargs, Mapping) \
            or not all(isinstance(k, str) for k in kwargs):
        raise ValueError(f"approximation {name!r}: the entry must be a callable fn(params), an import reference "
                         f"'module:attribute' or a pair ('module:attribute', {{keyword: value}}), got {entry!r}")


def register_approximation(name: str, entry: Entry, *, replace: bool = False) -> None:
    """Add ``entry`` to :data:`APPROXIMATIONS` under ``name``.

    Parameters
    ----------
    name : str
        Letters, digits and ``_ : . + -``, starting with a letter; its :func:`key_of` must differ from every
        other entry's (the maps' file names).
    entry : callable, str or (str, dict)
        ``fn(params) -> StickSlipObservables | dict``, or an import reference (module docstring).  A process
        pool's workers find an entry by name in this registry when they import this module, or else by the
        import reference of a module-level function; a callable defined elsewhere (a notebook, ``__main__``)
        needs ``max_workers=0``.
    replace : bool
        Registering another entry under a taken name raises ValueError unless True.

    Raises
    ------
    ValueError
        A bad name or entry, or a taken name without ``replace``.
    """
    if not isinstance(name, str) or not _NAME.match(name):
        raise ValueError(f"approximation name must match [A-Za-z][A-Za-z0-9_:.+-]*, got {name!r}")
    _check_entry(name, entry)
    clash = [other for other in APPROXIMATIONS if other != name and key_of(other) == key_of(name)]
    if clash:
        raise ValueError(f"approximation {name!r} has the file-name key {key_of(name)!r} of {clash[0]!r}: rename it")
    if name in APPROXIMATIONS and APPROXIMATIONS[name] is not entry and not replace:
        raise ValueError(f"approximation {name!r} is already registered; pass replace=True to replace it")
    APPROXIMATIONS[name] = entry


def _ref_of(fn: Callable) -> str | None:
    """``module:qualname`` of a module-level function a worker can import, else None."""
    module, qual = getattr(fn, "__module__", None), getattr(fn, "__qualname__", "")
    if not module or module in ("__main__", "__mp_main__") or "<" in qual:
        return None
    try:
        return f"{module}:{qual}" if import_ref(f"{module}:{qual}") is fn else None
    except Exception:
        return None


def resolve(name: str, ref: str | None = None) -> Callable[[PeelParams], Any]:
    """The callable of approximation ``name``: the import reference ``ref`` when given (how the atlas that
    started told its workers to find it), else its registry entry (an import reference resolved now, a pair
    bound to its keywords).

    Raises
    ------
    LookupError
        ``name`` is not registered and no ``ref`` is given.
    ImportError, AttributeError
        The import reference does not resolve (the function does not exist yet).
    TypeError
        It resolves to something that is not callable.
    """
    entry: Any = ref if ref not in (None, "registry") else APPROXIMATIONS.get(name)
    if entry is None:
        raise LookupError(f"approximation {name!r} is not registered in comparisons.atlas.APPROXIMATIONS "
                          f"(known: {sorted(APPROXIMATIONS)})")
    if callable(entry):
        return entry
    ref_, kwargs = (entry, {}) if isinstance(entry, str) else entry
    fn = import_ref(ref_)
    if not callable(fn):
        raise TypeError(f"approximation {name!r}: {ref_} is not callable")
    if not kwargs:
        return fn
    kw = dict(kwargs)
    return lambda params: fn(params, **kw)


def available(names: list[str] | None = None, *, serial: bool = True) -> tuple[dict[str, str], dict[str, str]]:
    """The approximations an atlas can run now: ``(run, skipped)``.

    ``run`` maps each name to how a worker finds it: an import reference (an entry's own, or a module-level
    function's), else ``"registry"`` (by name in this module's registry: a built-in entry); ``skipped`` maps a
    registered name whose import reference does not resolve to why.  ``names`` (default: every registered one)
    must all be registered (ValueError naming ``approximations`` otherwise).  Without ``serial`` (a process
    pool), a callable the workers can find neither in the registry module nor by import is a ValueError.
    """
    if names is None:
        names = list(APPROXIMATIONS)
    unknown = [n for n in names if n not in APPROXIMATIONS]
    if unknown:
        raise ValueError(f"approximations: unknown {unknown}; registered: {sorted(APPROXIMATIONS)}")
    if len(set(names)) != len(names):
        raise ValueError(f"approximations must not repeat a name, got {names}")
    run: dict[str, str] = {}
    skipped: dict[str, str] = {}
    for name in names:
        entry = APPROXIMATIONS[name]
        if not callable(entry):
            ref = entry if isinstance(entry, str) else entry[0]
            try:
                resolve(name)
            except (ImportError, AttributeError):
                skipped[name] = f"{ref} is not importable"
                continue
            # a reference alone travels as itself; with keywords, by name (a built-in entry, or max_workers=0)
            run[name] = entry if isinstance(entry, str) else "registry"
            continue
        builtin = _ref_of(entry) is not None or getattr(entry, "__module__", "").startswith("comparisons.atlas")
        if not serial and not builtin:
            raise ValueError(f"approximations: {name!r} ({entry!r}) cannot be found by worker processes (defined in "
                             "a notebook or __main__, or a lambda outside comparisons.atlas): define it at module "
                             "level in an importable module, or run in this process with max_workers=0")
        run[name] = _ref_of(entry) or "registry"
    return run, skipped


#: This thread's last output of each approximation: ``name -> (params, callable, output)`` (:func:`last_output`).
_LAST = threading.local()


def last_output(name: str, params: PeelParams, fn: Callable) -> Any:
    """What approximation ``name`` returned in this thread's last :func:`predict` if that call was for this very
    ``params`` object and ran ``fn``; else None.  The atlas's set measure reads the default prediction of the same
    point from it instead of computing it again (a sweep passes one ``params`` object to a point's measures)."""
    got = getattr(_LAST, "outputs", {}).get(name)
    return got[2] if got is not None and got[0] is params and got[1] is fn else None


def predict(name: str, params: PeelParams, ref: str | None = None) -> dict:
    """Approximation ``name`` at ``params`` as the fields of a :class:`peelapprox.StickSlipObservables`
    (``status``, ``reason``, ``period`` and :data:`OBSERVABLES`; absent ones None), checked: every observable
    a finite number or None, ``status`` and ``reason`` strings.

    Raises
    ------
    TypeError, ValueError
        The approximation returned something else (or raised: its exception propagates).
    """
    fn = resolve(name, ref)
    out = fn(params)
    if not hasattr(_LAST, "outputs"):
        _LAST.outputs = {}
    _LAST.outputs[name] = (params, fn, out)
    d = out.as_dict() if isinstance(out, StickSlipObservables) else out
    if not isinstance(d, Mapping):
        raise TypeError(f"approximation {name!r} returned {type(out).__name__}, not StickSlipObservables or a dict")
    status, reason = d.get("status"), d.get("reason", "")
    if not isinstance(status, str) or not isinstance(reason, str):
        raise TypeError(f"approximation {name!r}: status and reason must be strings, got {status!r}, {reason!r}")
    rec: dict[str, Any] = {"status": status, "reason": reason}
    period = d.get("period")
    if period is not None and (isinstance(period, bool) or not isinstance(period, int)):
        raise TypeError(f"approximation {name!r}: period must be an int or None, got {period!r}")
    rec["period"] = period
    for field in OBSERVABLES:
        v = d.get(field)
        if v is not None:
            if isinstance(v, bool) or not isinstance(v, numbers.Real) or not abs(float(v)) < float("inf"):
                raise ValueError(f"approximation {name!r}: {field} must be a finite number or None, got {v!r}")
            v = float(v)
        rec[field] = v
    return rec

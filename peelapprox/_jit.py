"""The one way the package compiles numba kernels: cached, with cache keys that follow the model source.

numba caches a compiled function on disk keyed on *its own* source file (time
stamp and size) and bytecode.  A kernel that inlines or calls functions from
other files (the generated model in ``_generated.py``, the peel force, the
DOP853 step) embeds their machine code, so after one of those files changes
(a regenerated model, a package upgrade) numba would load the old kernel: the
stale-kernel bug of issue 13 (a changed fvV coefficient gave CONSTR residuals
of 37 N).  :func:`kernel` therefore stamps every compiled function's cache
index with a hash of **all** the files compiled into kernels
(:data:`KERNEL_SOURCES`, :data:`SOURCE_TAG`) next to numba's own stamp: numba
discards an index whose stamp differs, so after a change to any of them the
kernels are compiled anew (the cache files keep their names and are
overwritten), and a cache written by other sources is never read.  On a numba
without the private stamp attribute the tag goes into the cache file names
instead.

Where no cache location is writable (read-only install, HOME, XDG cache and
``NUMBA_CACHE_DIR``: containers, HPC nodes) the kernels are compiled without
caching, with one :class:`~peelapprox.errors.KernelCacheWarning`: the
package works, and every new process compiles again.

Every function compiled by the package goes through :func:`kernel` (or, for a
formula that plain Python and numpy call as well, :func:`jitable`); both
refuse a function whose source file is not in :data:`KERNEL_SOURCES`, so a
new kernel module cannot silently escape the hash.
"""

from __future__ import annotations

import hashlib
import inspect
import types
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any, Literal

from numba import njit
from numba.extending import register_jitable

from .errors import KernelCacheWarning

__all__ = ["kernel", "jitable", "rebind", "KERNEL_SOURCES", "SOURCE_TAG", "source_tag", "caching_enabled"]

_ROOT = Path(__file__).resolve().parent.parent

#: Files (relative to the directory holding the packages) whose code is compiled into kernels.
KERNEL_SOURCES: tuple[str, ...] = (
    "peelapprox/_jit.py",
    "peelapprox/_generated.py",
    "peelapprox/_peelforce.py",
    "peelapprox/_law_abi.py",  # the peel-force law ABI and the compiled laws
    "peelapprox/_law_table_jit.py",  # the compiled tabulated law
    "peelapprox/_dop853.py",
    "peelapprox/_alpha.py",
    "peelapprox/_segment_kernel.py",
    "peelapprox/_packing.py",  # the parameter-vector layouts, frozen into the kernels
    "peelapprox/_status.py",  # the status codes, frozen into the kernels
    "peelapprox/kernels.py",
    "exact/_hybrid.py",
    "exact/_hybrid_law.py",
    "exact/_regularized.py",
    "exact/_tangent.py",
)


def source_tag(root: Path = _ROOT, sources: tuple[str, ...] = KERNEL_SOURCES) -> str:
    """First 16 hex digits of the SHA-256 of the kernel sources (path and bytes of each, in order).

    A missing file hashes as empty (a partial install still gets a consistent, distinct tag).
    """
    h = hashlib.sha256()
    for rel in sources:
        h.update(rel.encode())
        h.update(b"\0")
        try:
            h.update((root / rel).read_bytes())
        except OSError:
            pass
        h.update(b"\0")
    return h.hexdigest()[:16]


#: The tag every compiled function's cache name carries (see the module docstring).
SOURCE_TAG = source_tag()

_state = {"cache": True}
#: numba's ``njit``, untyped: its ``_nrt`` option (:func:`kernel`'s ``nrt``) is not in numba's type stubs.
_njit: Any = njit


def caching_enabled() -> bool:
    """False once a kernel had to be compiled without a writable cache location."""
    return bool(_state["cache"])


def _stamp_with_tag(dispatcher: Any) -> bool:
    """Make the dispatcher's on-disk cache index carry :data:`SOURCE_TAG` in its source stamp.

    numba stores the stamp of the function's own file in the index and discards the index when it differs
    on load; adding the tag discards it also when any other kernel source changed.  The cache files keep
    their names (overwritten, not accumulated).  Uses numba's private ``_cache._cache_file._source_stamp``
    (numba 0.58-0.68); returns False where that is not there.
    """
    cf = getattr(getattr(dispatcher, "_cache", None), "_cache_file", None)
    if cf is None or not hasattr(cf, "_source_stamp"):
        return False
    cf._source_stamp = (cf._source_stamp, SOURCE_TAG)
    return True


def _renamed(fn: Callable, name: str) -> Callable:
    """A copy of the plain function ``fn`` named ``name`` (numba names cache files after the qualname)."""
    g = types.FunctionType(fn.__code__, fn.__globals__, name, fn.__defaults__, fn.__closure__)
    g.__qualname__ = name
    g.__module__ = fn.__module__
    g.__doc__ = fn.__doc__
    g.__kwdefaults__ = fn.__kwdefaults__
    return g


def rebind(fn: Callable, **bound: Any) -> Callable:
    """A copy of the plain module-level function ``fn`` that reads ``bound`` as its globals (the rest as ``fn``
    does): how one driver body is compiled twice, with the peel-force law inlined and as an argument.  The copy
    has no closure, so numba caches it across processes (a closure over dispatchers is not cached); compile each
    copy under its own ``name`` (:func:`kernel`)."""
    g = types.FunctionType(fn.__code__, dict(fn.__globals__, **bound), fn.__name__, fn.__defaults__, None)
    g.__qualname__, g.__module__, g.__doc__ = fn.__qualname__, fn.__module__, fn.__doc__
    return g


def _check_source(fn: Callable) -> None:
    try:
        src = Path(inspect.getfile(fn)).resolve()
        rel = src.relative_to(_ROOT).as_posix()
    except (TypeError, ValueError):
        rel = None
    if rel not in KERNEL_SOURCES:
        raise RuntimeError(
            f"peelapprox._jit.kernel: {fn.__qualname__} is defined in {rel or inspect.getfile(fn)!r}, which is not "
            "in KERNEL_SOURCES; add the file there so that its changes invalidate the cached kernels"
        )


def kernel(fn: Callable | None = None, *, inline: Literal["never", "always"] = "never", fastmath: bool = False,
           name: str | None = None, signature: Any = None, nrt: bool = True) -> Any:
    """Compile ``fn`` with numba (``njit``), cached with an index stamped by :data:`SOURCE_TAG`.

    Use as ``@kernel``, ``@kernel(inline="always")`` or ``kernel(inline="always")(f)``.

    Parameters
    ----------
    fn : function
        Plain Python function defined in one of :data:`KERNEL_SOURCES`.
    inline : {"never", "always"}
        numba's IR-level inlining into the callers.
    fastmath : bool
        numba's fastmath flag (default False: IEEE semantics, as the tests assume).
    name : str, optional
        Base name of the cache files (default: the function's qualname); the
        DOP853 pieces of :func:`peelapprox._dop853.make_dop853` are named after
        their vector field.
    signature : numba signature, optional
        Compile for this one signature now (loaded from the cache when it is there) and never for another,
        as ``njit(signature)`` does: the form of a driver that takes a first-class function argument
        (``numba.types.FunctionType``, e.g. the peel-force law of :mod:`peelapprox._law_abi`), which numba
        caches across processes only when the argument's type is fixed in advance (a dispatcher passed to a
        lazily typed function is specialised on and recompiled in every process).  The source stamp is set
        before this compilation, so a changed kernel source recompiles it as any other kernel.
    nrt : bool
        numba's reference-counting runtime (its ``_nrt`` flag).  ``False`` for a function that allocates no array
        and calls a first-class function (the law of :mod:`peelapprox._law_abi`) with an array argument: numba
        then wraps every such call in atomic increments and decrements of the arrays' reference counts, which
        it cannot prune around the indirect call (measured: 62 ns instead of 29 ns per hybrid field
        evaluation); without the runtime the arrays are borrowed from the caller, which owns them.

    Returns
    -------
    numba dispatcher

    Raises
    ------
    RuntimeError
        If ``fn``'s source file is not in :data:`KERNEL_SOURCES` (a developer error).
    """
    if fn is None:
        return lambda f: kernel(f, inline=inline, fastmath=fastmath, name=name, signature=signature, nrt=nrt)
    d = _compile(fn, inline, fastmath, name, nrt)
    if signature is not None:
        d.compile(signature)
        d.disable_compile()
    return d


def _compile(fn: Callable, inline: Literal["never", "always"], fastmath: bool, name: str | None, nrt: bool) -> Any:
    """The dispatcher of :func:`kernel`, stamped (or uncached after one warning), not compiled yet."""
    _check_source(fn)
    if name is not None:  # distinct cache files for the pieces of each vector field (make_dop853)
        fn = _renamed(fn, name.replace("<locals>.", "").replace(".", "_"))
    if _state["cache"]:
        try:
            d = _njit(cache=True, inline=inline, fastmath=fastmath, _nrt=nrt)(fn)
            if not _stamp_with_tag(d):  # a numba without the private stamp: tag the cache file names instead
                # (old files then accumulate in __pycache__)
                base = fn.__qualname__.replace("<locals>.", "").replace(".", "_")
                d = _njit(cache=True, inline=inline, fastmath=fastmath, _nrt=nrt)(
                    _renamed(fn, f"{base}__src{SOURCE_TAG}"))
            return d
        except RuntimeError as e:  # numba: "cannot cache function ...: no locator available"
            if "no locator available" not in str(e):
                raise
            _state["cache"] = False
            warnings.warn(
                "peelapprox: no writable numba cache location (NUMBA_CACHE_DIR, the package's __pycache__, "
                "the user cache directory); kernels are compiled without caching, so every new process "
                "compiles them again (~20 s). Set NUMBA_CACHE_DIR to a writable directory to cache them.",
                KernelCacheWarning,
                stacklevel=3,
            )
    return _njit(cache=False, inline=inline, fastmath=fastmath, _nrt=nrt)(fn)


def jitable(fn: Callable) -> Callable:
    """Return the plain function ``fn``, registered so that kernels can call it too (one definition, both worlds).

    Python and numpy callers call ``fn`` itself (on scalars or arrays); a kernel that calls it gets it compiled
    into its own code and inlined at the IR level (numba's ``register_jitable(inline="always")``), so it is
    cached, and re-compiled on a source change, with that kernel.  Use for a formula of the model that both the
    vectorised public functions and the compiled solvers evaluate, e.g. the closed forms of the reduced α
    equations (:mod:`peelapprox._alpha`).

    Raises
    ------
    RuntimeError
        If ``fn``'s source file is not in :data:`KERNEL_SOURCES` (a developer error).
    """
    _check_source(fn)
    return register_jitable(inline="always")(fn)

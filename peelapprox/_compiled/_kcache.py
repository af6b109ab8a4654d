"""numba's on-disk cache of the package's kernels, private by construction.

numba's own locators put a function's cache files (an index ``*.nbi`` and data files ``*.nbc``, both *pickles*
that numba loads) in ``NUMBA_CACHE_DIR``, the package's ``__pycache__`` or ``~/.cache/numba``, in per-module folders
made with the umask's mode and never checked: under ``umask 000`` another user could replace an index and run
code as the next user of the cache.  Every kernel of the package (:func:`peelapprox._compiled._jit.kernel`) is cached
instead by :class:`PrivateCache`:

* the **root** is ``NUMBA_CACHE_DIR`` when it is set and private, else ``~/.cache/peelapprox/numba``
  (``$XDG_CACHE_HOME/peelapprox/numba``), made mode 0700 (:func:`kernel_root`); a ``NUMBA_CACHE_DIR`` that is not
  private is refused with a :class:`~peelapprox.errors.KernelCacheWarning` and the default root used; with no
  private root at all the kernels are compiled without caching (one warning).  A read-only install works: nothing
  is written beside the package;
* each module's folder ``<root>/<package>_<sha1 of its directory>`` (numba's naming) is made 0700 whatever the umask,
  and one that is a link, another user's or writable by others is replaced
  (:func:`peelapprox._compiled._private.private_dir`);
* before numba unpickles an index or data file, the file is checked: a regular file of this user's that no one
  else can write, not a link; another is not read, is removed, and the kernel is compiled (a warning says so);
  files are written 0600; a truncated or garbled file is a cache miss, as a missing one is.
"""

from __future__ import annotations

import contextlib
import inspect
import os
import pickle  # only its exception (numba unpickles its files itself, after the checks here)
import struct
import sys
import threading
import uuid
import warnings
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from numba.core import caching as _caching
from numba.core import config as numba_config

from ..errors import KernelCacheWarning
from ._private import cache_home, open_private, private_dir

__all__ = ["SUPPORTED", "PrivateCache", "default_root", "kernel_root", "root_problem"]

#: Whether this numba's cache classes have the methods the classes below override (numba 0.58-0.68 have them);
#: without them the kernels are compiled uncached (:mod:`peelapprox._compiled._jit`), never cached where the checks do
# not
#: reach (the classes themselves are in every numba since 0.49).
_BASES = ("_CacheLocator", "_SourceFileBackedLocatorMixin", "CompileResultCacheImpl", "IndexDataCacheFile",
          "FunctionCache", "Cache")
SUPPORTED = (all(hasattr(_caching, n) for n in _BASES)
             and all(hasattr(_caching.IndexDataCacheFile, n) for n in ("_load_index", "_load_data", "_open_for_write"))
             and hasattr(_caching.Cache, "_save_overload"))

_LOCK = threading.RLock()
#: (NUMBA_CACHE_DIR, default root) -> the root chosen, or None with the reason (``_NOTES``).
_ROOTS: dict[tuple[str, str], Path | None] = {}
_NOTES: dict[tuple[str, str], str] = {}

#: What unpickling a truncated or garbled cache file raises (pickle's own errors and those of the objects it
#: rebuilds from damaged bytes).
_CORRUPT = (pickle.UnpicklingError, EOFError, ValueError, TypeError, AttributeError, ImportError, IndexError,
            KeyError, struct.error, UnicodeDecodeError, MemoryError)


def default_root() -> Path:
    """``~/.cache/peelapprox/numba`` (``$XDG_CACHE_HOME/peelapprox/numba``): the kernels' root when
    ``NUMBA_CACHE_DIR`` is not set."""
    return cache_home() / "peelapprox" / "numba"


def _key() -> tuple[str, str]:
    return (getattr(numba_config, "CACHE_DIR", "") or "", str(default_root()))


def kernel_root() -> Path | None:
    """The private root of the kernels' cache in this process (module docstring), None when there is none (then
    :func:`root_problem` says why).  Chosen once per ``NUMBA_CACHE_DIR`` and home; one warning when a root was
    refused."""
    key = _key()
    if key in _ROOTS:
        return _ROOTS[key]
    with _LOCK:
        if key in _ROOTS:
            return _ROOTS[key]
        env, default = key[0], Path(key[1])
        notes, root = [], None
        if env:
            why = private_dir(Path(env))
            if why is None:
                root = Path(env)
            else:
                notes.append(f"NUMBA_CACHE_DIR={env!r} {why}")
        if root is None:
            why = private_dir(default, replace=True)
            if why is None:
                root = default
            else:
                notes.append(f"{str(default)!r} {why}")
        _ROOTS[key] = root
        if notes:
            _NOTES[key] = "; ".join(notes)
        if notes and root is not None:  # with no root at all, peelapprox._compiled._jit warns once (caching off)
            warnings.warn(f"peelapprox: {_NOTES[key]}; numba loads the pickled files it finds there, so peelapprox's "
                          f"kernels are cached in {str(root)!r} instead (point NUMBA_CACHE_DIR to a directory of yours "
                          "that only you can write)", KernelCacheWarning, stacklevel=5)
        return root


def root_problem() -> str | None:
    """Why :func:`kernel_root` refused a root in this process (None: it refused none)."""
    return _NOTES.get(_key())


class PrivateLocator(_caching._SourceFileBackedLocatorMixin, _caching._CacheLocator):
    """numba's cache locator for a function of ``py_file``: its module's folder under :func:`kernel_root`, made and
    checked by :func:`peelapprox._compiled._private.private_dir` (replaced when not private)."""

    def __init__(self, py_func: Any, py_file: str, root: Path):
        self._py_file = py_file
        self._lineno = py_func.__code__.co_firstlineno
        self._cache_path = str(root / self.get_suitable_cache_subpath(py_file))

    def get_cache_path(self) -> str:
        return self._cache_path

    def ensure_cache_path(self) -> None:
        why = private_dir(Path(self._cache_path), replace=True)
        if why is not None:
            raise OSError(f"the kernel cache folder {self._cache_path!r} {why}")

    @classmethod
    def from_function(cls, py_func: Any, py_file: str) -> PrivateLocator | None:
        root = kernel_root()
        if root is None or not os.path.exists(py_file):
            return None
        self = cls(py_func, py_file, root)
        try:
            self.ensure_cache_path()
        except OSError as exc:
            _NOTES[_key()] = str(exc)
            return None
        return self


class _PrivateImpl(_caching.CompileResultCacheImpl):
    """numba's compile-result cache with :class:`PrivateLocator` as its only locator (``NUMBA_CACHE_LOCATOR_CLASSES``
    does not apply)."""

    def __init__(self, py_func: Any):
        self._lineno = py_func.__code__.co_firstlineno
        source_path = inspect.getfile(py_func)
        locator = PrivateLocator.from_function(py_func, source_path)
        if locator is None:
            raise RuntimeError(f"cannot cache function {py_func.__qualname__!r}: no locator available for file "
                               f"{source_path!r}")
        self._locator = locator
        modname = os.path.splitext(os.path.basename(source_path))[0]
        self._filename_base = self.get_filename_base(f"{modname}.{py_func.__qualname__}",
                                                     getattr(sys, "abiflags", ""))


class _PrivateIndexFile(_caching.IndexDataCacheFile):
    """numba's index and data files, read only after :func:`peelapprox._compiled._private.open_private` accepted them (a
    corrupt one is a miss), written 0600 by a new file renamed over the old."""

    def _accepted(self, path: str) -> bool:
        if private_dir(Path(self._cache_path), replace=True, probe=False) is not None:
            return False
        fd, why = open_private(path)
        if fd is not None:
            os.close(fd)
            return True
        if why is not None:
            warnings.warn(f"peelapprox: the kernel cache file {path!r} {why}; it was not read (numba would unpickle "
                          "it) and is removed; the kernel is compiled anew", KernelCacheWarning, stacklevel=2)
            with contextlib.suppress(OSError):
                os.unlink(path)
        return False

    def _load_index(self) -> Any:
        if not self._accepted(self._index_path):
            return {}
        try:
            return super()._load_index()
        except _CORRUPT:
            return {}

    def _load_data(self, name: Any) -> Any:
        if not self._accepted(self._data_path(name)):
            return None
        try:
            return super()._load_data(name)
        except _CORRUPT:
            return None

    @contextlib.contextmanager
    def _open_for_write(self, filepath: str) -> Iterator[Any]:
        tmpname = f"{filepath}.tmp.{uuid.uuid4().hex[:16]}"
        fd = os.open(tmpname, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_NOFOLLOW", 0), 0o600)
        try:
            with os.fdopen(fd, "wb") as f:
                yield f
            os.replace(tmpname, filepath)
        except BaseException:
            with contextlib.suppress(OSError):
                os.unlink(tmpname)
            raise


class PrivateCache(_caching.FunctionCache):
    """numba's per-function cache (``Dispatcher._cache``) in the private root: :class:`PrivateLocator` and checked
    index and data files.  A file that cannot be written is a warning, never an error out of the user's call."""

    _impl_class = _PrivateImpl

    def __init__(self, py_func: Any):
        super().__init__(py_func)
        self._cache_file = _PrivateIndexFile(cache_path=self._cache_path, filename_base=self._impl.filename_base,
                                             source_stamp=self._impl.locator.get_source_stamp())

    def _save_overload(self, sig: Any, data: Any) -> None:
        try:
            super()._save_overload(sig, data)
        except OSError as exc:
            warnings.warn(f"peelapprox: a compiled kernel could not be cached ({exc}); it is compiled again in the "
                          "next process", KernelCacheWarning, stacklevel=2)

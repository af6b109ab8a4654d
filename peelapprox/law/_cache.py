"""The on-disk cache of the compiled expression laws: where it is, and the checks that keep it from being planted.

:func:`law_dir` is the verified directory (``$PEELAPPROX_CACHE_DIR``, else ``~/.cache/peelapprox/laws``; it and its
parents must pass :func:`peelapprox._compiled._jit.unsafe_dir`; numba's cache of the laws is in the kernels' private
root),
else a private temporary
one with a :class:`~peelapprox.errors.KernelCacheWarning`; :func:`read_verified` reads a law module without
following links and only from a regular file of this user's; :func:`write_atomic` replaces it.  What runs is
decided by :func:`peelapprox.law._kernels.expression_kernel`, which compares the file with the module it renders.
"""

from __future__ import annotations

import atexit
import os
import shutil
import stat
import tempfile
import warnings
from pathlib import Path

from .._compiled._jit import unsafe_dir
from .._compiled._private import cache_home
from ..errors import KernelCacheWarning

__all__ = ["MAX_MODULE_BYTES", "cache_dir", "law_dir", "read_verified", "write_atomic"]


def cache_dir() -> Path:
    """Where expression laws are written: ``$PEELAPPROX_CACHE_DIR``, else ``~/.cache/peelapprox/laws``
    (``$XDG_CACHE_HOME/peelapprox/laws``)."""
    env = os.environ.get("PEELAPPROX_CACHE_DIR")
    return Path(env) if env else cache_home() / "peelapprox" / "laws"


#: The largest law module read back from the cache [bytes] (a rendered law is a few kB).
MAX_MODULE_BYTES = 1 << 20

_FALLBACK: dict[str, Path] = {}


def law_dir() -> Path:
    """The verified cache directory (:func:`cache_dir`, which must pass :func:`peelapprox._compiled._jit.unsafe_dir`:
    its
    parents too; the default one, the package's own, is replaced when it fails), else a private temporary one for
    this process, with one :class:`~peelapprox.errors.KernelCacheWarning` naming why.  numba's cache of the laws
    is not here but in the kernels' private root (:mod:`peelapprox._compiled._kcache`)."""
    d = cache_dir()
    why = unsafe_dir(d, replace="PEELAPPROX_CACHE_DIR" not in os.environ)
    if why is None:
        return d
    if "dir" not in _FALLBACK:
        _FALLBACK["dir"] = Path(tempfile.mkdtemp(prefix="peelapprox-laws-"))  # mode 0700, new
        atexit.register(shutil.rmtree, _FALLBACK["dir"], ignore_errors=True)
        warnings.warn(f"peelapprox: the law cache directory {str(d)!r} {why}; expression laws are written to "
                      f"{str(_FALLBACK['dir'])!r} for this process only (set PEELAPPROX_CACHE_DIR to a directory of "
                      "yours that only you can write to keep them compiled across processes)",
                      KernelCacheWarning, stacklevel=3)
    return _FALLBACK["dir"]


def read_verified(path: Path) -> bytes | None:
    """The bytes of the law module at ``path`` if it is a regular file of this user's that no one else can write
    (never through a symbolic link: ``O_NOFOLLOW``), else None."""
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_NONBLOCK", 0))
    except OSError:
        return None
    with os.fdopen(fd, "rb") as fh:
        st = os.fstat(fh.fileno())
        if (not stat.S_ISREG(st.st_mode) or st.st_mode & 0o022 or st.st_size > MAX_MODULE_BYTES
                or (hasattr(os, "geteuid") and st.st_uid != os.geteuid())):
            return None
        return fh.read(MAX_MODULE_BYTES + 1)


def write_atomic(d: Path, path: Path, text: bytes) -> None:
    """Write ``text`` to ``path`` by a new file renamed over it (a link or a planted file is replaced, not
    followed)."""
    fd, tmp = tempfile.mkstemp(dir=d, prefix=f".{path.stem}-", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(text)
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise

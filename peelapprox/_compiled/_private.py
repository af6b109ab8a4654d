"""Private directories: the checks that keep the package's caches (pickles numba loads, law modules) its user's own.

A cache directory may hold code this process runs only if nobody but this user (and root) can have put anything
in it, now or before: every component of its path, from ``/`` down, must be a real directory (no symbolic link),
owned by this user or root, that no one else can write to unless it is sticky (as ``/tmp``: there others cannot
rename or delete what is not theirs); the directory itself and everything the package reads below it must be
owned by this user (:func:`os.geteuid`: as root, root's own) and writable by no one else.  Directories are created
mode 0700, one component at a time (``Path.mkdir(parents=True)`` would make the intermediate ones with the
umask's mode: 0777 under ``umask 000``), files 0600, so the modes do not depend on the umask.

:func:`private_dir` makes or checks such a directory; a folder the package made itself (numba's per-module
folders, the default roots) that fails is *replaced*: renamed away, deleted as far as possible, made anew, with a
:class:`~peelapprox.errors.KernelCacheWarning`; a directory the user named (``NUMBA_CACHE_DIR``,
``PEELAPPROX_CACHE_DIR``) is never deleted, only refused.  :func:`open_private` opens a file only if it is a
regular file of this user's that no one else can write, never through a link.
"""

from __future__ import annotations

import os
import shutil
import stat
import tempfile
import threading
import uuid
import warnings
from pathlib import Path

from ..errors import KernelCacheWarning

__all__ = ["cache_home", "chain_problem", "dir_problem", "file_problem", "open_private", "private_dir"]

_LOCK = threading.RLock()
#: (path, device, inode) of the directories checked in this process: the next request only lstat()s them again.
_CHECKED: set[tuple[str, int, int]] = set()


def _euid() -> int | None:
    return os.geteuid() if hasattr(os, "geteuid") else None


def cache_home() -> Path:
    """The user's cache directory: ``$XDG_CACHE_HOME`` if set to an absolute path, else ``~/.cache``."""
    env = os.environ.get("XDG_CACHE_HOME", "")
    return Path(env) if os.path.isabs(env) else Path.home() / ".cache"


def _mode(st: os.stat_result) -> str:
    return f"mode {stat.S_IMODE(st.st_mode):o}"


def chain_problem(path: Path) -> str | None:
    """Why a directory at ``path`` could be swapped or planted by someone else through one of its parents (None:
    it cannot): a parent is a symbolic link, not a directory, owned by another user than this one or root, or
    writable by others without the sticky bit.  Parents that do not exist yet are not checked (they are made by
    :func:`private_dir`, mode 0700)."""
    p = Path(os.path.abspath(path))
    me = _euid()
    for anc in reversed(p.parents):
        try:
            st = os.lstat(anc)
        except FileNotFoundError:
            return None
        except OSError as exc:
            return f"cannot be checked ({anc}: {exc.strerror or exc})"
        if stat.S_ISLNK(st.st_mode):
            return f"has a symbolic link in its path ({anc})"
        if not stat.S_ISDIR(st.st_mode):
            return f"has a path component that is not a directory ({anc})"
        if me is not None and st.st_uid not in (me, 0):
            return f"is inside {anc}, owned by another user (uid {st.st_uid}), who could swap it"
        if st.st_mode & 0o022 and not st.st_mode & stat.S_ISVTX:
            who = "others" if st.st_mode & 0o002 else "its group"
            return f"is inside {anc}, writable by {who} without the sticky bit ({_mode(st)}), who could swap it"
    return None


def dir_problem(st: os.stat_result) -> str | None:
    """Why the directory with ``lstat`` result ``st`` is not private (None: it is)."""
    if stat.S_ISLNK(st.st_mode):
        return "is a symbolic link"
    if not stat.S_ISDIR(st.st_mode):
        return "is not a directory"
    return _owner_or_mode_problem(st)


def file_problem(st: os.stat_result) -> str | None:
    """Why the file with ``fstat`` result ``st`` may not be read as code or a pickle (None: it may)."""
    if not stat.S_ISREG(st.st_mode):
        return "is not a regular file"
    return _owner_or_mode_problem(st)


def _owner_or_mode_problem(st: os.stat_result) -> str | None:
    """Another user's, or writable by group or others (None: neither): what makes a directory or file not ours."""
    me = _euid()
    if me is not None and st.st_uid != me:
        return f"is owned by another user (uid {st.st_uid})"
    if st.st_mode & 0o022:
        return f"is writable by {'others' if st.st_mode & 0o002 else 'its group'} ({_mode(st)})"
    return None


def open_private(path: str | os.PathLike) -> tuple[int | None, str | None]:
    """``(fd, None)`` for a regular file of this user's that no one else can write (opened read-only, never through
    a symbolic link), ``(None, None)`` if there is none, ``(None, why)`` if there is one that may not be read."""
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_NONBLOCK", 0))
    except FileNotFoundError:
        return None, None
    except OSError as exc:
        return None, "is a symbolic link" if os.path.islink(path) else f"cannot be opened ({exc.strerror or exc})"
    why = file_problem(os.fstat(fd))
    if why is not None:
        os.close(fd)
        return None, why
    return fd, None


def _make(d: Path) -> None:
    """Make ``d`` and its missing parents, each mode 0700 whatever the umask."""
    for c in [*reversed(d.parents), d]:
        if not os.path.lexists(c):
            try:
                os.mkdir(c, 0o700)
            except FileExistsError:
                pass


def _replace(d: Path, why: str) -> str | None:
    """Rename the non-private ``d`` away, delete what can be deleted of it, make it anew (0700); None when done."""
    aside = d.with_name(f".{d.name}.refused-{uuid.uuid4().hex[:12]}")
    try:
        os.rename(d, aside)
    except FileNotFoundError:
        pass  # another process replaced it first
    except OSError as exc:
        return f"{why}, and cannot be replaced ({exc.strerror or exc})"
    if os.path.islink(aside) or not os.path.isdir(aside):
        Path(aside).unlink(missing_ok=True)
    else:
        shutil.rmtree(aside, ignore_errors=True)  # what another user owns may stay, renamed, unused
    warnings.warn(f"peelapprox: the cache folder {str(d)!r} {why}; it was not used (numba would load the pickled files "
                  "in it) and a new private one (mode 0700) replaces it", KernelCacheWarning, stacklevel=5)
    try:
        os.mkdir(d, 0o700)
    except FileExistsError:
        pass
    except OSError as exc:
        return f"{why}, and cannot be made anew ({exc.strerror or exc})"
    return None


def private_dir(path: Path, *, replace: bool = False, probe: bool = True) -> str | None:
    """Make ``path`` a private directory of this user's, or say why it is not one (None: it is, now).

    Missing components are made mode 0700.  The parents must pass :func:`chain_problem`.  An existing ``path``
    that is a link, not a directory, another user's, or writable by others is refused, or with ``replace`` (for a
    folder the package made itself) renamed away and made anew with a
    :class:`~peelapprox.errors.KernelCacheWarning`.  With ``probe``, a temporary file is made in it (it must be
    writable).  Checked in full once per process; later calls only ``lstat`` it again."""
    d = Path(os.path.abspath(path))
    with _LOCK:
        try:
            st = os.lstat(d)
            if (str(d), st.st_dev, st.st_ino) in _CHECKED and dir_problem(st) is None:
                return None
        except OSError:
            pass
        why = chain_problem(d)
        if why is not None:
            return why
        try:
            _make(d)
            why = dir_problem(os.lstat(d))
        except OSError as exc:
            return f"cannot be made or read ({exc.strerror or exc})"
        if why is not None:
            if not replace:
                return why
            why = _replace(d, why)
            if why is not None:
                return why
            why = dir_problem(os.lstat(d))
            if why is not None:
                return why
        why = chain_problem(d)  # the parents made above: ours, 0700
        if why is not None:
            return why
        if probe:
            try:
                with tempfile.NamedTemporaryFile(dir=d, prefix=".probe-"):
                    pass
            except OSError as exc:
                return f"is not writable ({exc.strerror or exc})"
        st = os.lstat(d)
        _CHECKED.add((str(d), st.st_dev, st.st_ino))
        return None

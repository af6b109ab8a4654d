"""Checks the command line (:mod:`peelapprox.cli`) runs before any computation, and its exit statuses.

Argument types for :mod:`argparse` that reject out-of-range numbers with the
argument's name (exit status 2, no traceback), :func:`check_output_path`,
which decides the exact file name an output option writes and fails *before*
the run, not after it, when that name cannot be written, and
:func:`exit_status`, which maps an exception to the CLI's exit status.  The ranges come from
:mod:`peelapprox.validate`, so the CLI and the Python API say the same thing.
"""

from __future__ import annotations

import argparse
import contextlib
import math
import os
import re
import stat
import sys
from collections.abc import Callable, Iterator, Sequence
from typing import Any

from .. import validate as _validate
from .._checks import SHOWN_LIMIT
from ..validate import shown

__all__ = [
    "DASK_CONNECT_TIMEOUT_S",
    "add_pool_options",
    "EXIT_INTERNAL",
    "EXIT_INTERRUPTED",
    "EXIT_OK",
    "EXIT_STOP",
    "EXIT_USAGE",
    "EXIT_WRITE",
    "MESSAGE_LIMIT",
    "TRACEBACK_ENV",
    "OUTPUT_KINDS",
    "check_output_path",
    "check_sweep_plot_key",
    "clip",
    "connect_dask_scheduler",
    "exit_status",
    "finite_float_list",
    "nonnegative_float",
    "nonnegative_int",
    "one_line",
    "positive_float",
    "positive_int",
]


# --------------------------------------------------------------------------------------------- argument types

def _argtype(check: Callable[[str, float], object], text: str):
    """``check("value", text)``, its ValueError turned into argparse's "argument --x: <message>" (exit 2)."""
    try:
        x = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"value must be a real number, got {shown(text)}") from None
    try:
        return check("value", x)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def positive_float(text: str) -> float:
    """Argparse type: a finite float in (0, inf) (:func:`peelapprox.validate.positive`)."""
    return _argtype(_validate.positive, text)


def nonnegative_float(text: str) -> float:
    """Argparse type: a finite float in [0, inf) (:func:`peelapprox.validate.nonnegative`)."""
    return _argtype(_validate.nonnegative, text)


def _int_at_least(text: str, lo: int) -> int:
    """``int(text)`` if ``text`` is written as an integer (``"3"``, not ``"3.0"`` or ``"inf"``) >= ``lo``."""
    try:
        n = int(text)
    except ValueError:
        n = lo - 1
    if n < lo:
        raise argparse.ArgumentTypeError(f"value must be an integer >= {lo}, got {shown(text)}")
    return n


def positive_int(text: str) -> int:
    """Argparse type: an integer >= 1, written as one (``"3"``, not ``"3.0"`` or ``"inf"``)."""
    return _int_at_least(text, 1)


def nonnegative_int(text: str) -> int:
    """Argparse type: an integer >= 0, written as one."""
    return _int_at_least(text, 0)


def finite_float_list(text: str) -> list[float]:
    """Argparse type: a comma list of finite floats, at least one (:func:`peelapprox.validate.finite`)."""
    items = [s.strip() for s in text.split(",")]
    if not text.strip() or any(not s for s in items):
        raise argparse.ArgumentTypeError(f"value must be a comma list of numbers, got {shown(text)}")
    return [_argtype(_validate.finite, s) for s in items]


def grid_range(text: str, option: str, default_n: int = 40) -> tuple[float, float, int]:
    """``LO:HI[:N]`` (N values from LO to HI, ``default_n`` when omitted) as ``(lo, hi, n)``; ValueError naming
    ``option`` unless the numbers are finite, LO < HI and N >= 2."""
    parts = text.split(":")
    if len(parts) not in (2, 3):
        raise ValueError(f"{option} must be LO:HI or LO:HI:N, got {shown(text)}")
    try:
        lo, hi = float(parts[0]), float(parts[1])
        n = int(parts[2]) if len(parts) == 3 else default_n
    except ValueError:
        raise ValueError(f"{option} must be LO:HI[:N] with numbers, got {shown(text)}") from None
    if not (math.isfinite(lo) and math.isfinite(hi) and lo < hi and n >= 2):
        raise ValueError(f"{option} needs finite LO < HI and N >= 2, got {shown(text)}")
    return lo, hi, n


# --------------------------------------------------------------------------------------------- output paths

#: What an output option writes: ``"file"`` (any name), ``"table"`` (``.csv``/``.json``, by
#: :func:`peelapprox.io.write_rows`), ``"npz"`` (numpy's ``.npz``: appended to a name without an extension, as
#: numpy does; any other extension is refused, since numpy would write ``x.txt.npz`` for ``x.txt``), ``"image"``
#: (a matplotlib format by extension, ``.png`` appended when there is none, as matplotlib does) or ``"dir"`` (a
#: directory, created with its parents).
OUTPUT_KINDS = ("file", "table", "npz", "image", "dir")


def _image_formats() -> list[str]:
    from matplotlib.backend_bases import FigureCanvasBase

    return sorted(FigureCanvasBase.get_supported_filetypes())


def _file_name(path: str, kind: str, option: str) -> str:
    """The name a ``kind`` writer really writes for ``path`` (or ValueError for a name it refuses)."""
    if kind == "npz":
        if path.endswith(".npz"):  # numpy's test, case-sensitive: it writes x.NPZ.npz for x.NPZ
            return path
        ext = os.path.splitext(path)[1]
        if ext:
            raise ValueError(f"{option} {shown(path)}: the file is numpy's .npz, so the name must end in .npz (or "
                             f"have no extension: .npz is then appended), not {shown(ext)}")
        return path + ".npz"
    if kind == "table":
        from ..io import TABLE_EXTENSIONS

        if not path.endswith(TABLE_EXTENSIONS):
            raise ValueError(f"{option} must end in {' or '.join(TABLE_EXTENSIONS)}, got {shown(path)}")
        return path
    if kind == "image":
        ext = os.path.splitext(path)[1][1:].lower()
        if not ext:
            return path.rstrip(".") + ".png"
        formats = _image_formats()
        if ext not in formats:
            raise ValueError(f"{option} {shown(path)}: unknown image format {shown(ext)}; known: {', '.join(formats)}")
        return path
    return path


def _refuse_special(name: str, path: str, option: str) -> None:
    """ValueError if ``name`` exists and is not a regular file (a device, a FIFO, a socket): an output is written
    as a regular file, and a device given as the output (``--out /dev/full``) is a mistake to name, not a name
    to append ``.npz`` to."""
    try:
        mode = os.stat(name).st_mode
    except OSError:
        return
    if not stat.S_ISREG(mode):
        kind = ("a character device" if stat.S_ISCHR(mode) else "a block device" if stat.S_ISBLK(mode)
                else "a FIFO (named pipe)" if stat.S_ISFIFO(mode) else "a socket" if stat.S_ISSOCK(mode)
                else "not a regular file")
        what = "" if name == path else f" would write {shown(name)}, which"
        raise ValueError(f"{option} {shown(path)}{what} is {kind}; an output must be a regular file")


def _writable_dir(d: str) -> bool:
    return os.access(d, os.W_OK | os.X_OK)


def check_output_path(path: str, kind: str, option: str, *, read_only_ok: bool = False) -> str:
    """The exact path an output option will write, checked before any computation.

    Parameters
    ----------
    path : str
        As the user gave it.
    kind : str
        One of :data:`OUTPUT_KINDS`.
    option : str
        The option's name for messages, e.g. ``"--out"``.
    read_only_ok : bool
        ``kind="dir"`` only: an existing directory need not be writable (a
        complete sweep is only read).

    Returns
    -------
    str
        The name written: ``path``, or ``path`` with the extension the writer
        appends (``.npz``, ``.png``).  Print this one.

    Raises
    ------
    ValueError
        Naming ``option`` and the path: an empty path; a file output that is
        an existing directory, or whose directory is missing, not a directory
        or not writable; a name the writer refuses (extension) or the file
        system cannot hold (too long); a directory output that is an existing
        file, or that cannot be created.
    """
    if kind not in OUTPUT_KINDS:
        raise ValueError(f"kind must be one of {OUTPUT_KINDS}, got {shown(kind)}")
    if not path:
        raise ValueError(f"{option} must not be empty")
    if kind == "dir":
        if os.path.exists(path):
            if not os.path.isdir(path):
                raise ValueError(f"{option} {shown(path)} exists and is not a directory")
            if not read_only_ok and not _writable_dir(path):
                raise ValueError(f"{option} {shown(path)}: directory is not writable")
            return path
        parent = os.path.dirname(os.path.normpath(path))
        while parent and not os.path.exists(parent):  # the nearest existing ancestor: makedirs creates the rest
            parent = os.path.dirname(parent)
        parent = parent or "."
        if not os.path.isdir(parent):
            raise ValueError(f"{option} {shown(path)}: cannot create it, {shown(parent)} is not a directory")
        if not _writable_dir(parent):
            raise ValueError(f"{option} {shown(path)}: cannot create it, directory {shown(parent)} is not writable")
        return path
    if os.path.isdir(path):
        raise ValueError(f"{option} {shown(path)} is a directory, expected a file name")
    _refuse_special(path, path, option)  # /dev/full: not silently /dev/full.npz beside it
    name = _file_name(path, kind, option)
    if os.path.isdir(name):
        raise ValueError(f"{option} {shown(path)} would write {shown(name)}, which is a directory")
    _refuse_special(name, path, option)
    parent = os.path.dirname(name) or "."
    if not os.path.exists(parent):
        raise ValueError(f"{option} {shown(path)}: directory {shown(parent)} does not exist")
    if not os.path.isdir(parent):
        raise ValueError(f"{option} {shown(path)}: {shown(parent)} is not a directory")
    if not _writable_dir(parent) or (os.path.exists(name) and not os.access(name, os.W_OK)):
        raise ValueError(f"{option} {shown(path)}: not writable")
    longest = _name_max(parent)
    if len(os.fsencode(os.path.basename(name))) > longest:
        raise ValueError(f"{option} {shown(path)}: the file name is longer than the {longest} bytes the file system "
                         "allows")
    return name


def _name_max(directory: str) -> int:
    """The longest file name [bytes] in ``directory`` (``pathconf``), 255 where the system does not say."""
    try:
        return int(os.pathconf(directory, "PC_NAME_MAX"))
    except (AttributeError, ValueError, OSError):
        return 255


def check_sweep_plot_key(key: str, measures: Sequence[str]) -> None:
    """Before a sweep: ValueError unless ``key`` can be a record key of ``measures``.

    Record keys are the engine's (``I``, ``V``, ``status``) and the measures'
    keys, which the engine prefixes ``"<measure>_"`` (:func:`comparisons.sweep.record_key`,
    reused here so the rule stays in one place).  Which suffixes a measure
    returns is known only after it ran; the CLI checks the exact key again then.
    """
    from comparisons.sweep import RESERVED, record_key

    if os.sep in key or (os.altsep and os.altsep in key):
        raise ValueError(f"--plot {shown(key)}: a record key has no path separator (the plot goes to DIR/KEY.png)")
    if key in RESERVED or any(record_key(m, key) == key for m in measures):
        return
    raise ValueError(f"--plot {shown(key)} is not a key of the measures {list(measures)}: keys are "
                     f"{', '.join(RESERVED)} or start with {', '.join(m + '_' for m in measures)}")


#: Seconds ``sweep --dask-scheduler`` waits for the scheduler before giving up.
DASK_CONNECT_TIMEOUT_S = 10.0


def connect_dask_scheduler(address: str):
    """A ``distributed.Client`` on the scheduler at ``address``, or OSError within :data:`DASK_CONNECT_TIMEOUT_S`.

    Raises
    ------
    ValueError
        A malformed address (dask's message, e.g. a missing port).
    OSError
        Naming ``--dask-scheduler`` and the address: nothing answered in
        time, or what answered is not a dask scheduler.
    """
    from distributed import Client

    try:
        return Client(address, timeout=DASK_CONNECT_TIMEOUT_S)
    except ValueError as exc:
        raise ValueError(f"--dask-scheduler {shown(address)}: {one_line(exc)}") from None
    except Exception as exc:  # noqa: BLE001 - whatever a wrong address provokes in dask (timeout, garbage reply)
        raise OSError(f"--dask-scheduler {shown(address)}: cannot connect to a dask scheduler "
                      f"({type(exc).__name__}: {one_line(exc)})") from None


#: Longest message :func:`one_line` prints [characters]: ten lines of a wide terminal.
MESSAGE_LIMIT = 2000




#: ``--pool``'s help: what each local pool is, and the default (peelapprox.parallel).
POOL_HELP = ("local pool: 'processes' (loky's reusable process pool: tasks by cloudpickle, one BLAS thread per "
             "worker), 'threads', or 'auto' (default: processes on more than 2 CPUs, threads on 1-2; the "
             "environment variable PEELAPPROX_POOL overrides it)")


def add_pool_options(parser: argparse.ArgumentParser, *, dask: bool = True) -> None:
    """``--pool``, and ``--workers``, ``--dask-local`` and ``--dask-scheduler`` (mutually exclusive) of a grid
    command (sweep, atlas; basins without the dask options), which :func:`worker_pool` reads."""
    parser.add_argument("--pool", choices=("auto", "threads", "processes"), default="auto", help=POOL_HELP)
    where = parser.add_mutually_exclusive_group() if dask else parser
    where.add_argument("--workers", type=nonnegative_int, default=None, metavar="N",
                       help="local workers, processes or threads as --pool says (default: all CPUs; 0: in this "
                            "process)")
    if not dask:
        return
    where.add_argument("--dask-local", type=positive_int, default=None, metavar="N",
                       help="start a dask LocalCluster with N single-threaded worker processes")
    where.add_argument("--dask-scheduler", default=None, metavar="ADDR",
                       help="connect to a running dask scheduler, e.g. tcp://host:8786")

@contextlib.contextmanager
def worker_pool(args: argparse.Namespace) -> Iterator[tuple[Any, int | None]]:
    """``(executor, max_workers)`` of a grid command's ``--pool``, ``--workers``, ``--dask-local`` and
    ``--dask-scheduler`` (sweep, atlas): a dask client's executor, or ``--pool`` (a pool of
    :mod:`peelapprox.parallel`) and ``--workers`` (0: in this process); the dask client
    and local cluster are closed on exit.

    Raises
    ------
    ValueError
        A dask option without dask.distributed installed.
    """
    if not (args.dask_local or args.dask_scheduler):
        yield getattr(args, "pool", None), args.workers
        return
    try:
        from distributed import Client, LocalCluster
    except ImportError:
        raise ValueError("--dask-local/--dask-scheduler need dask.distributed: pip install "
                         "'peelapprox[distributed]'") from None
    cluster = None
    if args.dask_local:
        cluster = LocalCluster(n_workers=args.dask_local, threads_per_worker=1, dashboard_address=None)
        client = Client(cluster)
    else:
        client = connect_dask_scheduler(args.dask_scheduler)
    print(f"dask: {client}", file=sys.stderr)
    try:
        yield client.get_executor(), None
    finally:
        client.close()
        if cluster is not None:
            cluster.close()

def clip(text: str, limit: int = SHOWN_LIMIT) -> str:
    """``text`` with every run of more than ``limit`` non-blank characters cut as :func:`peelapprox.validate.shown`
    cuts a value (its first ``limit`` characters, then ``... (N characters)``): what a message echoes of a
    user's input (an option's value, a path, a name) stays short even where the message did not use ``shown``."""
    # runs up to limit + 3 pass: shown()'s own cut (limit characters and "...") is not cut a second time
    return re.sub(rf"\S{{{limit + 4},}}", lambda m: f"{m.group()[:limit]}... ({len(m.group())} characters)", text)


def one_line(exc: BaseException) -> str:
    """The exception's message on one line (whitespace runs, newlines included, become one space), each overlong
    word cut (:func:`clip`) and the whole at most :data:`MESSAGE_LIMIT` characters (then ``... (N characters)``)."""
    text = clip(" ".join(str(exc).split())) or type(exc).__name__
    if len(text) > MESSAGE_LIMIT:
        text = f"{text[:MESSAGE_LIMIT]}... ({len(text)} characters)"
    return text


# --------------------------------------------------------------------------------------------- exit statuses

def _loaded(module: str, name: str) -> tuple[type, ...]:
    """``module.name`` if the subcommand imported that module, else nothing (the CLI loads no package it does
    not use: ``peelapprox folds`` never imports the harness)."""
    mod = sys.modules.get(module)
    found = getattr(mod, name, None) if mod is not None else None
    return (found,) if isinstance(found, type) else ()


#: Exit status of the command line (:func:`exit_status`, :func:`peelapprox.cli.main`): the run completed.
EXIT_OK = 0
#: Writing failed after the checks (an ``OSError``: disk full, a path changed meanwhile); for ``sweep``, a point
#: failed.
EXIT_WRITE = 1
#: A usage error: a bad argument or output path, a missing optional package (a ``ValueError``).
EXIT_USAGE = 2
#: The model or the solver stopped (ModelBreakdown, SolverBudgetExceeded, SolverFailure, TransientNotPassed).
EXIT_STOP = 3
#: An internal error: any other exception, a bug of peelapprox, reported on one line (the traceback only with
#: :data:`TRACEBACK_ENV` set), so that a script can tell it from the user's errors and the model's stops.
EXIT_INTERNAL = 4
#: Interrupted by the user (Ctrl-C, SIGINT): 128 + 2, the shells' convention.
EXIT_INTERRUPTED = 130
#: The environment variable that makes :func:`peelapprox.cli.main` re-raise an internal error with its
#: traceback (set it to 1).
TRACEBACK_ENV = "PEELAPPROX_TRACEBACK"


def exit_status(exc: BaseException) -> int | None:
    """:data:`EXIT_USAGE` (2) for a bad argument, output path or missing optional package; :data:`EXIT_STOP` (3)
    when the model or solver stopped; :data:`EXIT_WRITE` (1) when writing failed after the checks (disk full, a
    path changed meanwhile); None for anything else (an internal error, :data:`EXIT_INTERNAL`)."""
    from ..errors import ModelBreakdown, SolverBudgetExceeded, SolverFailure
    from ..kernels._diffsl import PeerUnavailableError

    if isinstance(exc, (ValueError, PeerUnavailableError)):
        return EXIT_USAGE
    if isinstance(exc, (ModelBreakdown, SolverBudgetExceeded, SolverFailure,
                        *_loaded("comparisons", "TransientNotPassed"))):
        return EXIT_STOP
    if isinstance(exc, OSError):
        return EXIT_WRITE
    return None

"""Atomic file writes: a temporary file in the target's folder, then :func:`os.replace`.

A reader never sees a half-written file, and a failed write leaves the previous file (or no
file) in place. Use :func:`atomic_write_bytes` / :func:`atomic_write_text` for data in memory and
:func:`atomic_path` for libraries that write by file name (h5py, matplotlib, Pillow)::

    with atomic_path("run/results.h5") as tmp:
        with h5py.File(tmp, "w") as h5:
            ...

The temporary file keeps the target's suffix (``.png``, ``.gif`` …) so that libraries that
infer the format from the name still work. The parent folder must exist.

Folders (a run's results) are written with :func:`atomic_folder`: into a temporary sibling
folder, then swapped onto the target in one atomic step (Linux ``renameat2`` with
``RENAME_EXCHANGE``), so a reader sees the old results or the new ones, never neither.

Temporaries are named ``.<name>.tmp-<host>-<pid>-<random>`` (and ``.<name>.old-…`` for the
previous results during a replacement where no atomic exchange exists). A process killed
outright (SIGKILL, power loss) cannot clean up; the next atomic write in the same folder
finds temporaries whose process is gone (:func:`remove_stale`) and removes them — restoring
previous results that a replacement had moved aside if the target is missing. The CLI turns
SIGTERM into a clean exit, so ``timeout`` and batch schedulers leave nothing behind.
"""

from __future__ import annotations

import contextlib
import ctypes
import ctypes.util
import logging
import os
import re
import shutil
import socket
import tempfile
from collections.abc import Iterator
from pathlib import Path

from rotomorph.errors import InvalidParameterError

__all__ = [
    "atomic_folder",
    "atomic_path",
    "atomic_write_bytes",
    "atomic_write_text",
    "check_writable",
    "remove_stale",
    "temporary_prefix",
]

logger = logging.getLogger(__name__)
_HOST = re.sub(r"[^A-Za-z0-9]", "", socket.gethostname())[:32] or "host"
_STALE = re.compile(
    r"^\.(?P<name>.+)\.(?P<kind>tmp|old)-(?P<host>[A-Za-z0-9]+)-(?P<pid>\d+)-[A-Za-z0-9_]+"
)


def _current_umask() -> int:
    # os.umask can only be read by setting it; done once at import (single-threaded then)
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


_UMASK = _current_umask()


def _fsync_dir(folder: Path) -> None:
    """Flush the directory entry (POSIX); a no-op where directories cannot be opened."""
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def _remove_quietly(path: Path) -> None:
    with contextlib.suppress(FileNotFoundError):
        os.unlink(path)


def temporary_prefix(target: Path, kind: str = "tmp") -> str:
    """Prefix of the temporaries of ``target``: ``.<name>.<kind>-<host>-<pid>-``."""
    return f".{target.name}.{kind}-{_HOST}-{os.getpid()}-"


def _alive(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError):
        return True  # someone else's process (or not a pid we can test): leave it
    return True


def remove_stale(folder: str | os.PathLike[str]) -> list[Path]:
    """Remove temporaries in ``folder`` left by processes of this host that no longer run.

    A stale ``.<name>.old-…`` (previous results moved aside by a replacement that was killed
    half way) is renamed back onto ``<name>`` if that is missing, else removed. Temporaries
    of live processes, of other hosts and any other file are left alone.

    Returns
    -------
    list of pathlib.Path
        What was removed or restored (logged at INFO).
    """
    done: list[Path] = []
    try:
        entries = list(os.scandir(folder))
    except OSError:
        return done
    for entry in entries:
        m = _STALE.match(entry.name)
        if m is None or m["host"] != _HOST or _alive(int(m["pid"])):
            continue
        path = Path(entry.path)
        target = path.parent / m["name"]
        try:
            if m["kind"] == "old" and not target.exists() and not target.is_symlink():
                os.rename(path, target)
                logger.info("restored %s from an interrupted replacement", target)
            elif entry.is_dir(follow_symlinks=False):
                shutil.rmtree(path)
                logger.info("removed stale temporary folder %s", path)
            else:
                os.unlink(path)
                logger.info("removed stale temporary file %s", path)
        except FileNotFoundError:
            continue  # another process cleaned it first
        done.append(path)
    return done


_CLEANED: set[str] = set()


def _remove_stale_once(folder: Path) -> None:
    """:func:`remove_stale` once per folder and process (a sweep writes thousands of files)."""
    key = os.path.realpath(folder)
    if key not in _CLEANED:
        _CLEANED.add(key)
        remove_stale(folder)


def check_writable(path: str | os.PathLike[str], field: str, *, create_parent: bool) -> Path:
    """Refuse, before any work, an output ``path`` whose folder cannot take a new file.

    Parameters
    ----------
    path
        The file or folder to be written; its parent folder receives the temporaries.
    field
        Name of the option or argument that gave ``path`` (e.g. ``"-o/--output"``).
    create_parent
        Create missing parent folders (else a missing parent is refused).

    Returns
    -------
    pathlib.Path
        The parent folder.

    Raises
    ------
    InvalidParameterError
        The parent (or a folder above it) is a file, is missing (without ``create_parent``),
        cannot be created, or does not accept a new file (read-only, a virtual file system).
    """
    target = Path(path)
    parent = target.parent if str(target.parent) else Path(".")
    above = parent
    while not above.exists() and above != above.parent:
        above = above.parent
    if above.exists() and not above.is_dir():
        raise InvalidParameterError(
            field, f"{path}: {above} is a file, not a folder; choose another path"
        )
    if not parent.exists():
        if not create_parent:
            raise InvalidParameterError(
                field, f"{path}: folder {parent} does not exist; create it first"
            )
        try:
            parent.mkdir(parents=True, exist_ok=True)
        except OSError as err:
            raise InvalidParameterError(
                field, f"{path}: cannot create folder {parent} ({err.strerror or err})"
            ) from None
    try:
        with tempfile.TemporaryFile(dir=parent, prefix=temporary_prefix(target)):
            pass
    except OSError as err:
        raise InvalidParameterError(
            field,
            f"{path}: cannot write in {parent} ({err.strerror or err}); choose a folder you "
            "can write to",
        ) from None
    return parent


def _cannot_write(err: OSError, target: Path, folder: Path) -> OSError:
    """``err`` (from creating a temporary in ``folder``) re-addressed to ``target``."""
    why = f"cannot write in {folder} ({err.strerror or err})"
    return type(err)(err.errno, why, str(target)) if err.errno else OSError(why)


_RENAME_EXCHANGE = 2


def _exchange(a: Path, b: Path) -> bool:
    """Swap two paths atomically (Linux ``renameat2(RENAME_EXCHANGE)``); False if unsupported."""
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6", use_errno=True)
        renameat2 = libc.renameat2
    except (OSError, AttributeError):
        return False
    at_fdcwd = -100
    rc = renameat2(at_fdcwd, os.fsencode(a), at_fdcwd, os.fsencode(b), _RENAME_EXCHANGE)
    if rc == 0:
        return True
    err = ctypes.get_errno()
    if err in (22, 38, 95):  # EINVAL, ENOSYS, EOPNOTSUPP: file system or kernel cannot
        return False
    raise OSError(err, os.strerror(err), str(b))


@contextlib.contextmanager
def atomic_folder(path: str | os.PathLike[str]) -> Iterator[Path]:
    """Yield an empty temporary folder next to ``path``; put it onto ``path`` on success.

    Parameters
    ----------
    path
        The folder to (re)place. Its parent must exist; an existing folder of that name is
        replaced (the caller decides whether that is allowed).

    Notes
    -----
    An existing target is swapped with the new folder in one atomic step where the system
    allows it (Linux ``renameat2``), else moved aside to ``.<name>.old-…`` just before the new
    folder is renamed into place (a window of two renames, repaired by :func:`remove_stale`
    if the process dies inside it). On an exception (also a SIGTERM turned into one) the
    temporary folder is removed and ``path`` is untouched. Stale temporaries of dead
    processes in the parent folder are removed first.
    """
    target = Path(path)
    parent = target.parent if str(target.parent) else Path(".")
    remove_stale(parent)
    try:
        tmp = Path(tempfile.mkdtemp(prefix=temporary_prefix(target), dir=parent))
    except OSError as err:
        raise _cannot_write(err, target, parent) from None
    try:
        yield tmp
        os.chmod(tmp, 0o777 & ~_UMASK)
        if target.is_dir() and not target.is_symlink():
            if not _exchange(tmp, target):
                old = Path(tempfile.mkdtemp(prefix=temporary_prefix(target, "old"), dir=parent))
                os.rmdir(old)
                os.rename(target, old)
                os.rename(tmp, target)
                tmp = old
            shutil.rmtree(tmp, ignore_errors=True)  # now the previous results
        else:
            os.replace(tmp, target)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    _fsync_dir(parent)


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike[str], *, fsync: bool = True) -> Iterator[Path]:
    """Yield a temporary path next to ``path``; move it onto ``path`` when the block succeeds.

    Parameters
    ----------
    path
        Final file name. Its folder must exist (else :class:`FileNotFoundError`).
    fsync
        Flush the file and its folder to disk before and after the rename (default).

    Yields
    ------
    pathlib.Path
        An empty, already created temporary file ``.<name>.tmp-<host>-<pid>-<random><suffix>``
        in the same folder; the caller (or the library it calls) overwrites it. Stale
        temporaries of dead processes in that folder are removed first (:func:`remove_stale`).

    Notes
    -----
    If the block raises, the temporary file is deleted, ``path`` is left untouched and the
    exception propagates. If the block removes the temporary file itself, nothing is moved and
    :class:`FileNotFoundError` is raised. The final file gets the usual permissions
    (``0o666`` less the process umask), not the private mode of the temporary file.
    """
    target = Path(path)
    folder = target.parent if str(target.parent) else Path(".")
    _remove_stale_once(folder)
    try:
        fd, name = tempfile.mkstemp(
            dir=folder, prefix=temporary_prefix(target), suffix=target.suffix
        )
    except OSError as err:  # name the file asked for, not the temporary one
        raise _cannot_write(err, target, folder) from None
    os.close(fd)
    tmp = Path(name)
    try:
        yield tmp
        os.chmod(tmp, 0o666 & ~_UMASK)
        if fsync:
            with open(tmp, "rb+") as fh:
                os.fsync(fh.fileno())
        os.replace(tmp, target)
    except BaseException:
        _remove_quietly(tmp)
        raise
    if fsync:
        _fsync_dir(folder)


def atomic_write_bytes(path: str | os.PathLike[str], data: bytes, *, fsync: bool = True) -> Path:
    """Write ``data`` to ``path`` atomically and return the path.

    Parameters
    ----------
    path
        Destination file; its folder must exist.
    data
        Bytes to write (``b""`` writes an empty file).
    fsync
        Flush to disk before the rename (default).
    """
    target = Path(path)
    with atomic_path(target, fsync=fsync) as tmp, open(tmp, "wb") as fh:
        fh.write(bytes(data))
    return target


def atomic_write_text(
    path: str | os.PathLike[str], text: str, *, encoding: str = "utf-8", fsync: bool = True
) -> Path:
    """Write ``text`` to ``path`` atomically in ``encoding`` and return the path."""
    return atomic_write_bytes(path, text.encode(encoding), fsync=fsync)

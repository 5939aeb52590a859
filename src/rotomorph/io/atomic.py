"""Atomic file writes: a temporary file in the target's folder, then :func:`os.replace`.

A reader never sees a half-written file, and a failed write leaves the previous file (or no
file) in place. Use :func:`atomic_write_bytes` / :func:`atomic_write_text` for data in memory and
:func:`atomic_path` for libraries that write by file name (h5py, matplotlib, Pillow)::

    with atomic_path("run/results.h5") as tmp:
        with h5py.File(tmp, "w") as h5:
            ...

The temporary file keeps the target's suffix (``.png``, ``.gif`` …) so that libraries that
infer the format from the name still work. The parent folder must exist.
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Iterator
from pathlib import Path

__all__ = ["atomic_path", "atomic_write_bytes", "atomic_write_text"]


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
        An empty, already created temporary file ``.<name>.tmp-<random><suffix>`` in the same
        folder; the caller (or the library it calls) overwrites it.

    Notes
    -----
    If the block raises, the temporary file is deleted, ``path`` is left untouched and the
    exception propagates. If the block removes the temporary file itself, nothing is moved and
    :class:`FileNotFoundError` is raised. The final file gets the usual permissions
    (``0o666`` less the process umask), not the private mode of the temporary file.
    """
    target = Path(path)
    folder = target.parent if str(target.parent) else Path(".")
    fd, name = tempfile.mkstemp(dir=folder, prefix=f".{target.name}.tmp-", suffix=target.suffix)
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

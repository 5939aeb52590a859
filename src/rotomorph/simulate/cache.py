"""A disk cache for expensive, deterministic results of the paper report.

A result is stored under a key that hashes its arguments together with the bytes of every
source and data file of the installed ``rotomorph`` package, so any change of code or data
recomputes it; nothing stale can be served. The folder is ``$ROTOMORPH_CACHE_DIR`` or
``~/.cache/rotomorph``; ``ROTOMORPH_CACHE_DIR=off`` disables caching. Files are written
atomically (:func:`rotomorph.io.atomic.atomic_write_bytes`); an unreadable entry is recomputed.
Processes sharing the folder (two runs at once, a test suite's workers) compute an entry once:
while one computes it, the others wait on its lock file (``fcntl.flock``, released by the
system if that process dies) and then read it.
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import logging
import os
import pickle
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any, TypeVar

import rotomorph
from rotomorph.io.atomic import atomic_write_bytes

__all__ = ["cache_folder", "disk_cached", "source_digest"]

logger = logging.getLogger(__name__)

T = TypeVar("T")


@functools.lru_cache(maxsize=1)
def source_digest() -> str:
    """SHA-256 over the package's ``.py`` and data files (paths and contents)."""
    root = Path(rotomorph.__file__).resolve().parent
    h = hashlib.sha256(rotomorph.__version__.encode())
    for path in sorted(root.rglob("*")):
        if path.suffix in (".py", ".csv", ".json", ".toml") and "__pycache__" not in path.parts:
            h.update(str(path.relative_to(root)).encode())
            h.update(path.read_bytes())
    return h.hexdigest()


def cache_folder() -> Path | None:
    """The cache folder, or ``None`` when caching is off."""
    env = os.environ.get("ROTOMORPH_CACHE_DIR", "")
    if env.strip().lower() == "off":
        return None
    return Path(env) if env else Path.home() / ".cache" / "rotomorph"


def disk_cached(name: str, key: str, compute: Callable[[], T]) -> T:
    """``compute()``, or its cached result for ``(name, key, source_digest())``.

    Parameters
    ----------
    name
        Label of the result (file-name prefix).
    key
        Everything else the result depends on, as text (e.g. ``repr`` of the arguments).
    compute
        Deterministic function producing a picklable result.
    """
    folder = cache_folder()
    if folder is None:
        return compute()
    digest = hashlib.sha256(f"{name}\0{key}\0{source_digest()}".encode()).hexdigest()[:32]
    path = folder / f"{name}-{digest}.pickle"
    found = _read(path)
    if found is not None:
        return found[0]
    with _entry_lock(path):
        found = _read(path)  # computed by another process while this one waited
        if found is not None:
            return found[0]
        return _compute_and_store(path, compute)


def _read(path: Path) -> tuple[Any] | None:
    """``(value,)`` of a readable cache entry, else ``None``."""
    if not path.is_file():
        return None
    try:
        with path.open("rb") as fh:
            return (pickle.load(fh),)
    except Exception as err:
        logger.warning("cache entry %s unreadable (%s); recomputing", path, err)
        return None


@contextlib.contextmanager
def _entry_lock(path: Path) -> Iterator[None]:
    """Hold ``path``'s lock file while its entry is computed (no lock where the folder cannot
    be written or the system has no ``fcntl``: the entry is then just computed)."""
    try:
        import fcntl
    except ImportError:  # pragma: no cover - Windows
        yield
        return
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fh = path.with_suffix(".lock").open("a+b")
    except OSError as err:
        logger.debug("no lock for cache entry %s: %s", path, err)
        yield
        return
    with fh:
        fcntl.flock(fh, fcntl.LOCK_EX)
        yield


def _compute_and_store(path: Path, compute: Callable[[], T]) -> T:
    folder = path.parent
    result = compute()
    try:
        folder.mkdir(parents=True, exist_ok=True)
        atomic_write_bytes(path, pickle.dumps(result, protocol=pickle.HIGHEST_PROTOCOL))
    except OSError as err:
        logger.warning("could not write cache entry %s: %s", path, err)
    return result

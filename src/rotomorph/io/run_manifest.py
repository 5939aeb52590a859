"""The record a command leaves in its output folder, so that a second run of the same command
can recognise its own previous output and replace it, and never anything else.

``rotomorph-run.json`` lists every file the run wrote with its SHA-256::

    {"command": "paper", "version": "0.3.0", "files": {"report.md": "9f2c…", ...}}

:func:`previous_run` accepts a folder only when it holds a previous run of the same command
exactly as that run left it (files deleted since are fine): a file the run did not write, a
file changed since, a link, or a folder without the record is someone else's content, and the
command refuses the folder (``--force`` replaces it anyway).
"""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path

from rotomorph.io.atomic import atomic_write_text

__all__ = ["MANIFEST", "previous_run", "write_manifest"]

#: File name of the record, at the top of the output folder.
MANIFEST = "rotomorph-run.json"


def _sha256(path: Path) -> str:
    h = hashlib.sha256()
    with path.open("rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def _entries(folder: Path) -> tuple[list[str], list[str]]:
    """(files, other entries: links, special files, empty folders) under ``folder``, as
    POSIX paths relative to it; links are never followed."""
    files: list[str] = []
    other: list[str] = []
    for root, dirs, names in os.walk(folder, followlinks=False):
        here = Path(root)
        for d in list(dirs):
            p = here / d
            if p.is_symlink():
                other.append(p.relative_to(folder).as_posix())
                dirs.remove(d)
            elif not any(p.iterdir()):
                other.append(p.relative_to(folder).as_posix() + "/")
        for name in names:
            p = here / name
            rel = p.relative_to(folder).as_posix()
            (files if p.is_file() and not p.is_symlink() else other).append(rel)
    return sorted(files), sorted(other)


def write_manifest(folder: str | os.PathLike[str], command: str) -> Path:
    """Record every file under ``folder`` as written by ``command`` (call it last)."""
    import rotomorph

    out = Path(folder)
    files, _ = _entries(out)
    record = {
        "command": command,
        "version": rotomorph.__version__,
        "files": {f: _sha256(out / f) for f in files if f != MANIFEST},
    }
    return atomic_write_text(out / MANIFEST, json.dumps(record, indent=1, sort_keys=True) + "\n")


def previous_run(folder: str | os.PathLike[str], command: str) -> str | None:
    """``None`` when ``folder`` holds a previous run of ``command`` and nothing else (so it
    may be replaced), else why not, as a phrase naming the first offending entry."""
    out = Path(folder)
    record_path = out / MANIFEST
    if not record_path.is_file() or record_path.is_symlink():
        return f"it holds files that are not a previous `rotomorph {command}` run (no {MANIFEST})"
    try:
        record = json.loads(record_path.read_text(encoding="utf-8"))
        recorded = record["files"]
        ok = isinstance(recorded, dict) and all(isinstance(v, str) for v in recorded.values())
        if not ok or not isinstance(record.get("command"), str):
            raise ValueError("malformed")
    except (OSError, ValueError, KeyError, TypeError):
        return f"its {MANIFEST} is unreadable"
    if record["command"] != command:
        return f"it holds a previous `rotomorph {record['command']}` run, not `{command}`"
    files, other = _entries(out)
    # an emptied folder of the run (its files deleted since) is the run's; anything else not
    for entry in other:
        if not (entry.endswith("/") and any(f.startswith(entry) for f in recorded)):
            return f"it holds {entry}, which is not a file the previous run wrote"
    for rel in files:
        if rel == MANIFEST:
            continue
        if rel not in recorded:
            return f"it holds {rel}, which the previous run did not write"
        if _sha256(out / rel) != recorded[rel]:
            return f"{rel} was changed since the previous run wrote it"
    return None

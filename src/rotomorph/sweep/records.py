"""The record of one finished sweep run: its schema, its checksum, and the check on reading.

A record is one JSON object (``runs/<id[:2]>/<id>.json``)::

    {"record_format": 1, "run_id": "<64 hex>", "status": "ok" | "invalid" | "failed",
     "metrics": {...}, "error": null | {"type", "message", "diagnostics"},
     "warnings": [...], "wall_time_s": 1.2, "version": "0.1.0", "host": "...", "pid": 123,
     "results_sha256": null | "<64 hex>", "checksum": "<64 hex>"}

``checksum`` is the sha256 of the canonical JSON (sorted keys, no spaces) of every other key;
``results_sha256`` that of the run's HDF5 file, when one was written. A sweep trusts a record
only when :func:`check_record` accepts it: at most :data:`MAX_RECORD_BYTES`, UTF-8 JSON, the
schema above (metric values of the type :data:`~rotomorph.sweep.metrics.METRICS` gives them),
its ``run_id`` the file's name, its checksum right, and its HDF5 file (if any) present with the
same sha256. A record that fails (truncated by a full disk, emptied, overwritten with binary,
copied under another run's id, edited by hand) is reported by :class:`DamagedRecord` with the
reason, and the sweep computes that run again.
"""

from __future__ import annotations

import hashlib
import json
import math
import re
from collections.abc import Mapping
from pathlib import Path
from typing import Any, Final

from rotomorph.sweep.metrics import METRICS

__all__ = [
    "MAX_RECORD_BYTES",
    "RECORD_FORMAT",
    "DamagedRecord",
    "check_record",
    "file_sha256",
    "seal_record",
]

#: Version of the record layout (the module docstring).
RECORD_FORMAT: Final = 1
#: Largest record read (bytes): a record is a few kB (metrics, at most 20 warnings).
MAX_RECORD_BYTES: Final = 1024 * 1024
_HEX64: Final = re.compile(r"^[0-9a-f]{64}$")
_STATUSES: Final = ("ok", "invalid", "failed")
_TYPES: Final = {"float": (int, float), "int": (int,), "str": (str,), "bool": (bool,)}
_DTYPE: Final[dict[tuple[str, str], str]] = {(m.scope, m.name): m.dtype for m in METRICS}


class DamagedRecord(Exception):
    """A record that cannot be trusted; the message says why (one line)."""


def _canonical(record: Mapping[str, Any]) -> bytes:
    body = {k: v for k, v in record.items() if k != "checksum"}
    return json.dumps(body, sort_keys=True, separators=(",", ":"), allow_nan=False).encode()


def file_sha256(path: Path) -> str:
    """sha256 (hex) of a file's bytes, read in 1 MiB blocks."""
    digest = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def seal_record(record: Mapping[str, Any], results_sha256: str | None = None) -> dict[str, Any]:
    """``record`` with ``record_format``, ``results_sha256`` and its ``checksum`` set."""
    out = {k: v for k, v in record.items() if k != "checksum"}
    out["record_format"] = RECORD_FORMAT
    out["results_sha256"] = results_sha256
    out["checksum"] = hashlib.sha256(_canonical(out)).hexdigest()
    return out


def _is_json_value(value: Any, depth: int = 0) -> bool:
    if depth > 16:
        return False
    if value is None or isinstance(value, bool | int | str):
        return True
    if isinstance(value, float):
        return math.isfinite(value)
    if isinstance(value, list):
        return all(_is_json_value(v, depth + 1) for v in value)
    if isinstance(value, dict):
        return all(isinstance(k, str) and _is_json_value(v, depth + 1) for k, v in value.items())
    return False


def _check_metrics(metrics: Any) -> None:
    if not isinstance(metrics, dict):
        raise DamagedRecord("metrics is not a table")
    groups: list[tuple[str, Any]] = []
    if "lattice" in metrics:
        groups.append(("lattice", metrics["lattice"]))
    filaments = metrics.get("filaments", [])
    if not isinstance(filaments, list):
        raise DamagedRecord("metrics.filaments is not a list")
    groups += [("filament", f) for f in filaments]
    for scope, values in groups:
        if not isinstance(values, dict):
            raise DamagedRecord(f"metrics of a {scope} are not a table")
        for name, value in values.items():
            dtype = _DTYPE.get((scope, name))
            if value is None or dtype is None:
                if not _is_json_value(value):
                    raise DamagedRecord(f"metric {name!r} is not a JSON value")
                continue
            ok = isinstance(value, _TYPES[dtype]) and (dtype == "bool") == isinstance(value, bool)
            if not ok or (isinstance(value, float) and not math.isfinite(value)):
                raise DamagedRecord(f"metric {name!r} is not a {dtype}: {value!r:.40}")
    physical = metrics.get("physical", {})
    if not isinstance(physical, dict) or not all(
        v is None or isinstance(v, str) for v in physical.values()
    ):
        raise DamagedRecord("metrics.physical is not a table of texts")


def _check_schema(rec: Any) -> None:
    if not isinstance(rec, dict):
        raise DamagedRecord("is not a JSON object")
    if rec.get("record_format") != RECORD_FORMAT:
        raise DamagedRecord(f"record_format is {rec.get('record_format')!r}, not {RECORD_FORMAT}")
    for key in ("run_id", "checksum"):
        if not isinstance(rec.get(key), str) or not _HEX64.match(rec[key]):
            raise DamagedRecord(f"{key} is not a sha256")
    if rec.get("status") not in _STATUSES:
        raise DamagedRecord(f"status {rec.get('status')!r:.40} is not one of {_STATUSES}")
    _check_metrics(rec.get("metrics"))
    err = rec.get("error")
    if err is not None and not (
        isinstance(err, dict)
        and isinstance(err.get("type"), str)
        and isinstance(err.get("message"), str)
        and isinstance(err.get("diagnostics"), dict)
        and _is_json_value(err["diagnostics"])
    ):
        raise DamagedRecord("error is not {type, message, diagnostics}")
    if (rec["status"] == "ok") != (err is None):
        raise DamagedRecord("status and error disagree")
    warnings = rec.get("warnings")
    if not isinstance(warnings, list) or not all(isinstance(w, str) for w in warnings):
        raise DamagedRecord("warnings is not a list of texts")
    wall = rec.get("wall_time_s")
    if isinstance(wall, bool) or not isinstance(wall, int | float) or not 0 <= wall < 1e9:
        raise DamagedRecord("wall_time_s is not a time in seconds")
    digest = rec.get("results_sha256")
    if digest is not None and not (isinstance(digest, str) and _HEX64.match(digest)):
        raise DamagedRecord("results_sha256 is not a sha256")


def check_record(path: Path, run_id: str) -> dict[str, Any]:
    """The record of ``run_id`` stored at ``path`` if it can be trusted (module docstring).

    Raises
    ------
    DamagedRecord
        Why it cannot (one line, without the file name).
    OSError
        The file cannot be read.
    """
    with open(path, "rb") as fh:
        data = fh.read(MAX_RECORD_BYTES + 1)
    if not data:
        raise DamagedRecord("is empty")
    if len(data) > MAX_RECORD_BYTES:
        raise DamagedRecord(f"is larger than {MAX_RECORD_BYTES} bytes")
    try:
        rec = json.loads(data.decode("utf-8"))
    except UnicodeDecodeError:
        raise DamagedRecord("is not UTF-8 text (binary?)") from None
    except json.JSONDecodeError as err:
        raise DamagedRecord(f"is not JSON ({err.msg} at offset {err.pos}; truncated?)") from None
    except RecursionError:
        raise DamagedRecord("is not JSON (nested too deeply)") from None
    _check_schema(rec)
    if rec["run_id"] != run_id:
        raise DamagedRecord(f"belongs to run {rec['run_id'][:12]}, not {run_id[:12]} (copied?)")
    try:
        expected = hashlib.sha256(_canonical(rec)).hexdigest()
    except ValueError:  # a non-finite number
        raise DamagedRecord("holds a number that is not finite") from None
    if expected != rec["checksum"]:
        raise DamagedRecord("checksum does not match its content (edited or damaged)")
    if rec["results_sha256"] is not None:
        h5 = path.with_suffix(".h5")
        if not h5.is_file():
            raise DamagedRecord(f"its results file {h5.name} is missing")
        if file_sha256(h5) != rec["results_sha256"]:
            raise DamagedRecord(f"its results file {h5.name} does not match its sha256")
    return rec

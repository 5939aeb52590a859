"""Reading a results file that may have been damaged or tampered with, with bounded memory.

:func:`read_results` trusts nothing in the file: before a dataset is read, its declared size is
checked against what is left of :data:`MAX_RESULTS_BYTES` (a 97 kB gzip bomb declaring 9 GiB is
refused before a byte is inflated, and so is a chunk larger than the budget); attributes are
read only up to :data:`MAX_ATTRIBUTE_BYTES` of declared storage (HDF5 does not tell the length of a
variable-length string before it is read; such text cannot exceed the file's own size, as
attributes are never compressed); groups hold at most :data:`MAX_ENTRIES` items; only hard
links are followed, and data kept outside the file (external storage, virtual datasets) is
refused. What is read is then checked against the layout of :mod:`rotomorph.io.results`:

* every required dataset present, numeric, of the right shape (steps S ≤ :data:`MAX_STEPS`,
  nodes N ≤ :data:`~rotomorph.io.design_limits.MAX_NODES`), with its ``units``;
* positions and print programs finite; edge indices integers in ``[0, N)`` (a negative index
  would silently wrap in NumPy); branch flags one per node;
* the ``design`` and ``metadata`` attributes UTF-8 JSON objects (nesting bounded), the
  metadata's ``chains`` contiguous node ranges whose edges stay inside them, its ``filaments``
  and ``physical`` records of the types the figures and the viewer read;
* no text (names, units, design name) holding control or bidirectional characters.

Anything else is one :class:`~rotomorph.errors.InvalidParameterError` naming the file, the
object in it and what is wrong (the command line prints it as one line, exit status 2).
"""

from __future__ import annotations

import json
import math
import os
from typing import Any, Final

import h5py
import numpy as np

from rotomorph._text import unsafe_characters
from rotomorph.errors import InvalidParameterError
from rotomorph.io.design_limits import MAX_NODES
from rotomorph.io.results import (
    FORMAT,
    FORMAT_VERSION,
    PROGRAM_ATTRS,
    PROGRAM_UNITS,
    RunResults,
)

__all__ = [
    "MAX_ATTRIBUTE_BYTES",
    "MAX_ENTRIES",
    "MAX_RESULTS_BYTES",
    "MAX_STEPS",
    "read_results",
]

#: Most bytes of arrays read from one results file (declared sizes, before decompression).
MAX_RESULTS_BYTES: Final = 2 * 1024**3
#: Largest attribute read (the design and metadata JSON of a large lattice are < 1 MB).
MAX_ATTRIBUTE_BYTES: Final = 16 * 1024**2
#: Most datasets in one group (scalars, fields, static) and most print programs.
MAX_ENTRIES: Final = 10_000
#: Most stored steps (the heating steps of a run, plus the printed state).
MAX_STEPS: Final = 10_001
_NUMERIC: Final = "fiub"
_VERDICTS: Final = ("yes", "no", "unknown")


class _Reader:
    """One open file, the bytes still allowed, and errors that name the file."""

    def __init__(self, h5: h5py.File, path: str) -> None:
        self.h5 = h5
        self.path = path
        self.budget = MAX_RESULTS_BYTES

    def fail(self, where: str, message: str) -> InvalidParameterError:
        return InvalidParameterError(f"{self.path}: {where}", message)

    # -- low level ---------------------------------------------------------------------

    def get(self, name: str, parent: Any = None) -> Any:
        """The object at ``name`` (below ``parent``, default the root) or ``None``; only hard
        links are followed (a soft or external link could lead into another file)."""
        obj = self.h5 if parent is None else parent
        for part in name.split("/"):
            if not isinstance(obj, h5py.Group):
                return None
            key = part.encode()
            try:
                if not obj.id.links.exists(key):
                    return None
                kind = obj.id.links.get_info(key).type
            except (RuntimeError, KeyError, ValueError):
                return None
            if kind != h5py.h5l.TYPE_HARD:
                raise self.fail(name, "is a link (possibly into another file); refused")
            obj = obj[part]
        return obj

    def group(self, name: str, *, required: bool = True) -> h5py.Group | None:
        obj = self.get(name)
        if obj is None:
            if required:
                raise self.fail(name, "is missing; the file is damaged or not a rotomorph run")
            return None
        if not isinstance(obj, h5py.Group):
            raise self.fail(name, "must be a group")
        if len(obj) > MAX_ENTRIES:
            raise self.fail(name, f"holds {len(obj)} entries; the limit is {MAX_ENTRIES}")
        return obj

    def array(self, obj: Any, name: str, kinds: str = _NUMERIC) -> np.ndarray:
        """The data of dataset ``obj`` (called ``name``) after its type and size checks."""
        if not isinstance(obj, h5py.Dataset):
            raise self.fail(name, "is missing or not a dataset")
        if obj.external or obj.is_virtual:
            raise self.fail(name, "keeps its data outside the file; refused")
        dtype = obj.dtype
        if dtype.kind not in kinds or dtype.fields is not None or dtype.subdtype is not None:
            what = "whole numbers" if kinds == "iu" else "numbers"
            raise self.fail(name, f"has data type {dtype}; expected {what}")
        shape = obj.shape or ()
        if shape is None or any(n < 0 for n in shape):
            raise self.fail(name, "has no shape")
        size = math.prod(shape) * dtype.itemsize
        chunk = math.prod(obj.chunks) * dtype.itemsize if obj.chunks else 0
        if max(size, chunk) > self.budget:
            raise self.fail(
                name,
                f"declares {_size(max(size, chunk))} (shape {shape}, chunks {obj.chunks}); at "
                f"most {_size(MAX_RESULTS_BYTES)} of arrays are read from a results file (a "
                "compression bomb?)",
            )
        self.budget -= size
        try:
            data = obj[()]
        except (OSError, ValueError, TypeError, RuntimeError, KeyError) as err:
            raise self.fail(name, f"cannot be read ({' '.join(str(err).split())})") from None
        return np.asarray(data)

    def attr(self, obj: Any, key: str, where: str, *, required: bool = True) -> Any:
        """Attribute ``key`` of ``obj``: a text as ``str``, a number as a Python number."""
        try:
            size = h5py.h5a.open(obj.id, key.encode()).get_storage_size()
        except KeyError:
            if required:
                raise self.fail(f"{where} attribute {key!r}", "is missing") from None
            return None
        except (OSError, RuntimeError, ValueError) as err:
            raise self.fail(f"{where} attribute {key!r}", f"cannot be read ({err})") from None
        if size > MAX_ATTRIBUTE_BYTES:
            raise self.fail(f"{where} attribute {key!r}", f"is {size:,} bytes; too large")
        try:
            value = obj.attrs[key]
        except (OSError, ValueError, TypeError, RuntimeError, KeyError) as err:
            raise self.fail(f"{where} attribute {key!r}", f"cannot be read ({err})") from None
        if isinstance(value, bytes | np.bytes_):
            try:
                return bytes(value).decode("utf-8")
            except UnicodeDecodeError:
                raise self.fail(f"{where} attribute {key!r}", "is not UTF-8 text") from None
        if isinstance(value, str) and len(value) > MAX_ATTRIBUTE_BYTES:
            raise self.fail(f"{where} attribute {key!r}", f"is {len(value):,} characters; too long")
        if isinstance(value, np.ndarray) and value.shape == ():
            value = value[()]
        if isinstance(value, np.generic):
            value = value.item()
        return value

    def text(self, obj: Any, key: str, where: str, *, required: bool = True) -> str:
        value = self.attr(obj, key, where, required=required)
        if value is None:
            return ""
        return self.check_text(value, f"{where} attribute {key!r}")

    def check_text(self, value: Any, where: str) -> str:
        if not isinstance(value, str):
            raise self.fail(where, f"must be text; got {type(value).__name__}")
        if unsafe_characters(value):
            raise self.fail(where, "holds control or bidirectional-formatting characters")
        return value

    def json_object(self, key: str) -> dict[str, Any]:
        raw = self.attr(self.h5, key, "/")
        if not isinstance(raw, str):
            raise self.fail(f"attribute {key!r}", f"must be JSON text; got {type(raw).__name__}")
        try:
            value = json.loads(raw)
        except json.JSONDecodeError as err:
            raise self.fail(f"attribute {key!r}", f"is not JSON ({err.msg} at {err.pos})") from None
        except RecursionError:
            raise self.fail(f"attribute {key!r}", "is JSON nested too deeply") from None
        if not isinstance(value, dict):
            raise self.fail(f"attribute {key!r}", "must be a JSON object")
        return value


def _size(nbytes: float) -> str:
    """``1.5 GiB``-style size."""
    for unit in ("bytes", "KiB", "MiB", "GiB", "TiB"):
        if nbytes < 1024 or unit == "TiB":
            return f"{nbytes:,.0f} {unit}" if unit == "bytes" else f"{nbytes:,.1f} {unit}"
        nbytes /= 1024
    return ""  # pragma: no cover


def _frozen(a: np.ndarray) -> np.ndarray:
    a.setflags(write=False)
    return a


def _floats(r: _Reader, where: str, data: np.ndarray, *, finite: bool) -> np.ndarray:
    out = np.asarray(data, dtype=float)
    if finite and not np.isfinite(out).all():
        bad = np.argwhere(~np.isfinite(out))[0]
        raise r.fail(where, f"holds NaN or infinity (at index {tuple(int(i) for i in bad)})")
    return out


def _topology(r: _Reader) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    pos = r.array(r.get("steps/positions"), "steps/positions")
    if pos.ndim != 3 or pos.shape[2] != 3 or not 1 <= pos.shape[0] <= MAX_STEPS:
        raise r.fail("steps/positions", f"must have shape (steps, nodes, 3); got {pos.shape}")
    if not 2 <= pos.shape[1] <= MAX_NODES:
        raise r.fail("steps/positions", f"must hold 2 to {MAX_NODES} nodes; got {pos.shape[1]}")
    pos = _floats(r, "steps/positions", pos, finite=True)
    n = pos.shape[1]
    edges = r.array(r.get("topology/edges"), "topology/edges", kinds="iu")
    if edges.ndim != 2 or edges.shape[1] != 2 or not 1 <= len(edges) <= 4 * MAX_NODES:
        raise r.fail("topology/edges", f"must have shape (segments, 2); got {edges.shape}")
    if edges.min() < 0 or edges.max() >= n:
        raise r.fail("topology/edges", f"node indices must lie in [0, {n - 1}]")
    if np.any(edges[:, 0] == edges[:, 1]):
        raise r.fail("topology/edges", "a segment joins a node to itself")
    branch = r.array(r.get("topology/branch"), "topology/branch")
    if branch.shape != (n,) or not np.isin(branch, (0, 1)).all():
        raise r.fail("topology/branch", f"must hold {n} flags (0 or 1); got shape {branch.shape}")
    return edges.astype(np.int64), branch.astype(bool), pos


def _named_arrays(
    r: _Reader, group: str, units: dict[str, str], check: Any, *, required: bool
) -> dict[str, np.ndarray]:
    out: dict[str, np.ndarray] = {}
    g = r.group(group, required=required)
    if g is None:
        return out
    for name in g:
        where = f"{group}/{r.check_text(name, f'{group} name')}"
        ds = r.get(name, g)
        data = r.array(ds, where)
        check(where, name, data)
        units[name] = r.text(ds, "units", where)
        out[name] = _frozen(data.astype(np.int64) if data.dtype.kind in "iub" else data)
    return out


def _arrays(r: _Reader, s: int, n: int, e: int) -> tuple[dict, dict, dict, dict[str, str]]:
    units = {"positions": r.text(r.get("steps/positions"), "units", "steps/positions")}

    def scalar(where: str, name: str, v: np.ndarray) -> None:
        if v.shape != (s,):
            raise r.fail(where, f"must hold one value per step ({s}); got shape {v.shape}")

    def field(where: str, name: str, v: np.ndarray) -> None:
        if v.ndim not in (2, 3) or v.shape[0] != s or (v.ndim == 3 and v.shape[2] != 3):
            raise r.fail(where, f"must have shape ({s}, items[, 3]); got {v.shape}")
        if name in ("active_normal", "directors") and v.shape[1:] != (e, 3):
            raise r.fail(where, f"must have shape ({s}, {e}, 3); got {v.shape}")

    def static(where: str, name: str, v: np.ndarray) -> None:
        if v.ndim not in (1, 2) or v.shape[0] not in (n, e):
            raise r.fail(where, f"needs one row per node ({n}) or segment ({e}); got {v.shape}")

    scalars = _named_arrays(r, "steps/scalars", units, scalar, required=True)
    scalars = {k: _frozen(np.asarray(v, dtype=float)) for k, v in scalars.items()}
    fields = _named_arrays(r, "steps/fields", units, field, required=True)
    fields = {k: _frozen(np.asarray(v, dtype=float)) for k, v in fields.items()}
    return scalars, fields, _named_arrays(r, "static", units, static, required=False), units


def _programs(r: _Reader) -> tuple[dict[str, Any], ...]:
    g = r.group("programs", required=False)
    out = []
    for key in sorted(g or ()):
        where = f"programs/{r.check_text(key, 'program name')}"
        pg = r.get(key, g)
        if not isinstance(pg, h5py.Group):
            raise r.fail(where, "must be a group")
        prog: dict[str, Any] = {}
        for name in PROGRAM_UNITS:
            data = r.array(r.get(name, pg), f"{where}/{name}")
            v = _floats(r, f"{where}/{name}", data, finite=True)
            prog[name] = _frozen(v)
        m = prog["points"].shape[0] if prog["points"].ndim else 0
        if prog["points"].shape != (m, 3) or not 2 <= m <= MAX_NODES:
            raise r.fail(f"{where}/points", f"must have shape (n, 3); got {prog['points'].shape}")
        for name in ("speed", "nozzle_angle"):
            if prog[name].shape != (m,):
                raise r.fail(f"{where}/{name}", f"needs {m} values; got {prog[name].shape}")
        for name, unit in PROGRAM_ATTRS.items():
            if unit:
                value = r.attr(pg, name, where)
                if isinstance(value, bool) or not isinstance(value, int | float):
                    raise r.fail(f"{where} attribute {name!r}", "must be a number")
                if not math.isfinite(value):
                    raise r.fail(f"{where} attribute {name!r}", "must be finite")
                prog[name] = float(value)
            else:
                prog[name] = r.text(pg, name, where)
        out.append(prog)
    return tuple(out)


def _number_or_none(value: Any) -> bool:
    return value is None or (isinstance(value, int | float) and not isinstance(value, bool))


def _check_metadata(r: _Reader, meta: dict[str, Any], n: int, edges: np.ndarray) -> None:
    where = "attribute 'metadata'"
    kind = meta.get("kind", "filaments")
    if kind not in ("filaments", "lattice"):
        raise r.fail(f"{where} kind", f"must be 'filaments' or 'lattice'; got {kind!r:.40}")
    for key in ("design_name",):
        if key in meta:
            r.check_text(meta[key], f"{where} {key}")
    if not isinstance(meta.get("contact"), bool | dict | None):
        raise r.fail(f"{where} contact", "must be a table of the surroundings, or false")
    physical = meta.get("physical", {})
    if not isinstance(physical, dict) or physical.get("verdict", "unknown") not in _VERDICTS:
        raise r.fail(f"{where} physical", "must be {verdict: yes | no | unknown, reason}")
    chains = meta.get("chains", [])
    if not isinstance(chains, list):
        raise r.fail(f"{where} chains", "must be a list")
    owner = np.full(n, -1)
    for i, c in enumerate(chains):
        at = f"{where} chains[{i}]"
        if not isinstance(c, dict) or not all(
            isinstance(c.get(k), int) and not isinstance(c.get(k), bool) for k in ("start", "stop")
        ):
            raise r.fail(at, "must be {name, start, stop} with whole-number start and stop")
        if not 0 <= c["start"] < c["stop"] - 1 < n or np.any(owner[c["start"] : c["stop"]] >= 0):
            raise r.fail(at, f"must be a range of >= 2 nodes in [0, {n}) overlapping no other")
        r.check_text(c.get("name", ""), f"{at}.name")
        owner[c["start"] : c["stop"]] = i
    if chains and np.any(owner[edges[:, 0]] != owner[edges[:, 1]]):
        raise r.fail(f"{where} chains", "a segment joins two filaments (or leaves every chain)")
    filaments = meta.get("filaments", [])
    if not isinstance(filaments, list) or not all(isinstance(f, dict) for f in filaments):
        raise r.fail(f"{where} filaments", "must be a list of tables")
    for i, f in enumerate(filaments):
        at = f"{where} filaments[{i}]"
        r.check_text(f.get("name", ""), f"{at}.name")
        if not _number_or_none(f.get("end_to_end_ratio")):
            raise r.fail(f"{at}.end_to_end_ratio", "must be a number")
        if not isinstance(f.get("morphology") or "", str):
            raise r.fail(f"{at}.morphology", "must be text")
        helix = f.get("helix")
        if helix and not (
            isinstance(helix, dict) and _number_or_none(helix.get("rms_residual_mm"))
        ):
            raise r.fail(f"{at}.helix", "must be a table with a number rms_residual_mm")
        fp = f.get("physical") or {}
        steps = fp.get("steps") if isinstance(fp, dict) else None
        if not isinstance(fp, dict) or not (steps is None or isinstance(steps, list)):
            raise r.fail(f"{at}.physical", "must be {verdict, reason, steps}")


def read_results(path: str | os.PathLike[str] | Any) -> RunResults:
    """Read and validate a results file written by :func:`rotomorph.io.results.write_results`
    (module docstring: what is checked, and the size limits); ``path`` may also be a binary
    file object.

    Raises
    ------
    InvalidParameterError
        Not a rotomorph results file, a newer format, or damaged: one line naming the object.
    OSError
        The file cannot be opened as HDF5.
    """
    name = os.fspath(path) if isinstance(path, str | os.PathLike) else "<results>"
    with h5py.File(path, "r") as h5:
        r = _Reader(h5, name)
        fmt = r.attr(h5, "format", "/", required=False)
        if not isinstance(fmt, str) or fmt != FORMAT:
            raise InvalidParameterError("path", f"{name} is not a {FORMAT} file")
        version = r.attr(h5, "format_version", "/")
        if isinstance(version, bool) or not isinstance(version, int) or version < 1:
            raise r.fail("attribute 'format_version'", f"must be a whole number; got {version!r}")
        if version > FORMAT_VERSION:
            raise InvalidParameterError(
                "path", f"format version {version} is newer than {FORMAT_VERSION}; upgrade"
            )
        edges, branch, positions = _topology(r)
        s, n = positions.shape[:2]
        scalars, fields, static, units = _arrays(r, s, n, len(edges))
        design = r.json_object("design")
        metadata = r.json_object("metadata")
        _check_metadata(r, metadata, n, edges)
        return RunResults(
            design=design,
            edges=_frozen(edges),
            branch=_frozen(branch),
            positions=_frozen(positions),
            scalars=scalars,
            fields=fields,
            units=units,
            metadata=metadata,
            static=static,
            programs=_programs(r),
        )

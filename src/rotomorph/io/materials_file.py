"""Materials files on disk: reading (encodings, size, one-line errors), writing, the schema.

A materials file is TOML (``schema_version = 1``) holding one or more inks, every value with
its unit and provenance (:mod:`rotomorph.materials.materials_schema`; the format is documented
in ``docs/design-files.md``, *Materials files*). :func:`load_materials` reads one into a
:class:`~rotomorph.materials.parameter_set.MaterialSet`; :func:`save_materials` writes one
atomically, with every value as one inline table per line, so that the file reads like the
documentation; the written file reads back into the same set (same sha256).

Designs name their materials file (``materials = "inks.toml"``, relative to the design);
:func:`resolve_materials` turns that entry into a set.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any, Final

from rotomorph._text import check_text
from rotomorph.errors import MaterialError
from rotomorph.io.atomic import atomic_write_text
from rotomorph.io.tomlfile import decode_toml_bytes, read_toml
from rotomorph.materials.materials_schema import SCHEMA_VERSION, MaterialsDocument
from rotomorph.materials.parameter_set import MaterialSet, materials_from_mapping

__all__ = [
    "load_materials",
    "materials_schema",
    "materials_toml",
    "parse_materials_bytes",
    "resolve_materials",
    "save_materials",
]

_HEADER: Final = (
    "# rotomorph materials file: inks as data, every value with its unit and provenance\n"
    "# (measured / cited / assumed / calibrated). Format: docs/design-files.md, Materials files.\n"
)


def _error(name: str, message: str) -> MaterialError:
    return MaterialError(name, message)


def load_materials(path: str | Path) -> MaterialSet:
    """Read and validate the materials file at ``path``.

    Raises
    ------
    MaterialError
        Not a file, not UTF-8 (or UTF-16/32 with a byte-order mark), over 4 MiB, TOML syntax,
        or a schema problem: one line naming the file and the key path.
    OSError
        The file cannot be read.
    """
    p = Path(path)
    if not p.is_file():
        raise MaterialError(str(p), "no such materials file" if not p.exists() else "is not a file")
    data = read_toml(p, _error)
    try:
        return materials_from_mapping(data, str(p))
    except MaterialError as err:
        raise MaterialError(f"{p}: {err.field}", str(err).partition(": ")[2]) from None


def parse_materials_bytes(data: bytes, name: str = "<materials>") -> MaterialSet:
    """A materials file from its bytes (as :func:`load_materials`, without a file)."""
    mapping = decode_toml_bytes(data, name, _error)
    try:
        return materials_from_mapping(mapping, name)
    except MaterialError as err:
        raise MaterialError(f"{name}: {err.field}", str(err).partition(": ")[2]) from None


def resolve_materials(entry: Any, base: str | Path | None) -> MaterialSet:
    """The set a design's ``materials`` entry names: a path (relative to ``base``, the design's
    folder; the current folder when ``None``) or an inline table (a materials file's keys).

    Raises
    ------
    MaterialError
        Field ``materials``: a missing or invalid file, or an invalid inline table.
    """
    if isinstance(entry, dict):
        try:
            return materials_from_mapping(entry, "<inline>")
        except MaterialError as err:
            raise MaterialError(f"materials.{err.field}", str(err).partition(": ")[2]) from None
    if not isinstance(entry, str) or not entry.strip():
        raise MaterialError(
            "materials", "must be the path of a materials file (TOML, relative to the design)"
        )
    try:
        check_text(entry)
    except ValueError as err:
        raise MaterialError("materials", str(err)) from None
    shown = entry
    path = Path(base or ".") / entry
    if not path.is_file():
        where = "no such file" if not path.exists() else "is not a file"
        raise MaterialError(
            "materials", f"{shown}: {where} (looked for {path}; the path is relative to the design)"
        )
    try:
        return load_materials(path)
    except MaterialError as err:
        detail = str(err)[len(err.field) + 2 :]
        inner = err.field.removeprefix(str(path)).removeprefix(": ")
        raise MaterialError(
            "materials", f"{shown}: {inner + ': ' if inner else ''}{detail}"
        ) from None
    except OSError as err:
        raise MaterialError("materials", f"{shown}: cannot be read ({err.strerror})") from None


def materials_schema() -> dict[str, Any]:
    """JSON Schema of the materials file format (for editors and documentation)."""
    schema = MaterialsDocument.model_json_schema()
    schema["$id"] = f"https://rotomorph.invalid/materials-schema-v{SCHEMA_VERSION}.json"
    return schema


# ----------------------------------------------------------------------------- writing


def _string(text: str) -> str:
    """A TOML basic string (JSON escapes are TOML escapes; DEL must be escaped too)."""
    return json.dumps(text, ensure_ascii=False).replace("\x7f", "\\u007f")


def _scalar(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if not math.isfinite(value):
            raise MaterialError("save_materials", f"cannot write a non-finite number {value!r}")
        return repr(value)
    if isinstance(value, str):
        return _string(value)
    if isinstance(value, list):
        return "[" + ", ".join(_scalar(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{ " + ", ".join(f"{_key(k)} = {_scalar(v)}" for k, v in value.items()) + " }"
    raise MaterialError("save_materials", f"cannot write {type(value).__name__} values")


def _key(key: str) -> str:
    return (
        key if key.replace("_", "").replace("-", "").isalnum() and key.isascii() else _string(key)
    )


def _is_section(value: Any) -> bool:
    """A sub-table written as its own ``[section]``: a table that is not one value (values are
    inline tables), or the order-parameter curve (arrays read better on their own lines)."""
    return isinstance(value, dict) and ("provenance" not in value or "speed" in value)


def _section(lines: list[str], path: list[str], table: dict[str, Any]) -> None:
    inline = {k: v for k, v in table.items() if not _is_section(v)}
    nested = {k: v for k, v in table.items() if _is_section(v)}
    if path:
        lines.append("")
        lines.append("[" + ".".join(_key(p) for p in path) + "]")
    for k, v in inline.items():
        lines.append(f"{_key(k)} = {_scalar(v)}")
    for k, v in nested.items():
        _section(lines, [*path, k], v)


def materials_toml(materials: MaterialSet) -> str:
    """The text of ``materials`` as a materials file (canonical units, one value per line)."""
    data = materials.document.model_dump(mode="json", exclude_none=True)
    inks = data.pop("inks")
    lines: list[str] = []
    _section(lines, [], data)
    for name, ink in inks.items():
        _section(lines, ["inks", name], {"kind": ink.pop("kind"), **ink})
    return _HEADER + "\n".join(lines) + "\n"


def save_materials(materials: MaterialSet, path: str | Path) -> Path:
    """Write ``materials`` as a TOML materials file to ``path`` atomically; the file reads back
    into an equal set (same sha256)."""
    text = materials_toml(materials)
    again = parse_materials_bytes(text.encode("utf-8"), str(path))
    if again != materials:  # pragma: no cover - a writer defect, never a user's
        raise MaterialError("save_materials", "the written file does not read back identically")
    return atomic_write_text(path, text)

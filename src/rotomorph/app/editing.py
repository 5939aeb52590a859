"""Editing a design as data: field paths, typed text, validation as ``rotomorph validate`` does.

The page holds the design as the mapping a design file parses into (TOML tables as dicts). Each
field of the form is named by its path in the words of every rotomorph error
(``filaments[0].segments[2].speed``, ``lattice.n``); :func:`set_field` writes the text a person
typed into that place (a number where it reads as one, else the text itself, so the schema
refuses ``speed = "abc"`` exactly as it refuses it in a file) and :func:`check` validates the
whole design through the CLI's own path (:func:`rotomorph.io.designfile.parse_design`, the
materials and the built-in machine's placement), returning the one-line error with its field.
"""

from __future__ import annotations

import copy
import itertools
import math
import re
from typing import Any

from rotomorph.errors import InvalidParameterError, MachineLimitError

__all__ = [
    "EDGE_MODES",
    "check",
    "edge_modes",
    "error_field",
    "format_value",
    "get_field",
    "parse_field",
    "parse_value",
    "set_edge",
    "set_field",
]

EDGE_MODES = ("expanding", "contracting")
_PART = re.compile(r"([A-Za-z_][A-Za-z0-9_]*)|\[(\d+)\]")


def _parts(path: str) -> list[str | int]:
    out: list[str | int] = []
    for name, index in _PART.findall(path):
        out.append(int(index) if index else name)
    return out


def parse_value(text: Any) -> Any:
    """What typed ``text`` means in a design file: an int or float where it reads as one (as
    TOML would read it), ``true``/``false``, ``None`` for an empty field (the default), else
    the text itself (the schema then refuses it with the CLI's message)."""
    if not isinstance(text, str):
        return text
    raw = text.strip()
    if raw == "":
        return None
    if raw in ("true", "false"):
        return raw == "true"
    if re.fullmatch(r"[+-]?\d+", raw):
        return int(raw)
    try:
        value = float(raw)
    except ValueError:
        return text
    return value if math.isfinite(value) else text


#: Fields holding a point (``x, y, z``) or a list of points (one ``x, y, z`` per line or
#: separated by ``;``), by the last name of their path (mm).
POINT_FIELDS = frozenset({"start", "origin"})
POINT_LIST_FIELDS = frozenset({"points"})


def _point(text: str) -> list[Any] | None:
    parts = [p for p in re.split(r"[,\s]+", text.strip().strip("[]()")) if p]
    values = [parse_value(p) for p in parts]
    if not values or not all(
        isinstance(v, int | float) and not isinstance(v, bool) for v in values
    ):
        return None
    return values


def parse_field(path: str, text: Any) -> Any:
    """What typed ``text`` means at ``path``: a point's ``x, y, z`` as a list of numbers, a
    polyline's points (one ``x, y, z`` a line, or ``;`` between them) as a list of lists, else
    as :func:`parse_value` reads it. Text that reads as neither stays text, which the schema
    refuses with the CLI's message."""
    last = path.rsplit(".", 1)[-1]
    if not isinstance(text, str) or not text.strip():
        return parse_value(text)
    if last in POINT_FIELDS:
        point = _point(text)
        return text if point is None else point
    if last in POINT_LIST_FIELDS:
        rows = [r for r in re.split(r"[;\n]", text) if r.strip()]
        points = [_point(r) for r in rows]
        return text if any(p is None for p in points) else points
    return parse_value(text)


def format_value(value: Any) -> str:
    """The text a field shows for ``value``: points as ``x, y, z`` (a list of them one a
    line), numbers as TOML writes them, ``true``/``false``; ``""`` for none (the default)."""
    if value is None:
        return ""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float) and value.is_integer():
        return f"{value:g}" if abs(value) < 1e15 else repr(value)
    if isinstance(value, list | tuple):
        if value and all(isinstance(v, list | tuple) for v in value):
            return "\n".join(format_value(v) for v in value)
        return ", ".join(format_value(v) for v in value)
    return str(value)


def get_field(data: dict[str, Any], path: str) -> Any:
    """The value at ``path`` (None where absent)."""
    node: Any = data
    for part in _parts(path):
        try:
            node = node[part]
        except (KeyError, IndexError, TypeError):
            return None
    return node


def set_field(data: dict[str, Any], path: str, value: Any) -> dict[str, Any]:
    """A copy of ``data`` with ``value`` at ``path`` (``None`` removes the key: its default;
    ``data`` itself when the key is absent already, no empty table made for it)."""
    if value is None and get_field(data, path) is None:
        return data
    out = copy.deepcopy(data)
    parts = _parts(path)
    node: Any = out
    for part, nxt in itertools.pairwise(parts):
        if isinstance(part, int):
            node = node[part]
            continue
        if part not in node or node[part] is None:
            node[part] = [] if isinstance(nxt, int) else {}
        node = node[part]
    last = parts[-1]
    if value is None and isinstance(last, str):
        node.pop(last, None)
    else:
        node[last] = value
    return out


def error_field(field: str) -> str:
    """The form field an error's field path belongs to (the path itself, else its owner)."""
    return field.split(" ", 1)[0]


def check(data: dict[str, Any]) -> tuple[Any, tuple[str, str] | None]:
    """Validate ``data`` as ``rotomorph validate`` does: ``(design, None)`` or
    ``(None, (field, message))`` with the CLI's one-line message (``field: what and the fix``).

    Beyond the schema (:func:`rotomorph.io.designfile.parse_design`): every program's
    materials. Placement on a machine is checked where the program is written (G-code).
    """
    from rotomorph.io.designfile import parse_design
    from rotomorph.io.gcode import check_materials

    try:
        design = parse_design(data)
        check_materials(design.to_programs())
    except InvalidParameterError as err:
        return None, (err.field, str(err))
    except MachineLimitError as err:  # pragma: no cover - not raised without a machine
        return None, ("machine", f"machine limits: {err}")
    return design, None


def edge_modes(lattice: Any) -> list[str]:
    """Mode of every lattice edge of a validated ``LatticeModel`` (its pattern resolved)."""
    return [str(m) for m in lattice.to_lattice().edge_mode]


def set_edge(
    data: dict[str, Any], modes: list[str], edge: int, *, mode: str | None, speed: Any
) -> dict[str, Any]:
    """``data`` with lattice edge ``edge`` set to ``mode`` and ``speed`` (mm/s or typed text).

    The lattice becomes ``pattern = "custom"`` with every edge's mode written out (``modes``:
    the current modes, :func:`edge_modes`); speeds become ``edge_speeds`` (one per edge, the
    lattice's ``speed`` where not set).
    """
    lat = dict(data.get("lattice") or {})
    count = len(modes)
    if not 0 <= edge < count:
        raise InvalidParameterError("edge", f"must be 0..{count - 1}; got {edge}")
    if mode is not None:
        if mode not in EDGE_MODES:
            raise InvalidParameterError("mode", f"must be one of {EDGE_MODES}; got {mode!r}")
        new = list(lat.get("edge_modes") or modes)
        new[edge] = mode
        lat["pattern"], lat["edge_modes"] = "custom", new
    if speed is not None:
        base = lat.get("speed", 3.0)
        speeds = list(lat.get("edge_speeds") or [base] * count)
        speeds[edge] = parse_value(speed) if isinstance(speed, str) else speed
        lat["edge_speeds"] = speeds
    return {**data, "lattice": lat}

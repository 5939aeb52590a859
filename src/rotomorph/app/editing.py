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
    "get_field",
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
    """A copy of ``data`` with ``value`` at ``path`` (``None`` removes the key: its default)."""
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

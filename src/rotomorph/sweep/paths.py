"""Dotted field paths into a design mapping: ``filaments[0].speed``, ``lattice.amplitude``.

A path is a chain of keys separated by dots, each optionally followed by list indices in
brackets; ``[*]`` stands for every element of a list (``filaments[*].speed`` sets the speed of
all filaments). ``filaments.0.speed`` is accepted as a spelling of ``filaments[0].speed``.
Paths address the *file* layout of a design (:mod:`rotomorph.io.designfile`), so every name is
one a design file can contain.
"""

from __future__ import annotations

import copy
import re
from collections.abc import Mapping
from typing import Any

from rotomorph.errors import InvalidParameterError

__all__ = ["check_path", "parse_path", "set_path"]

_KEY = re.compile(r"^([A-Za-z_][A-Za-z0-9_]*)((?:\[(?:\d+|\*)\])*)$")
_INDEX = re.compile(r"\[(\d+|\*)\]")

Step = str | int  # a mapping key, a list index, or -1 for every element ("*")


def parse_path(path: str, field: str = "path") -> tuple[Step, ...]:
    """Split a dotted path into keys (str) and list indices (int, ``-1`` for ``[*]``).

    Raises
    ------
    InvalidParameterError
        Empty or malformed paths (names the ``field`` and shows the expected form).
    """
    if not isinstance(path, str) or not path.strip():
        raise InvalidParameterError(field, "must be a dotted field path like filaments[0].speed")
    steps: list[Step] = []
    for part in path.strip().split("."):
        if part.isdigit() and steps:
            steps.append(int(part))
            continue
        m = _KEY.match(part)
        if m is None:
            raise InvalidParameterError(
                field,
                f"{path!r}: cannot read {part!r}; write keys and indices like "
                "filaments[0].segments[1].length or lattice.amplitude",
            )
        steps.append(m.group(1))
        steps += [-1 if i == "*" else int(i) for i in _INDEX.findall(m.group(2))]
    return tuple(steps)


def _describe(steps: tuple[Step, ...]) -> str:
    out = ""
    for s in steps:
        if isinstance(s, int):
            out += "[*]" if s < 0 else f"[{s}]"
        else:
            out += ("." if out else "") + s
    return out


def _set(
    node: Any, steps: tuple[Step, ...], value: Any, done: tuple[Step, ...], strict: bool
) -> None:
    head, rest = steps[0], steps[1:]
    where = _describe(done) or "<design>"
    if isinstance(head, str):
        if node is None:
            raise InvalidParameterError(
                _describe((*done, head)),
                f"the base design has no {where}; add it to the base design first",
            )
        if not isinstance(node, dict):
            raise InvalidParameterError(_describe((*done, head)), f"{where} is not a table")
        if not rest:
            if strict and head not in node:
                raise InvalidParameterError(
                    _describe((*done, head)),
                    f"{where} has no field {head!r}; check its spelling (its fields: "
                    f"{', '.join(sorted(node))})",
                )
            node[head] = copy.deepcopy(value)
            return
        if head not in node:
            raise InvalidParameterError(
                _describe((*done, head)),
                f"the base design has no {head!r} in {where}; set it in the base design first",
            )
        _set(node[head], rest, value, (*done, head), strict)
        return
    if not isinstance(node, list):
        raise InvalidParameterError(_describe((*done, head)), f"{where} is not a list")
    indices = range(len(node)) if head < 0 else [head]
    if head >= len(node):
        raise InvalidParameterError(
            _describe((*done, head)), f"{where} has {len(node)} element(s); index {head} is past it"
        )
    for i in indices:
        if rest:
            _set(node[i], rest, value, (*done, i), strict)
        else:
            node[i] = copy.deepcopy(value)


def set_path(data: Mapping[str, Any], path: str, value: Any) -> dict[str, Any]:
    """A deep copy of ``data`` with the field at ``path`` set to ``value``.

    The last key may be new (a field the base design left at its default); every key and index
    before it must exist.

    Examples
    --------
    >>> set_path({"filaments": [{"speed": 3.0}]}, "filaments[0].speed", 1.5)
    {'filaments': [{'speed': 1.5}]}
    """
    out = copy.deepcopy(dict(data))
    _set(out, parse_path(path), value, (), strict=False)
    return out


def check_path(resolved: Mapping[str, Any], path: str) -> None:
    """Refuse a ``path`` that names no field of ``resolved`` (a design with every default
    filled in, e.g. ``Design.model_dump(mode="json")``): a misspelt key, an index past a list,
    a table the design does not have. Values are not checked (a sweep records out-of-range
    points as invalid runs).

    Raises
    ------
    InvalidParameterError
        Naming the first step of ``path`` that does not exist and what does.

    Examples
    --------
    >>> check_path({"filaments": [{"speed": 3.0}]}, "filaments[0].sped")
    Traceback (most recent call last):
    ...
    rotomorph.errors.InvalidParameterError: filaments[0].sped: filaments[0] has no field 'sped'; \
check its spelling (its fields: speed)
    """
    _set(copy.deepcopy(dict(resolved)), parse_path(path), None, (), strict=True)

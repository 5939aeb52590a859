"""Measurement tables (CSV) of a lab's own inks, read strictly: one-line errors naming file,
row and column.

Header (any column order, no other columns)::

    quantity,condition,x,x_unit,value,spread,unit,source
    janus_curvature,,3.0,mm/s,0.59,0.04,1/mm,"notebook 12, p. 4"
    free_length,active=lce; v=3 mm/s,120,C,0.86,0.01,1,dilatometry run 7

* ``quantity``: one of :data:`rotomorph.materials.lab_tables.QUANTITIES`;
* ``condition``: the fixed conditions as ``key=value unit`` parts separated by ``;``
  (:data:`~rotomorph.materials.lab_tables.CONDITION_KEYS`; other text is a label);
* ``x``, ``x_unit``: the swept control value and its unit (empty for single values);
* ``value``, ``spread``, ``unit``: mean, standard deviation (> 0) and their unit;
* ``source``: where the number comes from (required);
* ``provenance`` (optional column): ``measured`` (default) or ``cited`` (from a publication,
  ``source`` holding the citation).

Units are converted to mm, s, MPa, °C (:mod:`rotomorph.materials.units`). Lines starting with
``#`` are comments. Refused, with ``<file>: row <n>, column <name>: <what and the fix>``: a file
that is not UTF-8, over 4 MiB, a missing or unknown column, an unknown quantity, condition key
or unit, a number that is not one, a value outside its physical range, a zero or negative
spread, a curve with a single point, and two rows of the same quantity, conditions and x that
contradict each other (more than 3 combined standard deviations apart) or repeat each other.
"""

from __future__ import annotations

import csv
import hashlib
import io
import math
import re
from collections.abc import Sequence
from pathlib import Path
from typing import Final

from rotomorph._text import describe_character, terminal_safe, unsafe_characters
from rotomorph.errors import InvalidParameterError
from rotomorph.materials.lab_tables import (
    CONDITION_KEYS,
    QUANTITIES,
    Measurement,
    MeasurementSet,
    Quantity,
    data_sha256,
)
from rotomorph.materials.units import accepted_units, spread_to_canonical, to_canonical

__all__ = ["COLUMNS", "MAX_CSV_BYTES", "parse_measurements", "read_measurements"]

COLUMNS: Final = ("quantity", "condition", "x", "x_unit", "value", "spread", "unit", "source")
#: Optional columns: ``provenance`` = ``measured`` (default, the lab's own) or ``cited`` (from a
#: publication; ``source`` then holds the citation).
OPTIONAL: Final = ("provenance",)
#: Largest measurement file read (bytes).
MAX_CSV_BYTES: Final = 4 * 1024 * 1024
MAX_ROWS: Final = 100_000
MAX_TEXT: Final = 500
#: Two rows of one measurement further apart than this many combined sd contradict each other.
CONTRADICTION_SD: Final = 3.0

_NUMBER = re.compile(r"^[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?$")
_PART = re.compile(r"^\s*([A-Za-z_][A-Za-z0-9_*]*)\s*=\s*(.*?)\s*$")


def _shown(text: str) -> str:
    """``text`` safe for a one-line message (control characters escaped, shortened)."""
    text = text if len(text) <= 60 else text[:57] + "..."
    return repr(text) if text.isprintable() else f"'{terminal_safe(text)}'"


class _Row:
    """Error factory for one row of one file."""

    def __init__(self, file: str, row: int) -> None:
        self.file, self.row = file, row

    def error(self, column: str, message: str) -> InvalidParameterError:
        return InvalidParameterError(f"{self.file}: row {self.row}, column {column}", message)


def _number(at: _Row, column: str, text: str) -> float:
    t = text.strip()
    if not _NUMBER.match(t):
        raise at.error(column, f"must be a number (e.g. 0.59); got {_shown(text)}")
    value = float(t)
    if not math.isfinite(value):
        raise at.error(column, f"must be a finite number; got {_shown(text)}")
    return value


def _unit(at: _Row, column: str, dimension: str, text: str, q: str) -> str:
    unit = text.strip()
    if unit not in accepted_units(dimension):
        listed = ", ".join(repr(u) for u in accepted_units(dimension))
        raise at.error(column, f"{_shown(unit)} is not a unit of {q}'s {dimension}; use {listed}")
    return unit


def _conditions(at: _Row, text: str, q: Quantity) -> dict[str, float | str]:
    out: dict[str, float | str] = {}
    allowed = (
        set(q.required)
        | set(q.optional)
        | (
            {"active", "passive"}
            if q.ink == "either"
            else {"active"}
            if q.ink == "active"
            else set()
        )
    )
    for part in text.split(";"):
        if not part.strip():
            continue
        m = _PART.match(part)
        if m is None:
            continue  # a label
        key, raw = m.group(1), m.group(2)
        if key in ("omega", "omega*", "w*"):
            continue  # the rotation number of a row is its x (as in the paper's labels)
        if key not in CONDITION_KEYS or key not in allowed:
            known = ", ".join(sorted(allowed)) or "none"
            raise at.error(
                "condition", f"unknown condition key {_shown(key)} for {q.name}; known: {known}"
            )
        if key in out:
            raise at.error("condition", f"gives {key} twice")
        dim, _ = CONDITION_KEYS[key]
        if dim == "text":
            word = raw.strip()
            if not re.fullmatch(r"[A-Za-z0-9][A-Za-z0-9_.+-]{0,63}", word):
                raise at.error("condition", f"{key}: {_shown(word)} is not a name (one word)")
            out[key] = word
            continue
        num, _, unit = raw.partition(" ")
        value = _number(at, "condition", num)
        unit = unit.strip() or ("1" if dim == "ratio" else "")
        if not unit:
            raise at.error(
                "condition",
                f"{key}={num.strip()} needs its unit, e.g. {key}={num.strip()} "
                f"{accepted_units(dim)[0]}",
            )
        if unit not in accepted_units(dim):
            listed = ", ".join(repr(u) for u in accepted_units(dim))
            raise at.error(
                "condition", f"{key}: {_shown(unit)} is not a unit of {dim}; use {listed}"
            )
        out[key] = to_canonical(dim, value, unit)
    for key in q.required:
        if key not in out:
            dim, meaning = CONDITION_KEYS[key]
            example = f"{key}=3 mm/s" if dim == "speed" else f"{key}=..."
            raise at.error("condition", f"{q.name} needs {key} ({meaning}), e.g. '{example}'")
    if q.ink is not None:
        roles = [r for r in ("active", "passive") if r in out]
        if len(roles) != 1 or (q.ink == "active" and roles != ["active"]):
            need = "active=NAME" if q.ink == "active" else "active=NAME or passive=NAME"
            raise at.error("condition", f"{q.name} needs the ink it measures: {need}")
        if q.name == "free_length" and roles == ["active"] and "v" not in out:
            raise at.error(
                "condition",
                "free_length of the active ink needs the print speed v of the (pure, unrotated) "
                "filaments measured, e.g. 'active=lce; v=3 mm/s': the strain of a sample of "
                "unknown alignment says nothing about printed filaments",
            )
        if q.name == "free_length" and roles == ["passive"] and "v" in out:
            raise at.error("condition", "v: a passive ink's free length does not depend on it")
    if "v" in out and float(out["v"]) <= 0:
        raise at.error("condition", "v must be a print speed > 0 mm/s")
    for key in ("A", "wavelength", "l", "periods", "n", "layers", "ghost_nodes"):
        if key in out and not float(out[key]) > 0:
            raise at.error("condition", f"{key} must be > 0")
    if "side" in out and out["side"] not in ("outer", "inner"):
        raise at.error("condition", "side must be outer or inner")
    if "pattern" in out and out["pattern"] not in ("expanding", "contracting"):
        raise at.error("condition", "pattern must be expanding or contracting")
    return out


def _measurement(at: _Row, cells: dict[str, str]) -> Measurement:
    for column in cells:
        text = cells[column]
        if len(text) > MAX_TEXT:
            raise at.error(column, f"is {len(text)} characters; at most {MAX_TEXT}")
        bad = unsafe_characters(text)
        if bad:
            raise at.error(
                column,
                f"holds {describe_character(bad[0][1])} at position {bad[0][0]}: "
                f"{_shown(text)}; remove control and bidirectional-formatting characters",
            )
    name = cells["quantity"].strip()
    q = QUANTITIES.get(name)
    if q is None:
        raise at.error(
            "quantity", f"unknown quantity {_shown(name)}; use one of {', '.join(QUANTITIES)}"
        )
    conditions = _conditions(at, cells["condition"], q)
    if q.x is None:
        for column in ("x", "x_unit"):
            if cells[column].strip():
                raise at.error(column, f"{q.name} has no x; leave {column} empty")
        x = math.nan
    else:
        if not cells["x"].strip():
            raise at.error("x", f"{q.name} needs x ({q.x}) and its unit")
        raw = _number(at, "x", cells["x"])
        x = to_canonical(q.x, raw, _unit(at, "x_unit", q.x, cells["x_unit"], q.name))
        lo, hi = q.x_range
        if not lo < x < hi:
            unit_x = cells["x_unit"].strip()
            raise at.error(
                "x", f"{q.name}: x = {raw:g} {unit_x} is outside the physical range of its "
                f"{q.x} ({lo:g}..{hi:g} in canonical units)",
            )  # fmt: skip
    unit = _unit(at, "unit", q.value, cells["unit"], q.name)
    value = to_canonical(q.value, _number(at, "value", cells["value"]), unit)
    lo, hi = q.value_range
    if not lo < value < hi:
        raise at.error("value", f"{q.name} = {cells['value'].strip()} {unit} is outside the "
                       f"physical range ({lo:g}..{hi:g} in canonical units)")  # fmt: skip
    spread_raw = _number(at, "spread", cells["spread"])
    if not spread_raw > 0:
        raise at.error(
            "spread",
            f"must be the measurement's standard deviation, > 0; got {cells['spread'].strip()} "
            "(a zero spread would give the row infinite weight)",
        )
    source = cells["source"].strip()
    if not source:
        raise at.error("source", "is empty; say where the number comes from")
    provenance = cells.get("provenance", "").strip() or "measured"
    if provenance not in ("measured", "cited"):
        raise at.error(
            "provenance",
            f"must be measured or cited (source holding the citation); got {_shown(provenance)}",
        )
    return Measurement(
        file=at.file,
        row=at.row,
        quantity=q.name,
        conditions=conditions,
        label=cells["condition"].strip(),
        x=x,
        value=value,
        spread=spread_to_canonical(q.value, spread_raw, unit),
        source=source,
        provenance=provenance,
    )


def _decode(data: bytes, name: str) -> str:
    if len(data) > MAX_CSV_BYTES:
        raise InvalidParameterError(name, f"is {len(data)} bytes; the limit is {MAX_CSV_BYTES}")
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        row = data[: exc.start].count(b"\n") + 1
        raise InvalidParameterError(
            f"{name}: row {row}",
            f"is not UTF-8 text (byte 0x{data[exc.start]:02x} at offset {exc.start}); "
            "save it as UTF-8 (CSV UTF-8 in a spreadsheet)",
        ) from None


def _rows(text: str, name: str) -> list[Measurement]:
    lines = text.splitlines(keepends=True)
    kept = [("\n" if line.lstrip().startswith("#") else line) for line in lines]  # comments
    if "\x00" in text:
        raise InvalidParameterError(name, "holds NUL bytes: not a text file")
    reader = csv.reader(io.StringIO("".join(kept)), strict=True)
    header: list[str] | None = None
    out: list[Measurement] = []
    try:
        for cells in reader:
            if not any(c.strip() for c in cells):
                continue
            if header is None:
                header = [c.strip().lower() for c in cells]
                missing = [c for c in COLUMNS if c not in header]
                if missing:
                    raise InvalidParameterError(
                        f"{name}: row {reader.line_num}, column {missing[0]}",
                        f"missing from the header; the columns are {','.join(COLUMNS)}",
                    )
                extra = [c for c in header if c not in COLUMNS + OPTIONAL]
                if extra or len(set(header)) != len(header):
                    bad = extra[0] if extra else next(c for c in header if header.count(c) > 1)
                    raise InvalidParameterError(
                        f"{name}: row {reader.line_num}, column {_shown(bad)}",
                        f"{'unknown' if extra else 'repeated'} column; the columns are "
                        f"{','.join(COLUMNS)} (and optionally {','.join(OPTIONAL)})",
                    )
                continue
            at = _Row(name, reader.line_num)
            if len(cells) != len(header):
                raise at.error(
                    header[min(len(cells), len(header) - 1)],
                    f"has {len(cells)} cells, the header {len(header)}; quote text holding commas",
                )
            out.append(_measurement(at, dict(zip(header, cells, strict=True))))
            if len(out) > MAX_ROWS:
                raise at.error("quantity", f"more than {MAX_ROWS} rows; split the file")
    except csv.Error as exc:
        raise InvalidParameterError(
            f"{name}: row {reader.line_num}", f"is not CSV: {exc}"
        ) from None
    if header is None:
        raise InvalidParameterError(name, f"is empty; the header is {','.join(COLUMNS)}")
    if not out:
        raise InvalidParameterError(name, "has a header but no rows")
    return out


def _key(m: Measurement) -> tuple:
    return (m.quantity, tuple(sorted(m.conditions.items())), None if math.isnan(m.x) else m.x)


def _check_set(rows: list[Measurement]) -> None:
    """Contradictory or repeated rows, several inks of a role, curves of a single point."""
    seen: dict[tuple, Measurement] = {}
    for m in rows:
        first = seen.get(_key(m))
        if first is None:
            seen[_key(m)] = m
            continue
        where = (
            f"{first.where} and {m.where}"
            if first.file != m.file
            else f"{m.file}: rows {first.row} and {m.row}"
        )
        if first.value == m.value and first.spread == m.spread:
            raise InvalidParameterError(
                f"{where}, column value",
                f"the same {m.quantity} measurement twice; remove one (a repeat would double "
                "its weight)",
            )
        gap = abs(first.value - m.value) / math.hypot(first.spread, m.spread)
        if gap > CONTRADICTION_SD:
            raise InvalidParameterError(
                f"{where}, column value",
                f"{m.quantity} at the same conditions and x contradict each other "
                f"({first.value:g} ± {first.spread:g} and {m.value:g} ± {m.spread:g}, "
                f"{gap:.1f} combined sd apart); fix or remove one",
            )
    names: dict[str, Measurement] = {}
    for m in rows:
        if m.ink is None:
            continue
        role, name = m.ink
        other = names.get(role)
        if other is not None and other.ink is not None and other.ink[1] != name:
            raise InvalidParameterError(
                f"{m.where}, column condition",
                f"names {role} ink {name!r}, {other.where} names {other.ink[1]!r}; calibrate "
                "one active and one passive ink at a time",
            )
        names.setdefault(role, m)
    if "active" in names and "passive" in names:
        a, p = names["active"], names["passive"]
        if a.ink is not None and p.ink is not None and a.ink[1] == p.ink[1]:
            raise InvalidParameterError(
                f"{p.where}, column condition",
                f"the active and the passive ink are both called {a.ink[1]!r}; name them apart",
            )
    groups: dict[tuple[str, str], list[Measurement]] = {}
    for m in rows:
        role = m.ink[0] if m.ink else ""
        # the passive ink's free strain is one number (linear from the print temperature)
        if QUANTITIES[m.quantity].curve and (m.quantity, role) != ("free_length", "passive"):
            groups.setdefault((m.quantity, role), []).append(m)
    for (quantity, role), members in groups.items():
        if len({m.x for m in members}) < 2:
            m = members[0]
            ink = f" of the {role} ink" if role else ""
            raise InvalidParameterError(
                f"{m.where}, column x",
                f"{quantity}{ink} has one point (x = {m.x:g}); a curve needs >= 2 distinct x: "
                "add the other measurements or remove the row",
            )


def parse_measurements(files: Sequence[tuple[str, bytes]]) -> MeasurementSet:
    """A :class:`MeasurementSet` from ``(name, bytes)`` of measurement files (module
    docstring); raises :class:`InvalidParameterError` naming file, row and column."""
    if not files:
        raise InvalidParameterError("MEASUREMENTS", "give at least one measurement table (CSV)")
    rows: list[Measurement] = []
    for name, data in files:
        rows += _rows(_decode(data, name), name)
    _check_set(rows)
    return MeasurementSet(
        rows=tuple(rows),
        files=tuple((name, hashlib.sha256(data).hexdigest()) for name, data in files),
        sha256=data_sha256([data for _, data in files]),
    )


def read_measurements(paths: Sequence[str | Path]) -> MeasurementSet:
    """Read measurement files (CSV) into a :class:`MeasurementSet` (see
    :func:`parse_measurements`).

    Raises
    ------
    InvalidParameterError
        A missing file, or any problem of :func:`parse_measurements`.
    """
    files = []
    for path in paths:
        p = Path(path)
        if not p.is_file():
            raise InvalidParameterError(
                str(p), "no such file" if not p.exists() else "is not a file"
            )
        with open(p, "rb") as fh:
            files.append((str(p), fh.read(MAX_CSV_BYTES + 1)))
    return parse_measurements(files)

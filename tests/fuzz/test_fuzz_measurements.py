"""Fuzzed measurement tables: only one-line documented errors, and nothing nonsensical accepted.

Deterministic (``derandomize``), about 2 400 cases in all (the last test asserts >= 2 000 ran),
a few seconds:

* **cells** (900): one cell of an example table replaced by a nonsense value (empty, NaN, ∞,
  10⁴⁰⁰, negative or zero numbers, words, units of other dimensions, control characters) or by
  arbitrary text;
* **structure** (600): rows dropped, duplicated or cut, columns dropped or added, the header
  shuffled;
* **bytes** (900): raw bytes, examples re-encoded (Latin-1, cp1252, UTF-16) and examples with
  bytes flipped.

Every outcome is either :class:`InvalidParameterError` with a one-line message that starts
with the file name, or a table set whose every row is finite, has a spread > 0, a known
quantity and a unit-converted value inside its physical range.
"""

from __future__ import annotations

import math
import random
from pathlib import Path

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rotomorph.errors import InvalidParameterError
from rotomorph.io.measurement_csv import parse_measurements
from rotomorph.materials.lab_tables import CONDITION_KEYS, QUANTITIES

EXAMPLES = sorted((Path(__file__).parents[2] / "examples" / "inks").glob("*.csv"))
RAW = [p.read_bytes() for p in EXAMPLES]
LINES = [b.decode("utf-8").splitlines() for b in RAW]
COUNT = {"cases": 0}

BASE = settings(
    derandomize=True,
    deadline=None,
    database=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)

NONSENSE = [
    "", " ", "nan", "NaN", "inf", "-inf", "1e400", "-1", "0", "-0", "1e-320", "true", "3 mm/s",
    "mm/s", "1/mm", "kPa", "K", "%", "°C", "0x10", "1,5", "١٢", "\x00", "\x1b[2J", "é", "lce",
    "active=", "active=lce; active=lce", "v=3", "v=-3 mm/s", "T=3 mm/s", "side=up", "n=0",
    "=", ";;", '"', "1e5", "-1e5", "3" * 400,
]  # fmt: skip


def _check(files: list[tuple[str, bytes]]) -> None:
    COUNT["cases"] += 1
    try:
        data = parse_measurements(files)
    except InvalidParameterError as err:
        text = str(err)
        assert "\n" not in text and "\r" not in text, text
        assert any(text.startswith(name) for name, _ in files) or text.startswith("MEASUREMENTS")
        assert all(c.isprintable() for c in text), text
        return
    for m in data.rows:
        q = QUANTITIES[m.quantity]
        assert math.isfinite(m.value) and math.isfinite(m.spread) and m.spread > 0
        assert math.isnan(m.x) == (q.x is None)
        assert q.value_range[0] < m.value < q.value_range[1]
        assert set(m.conditions) <= set(CONDITION_KEYS)
        assert m.source.strip()


def _text(lines: list[str]) -> bytes:
    return ("\n".join(lines) + "\n").encode("utf-8")


def _data_rows(lines: list[str]) -> list[int]:
    return [i for i, line in enumerate(lines) if line and not line.startswith(("#", "quantity"))]


@settings(BASE, max_examples=500)
@given(st.integers(0, 10**9), st.sampled_from(NONSENSE))
def test_nonsense_cells(seed: int, value: str) -> None:
    rnd = random.Random(seed)
    k = rnd.randrange(len(LINES))
    lines = list(LINES[k])
    i = rnd.choice(_data_rows(lines))
    cells = lines[i].split(",") if '"' not in lines[i] else lines[i].rsplit(",", 2)
    j = rnd.randrange(len(cells))
    cells[j] = value if "," not in value else f'"{value}"'
    lines[i] = ",".join(cells)
    _check([(EXAMPLES[k].name, _text(lines))])


@settings(BASE, max_examples=400)
@given(st.integers(0, 10**9), st.text(max_size=40))
def test_arbitrary_cells(seed: int, value: str) -> None:
    rnd = random.Random(seed)
    k = rnd.randrange(len(LINES))
    lines = list(LINES[k])
    i = rnd.choice(_data_rows(lines))
    cells = lines[i].split(",")
    cells[rnd.randrange(len(cells))] = '"' + value.replace('"', '""') + '"'
    lines[i] = ",".join(cells)
    _check([(EXAMPLES[k].name, _text(lines))])


@settings(BASE, max_examples=600)
@given(st.integers(0, 10**9))
def test_structure(seed: int) -> None:
    rnd = random.Random(seed)
    files = []
    for k in rnd.sample(range(len(LINES)), rnd.randint(1, len(LINES))):
        lines = list(LINES[k])
        rows = _data_rows(lines)
        action = rnd.randrange(6)
        if action == 0:  # drop rows
            for i in sorted(rnd.sample(rows, rnd.randint(1, len(rows))), reverse=True):
                del lines[i]
        elif action == 1:  # duplicate a row (a repeat) or repeat it with another value
            i = rnd.choice(rows)
            lines.append(lines[i].replace(",0.", ",9.", 1) if rnd.random() < 0.5 else lines[i])
        elif action == 2:  # cut a row short
            i = rnd.choice(rows)
            lines[i] = lines[i][: rnd.randrange(len(lines[i]))]
        elif action == 3:  # drop a column from the header
            h = next(i for i, line in enumerate(lines) if line.startswith("quantity"))
            cols = lines[h].split(",")
            del cols[rnd.randrange(len(cols))]
            lines[h] = ",".join(cols)
        elif action == 4:  # shuffle the header (the cells no longer match their names)
            h = next(i for i, line in enumerate(lines) if line.startswith("quantity"))
            cols = lines[h].split(",")
            rnd.shuffle(cols)
            lines[h] = ",".join(cols)
        else:  # an extra column
            lines = [
                line + ",extra" if line and not line.startswith("#") else line for line in lines
            ]
        files.append((EXAMPLES[k].name, _text(lines)))
    _check(files)


@settings(BASE, max_examples=300)
@given(st.binary(max_size=400))
def test_raw_bytes(data: bytes) -> None:
    _check([("raw.csv", data)])


@settings(BASE, max_examples=300)
@given(
    st.integers(0, 10**9), st.sampled_from(["latin-1", "cp1252", "utf-16", "utf-16-le", "utf-8"])
)
def test_reencoded(seed: int, encoding: str) -> None:
    rnd = random.Random(seed)
    k = rnd.randrange(len(LINES))
    text = RAW[k].decode("utf-8")
    if rnd.random() < 0.5:
        text = text.replace("paper", "Käse", 1)
    _check([(EXAMPLES[k].name, text.encode(encoding, errors="replace"))])


@settings(BASE, max_examples=300)
@given(st.integers(0, 10**9))
def test_flipped_bytes(seed: int) -> None:
    rnd = random.Random(seed)
    k = rnd.randrange(len(RAW))
    data = bytearray(RAW[k])
    for _ in range(rnd.randint(1, 8)):
        data[rnd.randrange(len(data))] = rnd.randrange(256)
    _check([(EXAMPLES[k].name, bytes(data))])


def test_zz_enough_cases_ran() -> None:
    assert COUNT["cases"] >= 2000, COUNT

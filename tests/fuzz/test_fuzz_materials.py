"""Fuzzed materials files: only one-line documented errors, nothing from the file reaching a
terminal as control characters, and no nonsense accepted.

Validate-level (the file is read into a :class:`~rotomorph.materials.parameter_set.MaterialSet`
and every active/passive pair's :class:`~rotomorph.materials.natural.FilamentModel` is built),
deterministic (``derandomize``), about 2 600 cases (the last test asserts >= 2 000 ran), each
checked by :func:`_mutations.checked` (a documented :class:`~rotomorph.errors.MaterialError` in
one line naming a key, or an accepted set; the peak of traced allocations under 64 MiB). The
examples are the paper's inks (the package default) and the file ``rotomorph calibrate`` writes
from the example tables.

* **nonsense** (500): one number set to a boolean, the number as a string, ±10¹², 10²⁰, ±∞,
  NaN, 0, -1 or 10⁻³⁰⁰;
* **mutations** (700): a key replaced by an arbitrary TOML value, deleted, or an unknown key
  added;
* **text** (400): a text value (a source, unit, name, description) given a control, C1,
  line-separator or bidirectional-formatting character: always refused (a description may
  keep newlines and tabs), and the message shows the character escaped;
* **bytes** (400 + 200 + 400): raw bytes, examples re-encoded (Latin-1, cp1252, UTF-16/32,
  BOMs), examples with bytes flipped.

An accepted file: every value finite, every text free of refused characters
(:func:`rotomorph._text.unsafe_characters`), every pair's model built with finite fields.
"""

from __future__ import annotations

import copy
import math
from dataclasses import fields
from importlib import resources
from pathlib import Path
from typing import Any

import pytest
import tomli_w
from _mutations import (
    BASE,
    ENCODINGS,
    NONSENSE,
    TOML_VALUE,
    assert_cases_ran,
    checked,
    count,
    get,
    leaves,
    mutate,
    numeric_paths,
    set_value,
)
from hypothesis import given, settings
from hypothesis import strategies as st

from rotomorph._text import unsafe_characters
from rotomorph.errors import MaterialError
from rotomorph.io.materials_file import parse_materials_bytes
from rotomorph.io.tomlfile import decode_toml_bytes

RAW = [
    resources.files("rotomorph.materials").joinpath("data/paper_inks.toml").read_bytes(),
    (Path(__file__).parents[2] / "examples" / "inks" / "inks.toml").read_bytes(),
]
PARSED = [decode_toml_bytes(b, "example") for b in RAW]
#: Characters a text value must not carry (one of each class the house rules refuse).
REFUSED = ["\x00", "\x07", "\x08", "\r", "\x1b", "\x7f", "\x9b", "\u2028", "\u202e", "\u2066"]


def fuzz(cases: int) -> settings:
    return settings(BASE, max_examples=cases)


def _texts(node: Any, path: tuple = ()) -> list[tuple[tuple, str]]:
    if isinstance(node, dict):
        return [t for k, v in node.items() for t in _texts(v, (*path, k))]
    if isinstance(node, list):
        return [t for i, v in enumerate(node) for t in _texts(v, (*path, i))]
    return [(path, node)] if isinstance(node, str) else []


def _accepted_is_sane(materials: Any) -> None:
    doc = materials.document.model_dump()
    for path, text in _texts(doc):
        assert not unsafe_characters(text, newlines=path[-1] == "description"), (path, text)
    for path in leaves(doc):
        value = get(doc, path)
        if isinstance(value, float):
            assert math.isfinite(value), path
    assert materials.name.isprintable() and len(materials.sha256) == 64
    for active in materials.names("active"):
        for passive in materials.names("passive"):
            model = checked(lambda a=active, p=passive: materials.filament_model(a, p), ())
            for f in fields(model):
                value = getattr(model, f.name)
                if isinstance(value, float):
                    assert math.isfinite(value), (active, passive, f.name, value)


def _parse(blob: bytes) -> Any:
    """The set, or the refusal's message (one printable line starting with the file name)."""
    try:
        return parse_materials_bytes(blob, "fuzz.toml")
    except MaterialError as err:
        text = str(err)
        assert "\n" not in text and text.startswith("fuzz.toml") and text.isprintable(), text
        assert err.field, text
        return text


def _check(blob: bytes | None) -> None:
    if blob is None:
        return
    outcome = checked(lambda: _parse(blob), ())
    if not isinstance(outcome, str):
        _accepted_is_sane(outcome)


def _refused(blob: bytes) -> str:
    with pytest.raises(MaterialError) as info:
        parse_materials_bytes(blob, "fuzz.toml")
    text = str(info.value)
    assert "\n" not in text and text.startswith("fuzz.toml") and text.isprintable(), text
    return text


def test_examples_are_valid():
    for blob in RAW:
        _accepted_is_sane(parse_materials_bytes(blob))


@fuzz(500)
@given(data=st.data(), which=st.integers(0, len(PARSED) - 1), value=NONSENSE)
def test_nonsense_numbers(data, which, value):
    count()
    path = data.draw(st.sampled_from(numeric_paths(PARSED[which])))
    _check(set_value(PARSED[which], path, value))


@fuzz(700)
@given(
    data=st.data(),
    which=st.integers(0, len(PARSED) - 1),
    action=st.sampled_from(["replace", "delete", "add"]),
    value=TOML_VALUE,
)
def test_mutations(data, which, action, value):
    count()
    _check(mutate(PARSED[which], data, action, value))


@fuzz(400)
@given(
    data=st.data(),
    which=st.integers(0, len(PARSED) - 1),
    char=st.sampled_from([*REFUSED, "\n", "\t"]),
    where=st.floats(0, 1),
)
def test_control_characters_in_text(data, which, char, where):
    count()
    doc = copy.deepcopy(PARSED[which])
    path, text = data.draw(st.sampled_from(_texts(doc)))
    cut = int(where * len(text))
    get(doc, path[:-1])[path[-1]] = text[:cut] + char + text[cut:]
    blob = tomli_w.dumps(doc).encode()
    if char in "\n\t" and path[-1] == "description":
        _accepted_is_sane(parse_materials_bytes(blob, "fuzz.toml"))
        return
    message = _refused(blob)
    assert char not in message


@fuzz(400)
@given(raw=st.binary(max_size=400))
def test_raw_bytes(raw):
    count()
    _check(raw)


@fuzz(200)
@given(which=st.integers(0, len(RAW) - 1), encoding=st.sampled_from(ENCODINGS))
def test_re_encoded(which, encoding):
    count()
    text = RAW[which].decode().replace('source = "', 'source = "Gr\u00f6\u00dfe ', 1)
    _check(text.encode(encoding, errors="replace"))


@fuzz(400)
@given(
    which=st.integers(0, len(RAW) - 1),
    flips=st.lists(st.tuples(st.floats(0, 1, exclude_max=True), st.integers(0, 255)), max_size=6),
)
def test_flipped_bytes(which, flips):
    count()
    blob = bytearray(RAW[which])
    for where, byte in flips:
        blob[int(where * len(blob))] = byte
    _check(bytes(blob))


def test_zz_at_least_2000_cases_ran():
    """The fuzz tests above ran >= 2 000 cases in all (skipped when only some were selected)."""
    assert_cases_ran(__name__, globals(), 2000)

"""Fuzzed sweep files: only documented errors, nothing over the limits accepted, bounded memory.

Validate-level only (no run is computed), deterministic (``derandomize``), 2 500 cases (the last
test asserts >= 2 000 ran), each checked by :func:`_mutations.checked`: the file is refused with
:class:`~rotomorph.errors.InvalidParameterError` in one line naming a field, or accepted with at
most :data:`~rotomorph.sweep.spec.MAX_POINTS` points (small accepted sweeps are also planned:
every point resolves to a run or to a recorded invalid run); the peak of Python's traced
allocations stays under 64 MiB per file.

* **nonsense** (600): one number of an example set to a value of a class that must be handled
  (a boolean, a number as text, ±10¹², 10²⁰, NaN/∞, 0, −1, 10⁻³⁰⁰);
* **mutations** (800): a random key replaced by an arbitrary TOML value, deleted, or added;
* **sizes** (200): every list and count grown by 10 to 10⁹ times;
* **bytes** (400 + 200 + 300): raw bytes, examples re-encoded (Latin-1, cp1252, UTF-16/32,
  BOMs), examples with random bytes flipped.
"""

from __future__ import annotations

import copy
from pathlib import Path

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
    mutate,
    numeric_paths,
    set_value,
)
from hypothesis import given, settings
from hypothesis import strategies as st

from rotomorph.errors import InvalidParameterError
from rotomorph.io.tomlfile import decode_toml_bytes
from rotomorph.sweep.runner import plan_sweep
from rotomorph.sweep.spec import MAX_POINTS, parse_sweep_bytes

EXAMPLES = sorted((Path(__file__).parents[2] / "examples" / "sweeps").glob("*.toml"))
MACHINE = b"""schema_version = 1
name = "lhs"
outputs = ["end_to_end_ratio", "morphology"]
hdf5 = true
[design]
schema_version = 1
[[design.filaments]]
spacing = 0.5
segments = [{ kind = "line", length = 8.0 }]
[settings]
method = "closed_form"
[sampling]
method = "latin_hypercube"
samples = 8
seed = 3
[machine]
dialect = "rs274"
max_feed = 5.0
[[parameters]]
path = "filaments[0].speed"
distribution = { kind = "loguniform", low = 0.25, high = 3.0 }
[[parameters]]
path = "filaments[0].rotation_number"
range = { start = 0.0, stop = 1.0, step = 0.25 }
"""
RAW = [p.read_bytes() for p in EXAMPLES] + [MACHINE]
PARSED = [decode_toml_bytes(b, "example") for b in RAW]
FOLDER = EXAMPLES[0].parent


def _check(blob: bytes | None) -> None:
    if blob is None:
        return
    sweep = checked(
        lambda: parse_sweep_bytes(blob, "fuzz.toml", folder=FOLDER), (InvalidParameterError,)
    )
    if sweep is None:
        return
    points = sweep.point_count()
    assert points <= MAX_POINTS
    if points <= 20:
        specs = checked(lambda: plan_sweep(sweep)[1], ())
        assert len(specs) == points


def fuzz(cases: int):
    return settings(BASE, max_examples=cases)


def test_examples_are_valid():
    for blob in RAW:
        assert parse_sweep_bytes(blob, folder=FOLDER).point_count() >= 1


@fuzz(600)
@given(data=st.data(), which=st.integers(0, len(PARSED) - 1), value=NONSENSE)
def test_nonsense_numbers(data, which, value):
    count()
    doc = PARSED[which]
    path = data.draw(st.sampled_from(numeric_paths(doc)))
    _check(set_value(doc, path, value))


@fuzz(800)
@given(
    data=st.data(),
    which=st.integers(0, len(PARSED) - 1),
    action=st.sampled_from(["replace", "delete", "add"]),
    value=TOML_VALUE,
)
def test_mutations(data, which, action, value):
    count()
    _check(mutate(PARSED[which], data, action, value))


@fuzz(200)
@given(which=st.integers(0, len(PARSED) - 1), scale=st.sampled_from([10, 1000, 10**6, 10**9]))
def test_sizes(which, scale):
    """Every values list repeated, every num and samples multiplied, every step divided."""
    count()
    doc = copy.deepcopy(PARSED[which])
    for param in doc.get("parameters", []):
        if "values" in param:
            param["values"] = param["values"] * min(scale, 1000)
        rng = param.get("range", {})
        if "num" in rng:
            rng["num"] *= scale
        if "step" in rng:
            rng["step"] /= scale
    if "samples" in doc.get("sampling", {}):
        doc["sampling"]["samples"] *= scale
    for path in numeric_paths(doc):
        if path[-1] == "steps":
            get(doc, path[:-1])[path[-1]] *= scale
    _check(tomli_w.dumps(doc).encode())


@fuzz(400)
@given(raw=st.binary(max_size=400))
def test_raw_bytes(raw):
    count()
    _check(raw)


@fuzz(200)
@given(which=st.integers(0, len(RAW) - 1), encoding=st.sampled_from(ENCODINGS))
def test_re_encoded(which, encoding):
    count()
    text = RAW[which].decode().replace('name = "', 'name = "Gr\u00f6\u00dfe ', 1)
    _check(text.encode(encoding, errors="replace"))


@fuzz(300)
@given(
    which=st.integers(0, len(RAW) - 1),
    flips=st.lists(st.tuples(st.floats(0, 1, exclude_max=True), st.integers(0, 255)), max_size=4),
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

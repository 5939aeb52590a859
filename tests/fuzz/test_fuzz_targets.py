"""Fuzzed inverse-design target files: only documented errors, nothing over the limits accepted,
bounded memory.

Validate-level only (no design is computed), deterministic (``derandomize``), 2 500 cases (the
last test asserts >= 2 000 ran), each checked by :func:`_mutations.checked`: the file is
refused with :class:`~rotomorph.errors.InvalidDesignError` in one line naming a field, or
accepted within the limits (curve samples <= :data:`~rotomorph.inverse.targets.MAX_CURVE_SAMPLES`,
designed vertices <= :data:`~rotomorph.inverse.targets.MAX_CURVE_NODES`), and then its target
builds (small curves are sampled, surfaces evaluated); the peak of Python's traced
allocations stays under 64 MiB per file.

* **nonsense** (600), **mutations** (800), **sizes** (200: turns and samples grown 10 to 10⁹
  times, point lists up to 100 times, height maps up to 50 × 50, the spacing shrunk as much),
  **bytes** (400 + 200 + 300), as for sweep files.
"""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np
import tomli_w
from _mutations import (
    BASE,
    ENCODINGS,
    NONSENSE,
    TOML_VALUE,
    assert_cases_ran,
    checked,
    count,
    mutate,
    numeric_paths,
    set_value,
)
from hypothesis import given, settings
from hypothesis import strategies as st

from rotomorph.errors import InvalidDesignError
from rotomorph.inverse.targets import (
    MAX_CURVE_NODES,
    MAX_CURVE_SAMPLES,
    curve_length,
    curve_points,
    parse_target_bytes,
)
from rotomorph.io.tomlfile import decode_toml_bytes

EXAMPLES = sorted((Path(__file__).parents[2] / "examples" / "targets").glob("*.toml"))
HEIGHT_MAP = b"""schema_version = 1
kind = "height_map"
name = "bump"
[height_map]
x = [-10.0, -5.0, 0.0, 5.0, 10.0]
y = [-10.0, -5.0, 0.0, 5.0, 10.0]
z = [[0.0, 0.0, 0.0, 0.0, 0.0], [0.0, 0.5, 1.0, 0.5, 0.0], [0.0, 1.0, 2.0, 1.0, 0.0],
     [0.0, 0.5, 1.0, 0.5, 0.0], [0.0, 0.0, 0.0, 0.0, 0.0]]
[lattice]
n = 5
[options]
max_iterations = 5
"""
RAW = [p.read_bytes() for p in EXAMPLES] + [HEIGHT_MAP]
PARSED = [decode_toml_bytes(b, "example") for b in RAW]


def _check(blob: bytes | None) -> None:
    if blob is None:
        return
    target = checked(lambda: parse_target_bytes(blob, "fuzz.toml"), (InvalidDesignError,))
    if target is None:
        return
    if target.kind == "curve":
        spec = target.curve
        assert spec.samples() <= MAX_CURVE_SAMPLES
        assert curve_length(spec) / target.options.spacing + 1 <= MAX_CURVE_NODES
        if spec.samples() <= 5_000:
            pts = checked(lambda: curve_points(spec), ())
            assert np.isfinite(pts).all()
    else:
        surface = checked(lambda: target.surface_target(), (InvalidDesignError,))
        if surface is not None:
            values = surface.height(np.array([0.0, 1.0]), np.array([0.0, 1.0]))
            assert np.isfinite(np.asarray(values[0])).all()


def fuzz(cases: int):
    return settings(BASE, max_examples=cases)


def test_examples_are_valid():
    for blob in RAW:
        parse_target_bytes(blob)


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
    count()
    doc = copy.deepcopy(PARSED[which])
    curve = doc.get("curve", {})
    for key in ("turns", "samples_per_turn"):
        if key in curve:
            curve[key] *= scale
    if "points" in curve:
        curve["points"] = curve["points"] * min(scale, 100)
    options = doc.setdefault("options", {})
    options["spacing"] = options.get("spacing", 0.1) / scale
    hm = doc.get("height_map")
    if hm:
        grow = min(scale, 10)  # a 1 000 x 1 000 grid is 20 MB of TOML: tested by hand
        hm["x"] = [float(v) for v in np.linspace(-10, 10, 5 * grow)]
        hm["y"] = hm["x"]
        hm["z"] = [[0.0] * len(hm["x"]) for _ in hm["x"]]
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

"""Fuzzed design files: only documented errors, and no nonsense accepted (validate level).

Validate-level only (no solves), deterministic (``derandomize``), about 2 270 cases in all
(the last test asserts >= 2 000 ran):

* **nonsense** (700 + 36): one numeric field of an example set to a value of a class that must
  be refused — a boolean, the number as a string, ±10¹², 10²⁰, NaN/∞ — or a zero or negative
  feed, written as TOML and read back; the file must be refused with
  :class:`InvalidDesignError`.
* **mutations** (700 + 24): an example with a random key replaced by an arbitrary TOML value,
  deleted, or an unknown key added, or every count grown and spacing shrunk 10-10⁴ times; the
  result is either a documented error or a valid design whose programs build (small ones) with
  speeds, radii and active fractions in range.
* **bytes** (400 + 112 + 300): raw bytes, examples re-encoded (Latin-1, cp1252, UTF-16/32,
  BOMs) and examples with random bytes flipped; only :class:`InvalidDesignError` or a valid
  design.
"""

from __future__ import annotations

import copy
import math
import sys
from pathlib import Path
from typing import Any

import pytest
import tomli_w
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rotomorph.errors import InvalidDesignError
from rotomorph.io.design_limits import LIMITS
from rotomorph.io.designfile import design_size, parse_design_bytes
from rotomorph.io.tomlfile import decode_toml_bytes

EXAMPLES = sorted((Path(__file__).parents[2] / "examples" / "designs").glob("*.toml"))
RAW = [p.read_bytes() for p in EXAMPLES]
PARSED = [decode_toml_bytes(b, "example") for b in RAW]
SMALL = 5_000  # build the print programs of accepted designs up to this many rod nodes

BASE = settings(
    derandomize=True,
    deadline=None,
    database=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)


def fuzz(cases: int) -> settings:
    """Deterministic settings with ``cases`` examples (counted towards the 2 200)."""
    return settings(BASE, max_examples=cases)


def _leaves(node: Any, path: tuple = ()) -> list[tuple]:
    """Paths of every leaf value (and of every table) of a parsed TOML document."""
    out = []
    if isinstance(node, dict):
        out.append(path)
        for k, v in node.items():
            out += _leaves(v, (*path, k))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            out += _leaves(v, (*path, i))
    else:
        out.append(path)
    return out


def _get(doc: Any, path: tuple) -> Any:
    for part in path:
        doc = doc[part]
    return doc


def _set(doc: Any, path: tuple, value: Any) -> None:
    _get(doc, path[:-1])[path[-1]] = value


def _numeric_paths(doc: dict) -> list[tuple]:
    return [
        p
        for p in _leaves(doc)
        if p
        and p[0] != "schema_version"
        and isinstance(_get(doc, p), int | float)
        and not isinstance(_get(doc, p), bool)
    ]


def _accepted_is_sane(design: Any) -> None:
    """An accepted design: programs build (if small) with values in their physical ranges."""
    if design_size(design).nodes > SMALL:
        return
    try:
        programs = design.to_programs()
    except InvalidDesignError:
        return  # documented (e.g. a polyline that does not start at the current end)
    speed, radius = LIMITS["speed"], LIMITS["filament_radius"]
    for prog in programs:
        assert speed.minimum <= prog.speed.min() and prog.speed.max() <= speed.maximum
        assert radius.minimum <= prog.radius <= radius.maximum
        assert 0 < prog.active_fraction <= 1
        assert all(math.isfinite(float(v)) for v in prog.points.ravel())


CASES: dict[str, int] = {}


def _count() -> None:
    """Count one executed case of the calling test (the total is asserted at the end)."""
    name = sys._getframe(1).f_code.co_name
    CASES[name] = CASES.get(name, 0) + 1


def _check(blob: bytes) -> None:
    try:
        design = parse_design_bytes(blob, "fuzz.toml")
    except InvalidDesignError as err:
        assert "\n" not in str(err) and err.field
        return
    _accepted_is_sane(design)


NONSENSE = st.sampled_from(
    [True, False, "3.0", "1e12", 1e12, -1e12, 10**20, math.inf, -math.inf, math.nan]
)


@fuzz(700)
@given(data=st.data(), which=st.integers(0, len(PARSED) - 1), value=NONSENSE)
def test_nonsense_values_are_refused(data, which, value):
    _count()
    doc = copy.deepcopy(PARSED[which])
    path = data.draw(st.sampled_from(_numeric_paths(doc)))
    _set(doc, path, value)
    with pytest.raises(InvalidDesignError):
        parse_design_bytes(tomli_w.dumps(doc).encode(), "fuzz.toml")


@fuzz(200)
@given(data=st.data(), which=st.integers(0, len(PARSED) - 1), value=st.sampled_from([0, -3.0]))
def test_zero_and_negative_feeds_are_refused(data, which, value):
    _count()
    doc = copy.deepcopy(PARSED[which])
    speeds = [p for p in _numeric_paths(doc) if p[-1] == "speed"]
    _set(doc, data.draw(st.sampled_from(speeds)), value)
    with pytest.raises(InvalidDesignError, match=r"speed: must be >= 0\.01 mm/s"):
        parse_design_bytes(tomli_w.dumps(doc).encode(), "fuzz.toml")


TOML_SCALAR = st.one_of(
    st.booleans(),
    st.integers(-(2**63), 2**63 - 1),
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=12),
    st.sampled_from(["line", "arc", "sinusoid", "polyline", "dome", "custom", "lce", "outer"]),
)
TOML_VALUE = st.recursive(
    TOML_SCALAR,
    lambda inner: (
        st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=6), inner, max_size=3)
    ),
    max_leaves=8,
)


@fuzz(700)
@given(
    data=st.data(),
    which=st.integers(0, len(PARSED) - 1),
    action=st.sampled_from(["replace", "delete", "add"]),
    value=TOML_VALUE,
)
def test_mutated_examples_give_only_documented_errors(data, which, action, value):
    _count()
    doc = copy.deepcopy(PARSED[which])
    path = data.draw(st.sampled_from([p for p in _leaves(doc) if p]))
    parent = _get(doc, path[:-1])
    if action == "delete":
        del parent[path[-1]]
    elif action == "add" and isinstance(_get(doc, path), dict):
        _get(doc, path)[data.draw(st.text(min_size=1, max_size=8))] = value
    else:
        parent[path[-1]] = value
    try:
        blob = tomli_w.dumps(doc).encode()
    except (TypeError, ValueError):  # tomli_w cannot write some shapes (e.g. mixed arrays)
        return
    _check(blob)


@fuzz(200)
@given(which=st.integers(0, len(PARSED) - 1), scale=st.sampled_from([10.0, 100.0, 1e4]))
def test_scaled_sizes_are_refused_or_built(which, scale):
    """Grow every count and shrink every spacing: refused up front above the node limit."""
    _count()
    doc = copy.deepcopy(PARSED[which])
    for path in _numeric_paths(doc):
        if path[-1] in ("n", "ghost_nodes", "periods", "length"):
            _set(doc, path, type(_get(doc, path))(_get(doc, path) * scale))
        elif path[-1] == "spacing" and "filaments" in path:
            _set(doc, path, _get(doc, path) / scale)
    _check(tomli_w.dumps(doc).encode())


ENCODINGS = ["latin-1", "utf-16", "utf-16-le", "utf-16-be", "utf-32", "utf-8-sig", "cp1252"]


@fuzz(400)
@given(raw=st.binary(max_size=400))
def test_raw_bytes(raw):
    _count()
    _check(raw)


@fuzz(200)
@given(
    which=st.integers(0, len(RAW) - 1), encoding=st.sampled_from(ENCODINGS), accent=st.booleans()
)
def test_re_encoded_examples(which, encoding, accent):
    _count()
    text = RAW[which].decode()
    if accent:
        text = text.replace('name = "', 'name = "Gr\u00f6\u00dfe ', 1)
    _check(text.encode(encoding, errors="replace"))


@fuzz(300)
@given(
    which=st.integers(0, len(RAW) - 1),
    flips=st.lists(st.tuples(st.floats(0, 1, exclude_max=True), st.integers(0, 255)), max_size=4),
)
def test_flipped_bytes(which, flips):
    _count()
    blob = bytearray(RAW[which])
    for where, byte in flips:
        blob[int(where * len(blob))] = byte
    _check(bytes(blob))


def test_zz_at_least_2000_cases_ran():
    """The fuzz tests above ran >= 2 000 cases in all (skipped when only some were selected)."""
    fuzzers = {
        name
        for name in globals()
        if name.startswith("test_") and name != "test_zz_at_least_2000_cases_ran"
    }
    if set(CASES) != fuzzers:
        pytest.skip("only some fuzz tests were selected")
    assert sum(CASES.values()) >= 2000, CASES

"""Shared pieces of the TOML fuzz tests (sweep and target files): mutation of a parsed document,
TOML values, re-encodings, and a check that a call raises only documented errors and stays
under a memory bound."""

from __future__ import annotations

import copy
import math
import sys
import tracemalloc
from collections.abc import Callable
from typing import Any

import pytest
import tomli_w
from hypothesis import HealthCheck, settings
from hypothesis import strategies as st

BASE = settings(
    derandomize=True,
    deadline=None,
    database=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)

#: Peak of Python allocations allowed while validating one file (bytes): a file is <= 4 MiB.
PEAK_LIMIT = 64 * 2**20

NONSENSE = st.sampled_from(
    [True, False, "3.0", 1e9, 1e12, -1e12, 10**20, -1, 0, math.inf, -math.inf, math.nan, 1e-300]
)
TOML_SCALAR = st.one_of(
    st.booleans(),
    st.integers(-(2**63), 2**63 - 1),
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=12),
    st.sampled_from(["grid", "random", "latin_hypercube", "helix", "points", "dome", "\x1b[2J"]),
)
TOML_VALUE = st.recursive(
    TOML_SCALAR,
    lambda inner: (
        st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=6), inner, max_size=3)
    ),
    max_leaves=8,
)
ENCODINGS = ["latin-1", "utf-16", "utf-16-le", "utf-32", "utf-8-sig", "cp1252"]


def leaves(node: Any, path: tuple = ()) -> list[tuple]:
    """Paths of every leaf value (and of every table) of a parsed TOML document."""
    out = []
    if isinstance(node, dict):
        out.append(path)
        for k, v in node.items():
            out += leaves(v, (*path, k))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            out += leaves(v, (*path, i))
    else:
        out.append(path)
    return out


def get(doc: Any, path: tuple) -> Any:
    for part in path:
        doc = doc[part]
    return doc


def numeric_paths(doc: dict) -> list[tuple]:
    return [
        p
        for p in leaves(doc)
        if p
        and p[0] != "schema_version"
        and isinstance(get(doc, p), int | float)
        and not isinstance(get(doc, p), bool)
    ]


def mutate(doc: dict, data: Any, action: str, value: Any) -> bytes | None:
    """``doc`` with one key replaced by ``value``, deleted, or a new key added, as TOML bytes
    (``None`` when tomli_w cannot write the result)."""
    doc = copy.deepcopy(doc)
    path = data.draw(st.sampled_from([p for p in leaves(doc) if p]))
    parent = get(doc, path[:-1])
    if action == "delete":
        del parent[path[-1]]
    elif action == "add" and isinstance(get(doc, path), dict):
        get(doc, path)[data.draw(st.text(min_size=1, max_size=8))] = value
    else:
        parent[path[-1]] = value
    try:
        return tomli_w.dumps(doc).encode()
    except (TypeError, ValueError):  # tomli_w cannot write some shapes (e.g. mixed arrays)
        return None


def set_value(doc: dict, path: tuple, value: Any) -> bytes | None:
    doc = copy.deepcopy(doc)
    get(doc, path[:-1])[path[-1]] = value
    try:
        return tomli_w.dumps(doc).encode()
    except (TypeError, ValueError):
        return None


CASES: dict[str, int] = {}


def count() -> None:
    """Count one executed case of the calling test (the total is asserted at the end)."""
    frame = sys._getframe(1)
    name = f"{frame.f_globals['__name__']}.{frame.f_code.co_name}"
    CASES[name] = CASES.get(name, 0) + 1


def cases_of(module: str) -> dict[str, int]:
    """Cases counted for the tests of ``module``, by test name."""
    prefix = module + "."
    return {k[len(prefix) :]: v for k, v in CASES.items() if k.startswith(prefix)}


def assert_cases_ran(module: str, names: dict[str, Any], at_least: int) -> None:
    """The fuzz tests of ``module`` (its ``test_`` names, the case-count check itself and an
    examples check left out) ran ``>= at_least`` cases in all; skipped when only some ran."""
    mine = cases_of(module)
    fuzzers = {n for n in names if n.startswith("test_")} - {
        "test_zz_at_least_2000_cases_ran",
        "test_examples_are_valid",
    }
    if set(mine) != fuzzers:
        pytest.skip("only some fuzz tests were selected")
    assert sum(mine.values()) >= at_least, mine


def checked(call: Callable[[], Any], documented: tuple[type[BaseException], ...]) -> Any:
    """``call()``'s result, or ``None`` when it raised one of ``documented`` (one line, naming a
    field); any other exception fails the test, and so does a traced peak above
    :data:`PEAK_LIMIT`."""
    tracemalloc.start()
    try:
        try:
            result = call()
        except documented as err:
            assert "\n" not in str(err) and getattr(err, "field", "x"), repr(err)
            result = None
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak <= PEAK_LIMIT, f"{peak / 2**20:.0f} MiB allocated"
    return result

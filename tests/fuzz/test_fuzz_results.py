"""Fuzzed results files: only documented errors, and never more memory than the limit.

A small valid run (two filaments, everything a simulated run stores) is mutated in memory and
read back with :func:`rotomorph.io.results.read_results`; deterministic (``derandomize``),
2 100 cases (the last test asserts >= 2 000 ran; about 25 ms of CPU each, mostly h5py's cost
per object):

* **structure** (1 000): a dataset deleted, replaced by an array of another type or shape,
  given NaN, infinity or a huge or negative value, turned into a soft or external link or a
  compression bomb declaring up to 2⁴⁰ elements; an attribute deleted or set to arbitrary text,
  bytes or numbers;
* **metadata** (800): one value anywhere in the ``metadata`` or ``design`` JSON replaced by an
  arbitrary JSON value (nested lists and tables, text with control characters, numbers);
* **bytes** (300): the file truncated at an arbitrary offset.

Each case must either read (and then hold what the figures and the viewer rely on: finite
positions, edges inside the nodes, chains inside the nodes) or raise
:class:`~rotomorph.errors.InvalidParameterError` (``OSError`` only when the bytes are not HDF5 at
all); in the structure and truncation cases the peak of Python's traced allocations stays
under the array limit, lowered here to 4 MiB so that every bomb is far above it.
"""

from __future__ import annotations

import copy
import io
import json
import sys
import tracemalloc

import h5py
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import rotomorph.io.results_read as results_read
from rotomorph.errors import InvalidParameterError
from rotomorph.io.results import read_results, summarize, write_results
from rotomorph.io.validity import assess

LIMIT = 4 * 2**20  # bytes of arrays read (the documented MAX_RESULTS_BYTES, lowered)
SLACK = 4 * 2**20  # Python objects besides the arrays (metadata, names, h5py)

BASE = settings(
    derandomize=True,
    deadline=None,
    database=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)
CASES: dict[str, int] = {}


def _count() -> None:
    name = sys._getframe(1).f_code.co_name
    CASES[name] = CASES.get(name, 0) + 1


def _base_file(path) -> bytes:
    """The bytes of a valid results file written at ``path``."""
    steps, n = 3, 8
    s = np.linspace(0, 5, n)
    pos = np.stack(
        [
            np.concatenate([np.c_[s, 0 * s, 0.1 * k * s], np.c_[s, 0 * s + 3, 0 * s]])
            for k in range(3)
        ]
    )
    edges = np.array(
        [[i, i + 1] for i in range(n - 1)] + [[n + i, n + i + 1] for i in range(n - 1)]
    )
    e = len(edges)
    write_results(
        path,
        design={"name": "d", "filaments": [{"name": "a"}]},
        edges=edges,
        branch=None,
        positions=pos,
        scalars={"temperature": [25.0, 100.0, 175.0], "converged": np.ones(steps)},
        fields={
            "active_normal": np.tile([0.0, 0.0, 1.0], (steps, e, 1)),
            "end_to_end_ratio_per_filament": np.ones((steps, 2)),
        },
        units={"end_to_end_ratio_per_filament": "1"},
        metadata={
            "kind": "filaments",
            "design_name": "d",
            "contact": False,
            "chains": [
                {"name": "a", "start": 0, "stop": n},
                {"name": "b", "start": n, "stop": 2 * n},
            ],
            "filaments": [
                {"name": "a", "end_to_end_ratio": 1.0, "helix": {"rms_residual_mm": 0.0}},
                {"name": "b", "physical": {"verdict": "yes", "steps": ["yes"] * 3}},
            ],
            "physical": {"verdict": "yes", "reason": "all checks passed"},
        },
        static={"radius": np.full(e, 0.3)},
        programs=[
            {
                "name": "a",
                "points": pos[0, :n],
                "speed": np.full(n, 3.0),
                "nozzle_angle": np.zeros(n),
                "radius": 0.3,
                "active_fraction": 0.5,
                "active_material": "lce",
                "passive_material": "acrylate",
                "layer": 0.0,
            }
        ],
    )
    return path.read_bytes()


@pytest.fixture(scope="module", autouse=True)
def _lowered_limit():
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(results_read, "MAX_RESULTS_BYTES", LIMIT)
        yield


_BASE: list[bytes] = []
_OBJECTS: list[tuple[list[str], list[str]]] = []


@pytest.fixture(scope="module", autouse=True)
def _base(tmp_path_factory):
    """The valid file's bytes, kept in :data:`_BASE` (not a test argument, so that a failing
    case does not print 30 kB of bytes)."""
    _BASE.append(_base_file(tmp_path_factory.mktemp("fuzz-results") / "results.h5"))
    with h5py.File(io.BytesIO(_BASE[0]), "r") as h5:
        _OBJECTS.append(_objects(h5))
    yield
    _BASE.clear()
    _OBJECTS.clear()


def _objects(h5: h5py.File) -> tuple[list[str], list[str]]:
    """Paths of the datasets and of every object (groups included) of a file."""
    datasets, objects = [], []

    def visit(name, obj):
        objects.append(name)
        if isinstance(obj, h5py.Dataset):
            datasets.append(name)

    h5.visititems(visit)
    return datasets, objects


def _read(blob: bytes, *, traced: bool = True) -> None:
    """Read ``blob``; assert only documented errors and (``traced``) bounded memory."""
    assert results_read.MAX_RESULTS_BYTES == LIMIT
    if traced:
        tracemalloc.start()
    try:
        try:
            run = read_results(io.BytesIO(blob))
        except InvalidParameterError as err:
            assert "\n" not in str(err) and err.field
            run = None
        except OSError:
            with pytest.raises(OSError):  # documented only for bytes that are not HDF5
                h5py.File(io.BytesIO(blob), "r").close()
            run = None
        peak = tracemalloc.get_traced_memory()[1] if traced else 0
    finally:
        if traced:
            tracemalloc.stop()
    assert peak <= LIMIT + SLACK, f"{peak / 2**20:.1f} MiB allocated"
    if run is not None:
        n = run.positions.shape[1]
        assert np.isfinite(run.positions).all()
        assert run.edges.min() >= 0 and run.edges.max() < n
        for c in run.metadata.get("chains", []):
            assert 0 <= c["start"] < c["stop"] <= n
        assess(run.scalars, run.metadata, run.n_steps)
        json.dumps(summarize(run), allow_nan=False)
        run.step_labels()


def _mutated(base: bytes, change) -> bytes:
    bio = io.BytesIO(base)
    with h5py.File(bio, "r+") as h5:
        change(h5)
    return bio.getvalue()


def _array(shape, fill, dtype):
    with np.errstate(all="ignore"):
        return np.full(shape, fill).astype(dtype)


ARRAYS = st.builds(
    lambda dtype, shape, fill: _array(shape, fill, dtype),
    st.sampled_from(["f8", "f4", "i8", "i4", "u1", "?", "S3"]),
    st.lists(st.sampled_from([0, 1, 2, 3, 8, 14, 16]), max_size=3).map(tuple),
    st.sampled_from([0, 1, -1, 7, 2**31, 1e308, np.nan, np.inf, -np.inf]),
)
TEXT = st.text(st.characters(codec="utf-8", exclude_categories=["Cs"]), max_size=20)
ATTR = st.one_of(
    TEXT,
    st.binary(min_size=1, max_size=20).map(np.void),
    st.integers(-(2**40), 2**40),
    st.floats(allow_nan=True),
    st.lists(st.integers(-5, 5), max_size=4).map(np.array),
)
SPECIAL = st.sampled_from([np.nan, np.inf, -np.inf, -1, 10**6, -(10**9), 1e300])


@settings(BASE, max_examples=1_000)
@given(data=st.data())
def test_structure(data):
    _count()

    def change(h5):
        datasets, objects = _OBJECTS[0]  # the same for every case: each mutates a fresh copy
        kind = data.draw(st.sampled_from(["delete", "replace", "poke", "link", "bomb", "attr"]))
        name = data.draw(st.sampled_from(datasets if kind in ("replace", "poke") else objects))
        if kind == "delete":
            del h5[name]
        elif kind == "replace":
            attrs = dict(h5[name].attrs)
            del h5[name]
            h5.create_dataset(name, data=data.draw(ARRAYS)).attrs.update(attrs)
        elif kind == "poke":
            ds = h5[name]
            if ds.size and ds.dtype.kind in "fiub":
                index = tuple(data.draw(st.integers(0, k - 1)) for k in ds.shape)
                value = data.draw(SPECIAL)
                with np.errstate(all="ignore"):
                    ds[index] = np.array(value).astype(ds.dtype)
        elif kind == "link":
            del h5[name]
            h5[name] = data.draw(
                st.sampled_from([h5py.SoftLink("/topology/edges"), h5py.ExternalLink("x.h5", "/a")])
            )
        elif kind == "bomb":
            attrs = dict(h5[name].attrs) if isinstance(h5[name], h5py.Dataset) else {}
            del h5[name]
            rows = data.draw(st.integers(1, 2**20))
            d = h5.create_dataset(
                name, shape=(rows, 2**20, 3), dtype="f8", chunks=(1, 1024, 3), compression="gzip"
            )
            d.attrs.update(attrs)
        else:
            target = h5[name] if name in h5 else h5
            key = data.draw(
                st.sampled_from([*target.attrs.keys(), "units", "format_version", "metadata"])
            )
            if data.draw(st.booleans()) and key in target.attrs:
                del target.attrs[key]
            else:
                target.attrs[key] = data.draw(ATTR)

    _read(_mutated(_BASE[0], change))


JSON = st.recursive(
    st.none() | st.booleans() | st.integers(-(2**60), 2**60) | st.floats() | TEXT,
    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(TEXT, inner, max_size=4),
    max_leaves=12,
)


def _paths(node, path=()):
    out = [path]
    if isinstance(node, dict):
        for k, v in node.items():
            out += _paths(v, (*path, k))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            out += _paths(v, (*path, i))
    return out


@settings(BASE, max_examples=800)
@given(data=st.data(), which=st.sampled_from(["metadata", "design"]), value=JSON)
def test_metadata(data, which, value):
    _count()

    def change(h5):
        doc = json.loads(h5.attrs[which])
        path = data.draw(st.sampled_from(_paths(doc)))
        if not path:
            doc = value
        else:
            node = doc
            for part in path[:-1]:
                node = node[part]
            node[path[-1]] = copy.deepcopy(value)
        h5.attrs[which] = json.dumps(doc)

    # JSON of at most 12 leaves: nothing here can allocate much, so no tracing (it halves the
    # cost); the structure and truncation cases trace every read
    _read(_mutated(_BASE[0], change), traced=False)


@settings(BASE, max_examples=300)
@given(cut=st.floats(0.0, 1.0, exclude_max=True))
def test_truncated(cut):
    _count()
    _read(_BASE[0][: int(cut * len(_BASE[0]))])


def test_enough_cases_ran():
    if len(CASES) < 3:
        pytest.skip("run with the whole module")
    assert sum(CASES.values()) >= 2_000, CASES

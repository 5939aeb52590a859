"""Tampered results files are refused before use, with bounded memory: ``plot`` and ``view``
give one line (exit 2) for each of these, never a traceback, never a silent wrap-around."""

from __future__ import annotations

import json
import shutil
import tracemalloc

import h5py
import numpy as np
import pytest

from rotomorph.cli import EXIT_OK, EXIT_USAGE, main
from rotomorph.errors import InvalidParameterError
from rotomorph.io.results import read_results, write_results


def _valid(path):
    """A two-filament run of 3 steps with everything a simulated run stores."""
    steps, n = 3, 12
    s = np.linspace(0, 5, n)
    pos = np.stack(
        [
            np.concatenate([np.c_[s, np.zeros(n), 0.1 * k * s], np.c_[s, np.full(n, 3.0), 0 * s]])
            for k in range(steps)
        ]
    )
    edges = np.array(
        [[i, i + 1] for i in range(n - 1)] + [[n + i, n + i + 1] for i in range(n - 1)]
    )
    e = len(edges)
    prog = {
        "name": "f",
        "points": pos[0, :n],
        "speed": np.full(n, 3.0),
        "nozzle_angle": np.zeros(n),
        "radius": 0.3,
        "active_fraction": 0.5,
        "active_material": "lce",
        "passive_material": "acrylate",
        "layer": 0.0,
    }
    write_results(
        path,
        design={"name": "d"},
        edges=edges,
        branch=None,
        positions=pos,
        scalars={"temperature": [25.0, 100.0, 175.0], "converged": np.ones(steps)},
        fields={
            "active_normal": np.tile([0.0, 0.0, 1.0], (steps, e, 1)),
            "curvature": np.zeros((steps, 2 * n)),
            "end_to_end_ratio_per_filament": np.ones((steps, 2)),
        },
        metadata={
            "kind": "filaments",
            "design_name": "d",
            "chains": [
                {"name": "a", "start": 0, "stop": n},
                {"name": "b", "start": n, "stop": 2 * n},
            ],
            "filaments": [{"name": "a", "end_to_end_ratio": 1.0}, {"name": "b"}],
        },
        units={"end_to_end_ratio_per_filament": "1"},
        static={"radius": np.full(e, 0.3)},
        programs=[prog],
    )
    return path


def _meta(h5, change):
    meta = json.loads(h5.attrs["metadata"])
    change(meta)
    h5.attrs["metadata"] = json.dumps(meta)


def _replace(h5, name, data, **kw):
    attrs = dict(h5[name].attrs)
    del h5[name]
    h5.create_dataset(name, data=data, **kw).attrs.update(attrs)


def _bomb(h5):
    """A compressed dataset declaring 9 GiB that takes a few kB on disk."""
    units = h5["steps/positions"].attrs["units"]
    del h5["steps/positions"]
    d = h5.create_dataset(
        "steps/positions", shape=(3, 134_217_728, 3), dtype="f8", chunks=(1, 65_536, 3),
        compression="gzip", fillvalue=0.0,
    )  # fmt: skip
    d[0, :10] = 1.0
    d.attrs["units"] = units


def _chunk_bomb(h5):
    """A tiny dataset whose single chunk is declared 4 GiB (an unlimited axis allows it)."""
    units = h5["steps/positions"].attrs["units"]
    del h5["steps/positions"]
    d = h5.create_dataset(
        "steps/positions", shape=(3, 24, 3), maxshape=(None, None, 3), dtype="f8",
        chunks=(1, 178_956_970, 3), compression="gzip",
    )  # fmt: skip
    d.attrs["units"] = units


def _external(h5):
    attrs = dict(h5["topology/branch"].attrs)
    del h5["topology/branch"]
    h5.create_dataset("topology/branch", shape=(24,), dtype="u1", external=[("/etc/passwd", 0, 24)])
    h5["topology/branch"].attrs.update(attrs)


CASES = {
    "missing edges": (lambda h5: h5.__delitem__("topology/edges"), "topology/edges: is missing"),
    "missing branch": (lambda h5: h5.__delitem__("topology/branch"), "topology/branch"),
    "missing positions": (lambda h5: h5.__delitem__("steps/positions"), "steps/positions"),
    "missing scalars": (lambda h5: h5.__delitem__("steps/scalars"), "steps/scalars: is missing"),
    "missing fields": (lambda h5: h5.__delitem__("steps/fields"), "steps/fields: is missing"),
    "NaN positions": (
        lambda h5: h5["steps/positions"].__setitem__((1, 3, 0), np.nan),
        r"NaN or infinity \(at index \(1, 3, 0\)\)",
    ),
    "inf positions": (lambda h5: h5["steps/positions"].__setitem__((2, 0, 1), np.inf), "NaN or"),
    "edge out of range": (
        lambda h5: h5["topology/edges"].__setitem__((3, 1), 10_000),
        r"node indices must lie in \[0, 23\]",
    ),
    "negative edge": (
        lambda h5: h5["topology/edges"].__setitem__((0, 0), -1),
        r"node indices must lie in \[0, 23\]",
    ),
    "self edge": (lambda h5: h5["topology/edges"].__setitem__((0, 1), 0), "joins a node to itself"),
    "float edges": (
        lambda h5: _replace(h5, "topology/edges", h5["topology/edges"][()] + 0.5),
        "expected whole numbers",
    ),
    "edges (E, 3)": (
        lambda h5: _replace(h5, "topology/edges", np.zeros((5, 3), int)),
        r"shape \(segments, 2\)",
    ),
    "branch length": (lambda h5: _replace(h5, "topology/branch", np.zeros(3, bool)), "24 flags"),
    "garbage design JSON": (lambda h5: h5.attrs.__setitem__("design", "{not json"), "not JSON"),
    "binary metadata": (
        lambda h5: h5.attrs.__setitem__("metadata", np.void(b"\xff\xfe\x00junk")),
        "must be JSON text",
    ),
    "metadata array": (lambda h5: h5.attrs.__setitem__("metadata", "[1, 2]"), "a JSON object"),
    "metadata nested": (
        lambda h5: h5.attrs.__setitem__("metadata", "[" * 100_000 + "]" * 100_000),
        "nested too deeply",
    ),
    "chain beyond the nodes": (
        lambda h5: _meta(h5, lambda m: m["chains"][1].update(stop=10_000)),
        r"chains\[1\]",
    ),
    "overlapping chains": (
        lambda h5: _meta(h5, lambda m: m["chains"][1].update(start=5)),
        "overlapping no other",
    ),
    "chain name a number": (
        lambda h5: _meta(h5, lambda m: m["chains"][0].update(name=7)),
        r"chains\[0\]\.name: must be text",
    ),
    "ratio as text": (
        lambda h5: _meta(h5, lambda m: m["filaments"][0].update(end_to_end_ratio="x")),
        "end_to_end_ratio: must be a number",
    ),
    "control characters in a name": (
        lambda h5: _meta(h5, lambda m: m["chains"][0].update(name="\x1b[2Jok")),
        "control or bidirectional",
    ),
    "format_version text": (
        lambda h5: h5.attrs.__setitem__("format_version", "abc"),
        "must be a whole number",
    ),
    "positions as text": (
        lambda h5: _replace(h5, "steps/positions", np.array([["a"]], dtype="S1")),
        "expected numbers",
    ),
    "gzip bomb": (_bomb, r"declares 9\.0 GiB .* compression bomb"),
    "chunk bomb": (_chunk_bomb, r"declares 4\.0 GiB"),
    "external storage": (_external, "keeps its data outside the file"),
    "external link": (
        lambda h5: (
            h5["steps"].__delitem__("positions"),
            h5["steps"].__setitem__("positions", h5py.ExternalLink("/etc/x.h5", "/p")),
        ),
        "is a link",
    ),
    "scalar length": (
        lambda h5: _replace(h5, "steps/scalars/temperature", np.zeros(99)),
        r"one value per step \(3\)",
    ),
    "field steps": (
        lambda h5: _replace(h5, "steps/fields/curvature", np.zeros((1, 24))),
        r"\(3, items",
    ),
    "normals shape": (
        lambda h5: _replace(h5, "steps/fields/active_normal", np.zeros((3, 5, 3))),
        r"\(3, 22, 3\)",
    ),
    "units missing": (
        lambda h5: h5["steps/positions"].attrs.__delitem__("units"),
        "'units': is missing",
    ),
    "program points": (
        lambda h5: _replace(h5, "programs/0000/points", np.zeros((4, 2))),
        r"shape \(n, 3\)",
    ),
    "program attribute": (
        lambda h5: h5["programs/0000"].attrs.__delitem__("radius"),
        "'radius': is missing",
    ),
}


@pytest.fixture(scope="module")
def valid(tmp_path_factory):
    return _valid(tmp_path_factory.mktemp("valid") / "results.h5")


def test_the_valid_file_reads(valid):
    run = read_results(valid)
    assert run.positions.shape == (3, 24, 3) and len(run.programs) == 1


@pytest.mark.parametrize("case", list(CASES), ids=list(CASES))
def test_tampered_files_are_refused_in_one_line(valid, tmp_path, capsys, case):
    tamper, message = CASES[case]
    path = tmp_path / "results.h5"
    shutil.copyfile(valid, path)
    with h5py.File(path, "r+") as h5:
        tamper(h5)
    tracemalloc.start()
    try:
        with pytest.raises(InvalidParameterError, match=message):
            read_results(path)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 32 * 2**20, f"{peak / 2**20:.0f} MiB allocated"
    for command in (
        ["plot", str(path), "-o", str(tmp_path / "figs")],
        ["view", str(path), "--no-open"],
    ):
        assert main(command) == EXIT_USAGE
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and "Traceback" not in err, err
        assert err.startswith(f"rotomorph: error: {path}: ")
        assert "\x1b" not in err
    assert not (tmp_path / "figs").exists() and not (tmp_path / "view.html").exists()


def test_the_valid_file_plots_and_views(valid, tmp_path, capsys):
    path = tmp_path / "results.h5"
    shutil.copyfile(valid, path)
    assert main(["plot", str(path), "-o", str(tmp_path / "figs"), "--no-movie"]) == EXIT_OK
    assert main(["view", str(path), "--no-open"]) == EXIT_OK
    capsys.readouterr()


@pytest.mark.parametrize("contact", [None, False, {"self_contact": True, "floor": False}])
def test_every_contact_record_a_run_writes_is_read(valid, tmp_path, contact):
    path = tmp_path / "results.h5"
    shutil.copyfile(valid, path)
    with h5py.File(path, "r+") as h5:
        _meta(h5, lambda m: m.update(contact=contact, kind="filaments"))
    assert read_results(path).metadata["contact"] == contact

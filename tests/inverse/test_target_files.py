"""Target files: the documented ``points`` family works from a real TOML file, sizes are bounded
with estimates (``turns = 1e9`` is refused in microseconds, naming the field), and files that
are not UTF-8 are refused like design files."""

from __future__ import annotations

import time
from pathlib import Path

import pytest

from rotomorph.cli import EXIT_OK, EXIT_USAGE, main
from rotomorph.errors import InvalidDesignError
from rotomorph.inverse.targets import (
    MAX_CURVE_NODES,
    MAX_CURVE_SAMPLES,
    load_target,
    parse_target_bytes,
)
from rotomorph.io.designfile import load_design

POINTS = Path(__file__).parents[2] / "examples" / "targets" / "points.toml"
HELIX = (
    "schema_version = 1\nkind = 'curve'\n[curve]\nfamily = 'helix'\nradius_start = 2.0\n"
    "radius_end = 2.0\npitch = 1.0\n"
)


def test_a_points_target_from_toml_designs_a_filament(tmp_path, capsys):
    target = load_target(str(POINTS))
    assert target.curve.family == "points" and len(target.curve.points) == 13
    out = tmp_path / "design.toml"
    assert main(["inverse", str(POINTS), "-o", str(out)]) == EXIT_OK
    line = capsys.readouterr().out
    assert "all reachable" in line and "verified state physical" in line
    design = load_design(out)
    assert len(design.filaments) == 1


@pytest.mark.parametrize(
    ("curve", "field", "fragment"),
    [
        ("turns = 1e9", "curve.turns", "must be <= 10000"),
        ("turns = 5000.0\nsamples_per_turn = 2000", "curve", "10,000,000 samples"),
        ("turns = 1000.0\n[options]\nspacing = 0.001", "<target>", "filament vertices"),
        ("turns = 2.0\nradius_start = 1e300", "curve.radius_start", "must be <= 10000"),
    ],
)
def test_sizes_are_refused_before_anything_is_allocated(curve, field, fragment):
    text = HELIX.replace("radius_start = 2.0\n", "") if "radius_start" in curve else HELIX
    t0 = time.process_time()
    with pytest.raises(InvalidDesignError, match=fragment) as info:
        parse_target_bytes((text + curve + "\n").encode())
    assert time.process_time() - t0 < 0.5
    assert info.value.field == field
    message = str(info.value)
    assert "\n" not in message
    if "samples" in fragment:
        assert "GiB" in message and f"{MAX_CURVE_SAMPLES:,}" in message
    if "vertices" in fragment:
        assert "GB" in message and "min of CPU" in message and f"{MAX_CURVE_NODES:,}" in message


def test_ragged_height_maps_are_refused_at_parse():
    text = (
        "schema_version = 1\nkind = 'height_map'\n[height_map]\nx = [0.0, 1.0, 2.0, 3.0]\n"
        "y = [0.0, 1.0, 2.0, 3.0]\nz = [[0.0, 0.0, 0.0, 0.0], [0.0]]\n[lattice]\nn = 3\n"
    )
    with pytest.raises(InvalidDesignError, match="len\\(x\\) = 4 rows"):
        parse_target_bytes(text.encode())


def test_files_that_are_not_utf8_are_refused_like_design_files(tmp_path, capsys):
    path = tmp_path / "t.toml"
    path.write_bytes(("name = 'Größe'\n" + HELIX + "turns = 1.0\n").encode("latin-1"))
    assert main(["inverse", str(path), "-o", str(tmp_path / "d.toml")]) == EXIT_USAGE
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "is not UTF-8 text (byte 0xf6" in err and "UTF-8" in err
    path.write_bytes(("name = 'Größe'\n" + HELIX + "turns = 1.0\n").encode("utf-16"))  # with a BOM
    assert load_target(str(path)).name == "Größe"


def test_height_map_grids_are_bounded():
    from rotomorph.inverse.targets import MAX_GRID, parse_target

    x = [float(i) for i in range(MAX_GRID + 1)]
    data = {
        "schema_version": 1,
        "kind": "height_map",
        "height_map": {"x": x, "y": x[:4], "z": [[0.0] * 4] * len(x)},
        "lattice": {"n": 3},
    }
    with pytest.raises(InvalidDesignError, match=r"height_map\.x"):
        parse_target(data)
    data["height_map"] = {"x": x[:4], "y": [0.0, 1.0, 1.0 + 1e-9, 2.0], "z": [[0.0] * 4] * 4}
    with pytest.raises(InvalidDesignError, match=r"y must increase by >= 0\.001 mm"):
        parse_target(data)

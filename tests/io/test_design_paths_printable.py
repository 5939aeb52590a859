"""Print paths that no printer can lay down are refused when the design is read, naming the
filament and the segment, instead of passing validation and failing later (NaN tangents, an
internal 'Model.rest_length' error in simulate, G-code that prints over its own filament)."""

from __future__ import annotations

import numpy as np
import pytest

from rotomorph.cli import EXIT_USAGE, main
from rotomorph.design.path import Path, path_defect
from rotomorph.errors import InvalidDesignError
from rotomorph.io.designfile import parse_design


def _design(*segments):
    fil = {"spacing": 0.5, "segments": list(segments)}
    return {"schema_version": 1, "filaments": [{"spacing": 0.5, "segments": [LINE]}, fil]}


LINE = {"kind": "line", "length": 5.0}


@pytest.mark.parametrize(
    ("segments", "message"),
    [
        (
            [{"kind": "polyline", "points": [[0, 0, 0], [5, 0, 0], [0, 0, 0]]}],
            "filaments[1]: segments[0]: turns back on itself at vertex 10 (5, 0, 0) mm "
            "(a 180 deg turn)",
        ),
        (
            [{"kind": "polyline", "points": [[0, 0, 0], [5, 0, 0], [0, 1e-4, 0]]}],
            "filaments[1]: segments[0]: turns back on itself at vertex 10 (5, 0, 0) mm",
        ),
        (
            [LINE, {"kind": "polyline", "points": [[5, 0, 0], [1, 0, 0]]}],
            "filaments[1]: segments[1]: turns back on itself at vertex 10 (5, 0, 0) mm",
        ),
        (
            [{"kind": "polyline", "points": [[0, 0, 0], [0, 0, 0], [5, 0, 0]]}],
            "filaments[1]: segments[0]: vertices 0 and 1 (0, 0, 0) mm are repeated",
        ),
        (  # before: "segments[1].points: ..." without the filament
            [LINE, {"kind": "polyline", "points": [[6, 0, 0], [9, 0, 0]]}],
            "filaments[1]: segments[1].points: must start at the current end",
        ),
    ],
)
def test_unprintable_paths_name_filament_and_segment(segments, message):
    with pytest.raises(InvalidDesignError) as err:
        parse_design(_design(*segments))
    assert message in str(err.value)


def test_turns_up_to_the_limit_are_printable():
    square = [[0, 0, 0], [5, 0, 0], [5, 5, 0], [0, 5, 0]]  # 90 deg corners
    hairpin = [[0, 0, 0], [5, 0, 0], [0, 0.2, 0]]  # a 177.7 deg turn
    for points in (square, hairpin):
        parse_design(_design({"kind": "polyline", "points": points}))
    assert path_defect(np.array(hairpin, dtype=float)) is None
    with pytest.raises(InvalidDesignError, match=r"Path\.points: turns back on itself"):
        Path(np.array([[0.0, 0, 0], [1, 0, 0], [0, 0, 0]]))


def test_simulate_refuses_a_retracing_path_before_computing(tmp_path, capsys):
    design = tmp_path / "back.toml"
    design.write_text(
        "schema_version = 1\n[[filaments]]\nspacing = 0.5\n"
        'segments = [{ kind = "polyline", points = [[0,0,0],[5,0,0],[0,0,0]] }]\n'
    )
    assert main(["simulate", str(design), "-o", str(tmp_path / "run")]) == EXIT_USAGE
    err = capsys.readouterr().err.strip()
    assert err.startswith("rotomorph: error: filaments[0]: segments[0]: turns back on itself")
    assert not (tmp_path / "run").exists()


def test_a_lattice_only_contact_key_on_filaments_is_refused_not_ignored():
    # before: branch = "continuous" on a filament design was accepted, ignored by the
    # filament solve, and recorded in summary.json as if it had been applied
    data = _design(LINE)
    parse_design({**data, "contact": {"floor": True}})
    with pytest.raises(InvalidDesignError, match=r"contact\.branch applies to lattices"):
        parse_design({**data, "contact": {"floor": True, "branch": "continuous"}})


@pytest.mark.parametrize(
    ("segment", "message"),
    [
        (
            {"kind": "arc", "radius": 0.1, "angle_deg": 90},
            "segments[1]: an arc of radius 0.1 mm is tighter than the filament radius 0.3 mm",
        ),
        (  # crest radius 0.5 um: validate accepted it and sampled straight across the crests
            {"kind": "sinusoid", "amplitude": 50.0, "wavelength": 1.0},
            "segments[1]: the sinusoid's crests bend at radius wavelength^2/(4 pi^2 amplitude) "
            "= 0.000507 mm, below the filament radius 0.3 mm",
        ),
    ],
)
def test_turns_tighter_than_the_filament_radius_are_refused(segment, message):
    with pytest.raises(InvalidDesignError) as err:
        parse_design(_design(LINE, segment))
    assert message in str(err.value)
    ok = {**segment, "radius": 0.3} if segment["kind"] == "arc" else {**segment, "amplitude": 0.08}
    parse_design(_design(LINE, ok))


def test_a_lattice_whose_crests_are_tighter_than_its_filaments_is_refused():
    base = {"schema_version": 1, "lattice": {"n": 3, "spacing": 5.0}}
    parse_design({**base, "lattice": {**base["lattice"], "amplitude": 2.0}})  # A/l = 0.4
    with pytest.raises(InvalidDesignError, match=r"use amplitude <= 2\.11 mm"):
        parse_design({**base, "lattice": {**base["lattice"], "amplitude": 10.0}})


def test_a_material_of_the_wrong_kind_is_named_in_plain_english():
    # before: "'lce' is a active material; give a passive one"
    fil = {"passive_material": "lce", "spacing": 0.5, "segments": [LINE]}
    with pytest.raises(InvalidDesignError, match="'lce' is an active material; give a passive one"):
        parse_design({"schema_version": 1, "filaments": [fil]})


def test_the_same_fault_in_several_filaments_is_said_once():
    # before: "filaments[0].speed: must be >= 0.01 mm/s; got -3.0; also filaments[1].speed:
    # must be >= 0.01 mm/s; got -3.0; filaments[2].speed: ..." (cut off by the terminal)
    fil = {"speed": -3.0, "spacing": 0.5, "segments": [LINE]}
    with pytest.raises(InvalidDesignError) as err:
        parse_design({"schema_version": 1, "filaments": [fil, fil, fil]})
    assert str(err.value) == (
        "filaments[0].speed: must be >= 0.01 mm/s; got -3.0 (also filaments[1], filaments[2])"
    )


@pytest.mark.parametrize(
    ("data", "message"),
    [
        (  # before: "schema_version: Input should be 1; got 2"
            {"schema_version": 2, "filaments": []},
            "schema_version: must be 1; got 2",
        ),
        (  # before: "Input tag 'lines' found using 'kind' does not match any of the expected ..."
            {"schema_version": 1, "filaments": [{"segments": [{"kind": "lines", "length": 5}]}]},
            "filaments[0].segments[0]: kind must be one of 'line', 'arc', 'sinusoid', "
            "'polyline'; got 'lines'",
        ),
        (  # before: "List should have at least 1 item after validation, not 0; got []"
            {"schema_version": 1, "filaments": [{"segments": []}]},
            "filaments[0].segments: needs at least 1 item(s); got []",
        ),
        (  # before: "Input should be a finite number; got nan"
            {"schema_version": 1, "filaments": [{"speed": float("nan"), "segments": [LINE]}]},
            "filaments[0].speed: must be a finite number (mm/s); got nan",
        ),
    ],
)
def test_schema_errors_read_as_the_rest_of_the_messages(data, message):
    with pytest.raises(InvalidDesignError) as err:
        parse_design(data)
    assert str(err.value) == message

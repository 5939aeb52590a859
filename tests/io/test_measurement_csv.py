"""Measurement tables: the documented format reads, every bad file is one line naming file, row
and column."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from rotomorph.errors import InvalidParameterError
from rotomorph.io.measurement_csv import COLUMNS, parse_measurements, read_measurements

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = sorted((ROOT / "examples" / "inks").glob("*.csv"))
HEADER = ",".join(COLUMNS)
GOOD = [
    "janus_curvature,,0.25,mm/s,0.13,0.02,1/mm,notebook 1",
    "janus_curvature,,3,mm/s,0.59,0.04,1/mm,notebook 1",
    "youngs_modulus,active=lce,25,C,29.67,2.55,MPa,tensile test",
    "youngs_modulus,passive=acrylate,298.15,K,570,70,kPa,tensile test",
]


def _parse(*rows: str, header: str = HEADER, name: str = "lab.csv"):
    text = header + "\n" + "\n".join(rows) + "\n"
    return parse_measurements([(name, text.encode("utf-8"))])


def test_examples_read_with_units_converted() -> None:
    data = read_measurements(EXAMPLES)
    assert len(data.files) == len(EXAMPLES) == 3 and len(data.sha256) == 64
    assert data.ink_names() == {"active": "lce", "passive": "acrylate"}
    rows = _parse(*GOOD).rows
    assert rows[3].x == pytest.approx(25.0) and rows[3].value == pytest.approx(0.57)
    assert rows[3].spread == pytest.approx(0.07) and rows[3].row == 5
    assert rows[2].conditions == {"active": "lce"} and rows[2].provenance == "measured"
    reordered = ",".join(reversed(COLUMNS))
    again = _parse(
        ",".join(reversed(GOOD[0].split(","))),
        ",".join(reversed(GOOD[1].split(","))),
        header=reordered,
    )
    assert [m.value for m in again.rows] == [0.13, 0.59]
    converted = _parse(
        "janus_curvature,,15,mm/min,130,20,1/m,x", "janus_curvature,,180,mm/min,590,40,1/m,x"
    )
    assert converted.rows[0].x == pytest.approx(0.25) and converted.rows[1].value == pytest.approx(
        0.59
    )
    commented = _parse("# a comment line", *GOOD[:2])
    assert [m.row for m in commented.rows] == [3, 4]
    # the hash is of the contents: neither the names nor the order of the files change it
    a, b = (
        (HEADER + "\n" + GOOD[0] + "\n" + GOOD[1] + "\n").encode(),
        (HEADER + "\n" + GOOD[2] + "\n").encode(),
    )
    assert (
        parse_measurements([("a", a), ("b", b)]).sha256
        == parse_measurements([("y", b), ("x", a)]).sha256
    )


BAD = [
    # (rows, header, where, message)
    (
        GOOD,
        "quantity,condition,x,x_unit,value,unit,source",
        "lab.csv: row 1, column spread",
        "missing from the header",
    ),
    (GOOD, HEADER + ",colour", "lab.csv: row 1, column 'colour'", "unknown column"),
    (
        ["janus_curvature,,0.25,mm,0.13,0.02,1/mm,n", GOOD[1]],
        HEADER,
        "lab.csv: row 2, column x_unit",
        "not a unit of",
    ),
    (
        ["janus_curvature,,0.25,mm/s,0.13,0.02,mm,n", GOOD[1]],
        HEADER,
        "lab.csv: row 2, column unit",
        "not a unit of",
    ),
    (
        ["janus_curvature,,0.25,mm/s,0.13,0,1/mm,n", GOOD[1]],
        HEADER,
        "lab.csv: row 2, column spread",
        "> 0",
    ),
    (
        ["janus_curvature,,0.25,mm/s,0.13,-0.1,1/mm,n", GOOD[1]],
        HEADER,
        "lab.csv: row 2, column spread",
        "> 0",
    ),
    ([GOOD[0]], HEADER, "lab.csv: row 2, column x", "has one point"),
    (
        [GOOD[0], GOOD[1], "janus_curvature,,3,mm/s,1.59,0.04,1/mm,n"],
        HEADER,
        "lab.csv: rows 3 and 4, column value",
        "contradict",
    ),
    ([GOOD[0], GOOD[1], GOOD[1]], HEADER, "lab.csv: rows 3 and 4, column value", "twice"),
    (
        ["janus_curvature,,fast,mm/s,0.13,0.02,1/mm,n", GOOD[1]],
        HEADER,
        "lab.csv: row 2, column x",
        "must be a number",
    ),
    (
        ["janus_curvature,,nan,mm/s,0.13,0.02,1/mm,n", GOOD[1]],
        HEADER,
        "lab.csv: row 2, column x",
        "must be a number",
    ),
    (
        ["janus_curvature,,1e400,mm/s,0.13,0.02,1/mm,n", GOOD[1]],
        HEADER,
        "lab.csv: row 2, column x",
        "finite",
    ),
    (
        ["curvature,,0.25,mm/s,0.13,0.02,1/mm,n"],
        HEADER,
        "lab.csv: row 2, column quantity",
        "unknown quantity",
    ),
    (
        ["janus_curvature,V=3 mm/s,0.25,mm/s,0.13,0.02,1/mm,n", GOOD[1]],
        HEADER,
        "lab.csv: row 2, column condition",
        "unknown condition key",
    ),
    (
        ["pure_lce_length,,0.25,1,0.86,0.01,1,n"],
        HEADER,
        "lab.csv: row 2, column condition",
        "needs v",
    ),
    (
        ["pure_lce_length,v=3,0.25,1,0.86,0.01,1,n"],
        HEADER,
        "lab.csv: row 2, column condition",
        "needs its unit",
    ),
    (
        ["youngs_modulus,,25,C,29.67,2.55,MPa,n"],
        HEADER,
        "lab.csv: row 2, column condition",
        "needs the ink",
    ),
    (
        ["free_length,active=lce,100,C,0.9,0.01,1,n"],
        HEADER,
        "lab.csv: row 2, column condition",
        "print speed v",
    ),
    (
        ["janus_curvature,,0.25,mm/s,0.13,0.02,1/mm,", GOOD[1]],
        HEADER,
        "lab.csv: row 2, column source",
        "empty",
    ),
    (
        ["janus_curvature,,0.25,mm/s,0.13,0.02,1/mm,n,x"],
        HEADER,
        "lab.csv: row 2, column source",
        "cells",
    ),
    (
        ["youngs_modulus,active=lce,25,C,-3,1,MPa,n"],
        HEADER,
        "lab.csv: row 2, column value",
        "physical range",
    ),
    (["glass_transition,active=lce,25,C,-2,1,C,n"], HEADER, "lab.csv: row 2, column x", "has no x"),
    (
        [GOOD[2], "youngs_modulus,active=rm82,175,C,3,1,MPa,n"],
        HEADER,
        "lab.csv: row 3, column condition",
        "one active and one passive",
    ),
    (
        [GOOD[2], "youngs_modulus,passive=lce,25,C,0.5,0.1,MPa,n"],
        HEADER,
        "lab.csv: row 3, column condition",
        "both called",
    ),
    ([], HEADER, "lab.csv", "no rows"),
]


@pytest.mark.parametrize(
    ("rows", "header", "where", "message"), BAD, ids=[b[3] + str(i) for i, b in enumerate(BAD)]
)
def test_bad_rows_name_file_row_and_column(rows, header, where, message) -> None:
    with pytest.raises(InvalidParameterError) as err:
        _parse(*rows, header=header)
    text = str(err.value)
    assert text.startswith(where + ": ") and message in text and "\n" not in text, text


def test_bad_files_are_refused_in_one_line(tmp_path) -> None:
    latin = (HEADER + "\njanus_curvature,,0.25,mm/s,0.13,0.02,1/mm,K\xe4se\n").encode("latin-1")
    with pytest.raises(
        InvalidParameterError, match=r"^x\.csv: row 2: is not UTF-8 text \(byte 0xe4"
    ):
        parse_measurements([("x.csv", latin)])
    with pytest.raises(InvalidParameterError, match="is empty"):
        parse_measurements([("x.csv", b"\n\n")])
    with pytest.raises(InvalidParameterError, match="NUL"):
        parse_measurements([("x.csv", HEADER.encode() + b"\n\x00\n")])
    with pytest.raises(InvalidParameterError, match="no such file"):
        read_measurements([tmp_path / "missing.csv"])
    with pytest.raises(InvalidParameterError, match="at least one"):
        parse_measurements([])
    bom = ("\ufeff" + HEADER + "\n" + "\n".join(GOOD) + "\n").encode("utf-8")
    assert len(parse_measurements([("bom.csv", bom)]).rows) == 4
    control = _parse  # a control character in a cell is refused, not printed
    shown = r"U\+001B \(ESC\) at position 0: '\\x1b\[31mred'; remove control"
    with pytest.raises(InvalidParameterError, match=shown):
        control("janus_curvature,,0.25,mm/s,0.13,0.02,1/mm,\x1b[31mred", GOOD[1])


def test_rows_are_finite_and_in_range() -> None:
    for m in read_measurements(EXAMPLES).rows:
        assert math.isfinite(m.value) and m.spread > 0 and (math.isnan(m.x) or math.isfinite(m.x))

"""Sweep files are bounded before any point is listed (``num = 1e9`` is refused at once with
the field and the estimated memory and time), and files that are not UTF-8 (the sweep or the
design it names) are refused like design files, in one line."""

from __future__ import annotations

import time

import pytest

from rotomorph.cli import EXIT_USAGE, main
from rotomorph.errors import InvalidParameterError
from rotomorph.sweep.spec import MAX_POINTS, load_sweep, parse_sweep_bytes

SWEEP = """schema_version = 1
outputs = ["end_to_end_ratio"]
{extra}
[design]
schema_version = 1
[[design.filaments]]
spacing = 0.5
segments = [{{ kind = "line", length = 8.0 }}]
[[parameters]]
path = "filaments[0].speed"
{values}
"""


@pytest.mark.parametrize(
    ("extra", "values", "field", "fragment"),
    [
        ("", "range = { start = 0.25, stop = 3.0, num = 1e9 }", "parameters[0].range", "num ="),
        ("", "range = { start = 0.25, stop = 3.0, step = 1e-12 }", "parameters[0].range", "step"),
        (
            '[sampling]\nmethod = "random"\nsamples = 1000000000',
            "distribution = { kind = 'uniform', low = 0.5, high = 3.0 }",
            "<sweep>",
            "sampling.samples: the sweep has 1,000,000,000 points",
        ),
        (
            "[settings]\nsteps = 1000000000",
            "values = [1.0]",
            "settings.steps",
            "must be <= 10000",
        ),
    ],
)
def test_sizes_are_refused_with_estimates(extra, values, field, fragment):
    t0 = time.process_time()
    with pytest.raises(InvalidParameterError, match=fragment) as info:
        parse_sweep_bytes(SWEEP.format(extra=extra, values=values).encode())
    assert time.process_time() - t0 < 0.5, "refused only after listing the points"
    assert info.value.field == field and "\n" not in str(info.value)
    if "samples" in fragment or "num" in fragment or "step" in fragment:
        assert "GB" in str(info.value) and "min of CPU" in str(info.value)
        assert f"{MAX_POINTS:,}" in str(info.value)


def test_a_grid_product_over_the_limit_is_refused():
    values = "values = [" + ", ".join(f"{0.5 + i * 0.001:.3f}" for i in range(1000)) + "]"
    text = SWEEP.format(extra="", values=values) + (
        '[[parameters]]\npath = "filaments[0].radius"\n'
        "range = { start = 0.1, stop = 0.5, num = 1000 }\n"
    )
    with pytest.raises(InvalidParameterError, match="has 1,000,000 points"):
        parse_sweep_bytes(text.encode())


def test_files_that_are_not_utf8_are_refused(tmp_path, capsys):
    sweep = tmp_path / "s.toml"
    sweep.write_bytes(("name = 'Größe'\n" + SWEEP.format(extra="", values="values = [1.0]"))
                      .encode("cp1252"))  # fmt: skip
    assert main(["sweep", str(sweep), "-o", str(tmp_path / "out")]) == EXIT_USAGE
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "is not UTF-8 text (byte 0xf6" in err
    assert not (tmp_path / "out").exists()
    design = tmp_path / "d.toml"
    design.write_bytes("schema_version = 1\nname = 'Größe'\n".encode("latin-1"))
    sweep.write_text(
        'schema_version = 1\noutputs = ["end_to_end_ratio"]\ndesign = "d.toml"\n'
        '[[parameters]]\npath = "filaments[0].speed"\nvalues = [1.0]\n',
        encoding="utf-8",
    )
    with pytest.raises(InvalidParameterError, match=r"d\.toml: is not UTF-8 text"):
        load_sweep(sweep)
    sweep.write_bytes(SWEEP.format(extra="", values="values = [1.0]").encode("utf-16"))
    assert load_sweep(sweep).parameters[0].values == [1.0]

"""Output paths that cannot be written: every command refuses them at once, naming -o/--output
and the path the user gave (not an internal temporary file), exit 2, nothing computed."""

from __future__ import annotations

import tempfile
from pathlib import Path

import pytest

from rotomorph.cli import EXIT_USAGE, main
from rotomorph.errors import InvalidParameterError
from rotomorph.io.atomic import check_writable

ROOT = Path(__file__).resolve().parents[2]
DESIGN = (
    "schema_version = 1\n[[filaments]]\nspacing = 1.0\n"
    'segments = [{ kind = "line", length = 10.0 }]\n'
)
SWEEP = (
    'schema_version = 1\noutputs = ["end_to_end_ratio"]\n'
    "[design]\nschema_version = 1\n[[design.filaments]]\nspacing = 1.0\n"
    'segments = [{kind = "line", length = 5.0}]\n'
    '[[parameters]]\npath = "filaments[0].speed"\nvalues = [1.0]\n'
)


def _argv(command: str, tmp_path: Path, out: str) -> list[str]:
    design = tmp_path / "design.toml"
    design.write_text(DESIGN)
    if command == "inverse":
        return ["inverse", str(ROOT / "examples/targets/tendril.toml"), "-o", out]
    if command == "sweep":
        sweep = tmp_path / "sweep.toml"
        sweep.write_text(SWEEP)
        return ["sweep", str(sweep), "-o", out]
    return [command, str(design), "-o", out]


@pytest.mark.parametrize(
    ("command", "name"),
    [
        ("simulate", "run"),
        ("gcode", "x.gcode"),
        ("inverse", "x.toml"),
        ("sweep", "sweep"),
    ],
)
def test_an_output_below_a_file_is_refused_naming_the_option(tmp_path, capsys, command, name):
    # before: "sinusoids.toml: File exists" (inverse, after the computation) or
    # "...: folder does not exist" (gcode) for a path whose "folder" is a file
    blocker = tmp_path / "notes.txt"
    blocker.write_text("a file, not a folder")
    out = str(blocker / name)
    assert main(_argv(command, tmp_path, out)) == EXIT_USAGE
    err = capsys.readouterr().err.strip()
    assert err == (
        f"rotomorph: error: -o/--output: {out}: {blocker} is a file, not a folder; "
        "choose another path"
    )


@pytest.mark.parametrize(
    ("command", "name"),
    [("simulate", "run"), ("gcode", "x.gcode"), ("inverse", "x.toml"), ("sweep", "sweep")],
)
def test_a_folder_that_takes_no_file_is_refused_before_any_work(
    tmp_path, capsys, monkeypatch, command, name
):
    # before: "rotomorph: error: <dir>/.x.gcode.tmp-host-123-abc.gcode: Permission denied"
    # (a temporary name the user never gave), for inverse and simulate after the computation
    argv = _argv(command, tmp_path, str(tmp_path / name))

    def refuse(*args, **kwargs):
        raise PermissionError(13, "Permission denied")

    monkeypatch.setattr(tempfile, "TemporaryFile", refuse)
    assert main(argv) == EXIT_USAGE
    err = capsys.readouterr().err.strip()
    assert err == (
        f"rotomorph: error: -o/--output: {tmp_path / name}: cannot write in {tmp_path} "
        "(Permission denied); choose a folder you can write to"
    )
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
        {"design.toml", "sweep.toml"} & {p.name for p in tmp_path.iterdir()}
    )


def test_check_writable_creates_missing_parents_only_when_asked(tmp_path):
    deep = tmp_path / "a" / "b" / "run"
    with pytest.raises(InvalidParameterError, match=r"folder .*a/b does not exist; create it"):
        check_writable(deep, "-o", create_parent=False)
    assert not (tmp_path / "a").exists()
    assert check_writable(deep, "-o", create_parent=True) == deep.parent
    assert deep.parent.is_dir() and list(deep.parent.iterdir()) == []  # the probe is gone


def test_force_never_replaces_the_folder_holding_the_design(tmp_path, capsys):
    # before: `simulate runs/design.toml -o runs --force` computed, then deleted the design
    # file and everything else in runs/
    runs = tmp_path / "runs"
    runs.mkdir()
    design = runs / "design.toml"
    design.write_text(DESIGN)
    (runs / "notes.txt").write_text("mine")
    argv = ["simulate", str(design), "-o", str(runs), "--force", "--steps", "1"]
    assert main(argv) == EXIT_USAGE
    err = capsys.readouterr().err.strip()
    assert err == (
        f"rotomorph: error: -o/--output: {runs}: holds the input {design}; replacing it would "
        "delete it: give a new folder"
    )
    assert sorted(p.name for p in runs.iterdir()) == ["design.toml", "notes.txt"]


@pytest.mark.parametrize("command", ["simulate", "paper"])
def test_force_never_replaces_the_current_folder(tmp_path, capsys, monkeypatch, command):
    # before: `-o . --force` computed the whole run, then failed with ".: Device or resource
    # busy"; `-o .. --force` would have replaced the parent of the current folder
    work = tmp_path / "work"
    work.mkdir()
    (work / "design.toml").write_text(DESIGN)
    monkeypatch.chdir(work)
    for out in (".", str(tmp_path)):
        argv = [command, *(["design.toml"] if command == "simulate" else []), "-o", out]
        assert main([*argv, "--force"]) == EXIT_USAGE
        err = capsys.readouterr().err.strip()
        assert err.endswith(": is the current folder or holds it; replacing it would delete "
                            "what is in it: give a new folder"), err  # fmt: skip
    assert sorted(p.name for p in tmp_path.iterdir()) == ["work"]
    assert [p.name for p in work.iterdir()] == ["design.toml"]


def test_an_output_that_is_the_input_is_refused(tmp_path, capsys):
    # before: `gcode d.toml -o d.toml` replaced the design with G-code, `view RUN -o
    # RUN/results.h5` the results with HTML, `inverse t.toml -o t.toml --force` the target
    design = tmp_path / "d.toml"
    design.write_text(DESIGN)
    target = tmp_path / "t.toml"
    target.write_text((ROOT / "examples/targets/tendril.toml").read_text())
    cases = [
        (["gcode", str(design), "-o", str(design)], design),
        (["inverse", str(target), "-o", str(target), "--force"], target),
    ]
    for argv, item in cases:
        before = item.read_bytes()
        assert main(argv) == EXIT_USAGE
        assert capsys.readouterr().err.strip() == (
            f"rotomorph: error: -o/--output: {item}: is the input {item}; writing there would "
            "replace it: give another file name"
        )
        assert item.read_bytes() == before

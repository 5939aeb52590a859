"""Without ffmpeg the movie is a GIF: ``simulate`` and ``plot`` say so in one line before they
start, with how to get MP4, and ``summary.json`` names the files actually written."""

from __future__ import annotations

import json

import pytest

import rotomorph.plot.animate as animate
from rotomorph.cli import EXIT_OK, main

DESIGN = """schema_version = 1
name = "coil"
[[filaments]]
name = "w*=0.25"
speed = 0.25
rotation_number = 0.25
spacing = 0.5
segments = [{ kind = "line", length = 10.0 }]
"""


@pytest.fixture
def no_ffmpeg(monkeypatch):
    monkeypatch.setattr(animate, "ffmpeg_available", lambda: False)


def _notes(err: str) -> list[str]:
    return [line for line in err.splitlines() if "morphing.gif" in line]


def test_simulate_says_gif_once_and_names_what_it_wrote(tmp_path, capsys, no_ffmpeg):
    design = tmp_path / "coil.toml"
    design.write_text(DESIGN, encoding="utf-8")
    out = tmp_path / "run"
    assert main(["simulate", str(design), "-o", str(out), "--steps", "2"]) == EXIT_OK
    err = capsys.readouterr().err
    (note,) = _notes(err)
    assert note.startswith("rotomorph: note: no ffmpeg found") and "morphing.mp4" in note
    assert "install ffmpeg" in note and "rotomorph plot" in note
    assert (out / "figures" / "morphing.gif").is_file()
    assert not (out / "figures" / "morphing.mp4").exists()
    summary = json.loads((out / "summary.json").read_text(encoding="utf-8"))
    assert summary["movie"] == "figures/morphing.gif"
    written = sorted(p.relative_to(out).as_posix() for p in out.rglob("*") if p.is_file())
    assert summary["files"] == written

    # plot says it too, and names the movie it wrote
    figs = tmp_path / "figs"
    assert main(["plot", str(out), "-o", str(figs)]) == EXIT_OK
    captured = capsys.readouterr()
    assert len(_notes(captured.err)) == 1
    assert "(movie: morphing.gif)" in captured.out


def test_no_note_without_a_movie(tmp_path, capsys, no_ffmpeg):
    design = tmp_path / "coil.toml"
    design.write_text(DESIGN, encoding="utf-8")
    out = tmp_path / "run"
    args = ["simulate", str(design), "-o", str(out), "--steps", "1", "--no-movie"]
    assert main(args) == EXIT_OK
    assert _notes(capsys.readouterr().err) == []
    assert json.loads((out / "summary.json").read_text(encoding="utf-8"))["movie"] is None

"""A command's record of its output folder: its own previous run is recognised (and may be
replaced), anything else in the folder is named and protected."""

from __future__ import annotations

import json
import os

import pytest

from rotomorph.io.run_manifest import MANIFEST, previous_run, write_manifest


@pytest.fixture
def run(tmp_path):
    out = tmp_path / "out"
    (out / "figures").mkdir(parents=True)
    (out / "report.md").write_text("# report\n")
    (out / "figures" / "a.png").write_bytes(b"\x89PNG fake")
    write_manifest(out, "paper")
    return out


def test_a_previous_run_of_the_same_command_is_recognised(run):
    record = json.loads((run / MANIFEST).read_text())
    assert record["command"] == "paper" and set(record["files"]) == {"report.md", "figures/a.png"}
    assert previous_run(run, "paper") is None
    # files (and all of a folder's files) deleted since are still that run
    (run / "figures" / "a.png").unlink()
    assert previous_run(run, "paper") is None


def test_anything_else_is_named(run, tmp_path):
    assert "previous `rotomorph paper` run, not `simulate`" in previous_run(run, "simulate")
    (run / "notes.txt").write_text("mine")
    assert "notes.txt, which the previous run did not write" in previous_run(run, "paper")
    (run / "notes.txt").unlink()
    (run / "report.md").write_text("# edited by hand\n")
    assert "report.md was changed" in previous_run(run, "paper")


def test_links_empty_folders_and_foreign_folders_are_refused(run, tmp_path):
    (run / "mine").mkdir()
    assert "mine/" in previous_run(run, "paper")
    (run / "mine").rmdir()
    os.symlink(tmp_path, run / "link")
    assert "link" in previous_run(run, "paper")
    (run / "link").unlink()
    other = tmp_path / "other"
    other.mkdir()
    (other / "data.csv").write_text("1,2\n")
    assert f"no {MANIFEST}" in previous_run(other, "paper")
    (other / MANIFEST).write_text("{not json")
    assert "unreadable" in previous_run(other, "paper")

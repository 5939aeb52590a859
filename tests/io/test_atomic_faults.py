"""Killed runs: temporaries are removed on SIGTERM, found and removed after SIGKILL, and a
replacement (``--force``) never leaves the target missing."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

import rotomorph.io.atomic as atomic
from rotomorph.cli import EXIT_OK, main
from rotomorph.io.atomic import atomic_folder, atomic_write_text, remove_stale, temporary_prefix

DESIGN = """schema_version = 1
[[filaments]]
rotation_number = 0.25
spacing = 0.05
segments = [{ kind = "line", length = 30.0 }]
"""


def _temporaries(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if ".tmp-" in p.name or ".old-" in p.name)


def _dead_pid() -> int:
    proc = subprocess.Popen([sys.executable, "-c", "pass"])
    proc.wait()
    return proc.pid


def test_atomic_folder_swaps_and_keeps_the_old_results_until_then(tmp_path):
    target = tmp_path / "run"
    target.mkdir()
    (target / "old.txt").write_text("old")
    with atomic_folder(target) as tmp:
        (tmp / "new.txt").write_text("new")
        assert (target / "old.txt").exists() and tmp.name.startswith(temporary_prefix(target))
    assert sorted(os.listdir(target)) == ["new.txt"] and _temporaries(tmp_path) == []


def test_failed_folder_write_leaves_the_target(tmp_path):
    target = tmp_path / "run"
    target.mkdir()
    (target / "old.txt").write_text("old")
    with pytest.raises(RuntimeError), atomic_folder(target) as tmp:
        (tmp / "half.txt").write_text("x")
        raise RuntimeError
    assert sorted(os.listdir(target)) == ["old.txt"] and _temporaries(tmp_path) == []


def test_replacement_without_exchange_is_repaired_after_a_crash(tmp_path, monkeypatch):
    """No renameat2: the old folder is moved aside; a crash between the two renames is undone."""
    monkeypatch.setattr(atomic, "_exchange", lambda a, b: False)
    target = tmp_path / "run"
    target.mkdir()
    (target / "old.txt").write_text("old")
    with atomic_folder(target) as tmp:
        (tmp / "new.txt").write_text("new")
    assert os.listdir(target) == ["new.txt"] and _temporaries(tmp_path) == []
    # a process killed between "target -> .old" and ".tmp -> target"
    dead = _dead_pid()
    old = tmp_path / f".run.old-{atomic._HOST}-{dead}-abc123"
    os.rename(target, old)
    (tmp_path / f".run.tmp-{atomic._HOST}-{dead}-def456").mkdir()
    assert not target.exists()
    remove_stale(tmp_path)
    assert os.listdir(target) == ["new.txt"] and _temporaries(tmp_path) == []


def test_remove_stale_spares_live_processes_other_hosts_and_other_files(tmp_path):
    dead = _dead_pid()
    keep = [
        f".a.tmp-{atomic._HOST}-{os.getpid()}-live",
        f".a.tmp-someotherhost-{dead}-remote",
        ".a.tmp-legacy",
        "results.h5",
    ]
    for name in keep:
        (tmp_path / name).write_text("x")
    stale = tmp_path / f".fig.png.tmp-{atomic._HOST}-{dead}-xyz.png"
    stale.write_text("half")
    assert remove_stale(tmp_path) == [stale]
    assert sorted(os.listdir(tmp_path)) == sorted(keep)
    # the next atomic write into that folder also cleans (once per folder and process)
    stale.write_text("half")
    atomic._CLEANED.discard(os.path.realpath(tmp_path))
    atomic_write_text(tmp_path / "b.txt", "b")
    assert not stale.exists()


def _start(tmp_path: Path, out: Path) -> subprocess.Popen:
    design = tmp_path / "design.toml"
    design.write_text(DESIGN)
    env = dict(os.environ, PYTHONPATH=str(Path(__file__).parents[2] / "src"))
    cmd = [sys.executable, "-m", "rotomorph", "simulate", str(design), "-o", str(out)]
    proc = subprocess.Popen(
        [*cmd, "--steps", "40", "--no-movie"],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    deadline = time.monotonic() + 120
    while not _temporaries(tmp_path):
        if proc.poll() is not None or time.monotonic() > deadline:
            proc.kill()
            pytest.fail(f"no temporary folder appeared: {proc.communicate()}")
        time.sleep(0.01)
    return proc


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGKILL], ids=["SIGTERM", "SIGKILL"])
def test_killed_run_leaves_no_temporary_after_the_next_run(tmp_path, sig):
    out = tmp_path / "runs" / "a"
    out.parent.mkdir()
    proc = _start(out.parent, out)
    proc.send_signal(sig)
    _, err = proc.communicate(timeout=120)
    assert not out.exists()
    if sig == signal.SIGTERM:
        assert proc.returncode == 143 and "terminated (SIGTERM)" in err
        assert _temporaries(out.parent) == []  # cleaned by the run itself
    else:
        assert proc.returncode == -signal.SIGKILL
        assert _temporaries(out.parent)  # nothing can clean up after SIGKILL ...
    # ... the next run writing there does (a cheap one: G-code into the same folder)
    atomic._CLEANED.clear()
    design = tmp_path / "next.toml"
    design.write_text(DESIGN.replace("0.05", "1.0"))
    assert main(["gcode", str(design), "-o", str(out.parent / "next.gcode")]) == EXIT_OK
    assert _temporaries(out.parent) == []

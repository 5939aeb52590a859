"""Atomic writes: the target appears complete or not at all."""

from __future__ import annotations

import os
import stat

import pytest

from rotomorph.io.atomic import atomic_folder, atomic_path, atomic_write_bytes, atomic_write_text


def test_write_bytes_and_text(tmp_path):
    p = atomic_write_bytes(tmp_path / "a.bin", b"\x00\x01abc")
    assert p.read_bytes() == b"\x00\x01abc"
    q = atomic_write_text(tmp_path / "b.txt", "κ = 1/mm\n")
    assert q.read_text(encoding="utf-8") == "κ = 1/mm\n"
    assert sorted(os.listdir(tmp_path)) == ["a.bin", "b.txt"]


def test_overwrite_replaces_content(tmp_path):
    target = tmp_path / "x.txt"
    atomic_write_text(target, "old")
    atomic_write_text(target, "new")
    assert target.read_text() == "new"
    assert os.listdir(tmp_path) == ["x.txt"]


def test_exception_leaves_no_file_behind(tmp_path):
    target = tmp_path / "fig.png"
    with pytest.raises(RuntimeError, match="boom"), atomic_path(target) as tmp:
        tmp.write_bytes(b"partial")
        assert tmp.parent == tmp_path
        raise RuntimeError("boom")
    assert os.listdir(tmp_path) == []


def test_exception_keeps_previous_file(tmp_path):
    target = tmp_path / "r.h5"
    target.write_bytes(b"previous")
    with pytest.raises(KeyError), atomic_path(target) as tmp:
        tmp.write_bytes(b"half")
        raise KeyError("x")
    assert target.read_bytes() == b"previous"
    assert os.listdir(tmp_path) == ["r.h5"]


def test_temporary_keeps_suffix_and_target_untouched_until_success(tmp_path):
    target = tmp_path / "movie.gif"
    with atomic_path(target) as tmp:
        assert tmp.suffix == ".gif"
        assert tmp.name.startswith(".movie.gif.")
        assert not target.exists()
        tmp.write_bytes(b"GIF89a")
    assert target.read_bytes() == b"GIF89a"
    assert os.listdir(tmp_path) == ["movie.gif"]


def test_final_file_has_normal_permissions(tmp_path):
    target = atomic_write_text(tmp_path / "p.txt", "x")
    mask = os.umask(0o022)
    os.umask(mask)
    assert stat.S_IMODE(target.stat().st_mode) == 0o666 & ~mask


def test_missing_folder_raises(tmp_path):
    with pytest.raises(FileNotFoundError):
        atomic_write_text(tmp_path / "nope" / "x.txt", "x")


def test_an_unwritable_folder_is_reported_with_the_target_name(tmp_path, monkeypatch):
    # before: the error named the temporary file (".x.gcode.tmp-host-123-abc.gcode")
    import tempfile

    def refuse(*args, **kwargs):
        raise PermissionError(13, "Permission denied")

    monkeypatch.setattr(tempfile, "mkstemp", refuse)
    monkeypatch.setattr(tempfile, "mkdtemp", refuse)
    target = tmp_path / "x.gcode"
    with pytest.raises(PermissionError) as err:
        atomic_write_text(target, "G1")
    assert err.value.filename == str(target)
    assert err.value.strerror == f"cannot write in {tmp_path} (Permission denied)"
    with pytest.raises(PermissionError) as err, atomic_folder(tmp_path / "run"):
        pass
    assert err.value.filename == str(tmp_path / "run")

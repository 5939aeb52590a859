"""A machine profile's ``header_file``/``footer_file`` is confined to the profile's own folder:
no absolute path, no ``..``, no symbolic link out of it, no device or FIFO, a bounded size; a
shared profile cannot copy ``/etc/passwd`` or a key into a G-code program."""

from __future__ import annotations

import os

import pytest

from rotomorph.cli import EXIT_OK, EXIT_USAGE, main
from rotomorph.errors import InvalidParameterError
from rotomorph.io.machine import MAX_HEADER_BYTES, MachineProfile, load_machine_profile

HEADER = "DVAR $hFile\n; lab header\n"


@pytest.fixture
def lab(tmp_path):
    """``lab/profiles/m.toml`` beside a secret ``lab/secret.txt`` (outside the profile's folder)."""
    profiles = tmp_path / "lab" / "profiles"
    (profiles / "headers").mkdir(parents=True)
    (profiles / "a3200.txt").write_text(HEADER)
    (profiles / "headers" / "footer.txt").write_text("M2\n")
    (tmp_path / "lab" / "secret.txt").write_text("ssh-ed25519 AAAA secret\n")
    return profiles


def _profile(folder, **files):
    path = folder / "m.toml"
    keys = "".join(f'{k} = "{v}"\n' for k, v in files.items())
    path.write_text(f'[machine]\ndialect = "aerotech"\n{keys}')
    return path


def test_files_in_the_profile_folder_and_below_are_read(lab):
    machine = load_machine_profile(
        _profile(lab, header_file="a3200.txt", footer_file="headers/footer.txt")
    )
    assert machine.header_lines == ("DVAR $hFile", "; lab header")
    assert machine.footer_lines == ("M2",)


@pytest.mark.parametrize(
    ("value", "why"),
    [
        ("/etc/passwd", "must be relative"),
        ("~/.ssh/id_ed25519", "must be relative"),
        ("../secret.txt", r"no '\.\.'"),
        ("headers/../../secret.txt", r"no '\.\.'"),
        ("missing.txt", "is not a file"),
        ("headers", "is not a file"),
    ],
)
def test_paths_out_of_the_folder_are_refused(lab, value, why):
    with pytest.raises(InvalidParameterError, match=f"'header_file'.*{why}"):
        load_machine_profile(_profile(lab, header_file=value))


def test_a_symbolic_link_out_of_the_folder_is_refused(lab):
    (lab / "innocent.txt").symlink_to(lab.parent / "secret.txt")
    (lab / "inside.txt").symlink_to(lab / "a3200.txt")
    (lab / "up").symlink_to(lab.parent, target_is_directory=True)
    for name in ("innocent.txt", "up/secret.txt"):
        with pytest.raises(InvalidParameterError, match="leads outside the profile's folder"):
            load_machine_profile(_profile(lab, footer_file=name))
    assert load_machine_profile(_profile(lab, header_file="inside.txt")).header_lines[0] == (
        "DVAR $hFile"
    )


def test_a_fifo_or_device_is_refused_without_blocking(lab):
    os.mkfifo(lab / "pipe.txt")  # opening it for reading would wait for a writer forever
    with pytest.raises(InvalidParameterError, match="is not a file"):
        load_machine_profile(_profile(lab, header_file="pipe.txt"))
    (lab / "zero.txt").symlink_to("/dev/zero")
    with pytest.raises(InvalidParameterError, match=r"leads outside|is not a file"):
        load_machine_profile(_profile(lab, header_file="zero.txt"))


def test_size_and_encoding_are_bounded(lab):
    (lab / "big.txt").write_bytes(b"; x\n" * (MAX_HEADER_BYTES // 4 + 1))
    with pytest.raises(InvalidParameterError, match="larger than 256 KiB"):
        load_machine_profile(_profile(lab, header_file="big.txt"))
    (lab / "latin1.txt").write_bytes("; café\n".encode("latin-1"))
    with pytest.raises(InvalidParameterError, match=r"not ASCII text \(byte 0xe9"):
        load_machine_profile(_profile(lab, header_file="latin1.txt"))


def test_an_inline_profile_has_no_folder_to_read_from():
    with pytest.raises(InvalidParameterError, match="header_lines inline"):
        MachineProfile.from_dict({"header_file": "a3200.txt"})


def test_cli_gcode_refuses_with_one_line(lab, tmp_path, capsys):
    design = tmp_path / "d.toml"
    design.write_text(
        "schema_version = 1\n[[filaments]]\nstart = [10.0, 10.0, 0.0]\nspacing = 0.5\n"
        'segments = [{ kind = "line", length = 5.0 }]\n'
    )
    out = tmp_path / "p.gcode"
    profile = _profile(lab, header_file="/etc/passwd")
    assert main(["gcode", str(design), "-o", str(out), "--machine", str(profile)]) == EXIT_USAGE
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "header_file" in err and "root:" not in err
    assert not out.exists()
    profile = _profile(lab, header_file="a3200.txt")
    assert main(["gcode", str(design), "-o", str(out), "--machine", str(profile)]) == EXIT_OK
    assert "DVAR $hFile" in out.read_text()

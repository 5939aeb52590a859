"""Control characters (C0, DEL, C1, line separators, bidirectional formatting) are refused in
every text field of every file kind (design, machine profile, sweep, inverse target) with one
line naming the field, and nothing a file holds is printed raw on a terminal."""

from __future__ import annotations

import pytest

from rotomorph._text import check_text, markup_safe, terminal_safe, unsafe_characters
from rotomorph.cli import EXIT_USAGE, main
from rotomorph.errors import InvalidParameterError
from rotomorph.inverse.targets import load_target
from rotomorph.io.machine import load_machine_profile
from rotomorph.sweep import load_sweep

#: One of each class: C0 (NUL, BEL, ESC, CR, DEL), C1 (CSI), separators, bidi controls.
HOSTILE = [
    "\x00",
    "\x07",
    "\x1b[2J\x1b[HALL CHECKS PASSED",
    "a\rb",
    "\x7f",
    "\x9b2J",
    "\u2028",
    "\u202eevil",
    "\u2066x\u2069",
    "\u200f",
]


def _toml(text: str) -> str:
    """A TOML basic string holding ``text`` (every non-alphanumeric character escaped)."""
    return '"' + "".join(c if c.isalnum() or c == " " else f"\\u{ord(c):04x}" for c in text) + '"'


def _assert_one_safe_line(err: str) -> None:
    assert err.startswith("rotomorph: error: ") and err.count("\n") == 1
    assert not unsafe_characters(err.rstrip("\n")), repr(err)
    assert "Traceback" not in err


@pytest.mark.parametrize("bad", HOSTILE, ids=[f"U+{ord(b[0]):04X}" for b in HOSTILE])
def test_check_text_refuses_every_class(bad):
    assert unsafe_characters(bad)
    with pytest.raises(ValueError, match=r"must not hold control or bidirectional.*U\+"):
        check_text(bad)
    assert not unsafe_characters(terminal_safe(bad))


def test_free_text_keeps_newlines_and_tabs_only():
    assert check_text("line 1\n\tline 2", newlines=True) == "line 1\n\tline 2"
    with pytest.raises(ValueError, match="ESC"):
        check_text("line\n\x1b[2J", newlines=True)
    with pytest.raises(ValueError, match="newline"):
        check_text("a\nb")


def test_escapes_are_visible_and_reversible_for_humans():
    assert terminal_safe("\x1b[2J ok\u202e") == "\\x1b[2J ok\\u202e"
    assert terminal_safe("κ = 0.2 1/mm °C") == "κ = 0.2 1/mm °C"  # printable Unicode kept
    assert markup_safe("<a href='x'>&</a>") == "&lt;a href=&#x27;x&#x27;&gt;&amp;&lt;/a&gt;"


DESIGN = """schema_version = 1
name = {name}
description = {description}
[[filaments]]
name = {filament}
spacing = 0.5
segments = [{{ kind = "line", length = 5.0 }}]
"""


@pytest.mark.parametrize("field", ["name", "description", "filament"])
@pytest.mark.parametrize("bad", HOSTILE, ids=[f"U+{ord(b[0]):04X}" for b in HOSTILE])
def test_design_text_fields(tmp_path, capsys, field, bad):
    values = {"name": "ok", "description": "fine", "filament": "f"} | {field: bad}
    path = tmp_path / "d.toml"
    path.write_text(DESIGN.format(**{k: _toml(v) for k, v in values.items()}), encoding="utf-8")
    assert main(["validate", str(path)]) == EXIT_USAGE
    out, err = capsys.readouterr()
    assert out == ""
    _assert_one_safe_line(err)
    where = "filaments[0].name" if field == "filament" else field
    assert f"error: {where}: must not hold control" in err


def test_a_key_holding_escape_sequences_is_named_escaped(tmp_path, capsys):
    path = tmp_path / "d.toml"
    path.write_text(
        DESIGN.format(name='"ok"', description='"x"', filament='"f"')
        + '"\\u001b[2J\\u001b]0;pwned\\u0007" = 1\n',
        encoding="utf-8",
    )
    assert main(["validate", str(path)]) == EXIT_USAGE
    err = capsys.readouterr().err
    _assert_one_safe_line(err)
    assert "\\x1b[2J" in err and "unknown key" in err


def test_a_file_name_holding_escape_sequences_is_printed_escaped(tmp_path, capsys):
    path = tmp_path / "\x1b[2Jd.toml"
    path.write_text(DESIGN.format(name='"ok"', description='"x"', filament='"f"'))
    assert main(["validate", str(path)]) == 0
    out = capsys.readouterr().out
    assert "\x1b" not in out and "\\x1b[2Jd.toml" in out


@pytest.mark.parametrize("bad", HOSTILE, ids=[f"U+{ord(b[0]):04X}" for b in HOSTILE])
def test_machine_profile_text(tmp_path, bad):
    path = tmp_path / "m.toml"
    path.write_text(f'[machine]\ndialect = "rs274"\nname = {_toml(bad)}\n', encoding="utf-8")
    with pytest.raises(InvalidParameterError, match=r"'name'.*no newline or control"):
        load_machine_profile(path)
    path.write_text(f"[machine]\n{_toml(bad)} = 1\n", encoding="utf-8")
    with pytest.raises(InvalidParameterError, match="unknown setting") as info:
        load_machine_profile(path)
    assert not unsafe_characters(str(info.value))


SWEEP = """schema_version = 1
name = {name}
description = {description}
outputs = ["end_to_end_ratio"]
[design]
schema_version = 1
[[design.filaments]]
spacing = 0.5
segments = [{{ kind = "line", length = 5.0 }}]
[[parameters]]
path = "{path}"
name = {column}
values = [{value}]
"""


@pytest.mark.parametrize("field", ["name", "description", "column", "value"])
@pytest.mark.parametrize("bad", HOSTILE[::3], ids=[f"U+{ord(b[0]):04X}" for b in HOSTILE[::3]])
def test_sweep_text_fields(tmp_path, capsys, field, bad):
    values = {"name": "ok", "description": "fine", "column": "c", "value": "ok"}
    values = {k: _toml(v) for k, v in (values | {field: bad}).items()}
    values["path"] = "filaments[0].name"
    path = tmp_path / "s.toml"
    path.write_text(SWEEP.format(**values), encoding="utf-8")
    with pytest.raises(InvalidParameterError, match="must not hold control"):
        load_sweep(path)
    assert main(["sweep", str(path), "-o", str(tmp_path / "out")]) == EXIT_USAGE
    _assert_one_safe_line(capsys.readouterr().err)
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("bad", HOSTILE, ids=[f"U+{ord(b[0]):04X}" for b in HOSTILE])
def test_target_name(tmp_path, capsys, bad):
    path = tmp_path / "t.toml"
    path.write_text(
        f"schema_version = 1\nkind = 'dome'\nname = {_toml(bad)}\n[surface]\ncurvature = 0.07\n"
        "[lattice]\nn = 3\n",
        encoding="utf-8",
    )
    with pytest.raises(InvalidParameterError, match="name: must not hold control"):
        load_target(str(path))
    assert main(["inverse", str(path), "-o", str(tmp_path / "d.toml")]) == EXIT_USAGE
    _assert_one_safe_line(capsys.readouterr().err)

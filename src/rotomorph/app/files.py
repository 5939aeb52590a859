"""What the page offers for download, written by the CLI's own functions; what it reads.

Every file is written by the function the command line uses, into a temporary folder the
server chose, and offered as those bytes:

* the design file: the design's tables as the page holds them, written as TOML
  (``tomli_w``, as :func:`rotomorph.io.designfile.save_design` writes), after the same
  validation as ``rotomorph validate``; values the person left unset stay unset, as
  ``save_design`` leaves them (the nozzle's placeholder pressures and dwells are still
  flagged in the G-code made from the file);
* the G-code: the steps of ``rotomorph gcode DESIGN -o FILE [--machine PROFILE]`` —
  :func:`~rotomorph.io.gcode.check_materials`, :func:`~rotomorph.io.placement.check_placement`,
  :func:`~rotomorph.io.gcode.write_gcode` with the design's
  :meth:`~rotomorph.io.designfile.Design.gcode_options`; its controller configuration by
  :func:`~rotomorph.io.machine_config.write_machine_config` (``--machine-config DIR``);
* a run's folder: :func:`rotomorph.simulate.outputs.write_run_results` (``rotomorph simulate
  --no-movie``), in the worker.

Nothing the browser sends is a path: example designs and machine profiles are chosen by their
place in lists the server made from its own folders, and uploads are bytes parsed as the CLI
parses files (:func:`rotomorph.io.designfile.parse_design_bytes`, and a machine profile's TOML
as :func:`rotomorph.io.machine.load_machine_profile` reads it, without a folder: a profile
whose ``header_file`` names a file is refused).
"""

from __future__ import annotations

import io
import tempfile
import zipfile
from dataclasses import replace
from pathlib import Path
from typing import Any

from rotomorph.errors import InvalidParameterError

__all__ = [
    "BUILTIN_MACHINES",
    "controller_zip",
    "design_bytes",
    "folder_zip",
    "gcode_bytes",
    "list_toml",
    "machine_profile",
    "parse_machine_bytes",
]

#: Built-in machines (``rotomorph gcode`` without ``--machine``, or with ``--dialect``).
BUILTIN_MACHINES = ("aerotech", "rs274", "marlin")


def list_toml(folder: Path | None) -> list[Path]:
    """The ``*.toml`` files directly in ``folder`` (sorted; none when it is missing)."""
    if folder is None or not folder.is_dir():
        return []
    return sorted(p for p in folder.glob("*.toml") if p.is_file())


def parse_machine_bytes(data: bytes, name: str) -> Any:
    """A machine profile from the bytes of a TOML file (as ``load_machine_profile`` reads a
    file, with no folder: ``header_file``/``footer_file`` are refused, give the lines inline)."""
    from rotomorph.io.machine import MachineProfile, _bad, check_line
    from rotomorph.io.tomlfile import decode_toml_bytes

    table = decode_toml_bytes(data, name)
    table = table.get("machine", table)
    if not isinstance(table, dict):
        raise _bad("machine", f"must be a table [machine]; got {table!r}")
    table = {"continuous_rotation": False, **table}
    profile = MachineProfile.from_dict(table, folder=None)
    return replace(profile, source=check_line("machine profile path", name))


def machine_profile(choice: str, examples: list[Path], uploaded: Any) -> Any:
    """The machine of a choice of the page: ``builtin:<dialect>``, ``example:<i>`` (the i-th
    profile the server listed) or ``upload`` (the session's uploaded profile)."""
    from rotomorph.errors import InvalidParameterError
    from rotomorph.io.machine import MachineProfile, load_machine_profile

    kind, _, value = (choice or "builtin:aerotech").partition(":")
    if kind == "builtin" and value in BUILTIN_MACHINES:
        return MachineProfile(dialect=value)
    if kind == "example" and value.isdigit() and int(value) < len(examples):
        return load_machine_profile(examples[int(value)])
    if kind == "upload" and uploaded is not None:
        return uploaded
    raise InvalidParameterError("machine", f"unknown machine choice {choice!r}; pick one listed")


def design_bytes(data: dict[str, Any]) -> bytes:
    """The design file of ``data`` (the tables a design file parses into): TOML, UTF-8.

    Raises
    ------
    InvalidParameterError
        ``data`` is not a valid design (the message ``rotomorph validate`` prints).
    """
    import tomli_w

    from rotomorph.app.editing import check

    _, error = check(data)
    if error is not None:
        raise InvalidParameterError(error[0], error[1].removeprefix(f"{error[0]}: "))
    return tomli_w.dumps(data).encode("utf-8")


def gcode_bytes(design: Any, machine: Any, *, cure: float = 0.0) -> tuple[bytes, dict[str, bytes]]:
    """The G-code ``rotomorph gcode`` writes for ``design`` on ``machine`` and the controller
    files of ``--machine-config`` (name -> bytes)."""
    from rotomorph.io.gcode import check_materials, write_gcode
    from rotomorph.io.machine_config import write_machine_config
    from rotomorph.io.placement import check_placement

    programs = design.to_programs()
    check_materials(programs)
    options = design.gcode_options()
    check_placement(design, machine)
    with tempfile.TemporaryDirectory(prefix="rotomorph-app-") as tmp:
        out = Path(tmp) / "design.gcode"
        write_gcode(programs, out, machine, **options, layer_cure_s=cure)
        text = out.read_text(encoding="ascii")
        written = write_machine_config(machine, text, Path(tmp) / "config")
        return out.read_bytes(), {p.name: p.read_bytes() for p in written}


def controller_zip(files: dict[str, bytes]) -> bytes:
    """The controller files in one zip archive (names as ``--machine-config`` writes them)."""
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as archive:
        for name, data in sorted(files.items()):
            archive.writestr(name, data)
    return buf.getvalue()


def folder_zip(folder: Path) -> bytes:
    """Every file under ``folder`` in one zip archive (paths relative to it)."""
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as archive:
        for path in sorted(folder.rglob("*")):
            if path.is_file():
                archive.write(path, path.relative_to(folder).as_posix())
    return buf.getvalue()

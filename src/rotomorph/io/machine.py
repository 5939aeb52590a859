"""Machine profiles for the G-code writer: envelope, limits, axes, dialect, pressure idiom.

A profile is what a lab writes once per printer (a TOML file with a ``[machine]`` table, see
``examples/machines/``); the writer refuses (:class:`~rotomorph.errors.MachineLimitError`) any
program that would leave its envelope or exceed one of its limits, naming the key to change.

Dialects
--------
``aerotech``
    Aerotech A3200 as mecode writes it: setup ``G71`` (metric) ``G76`` (seconds) ``G90``;
    F in mm/s on its own ``G1 F<v>`` line whenever the speed changes (mecode's ``feed``);
    moves ``G1 X Y [Z] C`` (mecode's ``move(x=, y=, C=)``); dwell ``G4 P<s>``; pressure
    idiom ``alicat`` (``Call setAlicatPress P<com> Q<psi>``, off = ``Q0``) or ``nordson``
    (``Call setPress P<com> Q<psi>`` then ``Call togglePress P<com>``; off = a second toggle);
    optional A3200 header and footer files (DVAR declarations, the ``DFS setPress`` subroutines).
``rs274``
    LinuxCNC / RS-274/NGC: ``G21 G90 G94``; F in mm/min on every print move; rapid ``G0``
    travel; dwell ``G4 P<s>`` (seconds); pressure from templates, by default an analog output
    for the set-point (``M68 E{port} Q{psi}``) and digital outputs for the valves
    (``M64 P{port}`` on, ``M65 P{port}`` off); ``M2`` at the end.
``marlin``
    Marlin, Klipper and RepRapFirmware: ``G21 G90``; F in mm/min on *every* move, travel
    included (``G0`` is ``G1`` on these firmwares); dwell ``G4 P<ms>`` (milliseconds, which all
    three read the same way); pressure from templates (``M42``, ``SET_PIN`` or macros).

Rotary axis
-----------
The nozzle angle α_n (rad, counter-clockwise from +x seen from above) is written on
``rotary_axis`` (default ``C``: rotation about Z in RS-274/ISO; ``A`` is rotation about X, and in
many mecode labs a second Z stage), in ``rotary_units`` and with ``rotary_sign``. The program
assumes the axis reads 0 with the active half toward +x at the start. Between filaments the
angle is re-based (``rotary_rebase = "g92"``: ``G92 C<angle mod 360>``, restored at the end) or
unwound (``"unwind"``), so it never exceeds one turn between filaments.
"""

from __future__ import annotations

import math
import string
from collections.abc import Mapping
from dataclasses import dataclass, fields, replace
from pathlib import Path as FilePath
from typing import Any

from rotomorph._text import terminal_safe
from rotomorph.errors import InvalidParameterError
from rotomorph.io.tomlfile import read_toml

__all__ = [
    "DIALECTS",
    "PRESSURE_IDIOMS",
    "MachineProfile",
    "check_line",
    "fill_template",
    "load_machine_profile",
]

DIALECTS = ("aerotech", "rs274", "marlin")
PRESSURE_IDIOMS = ("alicat", "nordson", "template")
#: Controllers of each dialect (the first is the dialect's default); the controller decides the
#: generated controller-side configuration, the pause command and what G92 may carry.
CONTROLLERS: dict[str, tuple[str, ...]] = {
    "aerotech": ("a3200",),
    "rs274": ("linuxcnc",),
    "marlin": ("marlin", "klipper", "reprapfirmware"),
}
#: A real pause (waits for the operator) per controller, for a cure without lamp commands.
_PAUSE = {
    "a3200": "M0",
    "linuxcnc": "M0",
    "marlin": "M0",
    "klipper": "PAUSE",
    "reprapfirmware": "M226",
}
BUILTIN = "built-in default"
#: Time (s) one serial pressure call of an Aerotech subroutine takes (a Nordson togglePress was
#: measured at 0.15 s); counted in the time estimate unless the profile sets pressure_call_s.
SERIAL_CALL_S = 0.15

#: Dialect defaults of the keys left unset (``None``) in a profile.
_DEFAULTS: dict[str, dict[str, Any]] = {
    "aerotech": {
        "pressure_idiom": "alicat",
        "pressure_template": "",
        "valve_on_template": "",
        "valve_off_template": "",
        "dwell_template": "G4 P{s}",
        # metric, seconds, absolute, velocity blending between moves (no stop at each vertex)
        "setup_lines": ("G71", "G76", "G90", "VELOCITY ON"),
        "end_lines": ("M2",),
    },
    "rs274": {
        "pressure_idiom": "template",
        "pressure_template": "M68 E{port} Q{psi:.3f}",
        "valve_on_template": "M64 P{port}",
        "valve_off_template": "M65 P{port}",
        "dwell_template": "G4 P{s}",
        "setup_lines": ("G21", "G90", "G94"),
        "end_lines": ("M2",),
    },
    "marlin": {
        "pressure_idiom": "template",
        "pressure_template": "M42 P{port} S{pwm}",
        "valve_on_template": "",
        "valve_off_template": "",
        "dwell_template": "G4 P{ms}",
        "setup_lines": ("G21", "G90"),
        "end_lines": (),
    },
}
#: Controller defaults over the dialect's (Klipper: the generated printer.cfg's macros).
_CONTROLLER_DEFAULTS: dict[str, dict[str, Any]] = {
    "klipper": {
        "pressure_template": "SET_PIN PIN=pressure{port} VALUE={fraction:.4f}",
        "setup_lines": ("ROTOMORPH_START", "G21", "G90"),
        "end_lines": ("ROTOMORPH_END",),
    },
}
_PRESSURE_FIELDS = {"psi", "fraction", "pwm"}
_RESERVED = {"F", "G", "M", "N", "P", "Q", "S", "E", "T", "O"}


def _bad(field: str, message: str) -> InvalidParameterError:
    """An error naming the key of the machine-profile file (``[machine]`` table)."""
    return InvalidParameterError(f"machine profile key '{field}'", message)


def check_line(field: str, text: object, *, token: bool = False) -> str:
    """``text`` if it is one line of printable ASCII, else raise naming ``field``.

    Everything that a design or a machine profile contributes to a G-code program (names,
    templates, comments, header lines) passes through here, so no newline, carriage return,
    NUL or other control character can start a new block in the program.

    Parameters
    ----------
    field
        Name of the setting, for the message.
    text
        The value.
    token
        Also refuse spaces (a single word, e.g. a material name).
    """
    if not isinstance(text, str):
        raise InvalidParameterError(field, f"must be a string; got {type(text).__name__}")
    low = 33 if token else 32
    bad = [c for c in text if not (low <= ord(c) < 127)]
    if bad:
        what = "printable ASCII without spaces" if token else "one line of printable ASCII"
        raise InvalidParameterError(
            field, f"must be {what} (no newline or control character); got {text!r}"
        )
    return text


def _fields(template: str) -> set[str]:
    return {f[1] for f in string.Formatter().parse(template) if f[1] is not None}


def fill_template(template: str, **values: float) -> str:
    """``template.format(**values)`` with only the fields the template names (psi, port, …)."""
    return template.format(**{k: v for k, v in values.items() if k in _fields(template)})


@dataclass(frozen=True)
class MachineProfile:
    """A printer: where it can go, how fast, and how its G-code is spelled.

    Every key below is a key of the ``[machine]`` table of a profile file; ``None`` means the
    dialect's default (module docstring). Errors name the key to change.

    Parameters
    ----------
    name
        Label written in the G-code header (one line of printable ASCII).
    dialect
        ``"aerotech"``, ``"rs274"`` or ``"marlin"`` (module docstring).
    envelope_min, envelope_max
        Work envelope corners (x, y, z) in mm, in program coordinates (after ``z_offset``);
        every vertex and travel move must lie inside.
    max_feed, min_feed
        Print feed range (mm/s); slower or faster print moves are refused.
    travel_feed
        Feed of travel and lift moves (mm/s); written on every travel in ``marlin``, used for
        the time estimate of rapid ``G0`` moves elsewhere.
    max_rotation
        Highest nozzle rotation rate (rad/s) on any move, travel included (a file may give
        ``max_rotation_deg_s`` instead, in deg/s).
    max_pressure, min_pressure
        Pressure set-point limits (psi); the regulator's full scale for ``{fraction}``/``{pwm}``.
    active_port, passive_port
        COM port (aerotech) or output index (templates) of the active and passive channels.
    x_axis, y_axis, z_axis, rotary_axis
        Axis letters; the rotary default ``C`` is rotation about Z (RS-274/ISO).
    rotary_units
        ``"deg"`` (default) or ``"rad"`` for the rotary words.
    rotary_sign
        +1 if a positive rotary command turns the nozzle counter-clockwise seen from above.
    rotary_rebase
        ``"g92"`` (re-base the angle word with ``G92`` between filaments) or ``"unwind"``
        (turn back during the lowering move; slow after long rotating filaments).
    lift
        Travel clearance above the highest point printed so far (mm), > 0.
    z_offset
        Added to every design z (mm): program Z of the nozzle tip at design z = 0 (the
        substrate), so layers sit at ``z_offset + k * layer_height``.
    pressure_idiom
        ``"alicat"`` or ``"nordson"`` (aerotech), ``"template"`` (any dialect).
    pressure_template
        Set-point line with fields ``{port}`` and one of ``{psi}``, ``{fraction}``
        (psi / max_pressure) or ``{pwm}`` (0–255 of max_pressure); format specs allowed.
    valve_on_template, valve_off_template
        Optional lines (field ``{port}``) that open and close a channel; without them a
        channel is turned off by setting it to 0.
    dwell_template
        Dwell line with field ``{s}`` (seconds) or ``{ms}`` (milliseconds).
    uv_on_template, uv_off_template
        Optional lines around the per-layer UV-cure dwell.
    setup_lines, end_lines
        Lines after the header comment and at the end of the program.
    header_lines, footer_lines
        Verbatim lines before the setup and after the end (a file may give ``header_file``
        and ``footer_file``: ASCII text files of at most 256 KiB in the profile's own folder
        or below it, named relative to it; tabs become spaces).
    source
        Where the profile came from: the file name, or ``"built-in default"`` (stated in the
        G-code header). Not a file key.
    """

    name: str = "generic"
    dialect: str = "aerotech"
    envelope_min: tuple[float, float, float] = (0.0, 0.0, 0.0)
    envelope_max: tuple[float, float, float] = (300.0, 300.0, 100.0)
    max_feed: float = 50.0
    min_feed: float = 0.01
    travel_feed: float = 20.0
    max_rotation: float = 40.0
    max_pressure: float = 100.0
    min_pressure: float = 0.0
    active_port: int = 5
    passive_port: int = 6
    x_axis: str = "X"
    y_axis: str = "Y"
    z_axis: str = "Z"
    rotary_axis: str = "C"
    rotary_units: str = "deg"
    rotary_sign: int = 1
    rotary_rebase: str | None = None
    continuous_rotation: bool = True
    max_turns: float = 10.0
    controller: str | None = None
    lift: float = 2.0
    z_offset: float = 0.0
    pressure_idiom: str | None = None
    pressure_template: str | None = None
    valve_on_template: str | None = None
    valve_off_template: str | None = None
    dwell_template: str | None = None
    uv_on_template: str = ""
    uv_off_template: str = ""
    pause_template: str | None = None
    pressure_call_s: float = math.nan  # NaN: the idiom's default (SERIAL_CALL_S or 0)
    setup_lines: tuple[str, ...] | None = None
    end_lines: tuple[str, ...] | None = None
    header_lines: tuple[str, ...] = ()
    footer_lines: tuple[str, ...] = ()
    source: str = BUILTIN

    def __post_init__(self) -> None:
        check_line("machine profile key 'name'", self.name)
        check_line("machine profile source", self.source)
        if self.dialect not in DIALECTS:
            raise _bad("dialect", f"must be one of {DIALECTS}; got {self.dialect!r}")
        controller = self.controller or CONTROLLERS[self.dialect][0]
        defaults = {**_DEFAULTS[self.dialect], **_CONTROLLER_DEFAULTS.get(controller, {})}
        for key, value in defaults.items():
            if getattr(self, key) is None:
                object.__setattr__(self, key, value)
        self._check_controller()
        self._check_numbers()
        self._check_axes()
        self._check_text()

    def _check_controller(self) -> None:
        allowed = CONTROLLERS[self.dialect]
        if self.controller is None:
            object.__setattr__(self, "controller", allowed[0])
        if self.controller not in allowed:
            raise _bad(
                "controller",
                f"must be one of {allowed} for the {self.dialect!r} dialect; "
                f"got {self.controller!r}",
            )
        if not isinstance(self.continuous_rotation, bool):
            raise _bad(
                "continuous_rotation", f"must be true or false; got {self.continuous_rotation!r}"
            )
        v = self.max_turns
        if (
            isinstance(v, bool)
            or not isinstance(v, int | float)
            or not (math.isfinite(v) and v > 0)
        ):
            raise _bad("max_turns", f"must be a number of turns > 0; got {v!r}")
        if self.rotary_rebase is None:
            g92 = self.continuous_rotation and self.controller != "klipper"
            object.__setattr__(self, "rotary_rebase", "g92" if g92 else "unwind")
        if self.rotary_rebase == "g92" and self.controller == "klipper":
            raise _bad(
                "rotary_rebase",
                "Klipper's G92 sets X, Y, Z and E only (a 'G92 C...' zeroes X, Y and Z); "
                "use 'unwind' on Klipper",
            )
        if self.rotary_rebase == "g92" and not self.continuous_rotation:
            raise _bad(
                "rotary_rebase",
                "'g92' re-bases the angle word but leaves the nozzle's hoses wound; it needs a "
                "rotary union (continuous_rotation = true), else use 'unwind'",
            )
        if self.pause_template is None:
            object.__setattr__(self, "pause_template", _PAUSE[self.controller])
        if isinstance(self.pressure_call_s, float) and math.isnan(self.pressure_call_s):
            serial = self.pressure_idiom in ("alicat", "nordson")
            object.__setattr__(self, "pressure_call_s", SERIAL_CALL_S if serial else 0.0)
        v = self.pressure_call_s
        if (
            isinstance(v, bool)
            or not isinstance(v, int | float)
            or not (math.isfinite(v) and v >= 0)
        ):
            raise _bad("pressure_call_s", f"must be a time in s >= 0; got {v!r}")

    def _check_numbers(self) -> None:
        try:
            lo = tuple(float(v) for v in self.envelope_min)
            hi = tuple(float(v) for v in self.envelope_max)
        except (TypeError, ValueError):
            raise _bad("envelope_max", "corners must be three numbers [x, y, z] (mm)") from None
        if not all(math.isfinite(v) for v in lo + hi):
            raise _bad("envelope_max", f"corners must be finite (mm); got {lo} .. {hi}")
        if len(lo) != 3 or len(hi) != 3 or not all(a < b for a, b in zip(lo, hi, strict=False)):
            raise _bad("envelope_max", f"must exceed envelope_min on x, y, z; got {lo} .. {hi}")
        object.__setattr__(self, "envelope_min", lo)
        object.__setattr__(self, "envelope_max", hi)
        for name in ("max_feed", "min_feed", "travel_feed", "max_rotation", "max_pressure", "lift"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
                raise _bad(name, f"must be a finite number > 0; got {v!r}")
            if v <= 0:
                raise _bad(name, f"must be a finite number > 0; got {v!r}")
        for name in ("min_pressure", "z_offset"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
                raise _bad(name, f"must be a finite number; got {v!r}")
        if not self.min_feed < self.max_feed:
            raise _bad("min_feed", f"must be < max_feed {self.max_feed} mm/s; got {self.min_feed}")
        if not self.min_feed <= self.travel_feed:
            raise _bad("travel_feed", f"must be >= min_feed ({self.min_feed} mm/s)")
        if not 0 <= self.min_pressure < self.max_pressure:
            raise _bad("min_pressure", f"must lie in [0, max_pressure); got {self.min_pressure}")
        for name in ("active_port", "passive_port"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, int) or not 0 <= v <= 9999:
                raise _bad(name, f"must be an integer in [0, 9999]; got {v!r}")
        if self.active_port == self.passive_port:
            raise _bad("passive_port", "must differ from active_port")

    def _check_axes(self) -> None:
        letters = [self.x_axis, self.y_axis, self.z_axis, self.rotary_axis]
        names = ("x_axis", "y_axis", "z_axis", "rotary_axis")
        for key, a in zip(names, letters, strict=True):
            if not isinstance(a, str) or len(a) != 1 or not "A" <= a <= "Z" or a in _RESERVED:
                raise _bad(key, f"must be one capital letter, not {sorted(_RESERVED)}; got {a!r}")
        if len(set(letters)) != 4:
            raise _bad("rotary_axis", f"axis letters must be distinct; got {letters}")
        if self.rotary_units not in ("deg", "rad"):
            raise _bad("rotary_units", f"must be 'deg' or 'rad'; got {self.rotary_units!r}")
        if self.rotary_sign not in (1, -1) or isinstance(self.rotary_sign, bool):
            raise _bad("rotary_sign", f"must be +1 or -1; got {self.rotary_sign!r}")
        if self.rotary_rebase not in ("g92", "unwind"):
            raise _bad("rotary_rebase", f"must be 'g92' or 'unwind'; got {self.rotary_rebase!r}")

    def _check_text(self) -> None:
        if self.pressure_idiom not in PRESSURE_IDIOMS:
            raise _bad("pressure_idiom", f"must be one of {PRESSURE_IDIOMS}")
        if self.pressure_idiom != "template" and self.dialect != "aerotech":
            raise _bad("pressure_idiom", "'alicat' and 'nordson' are Aerotech subroutine calls")
        templates: dict[str, set[str]] = {
            "pressure_template": {"port"} | _PRESSURE_FIELDS,
            "valve_on_template": {"port"},
            "valve_off_template": {"port"},
            "dwell_template": {"s", "ms"},
            "uv_on_template": set(),
            "uv_off_template": set(),
            "pause_template": set(),
        }
        sample = {"port": 5, "psi": 1.5, "fraction": 0.5, "pwm": 128, "s": 1.5, "ms": 1500}
        for key, allowed in templates.items():
            text = check_line(f"machine profile key '{key}'", getattr(self, key))
            try:
                used = _fields(text)
                fill_template(text, **sample)
            except (ValueError, IndexError, KeyError) as exc:
                raise _bad(key, f"is not a valid template ({exc}); got {text!r}") from None
            if not used <= allowed:
                raise _bad(key, f"may only use fields {sorted(allowed)}; got {sorted(used)}")
            if "port" in allowed and text and "port" not in used:
                raise _bad(key, "must name the channel with {port} (the two channels differ)")
        if self.pressure_idiom == "template":
            if not self.pressure_template and not self.valve_on_template:
                raise _bad("pressure_template", "give a set-point or valve template")
            if (
                self.pressure_template
                and len(_fields(self.pressure_template) & _PRESSURE_FIELDS) != 1
            ):
                raise _bad("pressure_template", "must use exactly one of {psi}, {fraction}, {pwm}")
            if bool(self.valve_on_template) != bool(self.valve_off_template):
                raise _bad("valve_off_template", "give both valve templates or neither")
            if self.valve_on_template and self.valve_on_template == self.valve_off_template:
                raise _bad("valve_off_template", "must differ from valve_on_template")
        dwell = _fields(self.dwell_template or "")
        if len(dwell) != 1:
            raise _bad("dwell_template", "must use exactly one of {s} or {ms}")
        for key in ("setup_lines", "end_lines", "header_lines", "footer_lines"):
            lines = getattr(self, key)
            if isinstance(lines, str) or not isinstance(lines, tuple | list):
                raise _bad(key, "must be a list of lines")
            for i, line in enumerate(lines):
                check_line(f"machine profile key '{key}' line {i + 1}", line)
            object.__setattr__(self, key, tuple(line.rstrip() for line in lines))

    # ------------------------------------------------------------------ derived
    @property
    def is_builtin(self) -> bool:
        """True for the built-in default profile (no profile file was given)."""
        return self.source == BUILTIN

    @property
    def feed_scale(self) -> float:
        """Factor from mm/s to the dialect's F unit (1 for aerotech, 60 for mm/min)."""
        return 1.0 if self.dialect == "aerotech" else 60.0

    @property
    def rotary_scale(self) -> float:
        """Factor from nozzle angle (rad) to the rotary axis word (deg or rad, with sign)."""
        return self.rotary_sign * (180.0 / math.pi if self.rotary_units == "deg" else 1.0)

    @property
    def turn(self) -> float:
        """One full turn in rotary-word units (360 or 2π)."""
        return 360.0 if self.rotary_units == "deg" else 2 * math.pi

    def pressure_values(self, psi: float) -> dict[str, float]:
        """Template values for a set-point of ``psi``: psi, fraction and pwm (0–255)."""
        fraction = psi / self.max_pressure
        return {"psi": psi, "fraction": fraction, "pwm": round(255 * fraction)}

    # ------------------------------------------------------------------ files
    @classmethod
    def from_dict(
        cls, data: Mapping[str, Any], *, folder: FilePath | None = None
    ) -> MachineProfile:
        """Profile from a mapping (a ``[machine]`` table).

        ``max_rotation_deg_s`` (deg/s) may replace ``max_rotation``; ``header_file`` and
        ``footer_file`` name text files (relative to ``folder``) for the verbatim lines.
        """
        data = dict(data)
        if "max_rotation_deg_s" in data:
            if "max_rotation" in data:
                raise _bad("max_rotation", "give max_rotation (rad/s) or max_rotation_deg_s")
            deg = data.pop("max_rotation_deg_s")
            if isinstance(deg, bool) or not isinstance(deg, int | float):
                raise _bad("max_rotation_deg_s", f"must be a number (deg/s); got {deg!r}")
            data["max_rotation"] = math.radians(deg)
        for key in ("header", "footer"):
            if f"{key}_file" in data:
                if f"{key}_lines" in data:
                    raise _bad(f"{key}_file", f"give {key}_file or {key}_lines, not both")
                data[f"{key}_lines"] = _read_lines(f"{key}_file", data.pop(f"{key}_file"), folder)
        known = {f.name for f in fields(cls)} - {"source"}
        unknown = sorted(set(data) - known)
        if unknown:
            name = terminal_safe(str(unknown[0]))  # a key may hold ESC
            raise _bad(name, f"unknown setting; known: {sorted(known)}")
        for k, v in data.items():
            default = getattr(cls, k, None)
            if k == "continuous_rotation":
                if not isinstance(v, bool):
                    raise _bad(k, f"must be true or false; got {v!r}")
            elif k in ("envelope_min", "envelope_max"):
                if not isinstance(v, list | tuple) or not all(
                    isinstance(c, int | float) and not isinstance(c, bool) for c in v
                ):
                    raise _bad(k, f"must be three numbers [x, y, z] (mm); got {v!r}")
                data[k] = tuple(v)
            elif k.endswith("_lines"):
                if not isinstance(v, list | tuple) or not all(isinstance(c, str) for c in v):
                    raise _bad(k, f"must be a list of strings; got {v!r}")
                data[k] = tuple(v)
            elif (
                k.endswith(("_template", "_idiom"))
                or k in ("controller", "rotary_rebase")
                or isinstance(default, str)
            ):
                if not isinstance(v, str):
                    raise _bad(k, f"has the wrong type {type(v).__name__}; got {v!r}")
            elif isinstance(v, bool) or not isinstance(v, int | float):
                raise _bad(k, f"has the wrong type {type(v).__name__}; got {v!r} (give a number)")
        return cls(**data)


#: Largest header or footer file read (bytes); an A3200 header is a few kB.
MAX_HEADER_BYTES = 256 * 1024


def _read_lines(key: str, value: object, folder: FilePath | None) -> tuple[str, ...]:
    """Lines of the ``header_file``/``footer_file`` ``value``: a regular text file inside the
    profile's ``folder`` (a relative path without ``..``; after following symlinks still
    inside), so a shared profile cannot copy ``/etc/passwd`` or ``~/.ssh`` into a program."""
    if not isinstance(value, str) or not value:
        raise _bad(key, f"must be a file name; got {value!r}")
    fix = "put the file next to the profile and give its name"
    if folder is None:
        raise _bad(key, f"needs a profile file to be relative to; give {key[:6]}_lines inline")
    rel = FilePath(value)
    if rel.is_absolute() or value.startswith("~"):
        raise _bad(key, f"must be relative to the profile's folder; got {value!r}: {fix}")
    if ".." in rel.parts:
        raise _bad(key, f"must stay inside the profile's folder (no '..'); got {value!r}: {fix}")
    root = folder.resolve()
    path = (folder / rel).resolve()
    if not path.is_relative_to(root):
        raise _bad(key, f"{value!r} leads outside the profile's folder (a symbolic link?): {fix}")
    if not path.is_file():
        raise _bad(key, f"{value!r} is not a file in the profile's folder {folder}")
    try:
        with open(path, "rb") as fh:
            data = fh.read(MAX_HEADER_BYTES + 1)
    except OSError as exc:
        raise _bad(key, f"cannot read {value!r} ({exc.strerror})") from None
    if len(data) > MAX_HEADER_BYTES:
        raise _bad(key, f"{value!r} is larger than {MAX_HEADER_BYTES // 1024} KiB")
    try:
        text = data.decode("ascii")
    except UnicodeDecodeError as exc:
        raise _bad(
            key, f"{value!r} is not ASCII text (byte 0x{data[exc.start]:02x} at {exc.start})"
        ) from None
    return tuple(line.expandtabs(4).rstrip() for line in text.splitlines())


def load_machine_profile(path: str | FilePath) -> MachineProfile:
    """Read a profile from a TOML file (a ``[machine]`` table or top-level keys).

    Raises
    ------
    InvalidParameterError
        Not UTF-8 (or UTF-16/32 with a BOM), not valid TOML, unknown keys, wrong types or
        values out of range (one line naming the key).
    """
    path = FilePath(path)
    data = read_toml(path)
    table = data.get("machine", data)
    if not isinstance(table, dict):
        raise _bad("machine", f"must be a table [machine]; got {table!r}")
    # a profile file states whether the machine has a rotary union; unsaid, it has none
    table = {"continuous_rotation": False, **table}
    profile = MachineProfile.from_dict(table, folder=path.parent)
    return replace(profile, source=check_line("machine profile path", path.name))

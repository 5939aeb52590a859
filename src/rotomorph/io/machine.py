"""Machine profiles for the G-code writer: envelope, limits, axis letters, dialect, ports.

The writer refuses (raises :class:`~rotomorph.errors.MachineLimitError`) any toolpath that leaves
the envelope or exceeds a limit, so a profile is a required argument: there is no safe default
machine. Dialects (DESIGN.md section 7):

``aerotech``
    mecode-compatible: ``G71`` (metric), ``G76`` (time in seconds), ``G90``; F in mm/s;
    pressures as ``Call setAlicatPress P<com> Q<psi>``; dwell ``G4 P<s>``.
``rs274``
    ``G21``/``G90``; F in mm/min; pressures from :attr:`MachineProfile.pressure_template`;
    dwell ``G4 P<s>`` (RS274/NGC seconds).
``marlin``
    as ``rs274`` but dwell ``G4 S<s>`` and no ``M2`` at the end.
"""

from __future__ import annotations

import math
import string
from collections.abc import Mapping
from dataclasses import dataclass, fields, replace
from pathlib import Path as FilePath
from typing import Any

from rotomorph.errors import InvalidParameterError
from rotomorph.io.tomlfile import read_toml

__all__ = ["DIALECTS", "MachineProfile", "check_line", "load_machine_profile"]

DIALECTS = ("aerotech", "rs274", "marlin")
BUILTIN = "built-in default"


def _bad(field: str, message: str) -> InvalidParameterError:
    """An error naming the key of the machine-profile file (``[machine]`` table)."""
    return InvalidParameterError(f"machine profile key '{field}'", message)


def check_line(field: str, text: object, *, token: bool = False) -> str:
    """``text`` if it is one line of printable ASCII, else raise naming ``field``.

    Everything that a design or a machine profile contributes to a G-code program (names,
    templates, comments) passes through here, so no newline, carriage return, NUL or other
    control character can start a new block in the program.

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


@dataclass(frozen=True)
class MachineProfile:
    """A printer: where it can go, how fast, and how its G-code is spelled.

    Parameters
    ----------
    name
        Free label, written in the G-code header.
    dialect
        ``"aerotech"``, ``"rs274"`` or ``"marlin"`` (module docstring).
    envelope_min, envelope_max
        Work envelope corners (x, y, z) in mm; every vertex and travel move must lie inside.
    max_feed
        Highest print feed (mm/s).
    travel_feed
        Feed used to estimate travel time (mm/s); travel is written as rapid ``G0`` moves.
    max_rotation
        Highest nozzle rotation rate on a print move (rad/s).
    max_pressure, min_pressure
        Pressure set-point limits (psi); the Alicat PCD-100PSIG of the paper: 0..100 psi.
    active_port, passive_port
        COM ports (aerotech) or template ports of the active and passive pressure channels.
    x_axis, y_axis, z_axis, rotary_axis
        Axis letters. RS-274 names rotation about Z ``C``; many dispensing rigs use ``A`` for
        the rotary nozzle (default) but check that ``A`` is not a second Z stage on yours.
    rotary_units
        ``"deg"`` (default) or ``"rad"`` for the rotary axis words.
    rotary_sign
        +1 if a positive rotary command turns the nozzle counter-clockwise seen from above
        (the nozzle-angle sense), -1 otherwise.
    lift
        Travel height above the current layer (mm), > 0.
    pressure_template
        rs274/marlin pressure line with fields ``{port}`` and ``{psi}`` (a format spec on
        ``psi`` is allowed, e.g. ``{psi:.3f}``); map it to your controller's macro.
    uv_on_template, uv_off_template
        Optional lines around the per-layer UV-cure dwell (empty: dwell only).
    min_feed
        Lowest print feed (mm/s) the controller executes faithfully; slower moves are refused.
    source
        Where the profile came from: the file name, or ``"built-in default"`` (stated in the
        G-code header). Not a file key.

    Every text value must be one line of printable ASCII (:func:`check_line`); errors name the
    key of the profile file to change.
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
    rotary_axis: str = "A"
    rotary_units: str = "deg"
    rotary_sign: int = 1
    lift: float = 2.0
    pressure_template: str = "M800 P{port} Q{psi:.3f}"
    uv_on_template: str = ""
    uv_off_template: str = ""
    source: str = BUILTIN

    def __post_init__(self) -> None:
        check_line("machine profile key 'name'", self.name)
        check_line("machine profile source", self.source)
        if self.dialect not in DIALECTS:
            raise _bad("dialect", f"must be one of {DIALECTS}; got {self.dialect!r}")
        lo = tuple(float(v) for v in self.envelope_min)
        hi = tuple(float(v) for v in self.envelope_max)
        if not all(math.isfinite(v) for v in lo + hi):
            raise _bad("envelope_max", f"corners must be finite (mm); got {lo} .. {hi}")
        if len(lo) != 3 or len(hi) != 3 or not all(a < b for a, b in zip(lo, hi, strict=False)):
            raise _bad("envelope_max", f"must exceed envelope_min on x, y, z; got {lo} .. {hi}")
        object.__setattr__(self, "envelope_min", lo)
        object.__setattr__(self, "envelope_max", hi)
        for name in (
            "max_feed",
            "min_feed",
            "travel_feed",
            "max_rotation",
            "max_pressure",
            "lift",
        ):
            v = getattr(self, name)
            if (
                isinstance(v, bool)
                or not isinstance(v, int | float)
                or not (math.isfinite(v) and v > 0)
            ):
                raise _bad(name, f"must be a finite number > 0; got {v!r}")
        if not self.min_feed < self.max_feed:
            raise _bad(
                "min_feed", f"must be < max_feed ({self.max_feed} mm/s); got {self.min_feed}"
            )
        if not self.min_feed <= self.travel_feed:
            raise _bad("travel_feed", f"must be >= min_feed ({self.min_feed} mm/s)")
        if not (math.isfinite(self.min_pressure) and 0 <= self.min_pressure < self.max_pressure):
            raise _bad("min_pressure", f"must lie in [0, max_pressure); got {self.min_pressure}")
        letters = [self.x_axis, self.y_axis, self.z_axis, self.rotary_axis]
        if any(not isinstance(a, str) or len(a) != 1 or not ("A" <= a <= "Z") for a in letters):
            raise _bad("rotary_axis", f"axis letters must be single capitals; got {letters}")
        if len(set(letters)) != 4 or set(letters) & {"F", "G", "M", "P", "Q", "S", "N"}:
            raise _bad(
                "rotary_axis", f"axis letters must be distinct, not F/G/M/N/P/Q/S; got {letters}"
            )
        if self.rotary_units not in ("deg", "rad"):
            raise _bad("rotary_units", f"must be 'deg' or 'rad'; got {self.rotary_units!r}")
        if self.rotary_sign not in (1, -1):
            raise _bad("rotary_sign", f"must be +1 or -1; got {self.rotary_sign}")
        for name in ("active_port", "passive_port"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, int) or not 0 <= v <= 9999:
                raise _bad(name, f"must be an integer in [0, 9999]; got {v!r}")
        if self.active_port == self.passive_port:
            raise _bad("passive_port", "must differ from active_port")
        for name in ("pressure_template", "uv_on_template", "uv_off_template"):
            check_line(f"machine profile key '{name}'", getattr(self, name))
        try:
            names = {f[1] for f in string.Formatter().parse(self.pressure_template) if f[1]}
            self.pressure_template.format(port=1, psi=1.0)
        except (ValueError, KeyError, IndexError, AttributeError) as err:
            raise _bad(
                "pressure_template",
                f"is not a valid template ({err}); write e.g. 'M800 P{{port}} Q{{psi:.3f}}'",
            ) from None
        if names != {"port", "psi"}:
            raise _bad("pressure_template", f"must use exactly {{port}} and {{psi}}; got {names}")
        for name in ("uv_on_template", "uv_off_template"):
            if any(f[1] is not None for f in string.Formatter().parse(getattr(self, name))):
                raise _bad(name, "takes no {fields}; write the line literally")

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

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> MachineProfile:
        """Profile from a mapping; ``max_rotation_deg_s`` (deg/s) may replace ``max_rotation``."""
        data = dict(data)
        if "max_rotation_deg_s" in data:
            if "max_rotation" in data:
                raise _bad("max_rotation", "give max_rotation (rad/s) or max_rotation_deg_s")
            deg = data.pop("max_rotation_deg_s")
            if isinstance(deg, bool) or not isinstance(deg, int | float):
                raise _bad("max_rotation_deg_s", f"must be a number (deg/s); got {deg!r}")
            data["max_rotation"] = math.radians(deg)
        known = {f.name for f in fields(cls)} - {"source"}
        unknown = sorted(set(data) - known)
        if unknown:
            raise _bad(unknown[0], f"unknown setting; known: {sorted(known)}")
        for k in ("envelope_min", "envelope_max"):
            if k in data:
                v = data[k]
                if not isinstance(v, list | tuple) or not all(
                    isinstance(c, int | float) and not isinstance(c, bool) for c in v
                ):
                    raise _bad(k, f"must be three numbers [x, y, z] (mm); got {v!r}")
                data[k] = tuple(v)
        for k, v in data.items():
            expect = (str,) if isinstance(getattr(cls, k, None), str) else (int, float)
            if isinstance(getattr(cls, k, None), tuple):
                continue
            if isinstance(v, bool) or not isinstance(v, expect):
                raise _bad(k, f"has the wrong type {type(v).__name__}; got {v!r}")
        return cls(**data)


def load_machine_profile(path: str | FilePath) -> MachineProfile:
    """Read a profile from a TOML file (a ``[machine]`` table or top-level keys).

    Raises
    ------
    InvalidParameterError
        Not UTF-8 (or UTF-16/32 with a BOM), not valid TOML, unknown keys, wrong types or
        values out of range (one line naming the key).
    """
    data = read_toml(path)
    table = data.get("machine", data)
    if not isinstance(table, dict):
        raise _bad("machine", f"must be a table [machine]; got {table!r}")
    profile = MachineProfile.from_dict(table)
    return replace(profile, source=check_line("machine profile path", FilePath(path).name))

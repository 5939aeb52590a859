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
from dataclasses import dataclass, fields
from pathlib import Path as FilePath
from typing import Any

from rotomorph.errors import InvalidParameterError

try:  # Python >= 3.11
    import tomllib
except ModuleNotFoundError:  # pragma: no cover - Python 3.10
    import tomli as tomllib  # type: ignore[no-redef]

__all__ = ["DIALECTS", "MachineProfile", "load_machine_profile"]

DIALECTS = ("aerotech", "rs274", "marlin")


def _bad(field: str, message: str) -> InvalidParameterError:
    return InvalidParameterError(f"MachineProfile.{field}", message)


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
    """

    name: str = "generic"
    dialect: str = "aerotech"
    envelope_min: tuple[float, float, float] = (0.0, 0.0, 0.0)
    envelope_max: tuple[float, float, float] = (300.0, 300.0, 100.0)
    max_feed: float = 50.0
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

    def __post_init__(self) -> None:
        if self.dialect not in DIALECTS:
            raise _bad("dialect", f"must be one of {DIALECTS}; got {self.dialect!r}")
        lo = tuple(float(v) for v in self.envelope_min)
        hi = tuple(float(v) for v in self.envelope_max)
        if len(lo) != 3 or len(hi) != 3 or not all(a < b for a, b in zip(lo, hi, strict=False)):
            raise _bad("envelope_max", f"must exceed envelope_min on x, y, z; got {lo} .. {hi}")
        object.__setattr__(self, "envelope_min", lo)
        object.__setattr__(self, "envelope_max", hi)
        for name in ("max_feed", "travel_feed", "max_rotation", "max_pressure", "lift"):
            v = getattr(self, name)
            if not (math.isfinite(v) and v > 0):
                raise _bad(name, f"must be a finite number > 0; got {v!r}")
        if not (0 <= self.min_pressure < self.max_pressure):
            raise _bad("min_pressure", f"must lie in [0, max_pressure); got {self.min_pressure}")
        letters = [self.x_axis, self.y_axis, self.z_axis, self.rotary_axis]
        if any(len(a) != 1 or not a.isalpha() or not a.isupper() for a in letters):
            raise _bad("rotary_axis", f"axis letters must be single capitals; got {letters}")
        if len(set(letters)) != 4 or set(letters) & {"F", "G", "M", "P", "Q", "S", "N"}:
            raise _bad(
                "rotary_axis", f"axis letters must be distinct, not F/G/M/N/P/Q/S; got {letters}"
            )
        if self.rotary_units not in ("deg", "rad"):
            raise _bad("rotary_units", f"must be 'deg' or 'rad'; got {self.rotary_units!r}")
        if self.rotary_sign not in (1, -1):
            raise _bad("rotary_sign", f"must be +1 or -1; got {self.rotary_sign}")
        if self.active_port == self.passive_port:
            raise _bad("passive_port", "must differ from active_port")
        names = {f[1] for f in string.Formatter().parse(self.pressure_template) if f[1]}
        if names != {"port", "psi"}:
            raise _bad("pressure_template", f"must use exactly {{port}} and {{psi}}; got {names}")

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
            data["max_rotation"] = math.radians(float(data.pop("max_rotation_deg_s")))
        known = {f.name for f in fields(cls)}
        unknown = sorted(set(data) - known)
        if unknown:
            raise _bad(unknown[0], f"unknown setting; known: {sorted(known)}")
        for k in ("envelope_min", "envelope_max"):
            if k in data:
                data[k] = tuple(data[k])
        return cls(**data)


def load_machine_profile(path: str | FilePath) -> MachineProfile:
    """Read a profile from a TOML file (a ``[machine]`` table or top-level keys)."""
    with open(path, "rb") as fh:
        data = tomllib.load(fh)
    return MachineProfile.from_dict(data.get("machine", data))

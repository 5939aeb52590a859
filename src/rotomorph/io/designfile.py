"""Design files: TOML (``schema_version = 1``) validated by pydantic v2 (DESIGN.md section 7).

A design holds filaments and/or one lattice::

    schema_version = 1
    name = "composite_rotation"

    [[filaments]]
    name = "w*=0.25"
    speed = 3.0                    # mm/s, default for every segment
    rotation_number = 0.25         # ω* = Rω/v  (or rotation = ω in rad/s, or active_side)
    start = [0.0, 0.0, 0.0]        # mm
    [[filaments.segments]]
    kind = "line"                  # line | arc | sinusoid | polyline
    length = 30.0                  # mm

    [lattice]
    n = 5
    spacing = 5.0                  # mm
    amplitude = 1.25               # mm
    pattern = "dome"               # expanding | contracting | dome | saddle | custom
    layers = 3

Per segment, ``speed`` (mm/s) overrides the filament's (piecewise-constant v(s)); the nozzle is
driven by at most one of ``rotation`` (ω, rad/s), ``rotation_number`` (ω*) or
``interface_angle_deg`` (α held constant, nozzle tracks the heading); a filament-level
``active_side = "outer" | "inner"`` keeps the active half on one side of the curvature
(notes Q6), with ``flip_length`` (mm) spreading each π flip. Angles in files are in degrees
(``*_deg``), everything else in mm, s, rad/s, psi.

Errors name the field path and the fix, e.g.
``filaments[0].segments[2].speed: must be > 0 mm/s; got -2``, raised as
:class:`~rotomorph.errors.InvalidDesignError`.
"""

from __future__ import annotations

import hashlib
import json
import math
from pathlib import Path as FilePath
from typing import TYPE_CHECKING, Annotated, Any, Final, Literal

import numpy as np
import tomli_w
from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator

from rotomorph.design.lattices import Lattice, sinusoidal_lattice
from rotomorph.design.path import Arc, Line, Path, Polyline, Sinusoid, chain_segments
from rotomorph.design.program import PrintProgram, active_side_angle
from rotomorph.errors import InvalidDesignError
from rotomorph.io.atomic import atomic_write_text

if TYPE_CHECKING:
    from pydantic_core import ErrorDetails

try:  # Python >= 3.11
    import tomllib
except ModuleNotFoundError:  # pragma: no cover - Python 3.10
    import tomli as tomllib  # type: ignore[no-redef]

__all__ = [
    "SCHEMA_VERSION",
    "Design",
    "design_schema",
    "load_design",
    "parse_design",
    "save_design",
]

SCHEMA_VERSION: Final = 1
_UNITS = {
    "speed": "mm/s",
    "length": "mm",
    "radius": "mm",
    "spacing": "mm",
    "amplitude": "mm",
    "wavelength": "mm",
    "layer_height": "mm",
    "diameter": "mm",
    "rotation": "rad/s",
    "active_pressure": "psi",
    "passive_pressure": "psi",
}
Speed = Annotated[float, Field(gt=0, allow_inf_nan=False, description="mm/s")]
Length = Annotated[float, Field(gt=0, allow_inf_nan=False, description="mm")]
Vec3 = tuple[float, float, float]


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)


class _Control(_Model):
    speed: Speed | None = None
    rotation: float | None = Field(None, description="nozzle rotation rate ω (rad/s)")
    rotation_number: float | None = Field(None, description="ω* = Rω/v (dimensionless)")
    interface_angle_deg: float | None = Field(None, description="α held constant (deg)")

    @model_validator(mode="after")
    def _one_control(self) -> _Control:
        given = [
            k
            for k in ("rotation", "rotation_number", "interface_angle_deg")
            if getattr(self, k) is not None
        ]
        if len(given) > 1:
            raise ValueError(
                f"give at most one of rotation, rotation_number, interface_angle_deg; got {given}"
            )
        return self


class LineSegment(_Control):
    kind: Literal["line"]
    length: Length


class ArcSegment(_Control):
    kind: Literal["arc"]
    radius: Length
    angle_deg: float = Field(description="turn (deg), > 0 counter-clockwise")

    @model_validator(mode="after")
    def _turns(self) -> ArcSegment:
        if self.angle_deg == 0:
            raise ValueError("angle_deg must be non-zero (deg)")
        return self


class SinusoidSegment(_Control):
    kind: Literal["sinusoid"]
    amplitude: Length
    wavelength: Length
    periods: float = Field(1.0, gt=0)


class PolylineSegment(_Control):
    kind: Literal["polyline"]
    points: list[Vec3] = Field(min_length=2, description="lab coordinates (mm)")


SegmentModel = Annotated[
    LineSegment | ArcSegment | SinusoidSegment | PolylineSegment, Field(discriminator="kind")
]


class Filament(_Control):
    """One filament: a chain of segments and how to print it."""

    name: str = ""
    speed: Speed = 3.0
    active_side: Literal["outer", "inner"] | None = None
    flip_length: float = Field(0.0, ge=0, description="mm over which active-side flips turn")
    start: Vec3 = (0.0, 0.0, 0.0)
    heading_deg: float = 0.0
    initial_nozzle_angle_deg: float = 0.0
    spacing: Length = 0.1
    radius: Length = 0.3
    active_fraction: float = Field(0.5, ge=0, le=1)
    active_material: str = Field("lce", min_length=1)
    passive_material: str = Field("acrylate", min_length=1)
    layer: int = Field(0, ge=0)
    segments: list[SegmentModel] = Field(min_length=1)

    @model_validator(mode="after")
    def _side_excludes_rotation(self) -> Filament:
        if self.active_side is not None:
            for i, seg in enumerate(self.segments):
                if (
                    seg.rotation is not None
                    or seg.rotation_number is not None
                    or (seg.interface_angle_deg is not None)
                ):
                    raise ValueError(
                        f"segments[{i}] sets the nozzle but active_side is set; remove one of them"
                    )
        return self

    def to_program(self) -> PrintProgram:
        """The :class:`PrintProgram` of this filament.

        The nozzle angle integrates ω/v over each move (``rotation``, ``rotation_number``) or
        follows :math:`\\alpha_n = \\psi_v - \\alpha` (``interface_angle_deg``,
        ``active_side``); a segment without a control uses the filament's, else ω = 0.
        """
        geo = [_geometry(s) for s in self.segments]
        pts, owner = chain_segments(
            geo, start=self.start, heading=math.radians(self.heading_deg), spacing=self.spacing
        )
        path = Path(pts)
        speed = np.array([self.segments[o].speed or self.speed for o in owner])
        kw: dict[str, Any] = dict(
            radius=self.radius,
            active_fraction=self.active_fraction,
            active_material=self.active_material,
            passive_material=self.passive_material,
            layer=self.layer,
        )
        if self.active_side is not None:
            alpha = active_side_angle(path, self.active_side, self.flip_length)
            return PrintProgram.from_interface_angle(path, speed, alpha, **kw)
        h = path.heading
        psi_v = np.concatenate([[h[0]], 0.5 * (h[1:] + h[:-1]), [h[-1]]])
        s = path.arc_length
        angle = np.empty(len(s))
        for i in range(len(s)):
            kind, value = self._control(self.segments[owner[max(i - 1, 0)]])
            if kind == "alpha":
                angle[i] = psi_v[i] - value
                if i > 0:  # the same interface, reached without a needless full turn
                    angle[i] += 2 * np.pi * np.round((angle[i - 1] - angle[i]) / (2 * np.pi))
            elif i == 0:
                angle[i] = math.radians(self.initial_nozzle_angle_deg)
            else:
                rate = value if kind == "rotation" else value * speed[i - 1] / self.radius
                angle[i] = angle[i - 1] + rate / speed[i - 1] * (s[i] - s[i - 1])
        return PrintProgram(path.points, speed, angle, **kw)

    def _control(self, seg: _Control) -> tuple[str, float]:
        """(kind, value) driving a segment: its own control, else the filament's, else ω = 0."""
        for src in (seg, self):
            if src.rotation is not None:
                return "rotation", float(src.rotation)
            if src.rotation_number is not None:
                return "number", float(src.rotation_number)
            if src.interface_angle_deg is not None:
                return "alpha", math.radians(src.interface_angle_deg)
        return "rotation", 0.0


def _geometry(seg: Any) -> Any:
    if seg.kind == "line":
        return Line(seg.length)
    if seg.kind == "arc":
        return Arc(seg.radius, math.radians(seg.angle_deg))
    if seg.kind == "sinusoid":
        return Sinusoid(seg.amplitude, seg.wavelength, seg.periods)
    return Polyline(np.array(seg.points))


class LatticeModel(_Model):
    """The paper's sinusoidal lattice (:func:`rotomorph.design.lattices.sinusoidal_lattice`)."""

    n: int = Field(5, ge=2)
    spacing: Length = 5.0
    amplitude: float = Field(1.25, ge=0, description="mm")
    ghost_nodes: int = Field(10, ge=1)
    pattern: Literal["expanding", "contracting", "dome", "saddle", "custom"] = "expanding"
    edge_modes: list[Literal["expanding", "contracting"]] | None = None
    centre: Literal["central_cells", "interior"] = "central_cells"
    layers: int = Field(3, ge=1)
    layer_height: Length = 0.6
    speed: Speed = 3.0
    radius: Length = 0.3
    active_fraction: float = Field(0.5, ge=0, le=1)
    active_material: str = Field("lce", min_length=1)
    passive_material: str = Field("acrylate", min_length=1)
    origin: Vec3 = (0.0, 0.0, 0.0)

    @model_validator(mode="after")
    def _custom(self) -> LatticeModel:
        m = 2 * self.n * (self.n - 1)
        if self.pattern == "custom" and (self.edge_modes is None or len(self.edge_modes) != m):
            raise ValueError(f"pattern 'custom' needs edge_modes with one mode per edge ({m})")
        if self.pattern != "custom" and self.edge_modes is not None:
            raise ValueError("edge_modes is only used with pattern = 'custom'")
        return self

    def to_lattice(self) -> Lattice:
        """The :class:`Lattice` (network at the origin; programs moved by ``origin``)."""
        return sinusoidal_lattice(
            self.n,
            self.spacing,
            self.amplitude,
            self.ghost_nodes,
            self.edge_modes if self.pattern == "custom" else self.pattern,  # type: ignore[arg-type]
            centre=self.centre,
            layers=self.layers,
            layer_height=self.layer_height,
            speed=self.speed,
            radius=self.radius,
            active_fraction=self.active_fraction,
            active_material=self.active_material,
            passive_material=self.passive_material,
        )


class Nozzle(_Model):
    """Nozzle and pressure set-points used when writing G-code."""

    diameter: Length = 1.0
    active_pressure: float = Field(30.0, ge=0, description="psi")
    passive_pressure: float = Field(30.0, ge=0, description="psi")


class Design(_Model):
    """A validated design file (filaments and/or a lattice)."""

    schema_version: Literal[1] = SCHEMA_VERSION
    name: str = ""
    description: str = ""
    nozzle: Nozzle = Nozzle()
    filaments: list[Filament] = Field(default_factory=list)
    lattice: LatticeModel | None = None

    @model_validator(mode="after")
    def _not_empty(self) -> Design:
        if not self.filaments and self.lattice is None:
            raise ValueError("a design needs [[filaments]] or a [lattice]")
        return self

    def to_programs(self) -> list[PrintProgram]:
        """Print programs: the filaments, then the lattice lines layer by layer, sorted by layer."""
        progs = [f.to_program() for f in self.filaments]
        if self.lattice is not None:
            progs += [
                p.translated(self.lattice.origin)
                for p in self.lattice.to_lattice().print_programs()
            ]
        return sorted(progs, key=lambda p: p.layer)

    def gcode_options(self) -> dict[str, Any]:
        """Keyword arguments for :func:`rotomorph.io.gcode.write_gcode` (pressures, hash)."""
        pressure = (self.nozzle.active_pressure, self.nozzle.passive_pressure)
        return {"pressures": pressure, "design_hash": self.sha256()}

    def sha256(self) -> str:
        """sha256 (hex) of the canonical JSON of the design."""
        blob = json.dumps(self.model_dump(mode="json"), sort_keys=True, separators=(",", ":"))
        return hashlib.sha256(blob.encode()).hexdigest()


def _format_error(err: ErrorDetails) -> tuple[str, str]:
    loc: list[str] = []
    for part in err["loc"]:
        if isinstance(part, int):
            loc.append(f"[{part}]")
        elif part in ("line", "arc", "sinusoid", "polyline") and loc and loc[-1].startswith("["):
            continue  # discriminator tag of a segment
        else:
            loc.append(("." if loc else "") + str(part))
    field = "".join(loc) or "<design>"
    unit = _UNITS.get(str(err["loc"][-1]) if err["loc"] else "", "")
    ctx, kind, got = err.get("ctx", {}), err["type"], err.get("input")
    if kind in ("greater_than", "greater_than_equal", "less_than_equal", "less_than"):
        op = {
            "greater_than": ">",
            "greater_than_equal": ">=",
            "less_than_equal": "<=",
            "less_than": "<",
        }[kind]
        bound = next(iter(ctx.values()))
        bound = int(bound) if float(bound).is_integer() else bound
        msg = f"must be {op} {bound}{' ' + unit if unit else ''}; got {got!r}"
    elif kind == "extra_forbidden":
        msg = "unknown key; remove it or check its spelling (see design_schema())"
    elif kind == "missing":
        msg = "is required"
    else:
        msg = err["msg"].removeprefix("Value error, ") + (
            f"; got {got!r}" if kind != "value_error" and not isinstance(got, dict) else ""
        )
    return field, msg


def parse_design(data: dict[str, Any]) -> Design:
    """Validate a mapping (a parsed TOML document) into a :class:`Design`."""
    if "schema_version" not in data:
        raise InvalidDesignError(
            "schema_version", f"is required; add schema_version = {SCHEMA_VERSION}"
        )
    try:
        return Design.model_validate(data)
    except ValidationError as exc:
        errors = [_format_error(e) for e in exc.errors()]
        field, msg = errors[0]
        more = (
            "" if len(errors) == 1 else "; also " + "; ".join(f"{f}: {m}" for f, m in errors[1:4])
        )
        raise InvalidDesignError(field, msg + more) from None


def load_design(path: str | FilePath) -> Design:
    """Read and validate a TOML design file.

    Raises
    ------
    InvalidDesignError
        TOML syntax errors (``<file>``) and schema violations (field path and fix).
    """
    try:
        with open(path, "rb") as fh:
            data = tomllib.load(fh)
    except tomllib.TOMLDecodeError as exc:
        raise InvalidDesignError(str(path), f"is not valid TOML: {exc}") from None
    return parse_design(data)


def save_design(design: Design, path: str | FilePath) -> FilePath:
    """Write ``design`` as TOML to ``path`` atomically (temp file + os.replace)."""
    data = design.model_dump(mode="json", exclude_none=True)
    return atomic_write_text(path, tomli_w.dumps(data))


def design_schema() -> dict[str, Any]:
    """JSON Schema of the design file format (for editors and documentation)."""
    schema = Design.model_json_schema()
    schema["$id"] = f"https://rotomorph.invalid/design-schema-v{SCHEMA_VERSION}.json"
    return schema

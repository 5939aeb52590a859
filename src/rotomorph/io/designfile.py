"""Design files: TOML (``schema_version = 1``) validated by pydantic v2.

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
, with ``flip_length`` (mm) spreading each π flip. Angles in files are in degrees
(``*_deg``), everything else in mm, s, rad/s, psi. Process settings for G-code
(``active_pressure``, ``passive_pressure`` in psi, ``prime_dwell``, ``release_dwell`` in s) sit
in ``[nozzle]`` and may be overridden per filament or for the lattice (``docs/gcode.md``).

Errors name the field path and the fix, e.g.
``filaments[0].segments[2].speed: must be > 0 mm/s; got -2``, raised as
:class:`~rotomorph.errors.InvalidDesignError` (the CLI exits with status 2). Types are strict:
``speed = "3"`` or ``speed = true`` is an error, not a number; every numeric field has a
physical range (:data:`rotomorph.io.design_limits.LIMITS`), and the design's size in rod nodes
is estimated before anything is built and refused above
:data:`~rotomorph.io.design_limits.MAX_NODES`. ``validate``, ``simulate`` and ``gcode`` all go
through :func:`load_design`, so they accept exactly the same files. Every field, unit, range and
error is listed in ``docs/design-files.md``.
"""

from __future__ import annotations

import hashlib
import itertools
import json
import math
import re
from pathlib import Path as FilePath
from typing import TYPE_CHECKING, Annotated, Any, Final, Literal

import numpy as np
import tomli_w
from pydantic import (
    AfterValidator,
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    PrivateAttr,
    ValidationError,
    ValidationInfo,
    field_validator,
    model_serializer,
    model_validator,
)

from rotomorph._text import check_text, terminal_safe
from rotomorph.design.lattices import Lattice, sinusoidal_lattice
from rotomorph.design.path import (
    Arc,
    Line,
    Path,
    Polyline,
    Sinusoid,
    chain_segments,
    path_defect,
    tangent_headings,
)
from rotomorph.design.program import PrintProgram, active_side_angle
from rotomorph.errors import InvalidDesignError, MaterialError
from rotomorph.io.atomic import atomic_write_text
from rotomorph.io.design_limits import (
    FILAMENT_PER_NOZZLE,
    LIMITS,
    MAX_NODES,
    SizeEstimate,
    lattice_nodes,
    nozzle_for,
    segment_edges,
    sinusoid_length,
)
from rotomorph.io.gcode import Process
from rotomorph.io.materials_file import resolve_materials
from rotomorph.io.tomlfile import decode_toml_bytes, read_toml
from rotomorph.materials.material import get_material, known_materials
from rotomorph.materials.parameter_set import MaterialSet

if TYPE_CHECKING:
    from pydantic_core import ErrorDetails

__all__ = [
    "SCHEMA_VERSION",
    "ContactModel",
    "Design",
    "FreeText",
    "Label",
    "as_vector3",
    "design_schema",
    "design_size",
    "load_design",
    "parse_design",
    "parse_design_bytes",
    "save_design",
    "schema_error",
    "with_spacing",
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
    "start": "mm",
    "origin": "mm",
    "points": "mm",
    "flip_length": "mm",
    "interface_angle_deg": "deg",
    "angle_deg": "deg",
    "heading_deg": "deg",
    "initial_nozzle_angle_deg": "deg",
    "active_pressure": "psi",
    "passive_pressure": "psi",
}


def _ranged(kind: str, default: Any = ..., description: str = "", **kw: Any) -> Any:
    """A pydantic Field bounded by ``LIMITS[kind]`` (unit in the description)."""
    lim = LIMITS[kind]
    lo = {"gt": lim.minimum} if lim.exclusive_min else {"ge": lim.minimum}
    desc = f"{description} ({lim.unit})" if lim.unit and description else description or lim.unit
    return Field(default, le=lim.maximum, description=desc or None, **lo, **kw)  # type: ignore[call-overload]


def as_vector3(value: Any) -> Any:
    """TOML arrays are lists; a 3-vector field takes a list of exactly three numbers."""
    if isinstance(value, list | tuple):
        if len(value) != 3:
            raise ValueError(f"must be an array of 3 numbers [x, y, z] (mm); got {list(value)!r}")
        return tuple(value)
    return value


#: A label (design or filament name): one line, no control or bidirectional characters.
Label = Annotated[str, Field(max_length=200), AfterValidator(check_text)]
#: Free text: may span lines, no other control or bidirectional characters.
FreeText = Annotated[
    str, Field(max_length=10_000), AfterValidator(lambda text: check_text(text, newlines=True))
]
Speed = Annotated[float, _ranged("speed", description="print speed")]
Length = Annotated[float, _ranged("extent", description="length")]
Coordinate = Annotated[float, _ranged("coordinate")]
Vec3 = Annotated[tuple[Coordinate, Coordinate, Coordinate], BeforeValidator(as_vector3)]


class _Model(BaseModel):
    # strict: no bool/str -> number coercion (an int is still a valid float)
    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False, strict=True)


def _check_material(name: str, kind: str, info: ValidationInfo | None = None) -> str:
    """``name`` if it is a material of ``kind`` ("active" or "passive"): an ink of the design's
    materials file (validation context ``materials``) or, without one, a registered material."""
    inks = (info.context or {}).get("materials") if info is not None else None
    try:
        mat = get_material(name) if inks is None else inks.material(name)
    except MaterialError:
        known = known_materials() if inks is None else inks.names()
        where = "" if inks is None else f" in materials {inks.name!r}"
        raise ValueError(
            f"unknown material {name!r}{where}; use one of {', '.join(known)}"
        ) from None
    if mat.kind != kind:
        raise ValueError(f"{name!r} is {_article(mat.kind)} material; give {_article(kind)} one")
    return name


def _article(word: str) -> str:
    """``word`` with its indefinite article ("an active", "a passive")."""
    return f"{'an' if word[:1] in tuple('aeiou') else 'a'} {word}"


ActiveMaterial = Annotated[
    str,
    Field(min_length=1, max_length=100),
    AfterValidator(lambda name, info: _check_material(name, "active", info)),
]
PassiveMaterial = Annotated[
    str,
    Field(min_length=1, max_length=100),
    AfterValidator(lambda name, info: _check_material(name, "passive", info)),
]


_ACTIVE: Final = "active ink: a name in the design's materials file (default: the paper's inks)"
_PASSIVE: Final = "passive ink: a name in the design's materials file (default: the paper's inks)"


class _Control(_Model):
    speed: Speed | None = None
    rotation: float | None = _ranged("rotation", None, "nozzle rotation rate ω")
    rotation_number: float | None = _ranged("rotation_number", None, "ω* = Rω/v, dimensionless")
    interface_angle_deg: float | None = _ranged("angle_deg", None, "α held constant")

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
    angle_deg: float = _ranged("arc_angle_deg", ..., "turn, > 0 counter-clockwise")

    @model_validator(mode="after")
    def _turns(self) -> ArcSegment:
        if self.angle_deg == 0:
            raise ValueError("angle_deg must be non-zero (deg)")
        return self


class SinusoidSegment(_Control):
    kind: Literal["sinusoid"]
    amplitude: Length
    wavelength: Length
    periods: float = _ranged("periods", 1.0, "number of periods")


class PolylineSegment(_Control):
    kind: Literal["polyline"]
    points: list[Vec3] = Field(
        min_length=2, max_length=MAX_NODES, description="lab coordinates (mm)"
    )
    resample: bool = Field(
        True,
        description="split edges longer than the filament's spacing (false: vertices as given)",
    )


SegmentModel = Annotated[
    LineSegment | ArcSegment | SinusoidSegment | PolylineSegment, Field(discriminator="kind")
]


class _Process(_Model):
    """Per-filament process settings (unset: the ``[nozzle]`` table's)."""

    active_pressure: float | None = _ranged("pressure", None, "active channel pressure")
    passive_pressure: float | None = _ranged("pressure", None, "passive channel pressure")
    prime_dwell: float | None = Field(None, ge=0, le=3600, description="s after pressure-on")
    release_dwell: float | None = Field(None, ge=0, le=3600, description="s after pressure-off")

    def process(self, nozzle: Nozzle, program: PrintProgram) -> Process:
        """The :class:`~rotomorph.io.gcode.Process` of ``program``, printed by this filament
        or lattice: its own pressures and dwells, else the nozzle's flow model (if the nozzle
        gives conductances), else the nozzle's pressures and dwells."""
        dwells = {
            k: getattr(nozzle, k) if getattr(self, k) is None else getattr(self, k)
            for k in ("prime_dwell", "release_dwell")
        }
        base = Process(nozzle.active_pressure, nozzle.passive_pressure, **dwells)
        if nozzle.active_conductance is not None or nozzle.passive_conductance is not None:
            base = Process.from_flow(
                program,
                active_conductance=nozzle.active_conductance,
                passive_conductance=nozzle.passive_conductance,
                **dwells,
            )
        flow = nozzle.active_conductance is not None or nozzle.passive_conductance is not None
        unset = [  # defaults nobody set: flagged in the program's header and by `gcode`
            k
            for k in ("active_pressure", "passive_pressure", "prime_dwell", "release_dwell")
            if getattr(self, k) is None
            and k not in nozzle.model_fields_set
            and not (flow and k.endswith("_pressure"))
        ]
        return Process(
            base.active_pressure if self.active_pressure is None else self.active_pressure,
            base.passive_pressure if self.passive_pressure is None else self.passive_pressure,
            **dwells,
            placeholders=tuple(unset),
        )


class Filament(_Control, _Process):
    """One filament: a chain of segments and how to print it."""

    name: Label = Field("", description="label in results and figures")
    speed: Speed = 3.0
    active_side: Literal["outer", "inner"] | None = Field(
        None, description="keep the active half on this side of the curvature"
    )
    flip_length: float = Field(
        0.0, ge=0, le=LIMITS["extent"].maximum, description="mm over which active-side flips turn"
    )
    start: Vec3 = Field((0.0, 0.0, 0.0), description="first vertex (mm)")
    heading_deg: float = _ranged("angle_deg", 0.0, "initial heading")
    initial_nozzle_angle_deg: float = _ranged("angle_deg", 0.0, "initial nozzle angle")
    spacing: float = _ranged("vertex_spacing", 0.1, "rod vertex spacing")
    radius: float = _ranged("filament_radius", 0.3, "filament radius R")
    active_fraction: float = Field(0.5, gt=0, le=1, description="active share of the section")
    active_material: ActiveMaterial = Field("lce", description=_ACTIVE, validate_default=True)
    passive_material: PassiveMaterial = Field(
        "acrylate", description=_PASSIVE, validate_default=True
    )
    layer: int = _ranged("layer", 0, "printed layer")
    segments: list[SegmentModel] = Field(
        min_length=1, max_length=MAX_NODES, description="the path, segment by segment"
    )

    @model_validator(mode="after")
    def _rotation_rate(self) -> Filament:
        """ω = ω*·v/R must stay within the rotation range too (a tiny R makes ω* absurd)."""
        top = LIMITS["rotation"].maximum
        for i, seg in enumerate(self.segments):
            number = seg.rotation_number
            if number is None and seg.rotation is None and seg.interface_angle_deg is None:
                number = self.rotation_number
            rate = abs(number or 0.0) * (seg.speed or self.speed) / self.radius
            if rate > top:
                raise ValueError(
                    f"segments[{i}]: rotation_number gives ω = ω*·v/R = {rate:.4g} rad/s, above "
                    f"{top:g} rad/s; lower rotation_number or speed, or increase radius"
                )
        return self

    @model_validator(mode="after")
    def _size(self) -> Filament:
        nodes = self.node_count()
        if nodes < 3:
            raise ValueError(
                f"has {nodes} vertices at spacing {self.spacing} mm; a filament needs >= 3: "
                "make it longer or reduce spacing"
            )
        refusal = SizeEstimate(nodes).refusal()
        if refusal:
            raise ValueError(f"{refusal}; increase spacing or shorten the filament")
        return self

    def node_count(self) -> int:
        """Rod vertices of this filament at its ``spacing`` (computed without building it)."""
        edges = 0
        for seg in self.segments:
            if seg.kind == "polyline":
                if not seg.resample:
                    edges += len(seg.points) - 1
                    continue
                edges += sum(
                    segment_edges(math.dist(a, b), self.spacing)
                    for a, b in itertools.pairwise(seg.points)
                )
                continue
            if seg.kind == "line":
                length = seg.length
            elif seg.kind == "arc":
                length = seg.radius * math.radians(abs(seg.angle_deg))
            else:
                length = sinusoid_length(seg.amplitude, seg.wavelength, seg.periods)
            edges += segment_edges(length, self.spacing)
        return edges + 1

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

    @model_validator(mode="after")
    def _printable_path(self) -> Filament:
        for i, seg in enumerate(self.segments):  # turns tighter than the filament's own radius
            bend = _bend_radius(seg)
            if bend is not None and bend < self.radius:
                raise ValueError(f"segments[{i}]: {_too_tight(seg, bend, self.radius)}")
        # after _size: the path is built only for a design of a size that is accepted
        try:
            pts, owner = self._points()
        except InvalidDesignError as err:  # e.g. a polyline that does not start at the end
            raise ValueError(str(err)) from None
        defect = path_defect(pts)
        if defect is not None:
            i, why = defect
            raise ValueError(f"segments[{int(owner[i])}]: {why}")  # the edge leaving vertex i
        return self

    def _points(self) -> tuple[Any, Any]:
        """Vertices ``(N, 3)`` (mm) of the chained segments and each vertex's segment."""
        geo = [_geometry(s) for s in self.segments]
        return chain_segments(
            geo, start=self.start, heading=math.radians(self.heading_deg), spacing=self.spacing
        )

    def to_program(self) -> PrintProgram:
        """The :class:`PrintProgram` of this filament.

        The nozzle angle integrates ω/v over each move (``rotation``, ``rotation_number``) or
        follows :math:`\\alpha_n = \\psi_v - \\alpha` (``interface_angle_deg``,
        ``active_side``) with :math:`\\psi_v` the designed curve's tangent
        (:func:`~rotomorph.design.path.tangent_headings`: exact at the ends of arcs, which a
        program with arcs carries as ``tangent_heading``); a segment without a control uses
        the filament's, else ω = 0.
        """
        pts, owner = self._points()
        path = Path(pts)
        speed = np.array([self.segments[o].speed or self.speed for o in owner])
        geo = [_geometry(seg) for seg in self.segments]
        # the tangent of the designed curve (exact at the ends of arcs, where a chord lags it)
        psi_v = tangent_headings(geo, pts, owner, heading=math.radians(self.heading_deg))
        kw: dict[str, Any] = dict(
            radius=self.radius,
            active_fraction=self.active_fraction,
            active_material=self.active_material,
            passive_material=self.passive_material,
            layer=self.layer,
        )
        if any(seg.kind == "arc" for seg in self.segments):
            kw["tangent_heading"] = psi_v
        if self.active_side is not None:
            alpha = active_side_angle(path, self.active_side, self.flip_length)
            kw["step_flips"] = self.flip_length == 0  # ideal flips: steps in the natural field
            return PrintProgram.from_interface_angle(path, speed, alpha, **kw)
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


def _bend_radius(seg: Any) -> float | None:
    """Smallest radius of curvature (mm) of an arc or sinusoid segment's centre line."""
    if seg.kind == "arc":
        return float(seg.radius)
    if seg.kind == "sinusoid":  # at the crests of A sin(2 pi x / lambda): lambda^2/(4 pi^2 A)
        return float(seg.wavelength**2 / (4 * math.pi**2 * seg.amplitude))
    return None


def _too_tight(seg: Any, bend: float, radius: float) -> str:
    """Why a segment bending at radius ``bend`` (mm) cannot be printed with filament ``radius``."""
    overlap = "its inner side would overlap itself"
    if seg.kind == "arc":
        return (
            f"an arc of radius {bend:.4g} mm is tighter than the filament radius {radius:g} mm: "
            f"{overlap}; use radius >= {radius:g} mm"
        )
    most = seg.wavelength**2 / (4 * math.pi**2 * radius)
    return (
        f"the sinusoid's crests bend at radius wavelength^2/(4 pi^2 amplitude) = {bend:.3g} mm, "
        f"below the filament radius {radius:g} mm: {overlap}; use amplitude <= {most:.3g} mm "
        "or a longer wavelength"
    )


def _geometry(seg: Any) -> Any:
    if seg.kind == "line":
        return Line(seg.length)
    if seg.kind == "arc":
        return Arc(seg.radius, math.radians(seg.angle_deg))
    if seg.kind == "sinusoid":
        return Sinusoid(seg.amplitude, seg.wavelength, seg.periods)
    return Polyline(np.array(seg.points), resample=seg.resample)


class LatticeModel(_Process):
    """The paper's sinusoidal lattice (:func:`rotomorph.design.lattices.sinusoidal_lattice`)."""

    n: int = _ranged("lattice_n", 5, "branch nodes per side")
    spacing: float = _ranged("extent", 5.0, "branch-node spacing l")
    amplitude: float = Field(
        1.25, ge=0, le=LIMITS["extent"].maximum, description="sine amplitude A (mm)"
    )
    ghost_nodes: int = _ranged("ghost_nodes", 10, "rod nodes inside each edge")
    pattern: Literal["expanding", "contracting", "dome", "saddle", "custom"] = Field(
        "expanding", description="edge modes: all, or centre vs rest (dome/saddle), or custom"
    )
    edge_modes: list[Literal["expanding", "contracting"]] | None = Field(
        None, description="one mode per lattice edge, 2n(n-1) of them (pattern = custom)"
    )
    centre: Literal["central_cells", "interior"] = Field(
        "central_cells", description="which edges count as central for dome/saddle"
    )
    layers: int = _ranged("layers", 3, "printed layers")
    layer_height: float = _ranged(
        "layer_height", 0.6, "layer height, at most 2 x radius when layers > 1 (layers touch)"
    )
    speed: Speed = 3.0
    edge_speeds: list[Speed] | None = Field(
        None, description="one print speed per lattice edge, 2n(n-1) of them (mm/s)"
    )
    radius: float = _ranged("filament_radius", 0.3, "filament radius R")
    active_fraction: float = Field(0.5, gt=0, le=1, description="active share of the section")
    active_material: ActiveMaterial = Field("lce", description=_ACTIVE, validate_default=True)
    passive_material: PassiveMaterial = Field(
        "acrylate", description=_PASSIVE, validate_default=True
    )
    origin: Vec3 = Field(
        (20.0, 20.0, 0.0),
        description="where the lattice's first branch node is printed (mm); the default keeps "
        "the lattice 20 mm inside the machine's corner, within every example machine",
    )
    flip_length: float = Field(
        0.0,
        ge=0,
        le=LIMITS["extent"].maximum,
        description="arc length (mm) of each pi flip of the active side (0: a step)",
    )

    @model_validator(mode="after")
    def _crests_printable(self) -> LatticeModel:
        if self.amplitude > 0:
            bend = self.spacing**2 / (4 * math.pi**2 * self.amplitude)
            if bend < self.radius:
                most = self.spacing**2 / (4 * math.pi**2 * self.radius)
                raise ValueError(
                    f"the edges' crests bend at radius spacing^2/(4 pi^2 amplitude) = {bend:.3g} "
                    f"mm, below the filament radius {self.radius:g} mm: their inner side would "
                    f"overlap itself; use amplitude <= {most:.3g} mm or a larger spacing"
                )
        return self

    @model_validator(mode="after")
    def _layers_touch(self) -> LatticeModel:
        if self.layers > 1 and self.layer_height > 2.0 * self.radius * (1.0 + 1e-9):
            raise ValueError(
                f"layers {self.layer_height:g} mm apart do not touch (filament diameter "
                f"{2.0 * self.radius:g} mm): a printed stack needs layer_height <= "
                f"{2.0 * self.radius:g} mm (2 x radius)"
            )
        return self

    @model_validator(mode="after")
    def _size(self) -> LatticeModel:
        refusal = SizeEstimate(self.node_count()).refusal()
        if refusal:
            raise ValueError(
                f"{refusal} (n = {self.n}, ghost_nodes = {self.ghost_nodes}); reduce n or "
                "ghost_nodes"
            )
        return self

    def node_count(self) -> int:
        """Rod nodes of the lattice (computed without building it)."""
        return lattice_nodes(self.n, self.ghost_nodes)

    @model_validator(mode="after")
    def _custom(self) -> LatticeModel:
        m = 2 * self.n * (self.n - 1)
        if self.pattern == "custom" and (self.edge_modes is None or len(self.edge_modes) != m):
            raise ValueError(f"pattern 'custom' needs edge_modes with one mode per edge ({m})")
        if self.pattern != "custom" and self.edge_modes is not None:
            raise ValueError("edge_modes is only used with pattern = 'custom'")
        if self.edge_speeds is not None and len(self.edge_speeds) != m:
            raise ValueError(
                f"edge_speeds needs one speed per lattice edge ({m}); got {len(self.edge_speeds)}"
            )
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
            flip_length=self.flip_length,
            edge_speeds=self.edge_speeds,
        )


class Nozzle(_Model):
    """Nozzle and pressure set-points used when writing G-code."""

    diameter: float = _ranged("nozzle_diameter", 1.0, "nozzle diameter")
    active_pressure: float = _ranged("pressure", 30.0, "active channel pressure")
    passive_pressure: float = _ranged("pressure", 30.0, "passive channel pressure")
    prime_dwell: float = Field(0.0, ge=0, le=3600, description="s after pressure-on")
    release_dwell: float = Field(0.0, ge=0, le=3600, description="s after pressure-off")
    active_conductance: float | None = Field(
        None, gt=0, le=1e6, description="flow model: mm^3/s per psi of the active channel"
    )
    passive_conductance: float | None = Field(
        None, gt=0, le=1e6, description="flow model: mm^3/s per psi of the passive channel"
    )


class ContactModel(_Model):
    """How the heated structure touches itself and its surroundings.

    Absent from a design: no contact model (a state whose filaments pass through each other is
    computed, then flagged as not physical). Present: filaments touch instead of passing through
    each other (:mod:`rotomorph.contact`), optionally resting on the bath floor under their
    buoyant weight.
    """

    self_contact: bool = Field(
        True, description="filaments touch instead of passing through each other"
    )
    floor: bool = Field(
        False, description="a rigid floor (the bath bottom) just below the printed structure"
    )
    gravity: bool = Field(
        False, description="buoyant self-weight in the bath; needs floor = true (free structures)"
    )
    bath: Literal["silicone_oil"] = Field(
        "silicone_oil", description="bath fluid of the buoyancy (materials bath table)"
    )
    friction: float = Field(
        0.0, ge=0, le=10, description="Coulomb friction coefficient of every contact"
    )
    branch: Literal["lowest", "continuous"] = Field(
        "lowest",
        description="lattices resting on the floor under their weight: 'lowest' takes a lifted "
        "equilibrium where one is lower in energy, 'continuous' follows the resting state",
    )
    path_check: int = Field(
        1,
        ge=1,
        le=8,
        description="lattices: also ramp with every step split into this many sub-steps and "
        "keep the end state lower in total energy where the two differ (1: no check; "
        "frictionless only)",
    )

    @model_validator(mode="after")
    def _weight_needs_support(self) -> ContactModel:
        if self.gravity and not self.floor:
            raise ValueError(
                "gravity = true needs floor = true: a free structure under its weight must rest "
                "on the bath floor"
            )
        if not (self.self_contact or self.floor):
            raise ValueError(
                "nothing to touch: set self_contact = true or floor = true, or remove [contact]"
            )
        if self.path_check > 1 and self.friction > 0:
            raise ValueError(
                "path_check compares the energies of two ramps, which friction (dissipation) "
                "does not allow: set path_check = 1 or friction = 0"
            )
        return self


class Design(_Model):
    """A validated design file (filaments and/or a lattice)."""

    schema_version: Literal[1] = Field(SCHEMA_VERSION, description="format version; write 1")
    name: Label = Field("", description="label stored with results and G-code")
    description: FreeText = Field("", description="free text (newlines allowed)")
    nozzle: Nozzle = Field(Nozzle(), description="nozzle and pressures for G-code")
    filaments: list[Filament] = Field(
        default_factory=list, max_length=10_000, description="filaments (or a lattice, not both)"
    )
    lattice: LatticeModel | None = Field(None, description="one sinusoidal lattice")
    contact: ContactModel | None = Field(
        None, description="contact, floor and buoyant weight when heated (absent: none)"
    )
    materials: str | dict[str, Any] | None = Field(
        None,
        description="materials file of the inks (TOML, path relative to the design; or an "
        "inline table); absent: the paper's inks",
    )
    _material_set: MaterialSet | None = PrivateAttr(default=None)

    @model_serializer(mode="wrap")
    def _without_default_materials(self, handler: Any) -> Any:
        """Designs without a materials file dump (and hash) as before the key existed."""
        data = handler(self)
        if isinstance(data, dict) and data.get("materials") is None:
            data.pop("materials", None)
        return data

    @property
    def material_set(self) -> MaterialSet | None:
        """The materials file the design names (``None``: the paper's inks, the registry)."""
        return self._material_set

    @field_validator("schema_version", mode="before")
    @classmethod
    def _version_is_int(cls, value: Any) -> Any:
        if isinstance(value, bool):  # True == 1 in Python; not a version number
            raise ValueError(f"must be {SCHEMA_VERSION}; got {value!r}")
        return value

    @model_validator(mode="after")
    def _one_kind(self) -> Design:
        if not self.filaments and self.lattice is None:
            raise ValueError("a design needs [[filaments]] or a [lattice]")
        if self.filaments and self.lattice is not None:
            raise ValueError(
                "a design holds [[filaments]] or one [lattice], not both; split it into two files"
            )
        if self.filaments and self.contact is not None and self.contact.path_check != 1:
            raise ValueError(
                "contact.path_check applies to lattices; remove it from a filament design"
            )
        if (
            self.filaments
            and self.contact is not None
            and "branch" in self.contact.model_fields_set
        ):
            raise ValueError(
                "contact.branch applies to lattices resting on the floor; remove it from a "
                "filament design"
            )
        refusal = design_size(self).refusal()
        if refusal:
            raise ValueError(f"{refusal} over all filaments; split the design or increase spacing")
        return self

    @model_validator(mode="after")
    def _nozzle_fits(self) -> Design:
        """The printed diameter 2R must come out of the nozzle: within
        :data:`~rotomorph.io.design_limits.FILAMENT_PER_NOZZLE` nozzle diameters."""
        lo, hi = FILAMENT_PER_NOZZLE
        d = self.nozzle.diameter
        owners = [(f"filaments[{i}].radius", f.radius) for i, f in enumerate(self.filaments)]
        if self.lattice is not None:
            owners.append(("lattice.radius", self.lattice.radius))
        for where, radius in owners:
            if not lo * d <= 2 * radius <= hi * d:
                raise ValueError(
                    f"{where} = {radius:g} mm is a {2 * radius:g} mm filament, which a "
                    f"{d:g} mm nozzle cannot print: the filament diameter must lie within "
                    f"{lo:g}-{hi:g} nozzle diameters ({lo * d:g}-{hi * d:g} mm; the paper's 1 mm "
                    f"nozzle prints 0.6 mm filaments); set nozzle.diameter = "
                    f"{nozzle_for(radius):g} or change the radius"
                )
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

    def program_names(self) -> list[str]:
        """A label per program of :meth:`to_programs`, in its order: each filament's name (or
        ``filament i``), a lattice's ``x-line j`` / ``y-line i`` with the layer."""
        named = [(f.layer, f.name or f"filament {i}") for i, f in enumerate(self.filaments)]
        if self.lattice is not None:
            n = self.lattice.n
            lines = [f"x-line {j}" for j in range(n)] + [f"y-line {i}" for i in range(n)]
            named += [
                (k, f"{line}, layer {k}") for k in range(self.lattice.layers) for line in lines
            ]
        named.sort(key=lambda pair: pair[0])  # stable, as to_programs
        return [name for _, name in named]

    def gcode_options(self) -> dict[str, Any]:
        """Keyword arguments for :func:`rotomorph.io.gcode.write_gcode` (process, hash, and
        the materials file when the design names one).

        One :class:`~rotomorph.io.gcode.Process` per program of :meth:`to_programs`, in the
        same order: each filament's or the lattice's pressures and dwells, else the nozzle's
        flow model (``active_conductance``, ``passive_conductance``), else its pressures.
        """
        owners: list[tuple[_Process, PrintProgram]] = [(f, f.to_program()) for f in self.filaments]
        if self.lattice is not None:
            lattice = self.lattice
            owners += [(lattice, p) for p in lattice.to_lattice().print_programs()]
        owners.sort(key=lambda pair: pair[1].layer)  # stable, as to_programs
        process = [owner.process(self.nozzle, prog) for owner, prog in owners]
        options: dict[str, Any] = {"process": process, "design_hash": self.sha256()}
        if self._material_set is not None:  # its inks, and its name and hash in the header
            options["materials"] = self._material_set
        return options

    def sha256(self) -> str:
        """sha256 (hex) of the canonical JSON of the design (with the content hash of its
        materials file, so that a changed ink changes the design's hash)."""
        data = self.model_dump(mode="json")
        if self._material_set is not None:
            data["materials"] = {
                "entry": data.get("materials"),
                "sha256": self._material_set.sha256,
            }
        blob = json.dumps(data, sort_keys=True, separators=(",", ":"))
        return hashlib.sha256(blob.encode()).hexdigest()


_TYPE_ERRORS: Final = {
    "float_type": "a number",
    "int_type": "a whole number",
    "int_from_float": "a whole number",
    "string_type": "a text string in quotes",
    "list_type": "an array [...]",
    "tuple_type": "an array of 3 numbers [x, y, z]",
    "model_type": "a table",
    "dict_type": "a table",
    "bool_type": "true or false",
}


def schema_error(err: ErrorDetails) -> tuple[str, str]:
    """``(field, message)`` of one pydantic error, in the words of every rotomorph error
    (``filaments[0].speed``, ``must be >= 0.01 mm/s; got -2.0``); sweep and target files use it
    too."""
    loc: list[str] = []
    for part in err["loc"]:
        if isinstance(part, int):
            loc.append(f"[{part}]")
        elif part in ("line", "arc", "sinusoid", "polyline") and loc and loc[-1].startswith("["):
            continue  # discriminator tag of a segment
        else:
            loc.append(("." if loc else "") + terminal_safe(str(part)))  # a key may hold ESC
    field = "".join(loc) or "<design>"
    names = [str(part) for part in err["loc"] if isinstance(part, str)]
    unit = _UNITS.get(names[-1] if names else "", "")
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
    elif kind in _TYPE_ERRORS:
        what = _TYPE_ERRORS[kind] + (f" ({unit})" if unit else "")
        quoted = " without quotes" if isinstance(got, str) else ""
        msg = f"must be {what}{quoted}; got {got!r} ({type(got).__name__})"
    elif kind == "literal_error":  # pydantic: "Input should be 'a' or 'b'"
        msg = f"must be {ctx.get('expected', '')}; got {got!r}"
    elif kind == "finite_number":
        msg = f"must be a finite number{' (' + unit + ')' if unit else ''}; got {got!r}"
    elif kind == "too_short":
        msg = f"needs at least {ctx.get('min_length')} item(s); got {got!r}"
    elif kind == "union_tag_invalid":
        msg = f"kind must be one of {ctx.get('expected_tags', '')}; got {ctx.get('tag')!r}"
    else:
        msg = err["msg"].removeprefix("Value error, ") + (
            f"; got {got!r}" if kind != "value_error" and not isinstance(got, dict) else ""
        )
    return field, msg


def parse_design(
    data: dict[str, Any],
    *,
    base: str | FilePath | None = None,
    materials: MaterialSet | None = None,
) -> Design:
    """Validate a mapping (a parsed TOML document) into a :class:`Design`.

    Parameters
    ----------
    data
        The design's keys.
    base
        Folder a ``materials`` path is relative to (the design file's; default the current one).
    materials
        The design's materials set, already read (skips reading ``materials`` again).
    """
    if "schema_version" not in data:
        raise InvalidDesignError(
            "schema_version", f"is required; add schema_version = {SCHEMA_VERSION}"
        )
    entry = data.get("materials") if isinstance(data, dict) else None
    if entry is None:
        materials = None  # no materials file named: the paper's inks (the registry)
    elif not isinstance(entry, str | dict):
        raise InvalidDesignError(
            "materials",
            "must be the path of a materials file in quotes (TOML, relative to the design) or "
            f"an inline table; got {entry!r} ({type(entry).__name__})",
        )
    elif materials is None:
        try:
            materials = resolve_materials(entry, base)
        except MaterialError as err:
            raise InvalidDesignError(err.field, str(err).partition(": ")[2]) from None
    try:
        design = Design.model_validate(data, context={"materials": materials})
    except ValidationError as exc:
        errors = _same_fault_once([schema_error(e) for e in exc.errors()])
        field, msg = errors[0]
        more = (
            "" if len(errors) == 1 else "; also " + "; ".join(f"{f}: {m}" for f, m in errors[1:4])
        )
        raise InvalidDesignError(field, msg + more) from None
    design._material_set = materials
    return design


def _same_fault_once(errors: list[tuple[str, str]]) -> list[tuple[str, str]]:
    """One entry per fault: the same message at the same field of several filaments (or
    segments) is given once, naming the others, e.g. ``filaments[0].speed: must be >= 0.01
    mm/s; got -3.0 (also filaments[1], filaments[2])``."""
    groups: dict[tuple[str, str], list[str]] = {}
    for field, msg in errors:
        groups.setdefault((re.sub(r"\[\d+\]", "[]", field), msg), []).append(field)
    out = []
    for (_, msg), fields in groups.items():
        if len(fields) > 1:
            owners = [re.sub(r"\.[^\[\]]*$", "", f) if "." in f else f for f in fields[1:]]
            msg = f"{msg} (also {', '.join(owners)})"
        out.append((fields[0], msg))
    return out


def load_design(path: str | FilePath) -> Design:
    """Read and validate a TOML design file.

    Raises
    ------
    InvalidDesignError
        A file that is not UTF-8 (or UTF-16/32 with a byte-order mark) or larger than 4 MiB,
        TOML syntax errors (field ``<file>``), and schema violations (field path and fix).
    OSError
        The file cannot be read.
    """
    return parse_design(read_toml(path, InvalidDesignError), base=FilePath(path).parent)


def parse_design_bytes(
    data: bytes, name: str = "<design>", *, base: str | FilePath | None = None
) -> Design:
    """Validate the bytes of a TOML design file (as :func:`load_design`, without a file; a
    ``materials`` path is relative to ``base``, default the current folder)."""
    return parse_design(decode_toml_bytes(data, name, InvalidDesignError), base=base)


def design_size(design: Design) -> SizeEstimate:
    """Rod nodes of ``design`` (all filaments, or the lattice), estimated before building it."""
    nodes = sum(f.node_count() for f in design.filaments)
    if design.lattice is not None:
        nodes += design.lattice.node_count()
    return SizeEstimate(nodes)


def with_spacing(design: Design, spacing: float) -> Design:
    """``design`` with every filament's vertex spacing set to ``spacing`` (mm), re-validated.

    Raises
    ------
    InvalidDesignError
        ``spacing`` out of range, or the design too large or too coarse at that spacing.
    """
    data = design.model_dump(mode="python")
    for fil in data["filaments"]:
        fil["spacing"] = spacing
    return parse_design(data, materials=design.material_set)


def save_design(design: Design, path: str | FilePath) -> FilePath:
    """Write ``design`` as TOML to ``path`` atomically (temp file + os.replace).

    Only what the design sets is written (defaults stay defaults when it is read back): a
    default written out would read back as a chosen value, so a placeholder nozzle pressure
    or dwell would no longer be flagged as one in the G-code's header.
    """
    data = design.model_dump(mode="json", exclude_none=True, exclude_unset=True)
    return atomic_write_text(path, tomli_w.dumps(data))


def design_schema() -> dict[str, Any]:
    """JSON Schema of the design file format (for editors and documentation)."""
    schema = Design.model_json_schema()
    schema["$id"] = f"https://rotomorph.invalid/design-schema-v{SCHEMA_VERSION}.json"
    return schema

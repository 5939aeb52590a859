"""Target files of inverse design (TOML), validated like design files.

A target file says what shape is wanted and, for lattices, the printed geometry to design on::

    schema_version = 1
    kind = "curve"                    # curve | dome | saddle | height_map
    [curve]
    family = "helix"                  # helix | spiral | tendril | points
    radius_start = 2.0                # mm
    radius_end = 2.6
    pitch = 2.0                       # mm per turn
    turns = 2.0

Curve families (all lengths in mm):

* ``helix``: radius varying linearly from ``radius_start`` to ``radius_end`` over ``turns``
  turns of constant ``pitch`` (right-handed for ``pitch > 0``);
* ``spiral``: a planar spiral whose radius goes from ``radius_start`` to ``radius_end`` over
  ``turns`` turns;
* ``tendril``: two helices of opposite handedness (radius, pitch, ``turns`` each) joined at a
  perversion, as in a climbing plant's tendril;
* ``points``: sampled points ``[[x, y, z], ...]``.

Lattice targets (``dome``, ``saddle``, ``height_map``) give the curvatures (1/mm) or a height
grid and a ``[lattice]`` table with the printed geometry (``n``, ``spacing``, ``amplitude``,
``ghost_nodes``; the paper does not give the last three, so they are assumptions of the design).
A lab's own inks: ``materials = "inks.toml"`` (a materials file, relative to the target file)
and ``active_material``/``passive_material`` in ``[options]``; the design is then made with
that file's model, and the resulting design file names the same materials file.
Lattice designs are made in the surroundings of the ``[contact]`` table (the design file's:
``self_contact``, ``floor``, ``gravity``, ``bath``, ``friction``, ``branch``, ``path_check``);
without one, in the bath (self-contact, the bath floor, the buoyant weight, the lowest-energy
branch: :func:`rotomorph.inverse.bath.bath_contact`). Every equilibrium of the design and its
adjoint touch and rest as ``rotomorph simulate`` will (frictionless: friction and the path check
apply to the verification, ``simulate``'s own ramp), and the table is copied into the resulting
design file.
"""

from __future__ import annotations

import itertools
import math
from pathlib import Path
from typing import Annotated, Any, Final, Literal

import numpy as np
from pydantic import (
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    PrivateAttr,
    ValidationError,
    model_validator,
)

from rotomorph._typing import FloatArray
from rotomorph.errors import InvalidDesignError, MaterialError
from rotomorph.inverse.lattice import SurfaceTarget, dome, height_map, saddle
from rotomorph.io.design_limits import LIMITS
from rotomorph.io.designfile import ContactModel, Label, as_vector3, schema_error
from rotomorph.io.materials_file import resolve_materials
from rotomorph.io.tomlfile import decode_toml_bytes, read_toml
from rotomorph.materials.material import get_material
from rotomorph.materials.natural import FilamentModel
from rotomorph.materials.parameter_set import MaterialSet

__all__ = [
    "BYTES_PER_NODE",
    "CPU_S_PER_NODE",
    "MAX_CURVE_NODES",
    "MAX_CURVE_SAMPLES",
    "MAX_GRID",
    "MAX_POINTS",
    "TargetFile",
    "curve_length",
    "curve_points",
    "load_target",
    "parse_target",
    "parse_target_bytes",
]

#: Largest designed filament (rod vertices at ``options.spacing`` along the target).
MAX_CURVE_NODES: Final = 100_000
#: Most samples of a generated target curve (``samples_per_turn`` × ``turns``).
MAX_CURVE_SAMPLES: Final = 200_000
#: Most points of a ``points`` target, and of each axis of a height map.
MAX_POINTS: Final = 100_000
MAX_GRID: Final = 1_000
#: CPU time of a curve design per designed vertex (s; 0.9 ms measured at 3 500 vertices on a
#: 2-core machine, table lookup, per-vertex fit and the verifying solve), and its memory (bytes).
CPU_S_PER_NODE: Final = 1e-3
BYTES_PER_NODE: Final = 4_000

_EXTENT, _COORD = LIMITS["extent"], LIMITS["coordinate"]
Positive = Annotated[float, Field(gt=0, allow_inf_nan=False)]
#: A length or radius (mm) within the design file's range.
Extent = Annotated[float, Field(ge=_EXTENT.minimum, le=_EXTENT.maximum)]
Coordinate = Annotated[float, Field(ge=_COORD.minimum, le=_COORD.maximum)]
Point = Annotated[tuple[Coordinate, Coordinate, Coordinate], BeforeValidator(as_vector3)]


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False, strict=True)


class CurveSpec(_Model):
    """A target centre line."""

    family: Literal["helix", "spiral", "tendril", "points"]
    radius_start: Extent | None = None
    radius_end: Extent | None = None
    radius: Extent | None = None
    pitch: Coordinate | None = Field(None, description="mm per turn (< 0: left-handed)")
    turns: float | None = Field(None, gt=0, le=10_000)
    points: list[Point] | None = Field(None, max_length=MAX_POINTS)
    samples_per_turn: int = Field(120, ge=16, le=2000)

    @model_validator(mode="after")
    def _fields(self) -> CurveSpec:
        need = {
            "helix": ("radius_start", "radius_end", "pitch", "turns"),
            "spiral": ("radius_start", "radius_end", "turns"),
            "tendril": ("radius", "pitch", "turns"),
            "points": ("points",),
        }[self.family]
        missing = [k for k in need if getattr(self, k) is None]
        if missing:
            raise ValueError(f"family '{self.family}' needs {', '.join(missing)}")
        if self.family == "points" and self.points is not None and len(self.points) < 3:
            raise ValueError("points needs at least 3 points [[x, y, z], ...] (mm)")
        samples = self.samples()
        if samples > MAX_CURVE_SAMPLES:
            raise ValueError(
                f"turns: {self.turns:g} turns at {self.samples_per_turn} samples per turn are "
                f"{samples:,.0f} samples (~{24 * samples / 2**30:.3g} GiB); the limit is "
                f"{MAX_CURVE_SAMPLES:,}: fewer turns or samples_per_turn"
            )
        return self

    def samples(self) -> float:
        """Samples of the generated curve (the number of points of a ``points`` target)."""
        if self.family == "points":
            return float(len(self.points or ()))
        factor = 2 if self.family == "tendril" else 1
        return factor * self.samples_per_turn * float(self.turns or 0.0)


def curve_length(spec: CurveSpec) -> float:
    """Arc length (mm) of a curve target, computed from its parameters (not sampled)."""
    if spec.family == "points":
        pts = np.asarray(spec.points, dtype=float)
        return float(np.sum(np.linalg.norm(np.diff(pts, axis=0), axis=1)))
    turns = float(spec.turns or 0.0)
    pitch = float(spec.pitch or 0.0)
    if spec.family == "tendril":
        return 2 * turns * math.hypot(2 * math.pi * float(spec.radius or 0.0), pitch)
    r = max(float(spec.radius_start or 0.0), float(spec.radius_end or 0.0))
    return turns * math.hypot(2 * math.pi * r, pitch)


class LatticeSpec(_Model):
    """Printed lattice geometry to design on (assumed: the paper does not give it)."""

    n: int = Field(5, ge=2, le=12)
    spacing: Extent = 5.0
    amplitude: float = Field(1.25, ge=0, le=_EXTENT.maximum)
    ghost_nodes: int = Field(10, ge=2, le=40)


class SurfaceSpec(_Model):
    """Dome/saddle principal curvatures (1/mm, positive magnitudes)."""

    curvature: Positive
    curvature2: Positive | None = None


class HeightMapSpec(_Model):
    """Heights ``z[i][j]`` (mm) at ``(x[i], y[j])`` (mm), centred on the lattice."""

    x: list[Coordinate] = Field(min_length=4, max_length=MAX_GRID)
    y: list[Coordinate] = Field(min_length=4, max_length=MAX_GRID)
    z: list[list[Coordinate]] = Field(max_length=MAX_GRID)

    @model_validator(mode="after")
    def _grid(self) -> HeightMapSpec:
        if len(self.z) != len(self.x) or any(len(row) != len(self.y) for row in self.z):
            shape = f"{len(self.z)} rows of {sorted({len(r) for r in self.z})} values"
            raise ValueError(
                f"z must have len(x) = {len(self.x)} rows of len(y) = {len(self.y)} heights "
                f"(mm); got {shape}"
            )
        step = _EXTENT.minimum
        for axis in ("x", "y"):
            v = getattr(self, axis)
            if any(b - a < step for a, b in itertools.pairwise(v)):
                raise ValueError(f"{axis} must increase by >= {step:g} mm from point to point")
        return self


def _limited(kind: str, default: float) -> Any:
    lim = LIMITS[kind]
    return Field(default, ge=lim.minimum, le=lim.maximum, description=lim.unit)


class Options(_Model):
    """Settings of the design run."""

    spacing: float = _limited("vertex_spacing", 0.1)
    temperature: float = Field(175.0, ge=-50, le=300)
    min_speed: float = _limited("speed", 0.25)
    max_speed: float = _limited("speed", 3.0)
    speed_resolution: float = Field(0.05, ge=0.001, le=LIMITS["speed"].maximum)
    max_rotation: float = Field(40.0, gt=0, le=LIMITS["rotation"].maximum)
    max_iterations: int = Field(30, ge=1, le=500)
    radius: float = _limited("filament_radius", 0.3)
    tolerance: float = Field(0.005, gt=0, le=0.2, allow_inf_nan=False)
    active_material: Label = Field("lce", min_length=1, max_length=100)
    passive_material: Label = Field("acrylate", min_length=1, max_length=100)
    robust: bool = Field(
        False,
        description="lattices: choose the design minimising the expected misfit over the "
        "calibration band instead of the nominal one",
    )


class TargetFile(_Model):
    """A validated target file."""

    schema_version: Literal[1] = 1
    kind: Literal["curve", "dome", "saddle", "height_map"]
    name: Label = Field("", description="label of the designed file")
    curve: CurveSpec | None = None
    surface: SurfaceSpec | None = None
    height_map: HeightMapSpec | None = None
    lattice: LatticeSpec | None = None
    contact: ContactModel | None = None
    options: Options = Options()
    materials: Label | None = Field(
        None, description="materials file of the inks, relative to the target"
    )
    _material_set: MaterialSet | None = PrivateAttr(default=None)

    @property
    def material_set(self) -> MaterialSet | None:
        """The materials file the target names (``None``: the paper's inks)."""
        return self._material_set

    def filament_model(self) -> FilamentModel | None:
        """The model of the target's ink pair (``None``: the package default)."""
        inks = self._material_set
        if inks is None:
            return None
        return inks.filament_model(self.options.active_material, self.options.passive_material)

    @model_validator(mode="after")
    def _tables(self) -> TargetFile:
        table = {
            "curve": "curve",
            "dome": "surface",
            "saddle": "surface",
            "height_map": "height_map",
        }[self.kind]
        if getattr(self, table) is None:
            raise ValueError(f"kind '{self.kind}' needs a [{table}] table")
        if self.kind != "curve" and self.lattice is None:
            raise ValueError(f"kind '{self.kind}' needs a [lattice] table (n, spacing, amplitude)")
        if self.contact is not None and self.kind == "curve":
            raise ValueError("[contact] applies to lattice targets only; remove it")
        if self.options.min_speed >= self.options.max_speed:
            raise ValueError("options.min_speed must be < options.max_speed (mm/s)")
        if self.kind == "curve":
            assert self.curve is not None
            nodes = curve_length(self.curve) / self.options.spacing + 1
            if nodes > MAX_CURVE_NODES:
                raise ValueError(
                    f"options.spacing: the {curve_length(self.curve):.4g} mm target at "
                    f"{self.options.spacing:g} mm spacing is about {nodes:,.0f} filament "
                    f"vertices (~{nodes * BYTES_PER_NODE / 1e9:.2g} GB, "
                    f"~{nodes * CPU_S_PER_NODE / 60:.0f} min of CPU); the limit is "
                    f"{MAX_CURVE_NODES:,}: a larger spacing or a shorter target"
                )
        return self

    def surface_target(self) -> SurfaceTarget:
        """The :class:`SurfaceTarget` of a lattice target."""
        if self.kind == "dome":
            assert self.surface is not None
            return dome(self.surface.curvature, self.surface.curvature2)
        if self.kind == "saddle":
            assert self.surface is not None
            return saddle(self.surface.curvature, self.surface.curvature2)
        assert self.height_map is not None
        hm = self.height_map
        return height_map(np.array(hm.x), np.array(hm.y), np.array(hm.z))


def curve_points(spec: CurveSpec) -> FloatArray:
    """Points ``(M, 3)`` (mm) of a curve target."""
    if spec.family == "points":
        assert spec.points is not None
        return np.array(spec.points, dtype=float)
    turns = float(spec.turns)  # type: ignore[arg-type]
    m = max(round(spec.samples_per_turn * turns), 16)
    t = np.linspace(0.0, 2 * math.pi * turns, m + 1)
    if spec.family == "helix":
        r = np.linspace(spec.radius_start, spec.radius_end, len(t))  # type: ignore[arg-type]
        z = float(spec.pitch) * t / (2 * math.pi)  # type: ignore[arg-type]
        return np.stack([r * np.cos(t), r * np.sin(t), z], axis=1)
    if spec.family == "spiral":
        r = np.linspace(spec.radius_start, spec.radius_end, len(t))  # type: ignore[arg-type]
        return np.stack([r * np.cos(t), r * np.sin(t), np.zeros_like(t)], axis=1)
    # tendril: curvature and torsion both change sign through a smooth switch (a perversion):
    # (kappa, tau) -> (-kappa, -tau) keeps the helix axis and the direction of advance along it
    # and reverses the handedness (the sign of the torsion); the curve is straight at the joint
    rad, p = float(spec.radius), float(spec.pitch)  # type: ignore[arg-type]
    c = p / (2 * math.pi)
    kappa = rad / (rad * rad + c * c)
    tau = c / (rad * rad + c * c)
    length = 2 * turns * 2 * math.pi * math.hypot(rad, c)
    s = np.linspace(0.0, length, 2 * m + 1)
    width = 0.05 * length
    switch = np.tanh((0.5 * length - s) / width)
    return _frenet_curve(kappa * switch, tau * switch, s)


def _frenet_curve(kappa: FloatArray, tau: FloatArray, s: FloatArray) -> FloatArray:
    """Integrate the Frenet–Serret equations (exact rotation per step, midpoint rates)."""
    frame = np.eye(3)  # rows: tangent, normal, binormal
    pts = np.zeros((len(s), 3))
    for i in range(1, len(s)):
        h = s[i] - s[i - 1]
        k = 0.5 * (kappa[i] + kappa[i - 1])
        t = 0.5 * (tau[i] + tau[i - 1])
        darboux = t * frame[0] + k * frame[2]  # angular velocity of the frame
        ang = float(np.linalg.norm(darboux)) * h
        half = frame.copy()
        if ang > 0:
            axis = darboux / np.linalg.norm(darboux)
            frame = _rotate(frame, axis, ang)
            half = _rotate(half, axis, 0.5 * ang)
        pts[i] = pts[i - 1] + h * half[0]
    return pts


def _rotate(vectors: FloatArray, axis: FloatArray, angle: float) -> FloatArray:
    c, sn = math.cos(angle), math.sin(angle)
    return vectors * c + np.cross(axis, vectors) * sn + np.outer(vectors @ axis, axis) * (1 - c)


def _format(err: Any) -> tuple[str, str]:
    loc, msg = schema_error(err)  # the design file's wording
    loc = loc.replace("<design>", "<target>")
    if err["type"] == "extra_forbidden":
        return loc, "unknown key; remove it or check its spelling (see docs/inverse.md)"
    if err["type"] == "missing" and loc == "kind":
        return loc, "is required; add kind = 'curve', 'dome', 'saddle' or 'height_map'"
    return loc, msg


def parse_target(data: dict[str, Any], folder: str | Path | None = None) -> TargetFile:
    """Validate a mapping (parsed TOML) into a :class:`TargetFile` (a ``materials`` path is
    relative to ``folder``, the target file's; default the current folder)."""
    if "schema_version" not in data:
        raise InvalidDesignError("schema_version", "is required; add schema_version = 1")
    if "kind" not in data and ("filaments" in data or "lattice" in data):
        raise InvalidDesignError(
            "kind",
            "is required: this looks like a design file ([[filaments]] / [lattice]), not a "
            "target; give a target file with kind = 'curve', 'dome', 'saddle' or 'height_map' "
            "(examples/targets/)",
        )
    try:
        target = TargetFile.model_validate(data)
    except ValidationError as exc:
        field, msg = _format(exc.errors()[0])
        raise InvalidDesignError(field, msg) from None
    names = (target.options.active_material, target.options.passive_material)
    if target.materials is None:
        inks = None
        lookup = get_material
    else:
        try:
            inks = resolve_materials(target.materials, folder)
        except MaterialError as err:
            raise InvalidDesignError(err.field, str(err).partition(": ")[2]) from None
        lookup = inks.material
    for role, name in zip(("active", "passive"), names, strict=True):
        try:
            kind = lookup(name).kind
        except MaterialError as err:
            message = str(err).partition(": ")[2]
            raise InvalidDesignError(f"options.{role}_material", message) from None
        if kind != role:
            raise InvalidDesignError(
                f"options.{role}_material", f"{name!r} is a {kind} ink; give a {role} one"
            )
    target._material_set = inks
    return target


def parse_target_bytes(data: bytes, name: str = "<target>") -> TargetFile:
    """Validate the bytes of a TOML target file (as :func:`load_target`, without a file)."""
    return parse_target(decode_toml_bytes(data, name, InvalidDesignError))


def load_target(path: str) -> TargetFile:
    """Read and validate a TOML target file (as design files: UTF-8, or UTF-16/32 with a
    byte-order mark, at most 4 MiB).

    Raises
    ------
    InvalidDesignError
        Unreadable, not UTF-8, not TOML, or not a valid target (field path and fix).
    """
    try:
        data = read_toml(path, InvalidDesignError)
    except OSError as exc:
        raise InvalidDesignError(str(path), f"cannot be read: {exc.strerror}") from None
    return parse_target(data, Path(path).parent)

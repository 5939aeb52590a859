"""Sweep files: a base design, the parameters to vary, how to sample them, what to collect.

A sweep file is TOML (``schema_version = 1``) validated by pydantic, like a design file::

    schema_version = 1
    name = "janus_curvature_vs_speed"
    design = "../designs/janus_single.toml"   # a design file (relative to this file) ...
    outputs = ["curvature", "end_to_end_ratio", "morphology"]

    [settings]                  # how every run is computed (part of the run id)
    method = "rod"              # "rod" (rod solver over a heating ramp) or "closed_form"
    steps = 6                   # heating steps
    spacing = 0.5               # vertex spacing override (mm); coarser is faster

    [sampling]
    method = "grid"             # grid | random | latin_hypercube
    seed = 0                    # random and latin_hypercube
    # samples = 100             # random and latin_hypercube

    [[parameters]]
    path = "filaments[0].speed"               # dotted field path into the design
    values = [0.25, 0.5, 1.75, 3.0]           # a list ...
    # range = { start = 0.25, stop = 3.0, num = 12 }             # ... a range (ends included)
    # distribution = { kind = "uniform", low = 0.25, high = 3.0 } # ... or a distribution

``design`` may instead be an inline table (``[design]`` with the keys of a design file).
An optional ``[machine]`` table (the keys of a machine profile, or ``profile = "FILE.toml"``)
makes every point the machine cannot print an *invalid* run, recorded with its error.

Errors name the field (``parameters[1].range.num: must be >= 1``) and are raised as
:class:`~rotomorph.errors.InvalidParameterError`.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Annotated, Any, Final, Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator

from rotomorph.errors import InvalidDesignError, InvalidParameterError
from rotomorph.io.design_limits import LIMITS
from rotomorph.io.designfile import Design, FreeText, Label, parse_design, schema_error
from rotomorph.io.machine import MachineProfile, load_machine_profile
from rotomorph.io.tomlfile import decode_toml_bytes, read_toml
from rotomorph.simulate.options import MAX_STEPS, TEMPERATURE_RANGE
from rotomorph.sweep.paths import check_path, parse_path

__all__ = [
    "MAX_POINTS",
    "SCHEMA_VERSION",
    "Distribution",
    "Parameter",
    "Range",
    "Sampling",
    "Settings",
    "Sweep",
    "load_sweep",
    "parse_sweep",
    "parse_sweep_bytes",
    "sweep_schema",
]

SCHEMA_VERSION: Final = 1
#: Most points of a sweep (grid product or samples); each is resolved and held before any run.
MAX_POINTS: Final = 100_000
#: Memory to hold one resolved point: about four bytes per byte of the design's JSON (Python
#: objects) plus the record (measured 2.3 kB per point for a 600-byte filament design).
PLAN_BYTES_PER_JSON_BYTE: Final = 4
MIN_POINT_BYTES: Final = 2_300
#: Resolving one point (set the values, validate the design, hash it): 1.3 ms CPU measured.
PLAN_S_PER_POINT: Final = 1.3e-3
Scalar = float | int | Label | bool


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)


def _many(count: float) -> str:
    """A count for a message: ``1,000,000`` or ``2.75e+15``."""
    return f"{count:,.0f}" if count < 1e12 else f"{count:.3g}"


class Range(_Model):
    """Evenly spaced values from ``start`` to ``stop`` (both included).

    Give ``num`` (number of values) or ``step`` (spacing; ``stop`` is included when it falls on
    the grid within 1e-9 of a step). ``log = true`` spaces ``num`` values geometrically
    (``start`` and ``stop`` > 0).
    """

    start: float
    stop: float
    num: int | None = Field(None, ge=1)
    step: float | None = Field(None, gt=0)
    log: bool = False

    @model_validator(mode="after")
    def _one_size(self) -> Range:
        if (self.num is None) == (self.step is None):
            raise ValueError("give exactly one of num and step")
        if self.log and (self.step is not None or self.start <= 0 or self.stop <= 0):
            raise ValueError("log = true needs num and start, stop > 0")
        if self.step is not None and self.stop < self.start:
            raise ValueError("step needs stop >= start")
        count = self.count()
        if count > MAX_POINTS:
            what = f"num = {self.num}" if self.num is not None else f"step = {self.step:g}"
            raise ValueError(
                f"{what} gives {_many(count)} values (at least ~{count * MIN_POINT_BYTES / 1e9:.3g}"
                f" GB and ~{count * PLAN_S_PER_POINT / 60:,.0f} min of CPU to resolve them); a "
                f"sweep has at most {MAX_POINTS:,} points: use fewer values (or random / "
                "latin_hypercube sampling)"
            )
        return self

    def count(self) -> float:
        """Number of values (computed, not listed; may be huge before validation)."""
        if self.step is not None:
            return math.floor((self.stop - self.start) / self.step + 1e-9) + 1.0
        return float(self.num or 0)

    def values(self) -> list[float]:
        """The listed values."""
        if self.step is not None:
            n = int(self.count()) - 1
            return [self.start + i * self.step for i in range(n + 1)]
        assert self.num is not None
        if self.num == 1:
            return [self.start]
        if self.log:
            a, b = math.log(self.start), math.log(self.stop)
            return [math.exp(a + (b - a) * i / (self.num - 1)) for i in range(self.num)]
        return [self.start + (self.stop - self.start) * i / (self.num - 1) for i in range(self.num)]


class Distribution(_Model):
    """A continuous distribution sampled by ``random`` or ``latin_hypercube`` sampling.

    ``uniform`` on [low, high]; ``loguniform`` on [low, high] (> 0); ``normal`` with ``mean``
    and ``std``, optionally truncated to [low, high].
    """

    kind: Literal["uniform", "loguniform", "normal"]
    low: float | None = None
    high: float | None = None
    mean: float | None = None
    std: float | None = Field(None, gt=0)

    @model_validator(mode="after")
    def _complete(self) -> Distribution:
        if self.kind in ("uniform", "loguniform"):
            if self.low is None or self.high is None or not self.low < self.high:
                raise ValueError(f"{self.kind} needs low < high")
            if self.kind == "loguniform" and self.low <= 0:
                raise ValueError("loguniform needs low > 0")
            if self.mean is not None or self.std is not None:
                raise ValueError(f"{self.kind} takes low and high, not mean/std")
        else:
            if self.mean is None or self.std is None:
                raise ValueError("normal needs mean and std")
            if self.low is not None and self.high is not None and not self.low < self.high:
                raise ValueError("normal truncation needs low < high")
        return self


class Parameter(_Model):
    """One varied design field and its values (exactly one of values, range, distribution)."""

    path: str = Field(description="dotted field path into the design, e.g. filaments[0].speed")
    values: list[Scalar] | None = Field(None, min_length=1)
    range: Range | None = None
    distribution: Distribution | None = None
    name: Label = Field("", description="column name in the results table (default: the path)")

    @model_validator(mode="after")
    def _one_source(self) -> Parameter:
        given = [k for k in ("values", "range", "distribution") if getattr(self, k) is not None]
        if len(given) != 1:
            raise ValueError(f"give exactly one of values, range, distribution; got {given}")
        parse_path(self.path)
        return self

    @property
    def column(self) -> str:
        """Name of this parameter's column in the results table."""
        return self.name or self.path

    def count(self) -> float:
        """Number of levels (``inf`` for a distribution)."""
        if self.values is not None:
            return float(len(self.values))
        if self.range is not None:
            return self.range.count()
        return math.inf

    def levels(self) -> list[Scalar] | None:
        """The finite list of values (``None`` for a distribution)."""
        if self.values is not None:
            return list(self.values)
        if self.range is not None:
            return list(self.range.values())
        return None


class Sampling(_Model):
    """How points are drawn: the full grid, independent random draws, or a Latin hypercube."""

    method: Literal["grid", "random", "latin_hypercube"] = "grid"
    samples: int | None = Field(None, ge=1, description="points for random/latin_hypercube")
    seed: int = Field(0, ge=0)

    @model_validator(mode="after")
    def _samples(self) -> Sampling:
        if self.method == "grid" and self.samples is not None:
            raise ValueError("samples is only used by random and latin_hypercube sampling")
        if self.method != "grid" and self.samples is None:
            raise ValueError(f"{self.method} sampling needs samples = <number of points>")
        return self


class Settings(_Model):
    """How each run is computed (everything here enters the run id).

    ``method = "rod"`` solves the rod model over a heating ramp
    (:func:`rotomorph.simulate.design.simulate_design`); ``"closed_form"`` evaluates the
    closed-form free helix of each filament's natural field at ``temperature`` (uniform
    filaments only, no lattices; milliseconds per run).
    ``filament_model`` names the materials model: ``"calibrated"``
    (default; the joint fit to the paper's Janus curvatures and pure-LCE and composite L/L0,
    the model of ``rotomorph simulate`` and ``rotomorph paper``), ``"calibrated-without-<group>"``
    (the same fit leaving that group out, so the group's points are out-of-sample predictions,
    as in the report), ``"warner-terentjev"`` and ``"room-temperature"`` (physical priors; see
    :func:`rotomorph.materials.natural.named_model`). ``actuation`` is the lattice actuation
    rule (default ``"program"``, as ``rotomorph simulate``); temperatures and the filament model
    apply to lattices only with the temperature-driven rules ``program`` and ``thermal``.
    """

    method: Literal["rod", "closed_form"] = "rod"
    steps: int = Field(8, ge=1, le=MAX_STEPS, description="heating steps")
    start_temperature: float = Field(
        25.0, ge=TEMPERATURE_RANGE[0], le=TEMPERATURE_RANGE[1], description="°C"
    )
    temperature: float = Field(
        175.0, ge=TEMPERATURE_RANGE[0], le=TEMPERATURE_RANGE[1], description="°C"
    )
    spacing: float | None = Field(
        None,
        ge=LIMITS["vertex_spacing"].minimum,
        le=LIMITS["vertex_spacing"].maximum,
        description="vertex spacing override (mm)",
    )
    actuation: Literal["program", "thermal", "literal", "swapped", "radius", "additive"] = "program"
    filament_model: Literal[
        "calibrated",
        "calibrated-without-janus_curvature",
        "calibrated-without-pure_lce_length",
        "calibrated-without-composite_length",
        "warner-terentjev",
        "room-temperature",
    ] = "calibrated"

    @model_validator(mode="after")
    def _ramp(self) -> Settings:
        if not self.start_temperature < self.temperature:
            raise ValueError("temperature must exceed start_temperature (°C)")
        return self


class Sweep(_Model):
    """A validated sweep file."""

    schema_version: Literal[1] = SCHEMA_VERSION
    name: Label = ""
    description: FreeText = ""
    design: dict[str, Any] = Field(description="the base design (inline; a path is read in)")
    parameters: list[Parameter] = Field(min_length=1)
    sampling: Sampling = Sampling()
    settings: Settings = Settings()
    outputs: list[str] = Field(min_length=1, description="metrics to collect (see METRICS)")
    machine: dict[str, Any] | None = Field(
        None, description="machine profile keys; points it cannot print are invalid runs"
    )
    hdf5: bool = Field(False, description="also write one HDF5 results file per run")

    @model_validator(mode="after")
    def _consistent(self) -> Sweep:
        columns = [p.column for p in self.parameters]
        dup = sorted({c for c in columns if columns.count(c) > 1})
        if dup:
            raise ValueError(f"parameters vary {dup} twice; give each path (or name) once")
        if self.sampling.method == "grid":
            for i, p in enumerate(self.parameters):
                if p.distribution is not None:
                    raise ValueError(
                        f"parameters[{i}] has a distribution, which cannot be gridded; "
                        "give values or a range, or use random / latin_hypercube sampling"
                    )
        if len(set(self.outputs)) != len(self.outputs):
            raise ValueError("outputs lists a name twice")
        points = self.point_count()
        per_point = PLAN_BYTES_PER_JSON_BYTE * len(json.dumps(self.design, default=str)) + 1000
        if points > MAX_POINTS:
            field = "sampling.samples" if self.sampling.method != "grid" else "parameters"
            raise ValueError(
                f"{field}: the sweep has {_many(points)} points (~{points * per_point / 1e9:.3g} "
                f"GB and ~{points * PLAN_S_PER_POINT / 60:,.0f} min of CPU to resolve them "
                f"before the first run); the limit is {MAX_POINTS:,} points: vary fewer "
                "values, or sample (random / latin_hypercube)"
            )
        return self

    def point_count(self) -> float:
        """Points of the sweep (grid: the product of the levels; else ``samples``)."""
        if self.sampling.method != "grid":
            return float(self.sampling.samples or 0)
        return math.prod(p.count() for p in self.parameters)

    def base_design(self) -> Design:
        """The validated base design."""
        return parse_design(self.design)

    def machine_profile(self) -> MachineProfile | None:
        """The machine profile points are checked against, if any."""
        return None if self.machine is None else MachineProfile.from_dict(self.machine)

    def sha256(self) -> str:
        """sha256 (hex) of the canonical JSON of the sweep."""
        import hashlib

        blob = json.dumps(self.model_dump(mode="json"), sort_keys=True, separators=(",", ":"))
        return hashlib.sha256(blob.encode()).hexdigest()


def _format(err: Any) -> str:
    field, msg = schema_error(err)  # the design file's wording
    if err["type"] == "extra_forbidden":
        msg = "unknown key; remove it or check its spelling (see sweep_schema())"
    return f"{field.replace('<design>', '<sweep>')}: {msg}"


def parse_sweep(data: dict[str, Any], *, folder: str | Path = ".") -> Sweep:
    """Validate a mapping (a parsed TOML document) into a :class:`Sweep`.

    A string ``design`` is read as a design file relative to ``folder``, and so is
    ``machine.profile``; the base design and the outputs are checked here, so a bad sweep
    fails before any run starts.

    Raises
    ------
    InvalidParameterError
        Schema violations (field path and fix); :class:`InvalidDesignError` for the base design.
    """
    from rotomorph.sweep.metrics import check_outputs

    if "schema_version" not in data:
        raise InvalidParameterError(
            "schema_version", f"is required; add schema_version = {SCHEMA_VERSION}"
        )
    data = dict(data)
    base = Path(folder)
    design_folder = base
    if isinstance(data.get("design"), str):
        path = base / data["design"]
        design_folder = path.parent
        if not path.is_file():
            raise InvalidParameterError("design", f"{path}: no such design file")
        data["design"] = read_toml(path, InvalidDesignError)  # UTF-8, size, syntax
    design_data = data.get("design")
    if isinstance(design_data, dict) and isinstance(design_data.get("materials"), str):
        data["design"] = _inline_materials(design_data, design_folder)
    machine = data.get("machine")
    if isinstance(machine, dict) and "profile" in machine:
        rest = {k: v for k, v in machine.items() if k != "profile"}
        if rest:
            raise InvalidParameterError(
                "machine", f"give profile = FILE or inline keys, not both; got {sorted(rest)}"
            )
        path = base / str(machine["profile"])
        if not path.is_file():
            raise InvalidParameterError("machine.profile", f"{path}: no such file")
        data["machine"] = _profile_dict(load_machine_profile(path))
    try:
        sweep = Sweep.model_validate(data)
    except ValidationError as exc:
        errors = [_format(e) for e in exc.errors()]
        field, _, msg = errors[0].partition(": ")
        more = "" if len(errors) == 1 else "; also " + "; ".join(errors[1:4])
        raise InvalidParameterError(field, msg + more) from None
    try:
        design = sweep.base_design()
    except InvalidDesignError as err:
        raise InvalidDesignError(f"design.{err.field}", str(err).partition(": ")[2]) from None
    resolved = design.model_dump(mode="json")
    for i, parameter in enumerate(sweep.parameters):
        try:  # a misspelt path would make every point an invalid run
            check_path(resolved, parameter.path)
        except InvalidParameterError as err:
            raise InvalidParameterError(f"parameters[{i}].path", str(err)) from None
    sweep.machine_profile()
    check_outputs(sweep.outputs, design, sweep.settings.method)
    return sweep


def _inline_materials(design: dict[str, Any], folder: Path) -> dict[str, Any]:
    """``design`` with its materials file (a path relative to ``folder``) read in as an inline
    table: every run then carries its inks, the run ids hash their content, and runs on other
    machines (a Dask cluster) need no file."""
    from rotomorph.errors import MaterialError
    from rotomorph.io.materials_file import resolve_materials

    try:
        inks = resolve_materials(design["materials"], folder)
    except MaterialError as err:
        raise InvalidDesignError(f"design.{err.field}", str(err).partition(": ")[2]) from None
    return {**design, "materials": inks.document.model_dump(mode="json", exclude_none=True)}


def _profile_dict(profile: MachineProfile) -> dict[str, Any]:
    from dataclasses import asdict

    return {k: list(v) if isinstance(v, tuple) else v for k, v in asdict(profile).items()}


def parse_sweep_bytes(data: bytes, name: str = "<sweep>", *, folder: str | Path = ".") -> Sweep:
    """Validate the bytes of a TOML sweep file (as :func:`load_sweep`, without a file)."""
    return parse_sweep(decode_toml_bytes(data, name), folder=folder)


def load_sweep(path: str | Path) -> Sweep:
    """Read and validate a TOML sweep file (paths inside it are relative to its folder).

    Raises
    ------
    InvalidParameterError
        A file that is not UTF-8 (or UTF-16/32 with a byte-order mark) or larger than 4 MiB,
        TOML syntax errors and schema violations (field path and fix).
    OSError
        The file cannot be read.
    """
    p = Path(path)
    return parse_sweep(read_toml(p), folder=p.parent)  # UTF-8, size and syntax as design files


SweepSchema = Annotated[dict[str, Any], "JSON Schema"]


def sweep_schema() -> SweepSchema:
    """JSON Schema of the sweep file format (``design`` may also be a path string)."""
    schema = Sweep.model_json_schema()
    schema["properties"]["design"] = {
        "anyOf": [
            {"type": "string", "description": "design file, relative to the sweep file"},
            {"type": "object", "description": "inline design (keys of a design file)"},
        ]
    }
    schema["$id"] = f"https://rotomorph.invalid/sweep-schema-v{SCHEMA_VERSION}.json"
    return schema

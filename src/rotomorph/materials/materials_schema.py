"""Schema of a materials file: inks as data, every value with its unit and provenance.

A materials file is TOML (``schema_version = 1``) holding one or more inks; the layout, every
key and its unit is documented in ``docs/design-files.md`` (*Materials files*). Each value is a
table ``{ value, unit, provenance, source }`` with optional ``sd`` (standard deviation, same
unit), ``temperature`` (°C at which it applies) and ``interval`` (±1 sd interval, for values
fitted on a log scale). ``provenance`` is one of

* ``measured``: measured by the lab that wrote the file (``source``: where: file, row, method);
* ``cited``: from a publication (``source``: the citation);
* ``assumed``: a modelling choice or placeholder (``source``: why this value);
* ``calibrated``: fitted to measurements by ``rotomorph calibrate`` (``source``: the fit).

Values are converted to the package's units on reading (:mod:`rotomorph.materials.units`).
Validation errors are :class:`~rotomorph.errors.MaterialError` naming the key path, e.g.
``inks.lce.youngs_modulus.unit: 'kN' is not a unit of modulus; use one of 'MPa', …``.
"""

from __future__ import annotations

import re
from typing import Annotated, Any, Final, Literal

from pydantic import (
    AfterValidator,
    BaseModel,
    ConfigDict,
    Field,
    ValidationError,
    field_validator,
    model_validator,
)

from rotomorph._text import check_text
from rotomorph.errors import InvalidParameterError, MaterialError
from rotomorph.materials.units import to_canonical
from rotomorph.materials.value_ranges import (
    DIMENSION,
    SPEED_RANGE,
    check_range,
    convert_value,
)

__all__ = [
    "PROVENANCES",
    "SCHEMA_VERSION",
    "ActiveInk",
    "MaterialsDocument",
    "PassiveInk",
    "Value",
    "validate_document",
]

SCHEMA_VERSION: Final = 1
PROVENANCES: Final = ("measured", "cited", "assumed", "calibrated")
Provenance = Literal["measured", "cited", "assumed", "calibrated"]
#: Ink names are one word (they are written into G-code comments and design files).
INK_NAME: Final = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.+-]{0,63}$")


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False, strict=True)


def _one_line(text: str) -> str:
    return check_text(text)


def _free_text(text: str) -> str:
    return check_text(text, newlines=True)


#: Text from the file: shown on terminals, in reports and in G-code comments, so no control,
#: line-separator or bidirectional-formatting character (:func:`rotomorph._text.check_text`).
Text = Annotated[str, Field(max_length=2000), AfterValidator(_one_line)]
#: A ``description`` may keep newlines and tabs.
FreeText = Annotated[str, Field(max_length=2000), AfterValidator(_free_text)]
Word = Annotated[str, Field(max_length=64), AfterValidator(_one_line)]


class Value(_Model):
    """One value with its unit and where it comes from (see module docstring)."""

    value: float
    unit: Annotated[str, Field(max_length=20), AfterValidator(_one_line)]
    provenance: Provenance
    source: Text = Field(min_length=1)
    sd: float | None = Field(None, ge=0)
    temperature: float | None = Field(None, ge=-273.15, le=1000, description="°C")
    interval: list[float] | None = Field(None, min_length=2, max_length=2)


class Ratio(Value):
    """The active ink's modulus at full actuation relative to a passive ink's at the same
    temperature."""

    relative_to: Annotated[str, Field(min_length=1, max_length=64), AfterValidator(_one_line)]


class Curve(_Model):
    """The order parameter S measured at print speeds (interpolated linearly in ln v)."""

    speed: list[float] = Field(min_length=2, max_length=1000)
    speed_unit: Annotated[str, Field(max_length=20), AfterValidator(_one_line)] = "mm/s"
    value: list[float] = Field(min_length=2, max_length=1000)
    sd: list[float] | None = None
    unit: Annotated[str, Field(max_length=20), AfterValidator(_one_line)] = "1"
    provenance: Provenance
    source: Text = Field(min_length=1)


class _Converting(_Model):
    """A table of values converted to canonical units after validation, each checked
    against its physical range (:data:`~rotomorph.materials.value_ranges.RANGE`)."""

    @model_validator(mode="after")
    def _units(self) -> _Converting:
        updates = {}
        for key in type(self).model_fields:
            v = getattr(self, key)
            if isinstance(v, Value) and key in DIMENSION:
                updates[key] = convert_value(key, v)
                check_range(key, updates[key])
        for key, v in updates.items():
            object.__setattr__(self, key, v)
        return self


class Conditions(_Converting):
    """Temperatures the stored values refer to."""

    print_temperature: Value
    actuation_temperature: Value

    @model_validator(mode="after")
    def _order(self) -> Conditions:
        if not self.print_temperature.value < self.actuation_temperature.value:
            raise ValueError(
                "actuation_temperature.value: must exceed print_temperature (°C): the values "
                "at full actuation are those reached on heating from the print temperature"
            )
        return self


class NozzleGeometry(_Converting):
    """The printed section the calibration filaments were made with."""

    outlet_diameter: Value | None = None
    filament_radius: Value
    active_fraction: Value

    @model_validator(mode="after")
    def _ranges(self) -> NozzleGeometry:
        if not 0.01 <= self.filament_radius.value <= 10.0:
            got = self.filament_radius.value
            raise ValueError(f"filament_radius.value: must lie in [0.01, 10] mm; got {got}")
        if not 0.0 < self.active_fraction.value <= 1.0:
            raise ValueError(
                f"active_fraction.value: must lie in (0, 1]; got {self.active_fraction.value}"
            )
        return self


class _Ink(_Converting):
    description: FreeText = ""
    youngs_modulus: Value
    poisson_ratio: Value
    glass_transition: Value | None = None
    density: Value
    free_length: Value | None = None

    @model_validator(mode="after")
    def _physical(self) -> _Ink:
        if not self.youngs_modulus.value > 0:
            raise ValueError(
                f"youngs_modulus.value: must be > 0 MPa; got {self.youngs_modulus.value}"
            )
        if not -1.0 < self.poisson_ratio.value <= 0.5:
            raise ValueError(
                f"poisson_ratio.value: must lie in (-1, 0.5]; got {self.poisson_ratio.value}"
            )
        if not 0.01 <= self.density.value <= 30.0:
            raise ValueError(
                f"density.value: must lie in [0.01, 30] g/cm3; got {self.density.value}"
            )
        if self.free_length is not None and not 0.05 < self.free_length.value < 20.0:
            raise ValueError(
                f"free_length.value: must lie in (0.05, 20) (L/L0); got {self.free_length.value}"
            )
        if self.glass_transition is not None and self.glass_transition.value < -273.15:
            raise ValueError("glass_transition.value: must be >= -273.15 °C")
        return self


class ActiveInk(_Ink):
    """A liquid-crystal elastomer ink (actuates through its nematic-isotropic transition)."""

    kind: Literal["active"]
    modulus_law: Literal["nematic-isotropic"] = "nematic-isotropic"
    actuated_modulus_ratio: Ratio
    transition_temperature: Value
    transition_width: Value
    hysteresis: Value | None = None
    strain_law: Literal["threshold", "warner-terentjev"] = "threshold"
    strain_gain: Value | None = None
    strain_threshold: Value | None = None
    order_scale: Value | None = None
    order_parameter: Curve
    director_pitch: Value | None = None

    @model_validator(mode="after")
    def _law(self) -> ActiveInk:
        need = (
            ("strain_gain", "strain_threshold")
            if self.strain_law == "threshold"
            else ("order_scale",)
        )
        missing = [k for k in need if getattr(self, k) is None]
        if missing:
            raise ValueError(f"{missing[0]}: is required by strain_law = '{self.strain_law}'")
        other = {"strain_gain", "strain_threshold", "order_scale"} - set(need)
        extra = sorted(k for k in other if getattr(self, k) is not None)
        if extra:
            raise ValueError(
                f"{extra[0]}: is not used by strain_law = '{self.strain_law}'; remove it"
            )
        if self.strain_gain is not None and not self.strain_gain.value > 0:
            raise ValueError(
                "strain_gain.value: must be > 0 (the LCE contracts along its director)"
            )
        if self.order_scale is not None and not self.order_scale.value > 0:
            raise ValueError("order_scale.value: must be > 0")
        if not self.actuated_modulus_ratio.value > 0:
            raise ValueError("actuated_modulus_ratio.value: must be > 0")
        if not self.transition_width.value > 0:
            raise ValueError("transition_width.value: must be > 0 °C")
        if self.hysteresis is not None and self.hysteresis.value < 0:
            raise ValueError("hysteresis.value: must be >= 0 °C")
        if self.director_pitch is not None and not 0 < self.director_pitch.value <= 10:
            raise ValueError("director_pitch.value: must lie in (0, 10]")
        return self

    @field_validator("order_parameter")
    @classmethod
    def _curve(cls, c: Curve) -> Curve:
        if len(c.value) != len(c.speed) or (c.sd is not None and len(c.sd) != len(c.speed)):
            raise ValueError("value: needs one entry (and one sd) per measured speed")
        try:
            speeds = [to_canonical("speed", s, c.speed_unit) for s in c.speed]
        except InvalidParameterError as err:
            raise ValueError(f"speed_unit: {str(err).split(': ', 1)[-1]}") from None
        if c.unit.strip() != "1":
            raise ValueError(f"unit: {c.unit!r} is not the unit of an order parameter; use '1'")
        if any(s <= 0 for s in speeds) or len(set(speeds)) != len(speeds):
            raise ValueError("speed: must hold distinct print speeds > 0")
        if not SPEED_RANGE[0] <= min(speeds) <= max(speeds) <= SPEED_RANGE[1]:
            raise ValueError(
                f"speed: print speeds must lie in [{SPEED_RANGE[0]:g}, {SPEED_RANGE[1]:g}] mm/s; "
                f"got {min(speeds):g}-{max(speeds):g}"
            )
        if any(not 0.0 <= s < 1.0 for s in c.value):
            raise ValueError("value: must hold order parameters in [0, 1)")
        if c.sd is not None and any(s < 0 for s in c.sd):
            raise ValueError("sd: must be >= 0")
        return c.model_copy(update={"speed": speeds, "speed_unit": "mm/s"})


class PassiveInk(_Ink):
    """A passive elastomer ink (thermal expansion only)."""

    kind: Literal["passive"]
    modulus_law: Literal["entropic"] = "entropic"
    strain_law: Literal["linear"] = "linear"
    free_strain: Value

    @model_validator(mode="after")
    def _strain(self) -> PassiveInk:
        if not -0.5 < self.free_strain.value < 0.5:
            raise ValueError(
                f"free_strain.value: must lie in (-0.5, 0.5); got {self.free_strain.value}"
            )
        return self


Ink = Annotated[ActiveInk | PassiveInk, Field(discriminator="kind")]


class CalibrationRecord(_Model):
    """How the calibrated values were obtained (written by ``rotomorph calibrate``).

    ``parameters`` (``ink.key`` of the fitted values), ``coordinates`` (``ln`` or ``linear``:
    the fit coordinate of each) and ``covariance`` (the posterior covariance in those
    coordinates) carry the calibration's uncertainty to predictions (``rotomorph predict``'s
    band).
    """

    method: Text
    tables: list[Text] = Field(default_factory=list, max_length=1000)
    data_sha256: str = Field(pattern=r"^[0-9a-f]{64}$")
    chosen_branch: Text = ""
    branch_choice: Text = ""
    determined: list[Word] = Field(default_factory=list, max_length=100)
    at_prior: list[Word] = Field(default_factory=list, max_length=100)
    report: Text = ""
    parameters: list[str] = Field(default_factory=list, max_length=20)
    coordinates: list[Literal["ln", "linear"]] = Field(default_factory=list, max_length=20)
    covariance: list[list[float]] = Field(default_factory=list, max_length=20)

    @model_validator(mode="after")
    def _covariance(self) -> CalibrationRecord:
        n = len(self.parameters)
        if len(self.coordinates) != n or len(self.covariance) != n:
            raise ValueError(
                "covariance: needs one row, and coordinates one entry, per parameter "
                f"({n} parameters)"
            )
        for i, row in enumerate(self.covariance):
            if len(row) != n:
                raise ValueError(f"covariance: row {i} has {len(row)} entries, not {n}")
            if row[i] < 0:
                raise ValueError(f"covariance: a variance must be >= 0; got {row[i]} at [{i}][{i}]")
            for j in range(i):
                if abs(row[j] - self.covariance[j][i]) > 1e-9 * (1.0 + abs(row[j])):
                    raise ValueError(f"covariance: must be symmetric; [{i}][{j}] != [{j}][{i}]")
        for name in self.parameters:
            if not re.fullmatch(r"[A-Za-z0-9][A-Za-z0-9_.+-]{0,63}\.[a-z_]+", name):
                raise ValueError(f"parameters: {name!r} is not 'ink.key'")
        return self


class MaterialsDocument(_Model):
    """A validated materials file."""

    schema_version: Literal[1] = Field(SCHEMA_VERSION, description="format version; write 1")
    name: str = Field(min_length=1, max_length=100, pattern=INK_NAME.pattern)
    version: str = Field("1", max_length=40, pattern=r"^[A-Za-z0-9_.+-]+$")
    description: FreeText = ""
    strain_measure: Literal["hencky", "engineering"] = "hencky"
    conditions: Conditions
    nozzle: NozzleGeometry
    inks: dict[str, Ink] = Field(min_length=1, max_length=100)
    calibration: CalibrationRecord | None = None

    @model_validator(mode="after")
    def _consistent(self) -> MaterialsDocument:
        for key in self.calibration.parameters if self.calibration is not None else ():
            ink_name, _, value_key = key.rpartition(".")
            ink = self.inks.get(ink_name)
            if ink is None or not isinstance(getattr(ink, value_key, None), Value):
                raise ValueError(
                    f"calibration.parameters: {key!r} names no value of this file's inks (ink.key)"
                )
        for name, ink in self.inks.items():
            if not INK_NAME.match(name):
                shown = name.encode("unicode_escape").decode("ascii")
                raise ValueError(
                    f"inks: {shown!r} is not an ink name (letters, digits, _ . + -, at most 64)"
                )
            if isinstance(ink, ActiveInk):
                ref = self.inks.get(ink.actuated_modulus_ratio.relative_to)
                if not isinstance(ref, PassiveInk):
                    raise ValueError(
                        f"inks.{name}.actuated_modulus_ratio.relative_to: "
                        f"{ink.actuated_modulus_ratio.relative_to!r} is not a passive ink of "
                        "this file"
                    )
            elif ink.free_strain.temperature is not None and not _same(
                ink.free_strain.temperature, self.conditions.actuation_temperature.value
            ):
                raise ValueError(
                    f"inks.{name}.free_strain.temperature: the free strain is the one reached "
                    f"at the actuation temperature "
                    f"{self.conditions.actuation_temperature.value:g} °C; got "
                    f"{ink.free_strain.temperature:g}"
                )
        return self


def _same(a: float, b: float) -> bool:
    return abs(a - b) <= 1e-9 * max(1.0, abs(b))


def _location(loc: tuple[int | str, ...]) -> str:
    out: list[str] = []
    for part in loc:
        if isinstance(part, int):
            out.append(f"[{part}]")
        elif part in ("active", "passive") and out and not out[-1].startswith("["):
            continue  # discriminator tag of an ink
        else:
            text = str(part)
            text = text if text.isprintable() else text.encode("unicode_escape").decode("ascii")
            out.append(("." if out else "") + text)
    return "".join(out) or "<materials>"


def _message(err: Any) -> str:
    kind, got = err["type"], err.get("input")
    if kind == "extra_forbidden":
        return "unknown key; remove it or check its spelling (docs/design-files.md)"
    if kind == "missing":
        return "is required"
    if kind == "union_tag_invalid":
        return f"kind must be 'active' or 'passive'; got {err.get('ctx', {}).get('tag')!r}"
    if kind in ("float_type", "int_type"):
        return f"must be a number without quotes; got {got!r} ({type(got).__name__})"
    msg = str(err["msg"]).removeprefix("Value error, ")
    if kind != "value_error" and not isinstance(got, dict | list):
        msg += f"; got {got!r}"
    return msg


def validate_document(data: Any, name: str = "<materials>") -> MaterialsDocument:
    """Validate a parsed materials file (a mapping) into a :class:`MaterialsDocument`.

    Raises
    ------
    MaterialError
        The first problem, naming the key path and the fix (``name`` prefixes file-level
        problems such as a missing version).
    """
    if not isinstance(data, dict):
        raise MaterialError(name, "must be a TOML table of a materials file")
    if "schema_version" not in data:
        raise MaterialError(f"{name}: schema_version", "is required; add schema_version = 1")
    try:
        return MaterialsDocument.model_validate(data)
    except ValidationError as exc:
        first = exc.errors()[0]
        field = _location(first["loc"])
        msg = _message(first)
        nested = re.match(r"^([A-Za-z_][\w.\[\]]*): (.*)$", msg)
        if nested and first["type"] == "value_error":  # a cross-field check names its key
            key, msg = nested.group(1), nested.group(2)
            field = key if field == "<materials>" else f"{field}.{key}"
        raise MaterialError(field, msg) from None

"""Materials as parameter sets: one named, versioned file of inks, each value with its provenance.

A :class:`MaterialSet` is a validated materials file (:mod:`~rotomorph.materials.materials_schema`)
as a value: the inks as :class:`~rotomorph.materials.material.Material` s, the filament model
of any active/passive pair (:meth:`MaterialSet.filament_model`), every value with its unit,
provenance and source (:meth:`MaterialSet.values`), and the sha256 of its canonical content,
which every run that uses the set records. The paper's two inks ship as the default set
(``data/paper_inks.toml``, :func:`default_materials`); a lab's own file is read with
:func:`rotomorph.io.materials_file.load_materials` or written by ``rotomorph calibrate``.

Two sets are equal when their contents are (same sha256), whatever file they came from.
"""

from __future__ import annotations

import hashlib
import json
import math
from dataclasses import dataclass, field, replace
from functools import lru_cache
from importlib import resources
from typing import TYPE_CHECKING, Any, Final

import numpy as np

from rotomorph.errors import MaterialError
from rotomorph.materials.inference import Fit, Parameter, get_parameter
from rotomorph.materials.material import Material
from rotomorph.materials.materials_schema import (
    ActiveInk,
    MaterialsDocument,
    PassiveInk,
    Value,
    validate_document,
)
from rotomorph.materials.process import EmpiricalThreshold, WarnerTerentjev

if TYPE_CHECKING:
    from rotomorph.materials.natural import FilamentModel

try:  # Python >= 3.11
    import tomllib
except ModuleNotFoundError:  # pragma: no cover - Python 3.10
    import tomli as tomllib  # type: ignore[no-redef]

__all__ = ["DEFAULT_FILE", "MaterialSet", "ValueRow", "default_materials", "materials_from_mapping"]

#: The paper's inks (package data).
DEFAULT_FILE: Final = "data/paper_inks.toml"


@dataclass(frozen=True)
class ValueRow:
    """One value of a set: ink (or ``conditions`` / ``nozzle``), key, value in its unit, sd,
    provenance and source."""

    owner: str
    key: str
    value: float | str
    unit: str
    sd: float | None
    provenance: str
    source: str


def _sha256(document: MaterialsDocument) -> str:
    blob = json.dumps(document.model_dump(mode="json"), sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(blob.encode()).hexdigest()


@dataclass(frozen=True, eq=False, repr=False)
class MaterialSet:
    """A validated materials file (see module docstring).

    Build with :func:`materials_from_mapping` (or read a file with
    :func:`rotomorph.io.materials_file.load_materials`).

    Attributes
    ----------
    document
        The validated file in canonical units.
    source
        Where it was read from (a path, ``"<package>"`` or ``"<inline>"``); not part of its
        identity.
    """

    document: MaterialsDocument
    source: str = "<inline>"
    sha256: str = field(init=False)
    _materials: dict[str, Material] = field(init=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "sha256", _sha256(self.document))
        object.__setattr__(
            self,
            "_materials",
            {name: _material(name, ink, self.document) for name, ink in self.document.inks.items()},
        )

    # -- identity ------------------------------------------------------------------------
    def __eq__(self, other: object) -> bool:
        return isinstance(other, MaterialSet) and other.sha256 == self.sha256

    def __hash__(self) -> int:
        return hash(self.sha256)

    def __repr__(self) -> str:
        return f"MaterialSet({self.name!r}, sha256={self.sha256[:12]})"

    @property
    def name(self) -> str:
        """Name of the set (``name`` key)."""
        return self.document.name

    @property
    def version(self) -> str:
        """Version of the set (``version`` key)."""
        return self.document.version

    def record(self) -> dict[str, Any]:
        """What a run stores about the set it used: name, version, sha256, source."""
        return {
            "name": self.name,
            "version": self.version,
            "sha256": self.sha256,
            "source": self.source,
        }

    # -- inks ----------------------------------------------------------------------------
    def names(self, kind: str | None = None) -> tuple[str, ...]:
        """Ink names of the set (of one ``kind``: ``"active"`` or ``"passive"``), in file order."""
        return tuple(n for n, i in self.document.inks.items() if kind is None or i.kind == kind)

    def material(self, name: str) -> Material:
        """The ink ``name`` as a :class:`Material` (exact name).

        Raises
        ------
        MaterialError
            Unknown name; the message lists the set's inks.
        """
        try:
            return self._materials[str(name)]
        except KeyError:
            raise MaterialError(
                "material",
                f"unknown ink {name!r} in materials {self.name!r}; its inks: "
                f"{', '.join(self.names())}",
            ) from None

    def ink(self, name: str) -> ActiveInk | PassiveInk:
        """The validated entry of ink ``name``."""
        self.material(name)
        return self.document.inks[name]

    @property
    def materials(self) -> dict[str, Material]:
        """Name → :class:`Material` of every ink (a copy)."""
        return dict(self._materials)

    # -- model ---------------------------------------------------------------------------
    def modulus_ratio(self, active: str, passive: str) -> float:
        """E_a/E_p at full actuation of the pair (dimensionless).

        The active ink stores its actuated modulus relative to one passive ink; for another
        passive ink the ratio scales by their moduli at the print temperature (both follow
        the same temperature law, so the scale holds at every temperature).
        """
        ink = self._active(active)
        self._passive(passive)
        ratio = ink.actuated_modulus_ratio
        ref = self.material(ratio.relative_to).youngs_modulus
        return float(ratio.value * (ref / self.material(passive).youngs_modulus))

    def order_points(self, active: str) -> tuple[tuple[float, float], ...]:
        """(speed mm/s, S) pairs of the active ink's order parameter."""
        curve = self._active(active).order_parameter
        return tuple((float(v), float(s)) for v, s in zip(curve.speed, curve.value, strict=True))

    def filament_model(self, active: str, passive: str, **changes: Any) -> FilamentModel:
        """The :class:`~rotomorph.materials.natural.FilamentModel` of this active/passive pair.

        Strain law, order parameter, modulus ratio at actuation, passive free strain,
        transition, director pitch and reference temperatures come from the set; the model
        carries the set (``materials``) so that every layer looks its inks up here. ``changes``
        override model fields (e.g. ``resolution``).
        """
        from rotomorph.materials.natural import FilamentModel

        values = self.model_values(active, passive)
        values.update(changes)
        return FilamentModel(**values)

    def model_values(self, active: str, passive: str) -> dict[str, Any]:
        """The :class:`~rotomorph.materials.natural.FilamentModel` fields of the pair (see
        :meth:`filament_model`), as keyword arguments."""
        a, p = self._active(active), self._passive(passive)
        doc = self.document
        measure = doc.strain_measure
        points = self.order_points(active)
        law: Any
        if a.strain_law == "threshold":
            assert a.strain_gain is not None and a.strain_threshold is not None
            law = EmpiricalThreshold(
                gain=a.strain_gain.value,
                threshold=a.strain_threshold.value,
                measure=measure,
                order_points=points,
            )
        else:
            assert a.order_scale is not None
            law = WarnerTerentjev(
                measure=measure, order_scale=a.order_scale.value, order_points=points
            )
        values: dict[str, Any] = {
            "strain_model": law,
            "modulus_ratio": self.modulus_ratio(active, passive),
            "passive_strain": p.free_strain.value,
            "transition_width": a.transition_width.value,
            "hysteresis": 0.0 if a.hysteresis is None else a.hysteresis.value,
            "director_pitch": 1.0 if a.director_pitch is None else a.director_pitch.value,
            "print_temperature": doc.conditions.print_temperature.value,
            "actuation_temperature": doc.conditions.actuation_temperature.value,
            "materials": self,
        }
        return values

    def _active(self, name: str) -> ActiveInk:
        ink = self.ink(name)
        if not isinstance(ink, ActiveInk):
            raise MaterialError("active_material", f"{name!r} is a passive ink; give an active one")
        return ink

    def _passive(self, name: str) -> PassiveInk:
        ink = self.ink(name)
        if not isinstance(ink, PassiveInk):
            raise MaterialError(
                "passive_material", f"{name!r} is an active ink; give a passive one"
            )
        return ink

    def calibration_fit(
        self, active: str, passive: str, *, resolution: int | None = 64
    ) -> Fit | None:
        """The calibration's posterior for the pair's model, for propagating its uncertainty
        (:meth:`~rotomorph.materials.inference.Fit.propagate`), or ``None`` when the file stores
        no covariance (``[calibration] parameters, coordinates, covariance``).

        The fitted values that are fields of the pair's model (the modulus ratio, the strain
        law's gain and threshold, the passive free strain when ``passive`` is the calibrated
        ink, the transition width) keep their joint covariance; the others (T_NI) are
        marginalised out (their block of the covariance dropped). ``resolution`` is the section
        mesh of the sensitivities (the fit's; ``None``: the model's default).
        """
        cal = self.document.calibration
        if cal is None or not cal.parameters:
            return None
        keys = {
            f"{active}.actuated_modulus_ratio": "modulus_ratio",
            f"{active}.strain_gain": "strain_model.gain",
            f"{active}.strain_threshold": "strain_model.threshold",
            f"{active}.transition_width": "transition_width",
            f"{passive}.free_strain": "passive_strain",
        }
        model = self.filament_model(active, passive)
        if resolution is not None:
            model = replace(model, resolution=resolution)
        rows = [i for i, name in enumerate(cal.parameters) if name in keys]
        if not rows:
            return None
        cov = np.array(cal.covariance, dtype=float)[np.ix_(rows, rows)]
        params, theta = [], []
        for k, i in enumerate(rows):
            name = keys[cal.parameters[i]]
            log = cal.coordinates[i] == "ln"
            value = float(get_parameter(model, name))
            t = math.log(value) if log else value
            sd = math.sqrt(max(cov[k, k], 0.0)) or 1e-12
            params.append(Parameter(name, t, sd, log=log, reason="from the materials file"))
            theta.append(t)
        return Fit(
            label=cal.chosen_branch or "materials file",
            parameters=tuple(params),
            theta=np.array(theta),
            covariance=cov,
            model=model,
            chi2_data=float("nan"),
            chi2_prior=float("nan"),
            n_data=0,
            at_bound=(),
            success=True,
            base=model,
        )

    # -- provenance ----------------------------------------------------------------------
    def values(self) -> list[ValueRow]:
        """Every value of the set with its unit, sd, provenance and source (for reports)."""
        rows: list[ValueRow] = []
        doc = self.document

        def add(owner: str, key: str, v: Any) -> None:
            if isinstance(v, Value):
                rows.append(ValueRow(owner, key, v.value, v.unit, v.sd, v.provenance, v.source))

        for part in ("conditions", "nozzle"):
            table = getattr(doc, part)
            for key in type(table).model_fields:
                add(part, key, getattr(table, key))
        for name, ink in doc.inks.items():
            for key in type(ink).model_fields:
                add(name, key, getattr(ink, key))
            if isinstance(ink, ActiveInk):
                c = ink.order_parameter
                text = ", ".join(
                    f"{s:g} at {v:g} mm/s" for v, s in zip(c.speed, c.value, strict=True)
                )
                rows.append(
                    ValueRow(name, "order_parameter", text, "1", None, c.provenance, c.source)
                )
        return rows


def _material(name: str, ink: ActiveInk | PassiveInk, doc: MaterialsDocument) -> Material:
    """The :class:`Material` of one ink (its values at the print temperature)."""
    sources, assumptions = [f"materials {doc.name!r} (version {doc.version})"], []
    for key in type(ink).model_fields:
        v = getattr(ink, key)
        if isinstance(v, Value):
            if v.provenance == "assumed":
                assumptions.append(f"{key} {v.value:g} {v.unit} assumed: {v.source}")
            else:
                sources.append(f"{key} ({v.provenance}): {v.source}")
    if ink.free_length is not None:
        length = ink.free_length.value
        length_sd = ink.free_length.sd or 0.0
    else:  # not given: the model's own free length at full actuation (derived, stated)
        if isinstance(ink, PassiveInk):
            eps = ink.free_strain.value
        else:
            fastest = max(ink.order_parameter.speed)
            law = _law(ink, doc)
            eps = float(law.active_strains(fastest)[0])
        length = math.exp(eps) if doc.strain_measure == "hencky" else 1.0 + eps
        length_sd = 0.0
        assumptions.append(
            f"actuation_length {length:.4g} derived from the model's free strain (not measured)"
        )
    return Material(
        name=name,
        kind=ink.kind,
        youngs_modulus=ink.youngs_modulus.value,
        youngs_modulus_spread=ink.youngs_modulus.sd or 0.0,
        poisson_ratio=ink.poisson_ratio.value,
        glass_transition=None if ink.glass_transition is None else ink.glass_transition.value,
        transition_temperature=(
            ink.transition_temperature.value if isinstance(ink, ActiveInk) else None
        ),
        actuation_length=length,
        actuation_length_spread=length_sd,
        density=ink.density.value,
        source=tuple(sources),
        assumptions=tuple(assumptions),
    )


def _law(ink: ActiveInk, doc: MaterialsDocument) -> EmpiricalThreshold | WarnerTerentjev:
    points = tuple(zip(ink.order_parameter.speed, ink.order_parameter.value, strict=True))
    if ink.strain_law == "threshold":
        assert ink.strain_gain is not None and ink.strain_threshold is not None
        return EmpiricalThreshold(
            ink.strain_gain.value, ink.strain_threshold.value, doc.strain_measure, points
        )
    assert ink.order_scale is not None
    return WarnerTerentjev(doc.strain_measure, ink.order_scale.value, points)


def materials_from_mapping(data: Any, source: str = "<inline>") -> MaterialSet:
    """A :class:`MaterialSet` from a parsed materials file (a mapping).

    Raises
    ------
    MaterialError
        The first problem, naming the key path (``inks.lce.youngs_modulus.unit: …``).
    """
    return MaterialSet(validate_document(data, source), source)


@lru_cache(maxsize=1)
def default_materials() -> MaterialSet:
    """The paper's inks (``data/paper_inks.toml``): the package's default set."""
    text = resources.files("rotomorph.materials").joinpath(DEFAULT_FILE).read_text("utf-8")
    return materials_from_mapping(tomllib.loads(text), "<package>/paper_inks.toml")

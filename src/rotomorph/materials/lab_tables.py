"""A lab's measurement tables as values: what each quantity means, its units and its role.

Measurement files are CSV with the columns ``quantity, condition, x, x_unit, value, spread,
unit, source`` (:mod:`rotomorph.io.measurement_csv` reads them; the format is documented in
``docs/design-files.md``, *Measurement tables*). Each row is one measured mean with its
standard deviation; ``condition`` holds the fixed conditions of the row as ``key=value unit``
parts separated by ``;`` (e.g. ``active=lce; v=3 mm/s``), other text in it is a label.

:data:`QUANTITIES` lists what a table may hold, the dimension of ``x`` and of the value, the
conditions each row needs, and its role in a calibration:

* ``fit``: fitted (a group of the joint calibration and of its leave-one-group-out check);
* ``input``: used as given (the order parameter's points, the moduli at the print temperature);
* ``value``: a property of an ink stored as measured (glass transition, density, Poisson ratio);
* ``validation``: never fitted, only predicted (sinusoid end-to-end ratios, lattice areas).
"""

from __future__ import annotations

import hashlib
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Final, Literal

import numpy as np

from rotomorph._typing import FloatArray
from rotomorph.materials.measurements import MeasuredTable

__all__ = [
    "CONDITION_KEYS",
    "QUANTITIES",
    "Measurement",
    "MeasurementSet",
    "Quantity",
    "data_sha256",
]

Role = Literal["fit", "input", "value", "validation"]


@dataclass(frozen=True)
class Quantity:
    """What a measured quantity is (see module docstring).

    Attributes
    ----------
    name
        The ``quantity`` column's word.
    meaning
        What is measured, in words.
    x
        Dimension of ``x`` (:mod:`~rotomorph.materials.units`), or ``None`` (no ``x``).
    value
        Dimension of ``value`` and ``spread``.
    role
        ``fit``, ``input``, ``value`` or ``validation``.
    ink
        Whether each row names its ink (``active=NAME`` or ``passive=NAME``): ``"either"``,
        ``"active"``, or ``None`` (a filament of both inks).
    required, optional
        Condition keys each row must (may) give.
    curve
        Whether the quantity is a curve in ``x`` (needs >= 2 distinct ``x``; the passive ink's
        free length, one number of a linear law, excepted).
    x_range, value_range
        Physically possible ranges (canonical units, ends excluded).
    """

    name: str
    meaning: str
    x: str | None
    value: str
    role: Role
    ink: Literal["either", "active"] | None = None
    required: tuple[str, ...] = ()
    optional: tuple[str, ...] = ()
    curve: bool = False
    x_range: tuple[float, float] = (-np.inf, np.inf)
    value_range: tuple[float, float] = (-np.inf, np.inf)


_T = (-273.15, 1000.0)
_V = (0.0, 1000.0)
QUANTITIES: Final[dict[str, Quantity]] = {
    q.name: q
    for q in (
        Quantity(
            "janus_curvature",
            "natural curvature K_J of half-and-half filaments printed without rotation, heated "
            "to the actuation temperature, vs print speed",
            "speed",
            "curvature",
            "fit",
            optional=("T",),
            curve=True,
            x_range=_V,
            value_range=(-100.0, 100.0),
        ),
        Quantity(
            "pure_lce_length",
            "end-to-end ratio L/L0 of pure active filaments vs rotation number omega*",
            "ratio",
            "ratio",
            "fit",
            required=("v",),
            optional=("T",),
            x_range=(-100.0, 100.0),
            value_range=(0.0, 10.0),
        ),
        Quantity(
            "composite_length",
            "end-to-end ratio L/L0 of Janus filaments vs rotation number omega*",
            "ratio",
            "ratio",
            "fit",
            required=("v",),
            optional=("T",),
            x_range=(-100.0, 100.0),
            value_range=(0.0, 10.0),
        ),
        Quantity(
            "free_length",
            "free length L/L0 of one ink vs temperature (the active ink: pure filaments "
            "printed at speed v without rotation)",
            "temperature",
            "ratio",
            "fit",
            ink="either",
            optional=("v",),
            curve=True,
            x_range=_T,
            value_range=(0.0, 10.0),
        ),
        Quantity(
            "youngs_modulus",
            "tensile Young's modulus of one ink vs temperature",
            "temperature",
            "modulus",
            "fit",
            ink="either",
            x_range=_T,
            value_range=(0.0, 1e5),
        ),
        Quantity(
            "order_parameter",
            "nematic order parameter S of the printed active ink vs print speed (WAXS)",
            "speed",
            "ratio",
            "input",
            ink="active",
            curve=True,
            x_range=_V,
            value_range=(-1e-12, 1.0),
        ),
        Quantity(
            "glass_transition",
            "glass-transition temperature of one ink (DSC)",
            None,
            "temperature",
            "value",
            ink="either",
            value_range=_T,
        ),
        Quantity(
            "density",
            "mass density of one cured ink",
            None,
            "density",
            "value",
            ink="either",
            value_range=(0.0, 30.0),
        ),
        Quantity(
            "poisson_ratio",
            "Poisson ratio of one cured ink",
            None,
            "ratio",
            "value",
            ink="either",
            value_range=(-1.0, 0.5 + 1e-12),
        ),
        Quantity(
            "sinusoid_end_to_end",
            "end-to-end ratio of a sinusoidal filament whose active half is kept on one side",
            None,
            "ratio",
            "validation",
            required=("side", "A", "wavelength", "periods", "v"),
            value_range=(0.0, 10.0),
        ),
        Quantity(
            "lattice_area",
            "area change of a printed sinusoidal lattice on heating (100 (A/A0 - 1), %)",
            None,
            "percent",
            "validation",
            required=("pattern", "n", "l", "A", "v"),
            optional=("layers", "ghost_nodes"),
            value_range=(-100.0, 10000.0),
        ),
    )
}

#: Condition keys: their dimension (``"text"`` for words) and meaning.
CONDITION_KEYS: Final[dict[str, tuple[str, str]]] = {
    "active": ("text", "name of the active ink the row measures"),
    "passive": ("text", "name of the passive ink the row measures"),
    "v": ("speed", "print speed"),
    "T": ("temperature", "temperature of the measurement (default: the actuation temperature)"),
    "side": ("text", "side of the curvature the active half is kept on: outer or inner"),
    "A": ("length", "sine amplitude"),
    "wavelength": ("length", "sine wavelength"),
    "periods": ("ratio", "number of sine periods"),
    "pattern": ("text", "lattice pattern: expanding or contracting"),
    "n": ("ratio", "branch nodes per lattice side"),
    "l": ("length", "lattice cell size (branch-node spacing)"),
    "layers": ("ratio", "printed layers of the lattice"),
    "ghost_nodes": ("ratio", "rod nodes per lattice edge of the prediction"),
}


@dataclass(frozen=True)
class Measurement:
    """One row of a measurement table, in canonical units (mm, s, MPa, °C).

    Attributes
    ----------
    file, row
        Where it was read (file name, line number).
    quantity
        Key of :data:`QUANTITIES`.
    conditions
        Condition keys → values (canonical units; names and words as text).
    label
        The condition column as written (for reports).
    x
        Control value (NaN for quantities without one).
    value, spread
        Measured mean and standard deviation.
    source
        Where the number comes from.
    provenance
        ``"measured"`` (the lab's own) or ``"cited"`` (from a publication: ``source``).
    """

    file: str
    row: int
    quantity: str
    conditions: Mapping[str, float | str]
    label: str
    x: float
    value: float
    spread: float
    source: str
    provenance: str = "measured"

    @property
    def ink(self) -> tuple[str, str] | None:
        """``(role, name)`` of the ink the row measures, if it names one."""
        for role in ("active", "passive"):
            if role in self.conditions:
                return role, str(self.conditions[role])
        return None

    @property
    def where(self) -> str:
        """``file: row N`` (for messages)."""
        return f"{self.file}: row {self.row}"


def data_sha256(contents: list[bytes]) -> str:
    """sha256 (hex) of a set of measurement files: of their sorted content hashes, so neither
    their names nor their order on the command line change it."""
    digests = sorted(hashlib.sha256(c).digest() for c in contents)
    return hashlib.sha256(b"".join(digests)).hexdigest()


@dataclass(frozen=True, eq=False)
class MeasurementSet:
    """All rows of a calibration's measurement files.

    Attributes
    ----------
    rows
        The measurements, in file and row order.
    files
        ``(name, sha256)`` of every file read.
    sha256
        :func:`data_sha256` of the files' contents.
    """

    rows: tuple[Measurement, ...]
    files: tuple[tuple[str, str], ...] = ()
    sha256: str = ""
    _by: dict[str, tuple[Measurement, ...]] = field(init=False, repr=False)

    def __post_init__(self) -> None:
        by: dict[str, list[Measurement]] = {}
        for m in self.rows:
            by.setdefault(m.quantity, []).append(m)
        object.__setattr__(self, "_by", {k: tuple(v) for k, v in by.items()})

    def of(self, quantity: str, ink: str | None = None) -> tuple[Measurement, ...]:
        """Rows of ``quantity`` (of ink role ``ink``, ``"active"`` or ``"passive"``)."""
        rows = self._by.get(quantity, ())
        if ink is None:
            return rows
        return tuple(m for m in rows if m.ink is not None and m.ink[0] == ink)

    def quantities(self) -> tuple[str, ...]:
        """The quantities present, in :data:`QUANTITIES` order."""
        return tuple(q for q in QUANTITIES if q in self._by)

    def ink_names(self) -> dict[str, str]:
        """``{"active": name, "passive": name}`` named by the rows (either may be missing)."""
        out: dict[str, str] = {}
        for m in self.rows:
            if m.ink is not None:
                out.setdefault(m.ink[0], m.ink[1])
        return out


def table(name: str, rows: tuple[Measurement, ...] | list[Measurement]) -> MeasuredTable:
    """The rows as a :class:`~rotomorph.materials.measurements.MeasuredTable` named ``name``."""
    x: FloatArray = np.array([m.x for m in rows], dtype=float)
    return MeasuredTable(
        name=name,
        condition=tuple(m.label for m in rows),
        x=x,
        x_unit=tuple("" for _ in rows),
        value=np.array([m.value for m in rows], dtype=float),
        spread=np.array([m.spread for m in rows], dtype=float),
        unit=tuple("" for _ in rows),
        source=tuple(f"{m.where}: {m.source}" for m in rows),
    )

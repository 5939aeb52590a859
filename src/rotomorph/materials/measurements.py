"""Measured tables of the seed paper, shipped as CSV in ``materials/data/``.

Every table has the columns ``condition, x, x_unit, value, spread, unit, source`` where
``condition`` is a human label, ``x`` the numerical control variable (print speed v in mm/s,
dimensionless rotation rate ω*, temperature in °C; empty when none), ``spread`` the reported
standard deviation (n = 3 in the paper) and ``source`` the figure of the paper.

Available tables (see :func:`table_names`): ``order_parameter`` (S vs v), ``janus_curvature``
(K_J vs v, ω* = 0), ``pure_lce_length`` (L/L0 vs ω*, v = 3 mm/s), ``composite_length``
(L/L0 vs ω*), ``normalized_length`` (bulk controls at 150 °C), ``sinusoid_end_to_end``
(1.37 ± 0.07 and 0.64 ± 0.05), ``lattice_area`` (+99 ± 11 % and -28 ± 11 %).
"""

from __future__ import annotations

import csv
import io
from dataclasses import dataclass
from importlib import resources

import numpy as np

from rotomorph._typing import BoolArray, FloatArray
from rotomorph.errors import InvalidParameterError

_DATA = "data"


@dataclass(frozen=True, eq=False)
class MeasuredTable:
    """One measured quantity of the paper as a function of a control variable.

    Parameters
    ----------
    name
        Table name (file stem), e.g. ``"janus_curvature"``.
    condition
        Row labels ``(n,)``.
    x
        Control variable ``(n,)`` in ``x_unit`` (NaN when the row has none).
    x_unit
        Unit of ``x`` per row (``"mm/s"``, ``"1"``, ``"C"`` or empty).
    value, spread
        Measured value and standard deviation ``(n,)`` in ``unit``.
    unit
        Unit of ``value`` per row (``"1/mm"``, ``"1"``, ``"%"``).
    source
        Figure of the paper per row.
    """

    name: str
    condition: tuple[str, ...]
    x: FloatArray
    x_unit: tuple[str, ...]
    value: FloatArray
    spread: FloatArray
    unit: tuple[str, ...]
    source: tuple[str, ...]

    def __post_init__(self) -> None:
        n = len(self.condition)
        for attr in ("x", "value", "spread"):
            arr = np.asarray(getattr(self, attr), dtype=float).reshape(-1)
            if arr.shape != (n,):
                raise InvalidParameterError(
                    f"MeasuredTable.{attr}", f"must have {n} entries; got {arr.shape[0]}"
                )
            object.__setattr__(self, attr, arr)
        if not np.all(np.isfinite(self.value)):
            raise InvalidParameterError("MeasuredTable.value", "must be finite")
        if np.any(~np.isfinite(self.spread)) or np.any(self.spread < 0.0):
            raise InvalidParameterError("MeasuredTable.spread", "must be finite and >= 0")

    def __len__(self) -> int:
        return len(self.condition)

    def select(self, rows: BoolArray | list[int] | tuple[int, ...]) -> MeasuredTable:
        """Sub-table of the given row indices or boolean mask."""
        idx = np.arange(len(self))[np.asarray(rows)]
        return MeasuredTable(
            name=self.name,
            condition=tuple(self.condition[i] for i in idx),
            x=self.x[idx],
            x_unit=tuple(self.x_unit[i] for i in idx),
            value=self.value[idx],
            spread=self.spread[idx],
            unit=tuple(self.unit[i] for i in idx),
            source=tuple(self.source[i] for i in idx),
        )

    def near(self, x: float, *, rtol: float = 1e-9) -> int:
        """Index of the row whose ``x`` equals ``x`` (relative tolerance ``rtol``)."""
        hits = np.flatnonzero(np.isclose(self.x, x, rtol=rtol, atol=0.0))
        if len(hits) == 0:
            raise InvalidParameterError(
                f"{self.name}.x", f"no row at x = {x}; available: {self.x.tolist()}"
            )
        return int(hits[0])


def table_names() -> tuple[str, ...]:
    """Names of the shipped measured tables, sorted."""
    folder = resources.files("rotomorph.materials").joinpath(_DATA)
    names = [p.name[:-4] for p in folder.iterdir() if p.name.endswith(".csv")]
    return tuple(sorted(n for n in names if n != "materials"))


def load_table(name: str) -> MeasuredTable:
    """Load a measured table of the paper by name (package data, via ``importlib.resources``).

    Raises
    ------
    InvalidParameterError
        Unknown table name (the message lists the available ones).
    """
    if name not in table_names():
        raise InvalidParameterError(
            "load_table.name", f"unknown table {name!r}; available: {', '.join(table_names())}"
        )
    text = resources.files("rotomorph.materials").joinpath(f"{_DATA}/{name}.csv").read_text("utf-8")
    rows = list(csv.DictReader(io.StringIO(text)))
    return MeasuredTable(
        name=name,
        condition=tuple(r["condition"] for r in rows),
        x=np.array([float(r["x"]) if r["x"].strip() else np.nan for r in rows]),
        x_unit=tuple(r["x_unit"] for r in rows),
        value=np.array([float(r["value"]) for r in rows]),
        spread=np.array([float(r["spread"]) for r in rows]),
        unit=tuple(r["unit"] for r in rows),
        source=tuple(r["source"] for r in rows),
    )

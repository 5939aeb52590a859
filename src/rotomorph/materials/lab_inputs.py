"""What a lab's measurement tables give as measured: the inputs of a calibration.

The moduli at the print temperature (weighted means), the order parameter's points, the
glass transitions, densities and Poisson ratios (assumed where no table gives them, and said
so), and the rows of each fitted group (:data:`GROUPS`). Every value carries its provenance
(``measured``, or ``cited`` when every row it comes from is) and the rows it was read from.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import PurePath
from typing import Final

import numpy as np

from rotomorph.errors import InvalidParameterError
from rotomorph.materials.lab_tables import Measurement, MeasurementSet
from rotomorph.materials.process import PAPER_ORDER_POINTS

__all__ = ["GROUPS", "cite", "groups", "ink_inputs", "order_points", "provenance", "weighted"]

GROUPS: Final = (
    ("janus_curvature", None),
    ("pure_lce_length", None),
    ("composite_length", None),
    ("free_length", "active"),
    ("free_length", "passive"),
    ("youngs_modulus", "active"),
    ("youngs_modulus", "passive"),
)


def weighted(rows: Sequence[Measurement]) -> tuple[float, float]:
    w = np.array([1.0 / m.spread**2 for m in rows])
    v = np.array([m.value for m in rows])
    return float(np.sum(w * v) / np.sum(w)), float(1.0 / math.sqrt(np.sum(w)))


def cite(rows: Sequence[Measurement]) -> str:
    """``name.csv rows 3, 4 (source)``: the file's name (not its folder: the file written is
    the same wherever the tables were read from; the data hash identifies them)."""
    files: dict[str, list[int]] = {}
    for m in rows:
        files.setdefault(PurePath(m.file).name, []).append(m.row)
    parts = [
        f"{f} row{'s' if len(r) > 1 else ''} {', '.join(map(str, r))}" for f, r in files.items()
    ]
    first = rows[0].source if rows else ""
    return f"{'; '.join(parts)} ({first})" if first else "; ".join(parts)


def provenance(rows: Sequence[Measurement]) -> str:
    """``cited`` when every row is cited from a publication, else ``measured``."""
    return "cited" if rows and all(m.provenance == "cited" for m in rows) else "measured"


def ink_inputs(
    data: MeasurementSet, role: str, name: str, t_print: float
) -> dict[str, tuple[float, float | None, str, str]]:
    """(value, sd, provenance, source) of an ink's measured or assumed single values."""
    moduli = [m for m in data.of("youngs_modulus", role) if abs(m.x - t_print) <= 0.5]
    if not moduli:
        raise InvalidParameterError(
            "MEASUREMENTS",
            f"missing measurement: youngs_modulus of the {role} ink {name!r} at the print "
            f"temperature {t_print:g} °C (a tensile test; condition {role}={name})",
        )
    out: dict[str, tuple[float, float | None, str, str]] = {}
    e, sd = weighted(moduli)
    out["youngs_modulus"] = (e, sd, provenance(moduli), cite(moduli))
    defaults = {
        "poisson_ratio": (0.5, "incompressible elastomer (no poisson_ratio table)"),
        "density": (1.1, "typical acrylate elastomer (no density table); only the weight uses it"),
    }
    for key in ("poisson_ratio", "density", "glass_transition"):
        rows = data.of(key, role)
        if rows:
            v, s = weighted(rows)
            out[key] = (v, s, provenance(rows), cite(rows))
        elif key in defaults:
            out[key] = (defaults[key][0], None, "assumed", defaults[key][1])
    return out


def groups(data: MeasurementSet, t_print: float) -> dict[str, tuple[Measurement, ...]]:
    out: dict[str, tuple[Measurement, ...]] = {}
    for quantity, role in GROUPS:
        rows = data.of(quantity, role)
        if quantity == "youngs_modulus":  # the print-temperature rows are inputs
            rows = tuple(m for m in rows if abs(m.x - t_print) > 0.5)
        if rows:
            out[quantity if role is None else f"{quantity}_{role}"] = rows
    return out


def order_points(
    data: MeasurementSet,
) -> tuple[tuple[tuple[float, float], ...], tuple[float, ...] | None, str, str]:
    rows = data.of("order_parameter")
    if not rows:
        return (
            PAPER_ORDER_POINTS,
            None,
            "assumed",
            "no order_parameter table: the paper's WAXS points (Abdelrahman et al., Supp. "
            "Figs 8-9) are assumed; S is then only the coordinate of the strain law",
        )
    speeds = sorted({m.x for m in rows})
    points, sds = [], []
    for v in speeds:
        mean, sd = weighted([m for m in rows if m.x == v])
        points.append((v, mean))
        sds.append(sd)
    return tuple(points), tuple(sds), provenance(rows), cite(rows)

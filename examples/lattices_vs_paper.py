"""Lattices against the paper
==========================

Lattices vs the paper (Fig. 3/4): one JSON line per quantity.

Calibration (honest, one number): the sinusoid amplitude A/l is chosen so that a free expanding
edge reaches the paper's end-to-end ratio 1.37 at the end of the ramp (reading (b), x = 0.75,
notes Q4/Q5); that line has ``calibration: true``. Everything else is predicted with that A/l:
the contracting edge's ratio (0.64 ± 0.05), the expanding and contracting lattices' area change
(+99 ± 11 %, −28 ± 11 %) and the Gaussian-curvature signs of the dome and saddle patterns.
Run: ``python examples/lattices_vs_paper.py [--quick]``.
"""

from __future__ import annotations

import json
import sys

from scipy.optimize import brentq

from rotomorph.design.lattices import sinusoidal_lattice
from rotomorph.lattice import CurvatureScaling, free_edge_ratio, heat_lattice
from rotomorph.materials.measurements import load_table

SPACING = 5.0  # mm; only A/l matters for the shapes


def _row(quantity, condition, measured, spread, predicted, calibration=False, **extra):
    error = None if measured is None or predicted is None else predicted - measured
    row = {
        "quantity": quantity,
        "condition": condition,
        "measured": measured,
        "spread": spread,
        "predicted": predicted,
        "error": error,
        "calibration": calibration,
    }
    row.update(extra)
    return row


def main(quick: bool = False) -> list[dict]:
    steps = 4 if quick else 16
    edges = load_table("sinusoid_end_to_end")
    areas = load_table("lattice_area")
    target = float(edges.value[0])

    def mismatch(ratio_a_l: float) -> float:
        lat = sinusoidal_lattice(spacing=SPACING, amplitude=ratio_a_l * SPACING)
        return free_edge_ratio(lat, actuation="swapped", steps=4) - target

    a_l = brentq(mismatch, 0.12, 0.35, xtol=1e-4)
    rows = []
    expanding = sinusoidal_lattice(spacing=SPACING, amplitude=a_l * SPACING)
    contracting = sinusoidal_lattice(
        spacing=SPACING, amplitude=a_l * SPACING, pattern="contracting"
    )
    r_exp = free_edge_ratio(expanding, actuation="swapped")
    r_con = free_edge_ratio(contracting, actuation="swapped")
    rows.append(
        _row(
            "edge end-to-end ratio",
            edges.condition[0],
            target,
            float(edges.spread[0]),
            r_exp,
            True,
            amplitude_over_spacing=a_l,
            actuation="swapped",
        )
    )
    rows.append(
        _row(
            "edge end-to-end ratio",
            edges.condition[1],
            float(edges.value[1]),
            float(edges.spread[1]),
            r_con,
        )
    )
    for lat, k, note in (
        (expanding, 0, "homogeneous lattice: area ratio = edge ratio squared (notes C1)"),
        (
            contracting,
            1,
            "contact and jamming are not modelled (notes C2): free contracting edges give "
            "(0.64)^2 - 1 = -59 % in the paper's own numbers, and filaments here pass through "
            "each other (min_clearance ~ 0) long before the ramp ends; the paper's -28 % is "
            "set by self-contact, so this gap is expected, not a calibration error",
        ),
    ):
        res = heat_lattice(lat, actuation="swapped", steps=steps)
        rows.append(
            _row(
                "lattice area change (%)",
                areas.condition[k],
                float(areas.value[k]),
                float(areas.spread[k]),
                100.0 * (res.final_area_ratio - 1.0),
                note=note,
                first_overlap_x=res.first_overlap(),
            )
        )
    # the signs are read early in the ramp (x = 0.3): by x = 0.75 both shapes fold through
    # themselves without contact (notes section 6)
    early = CurvatureScaling("swapped", end=0.3)
    for pattern, sign in (("dome", 1), ("saddle", -1)):
        lat = sinusoidal_lattice(spacing=SPACING, amplitude=a_l * SPACING, pattern=pattern)
        res = heat_lattice(lat, actuation=early, steps=6)
        rows.append(
            _row(
                "Gaussian curvature sign",
                f"{pattern} pattern (Fig. 4)",
                sign,
                0,
                int(res.gaussian_sign[-1]),
                characteristic_curvature=float(res.characteristic_curvature[-1]),
                mean_edge_strain=float(res.mean_edge_strain[-1]),
                x=0.3,
            )
        )
    return rows


if __name__ == "__main__":
    for row in main(quick="--quick" in sys.argv):
        print(json.dumps(row))

"""Synthetic measurement tables generated from known ink parameters (for recovery tests).

:func:`synthetic_tables` evaluates the model at known parameters (:data:`TRUTH`), adds Gaussian
noise at each row's stated spread and writes the rows as measurement CSV text, the format a lab
gives ``rotomorph calibrate``. The order parameter's points and the moduli at the print
temperature are inputs of the calibration (used as given); they are noised too, at their small
stated spreads.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from rotomorph.materials.lab_model import InkPair, curve
from rotomorph.materials.material import Material
from rotomorph.materials.natural import FilamentModel
from rotomorph.materials.process import EmpiricalThreshold

#: The known parameters (fit names) the tables are generated from.
TRUTH = {
    "model.modulus_ratio": 3.0,
    "model.strain_model.gain": 1.8,
    "model.strain_model.threshold": 0.12,
    "model.passive_strain": 0.02,
    "active.transition_temperature": 95.0,
    "model.transition_width": 8.0,
}
ORDER = ((0.25, 0.15), (3.0, 0.23))
E_ACTIVE, E_PASSIVE = 20.0, 0.8
HEADER = "quantity,condition,x,x_unit,value,spread,unit,source\n"


def truth_pair(resolution: int = 32) -> InkPair:
    """The generating model."""
    model = FilamentModel(
        strain_model=EmpiricalThreshold(
            TRUTH["model.strain_model.gain"], TRUTH["model.strain_model.threshold"], "hencky", ORDER
        ),
        modulus_ratio=TRUTH["model.modulus_ratio"],
        passive_strain=TRUTH["model.passive_strain"],
        transition_width=TRUTH["model.transition_width"],
        resolution=resolution,
    )
    active = Material(
        "rm82", "active", E_ACTIVE, 0.5, 0.0, TRUTH["active.transition_temperature"], 1.0, 1.1
    )
    passive = Material("pdms", "passive", E_PASSIVE, 0.5, -120.0, None, 1.0, 1.05)
    return InkPair(model, active, passive, 0.3, 0.5)


def synthetic_tables(seed: int, *, transition: bool, resolution: int = 32) -> str:
    """CSV text of the generated tables; ``transition``: include the active ink's free length
    through the transition (which determines T_NI and its width)."""
    rng = np.random.default_rng(seed)
    pair = truth_pair(resolution)
    rows: list[str] = []

    def add(
        quantity: str, condition: str, x: str, x_unit: str, value: float, sd: float, unit: str
    ) -> None:
        noisy = value + sd * rng.standard_normal()
        rows.append(
            f"{quantity},{condition},{x},{x_unit},{noisy:.6g},{sd:g},{unit},synthetic seed {seed}"
        )

    speeds = np.array([0.25, 0.5, 1.0, 1.75, 3.0])
    for v, k in zip(speeds, curve("janus_curvature", pair, speeds), strict=True):
        add("janus_curvature", "", f"{v:g}", "mm/s", float(k), 0.02, "1/mm")
    w = np.array([0.06, 0.25, 1.0])
    for x, y in zip(w, curve("pure_lce_length", pair, w, speed=3.0), strict=True):
        add("pure_lce_length", "v=3 mm/s", f"{x:g}", "1", float(y), 0.01, "1")
    w = np.array([0.06, 0.5, 2.0])
    for x, y in zip(w, curve("composite_length", pair, w, speed=3.0), strict=True):
        add("composite_length", "v=3 mm/s", f"{x:g}", "1", float(y), 0.01, "1")
    temps = np.array([100.0, 175.0])
    for t, y in zip(temps, curve("free_length", pair, temps, role="passive"), strict=True):
        add("free_length", "passive=pdms", f"{t:g}", "C", float(y), 0.004, "1")
    if transition:
        temps = np.array([40.0, 70.0, 85.0, 95.0, 105.0, 120.0, 150.0, 175.0])
        ys = curve("free_length", pair, temps, role="active", speed=3.0)
        for t, y in zip(temps, ys, strict=True):
            add("free_length", "active=rm82; v=3 mm/s", f"{t:g}", "C", float(y), 0.005, "1")
    for role, name, e in (("active", "rm82", E_ACTIVE), ("passive", "pdms", E_PASSIVE)):
        add("youngs_modulus", f"{role}={name}", "25", "C", e, 0.03 * e, "MPa")
        hot = float(curve("youngs_modulus", pair, np.array([175.0]), role=role)[0])
        add("youngs_modulus", f"{role}={name}", "175", "C", hot, 0.05 * hot, "MPa")
    for v, s in ORDER:
        add("order_parameter", "active=rm82", f"{v:g}", "mm/s", s, 0.001, "1")
    return HEADER + "\n".join(rows) + "\n"


def with_resolution(pair: InkPair, resolution: int) -> InkPair:
    """``pair`` with another section-mesh resolution."""
    return replace(pair, model=replace(pair.model, resolution=resolution))

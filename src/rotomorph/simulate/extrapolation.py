"""Whether a simulation's settings lie outside the range its materials law was calibrated on.

The calibrated range (:func:`rotomorph.materials.calibrated_range.calibrated_range`) is where
the paper's filament measurements lie: print speeds 0.25-3 mm/s at ω* = 0, ω* up to ±2 at
3 mm/s, 175 °C, R = 0.3 mm, half or all of the section active, the paper's two inks. A run
outside it extrapolates the fitted laws; :func:`run_extrapolation` says why, and
:func:`~rotomorph.simulate.run_data.describe_run` puts it into every output of ``simulate``
(the command line, ``summary.json``, the results file's metadata and every figure title).

The temperature judged is the end of the heating ramp (the state a run reports); the states on
the way rely on the assumed actuation curve x(T) whatever the range. Runs of the paper's
curvature-rescaling recipe (``actuation = "paper-*"``) do not use the materials law, so they are
never flagged.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from rotomorph.materials.calibrated_range import calibrated_range

__all__ = ["program_extrapolation", "run_extrapolation"]

#: Lattice actuation modes that drive the edges through the calibrated materials law.
MATERIAL_MODES = ("program", "thermal")


def program_extrapolation(program: Any, temperature: float) -> list[str]:
    """Why one print program, heated to ``temperature`` (°C), lies outside the range."""
    if program is None:
        return []
    return calibrated_range().outside(
        speed=np.asarray(program.speed, dtype=float),
        rotation_number=np.asarray(program.rotation_number, dtype=float),
        temperature=float(temperature),
        radius=float(program.radius),
        active_fraction=float(program.active_fraction),
        materials=(str(program.active_material), str(program.passive_material)),
    )


def run_extrapolation(sim: Any) -> tuple[list[str], list[list[str]]]:
    """(reasons for the run, reasons per filament) for a
    :class:`~rotomorph.simulate.design.DesignSimulation`; empty lists: inside the range."""
    per_filament: list[list[str]] = []
    if sim.kind == "lattice" and sim.lattice is not None:
        res = sim.lattice
        mode = str(getattr(res, "actuation", ""))
        if not any(mode.startswith(m) for m in MATERIAL_MODES):
            return [], []
        lat = res.lattice
        reasons = calibrated_range().outside(
            speed=np.asarray(lat.speeds, dtype=float),
            rotation_number=0.0,
            temperature=float(np.asarray(res.parameter)[-1]),
            radius=float(lat.radius),
            active_fraction=float(lat.active_fraction),
            materials=(str(lat.active_material), str(lat.passive_material)),
        )
        return reasons, []
    for fil in sim.filaments:
        per_filament.append(
            program_extrapolation(getattr(fil, "program", None), float(fil.temperature[-1]))
        )
    reasons = list(dict.fromkeys(r for rs in per_filament for r in rs))
    return reasons, per_filament

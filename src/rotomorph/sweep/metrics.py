"""What a sweep can collect from each run: the metrics of the analysis layer, by name.

Every run stores *all* metrics of its kind (so adding an output to a finished sweep needs no
recomputation); the sweep file's ``outputs`` only choose the table's columns. Filament metrics
are per filament: a design with one filament names them plainly (``end_to_end_ratio``), a
design with several names the filament (``filaments[1].end_to_end_ratio``).

Physicality is the run's own verdict (:mod:`rotomorph.io.validity`, the same one
``rotomorph simulate`` writes): ``yes`` when every step converged, was verified stable and no
filament passes through another (``min_clearance``, in filament diameters, >= 1 without a
contact model); ``no`` when a check failed; ``unknown`` when a check was not made (e.g. the
solver did not verify stability). ``closed_form`` runs compute no equilibrium: unknown.
"""

from __future__ import annotations

import functools
import re
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from rotomorph.errors import InvalidParameterError

__all__ = [
    "METRICS",
    "Metric",
    "check_outputs",
    "closed_form_metrics",
    "filament_metrics",
    "filament_model",
    "is_physical",
    "lattice_metrics",
    "physical_reason",
    "select_output",
]


@dataclass(frozen=True)
class Metric:
    """A collectable quantity: name, unit, value type, scope and the methods providing it."""

    name: str
    unit: str
    dtype: Literal["float", "int", "str", "bool"]
    scope: Literal["filament", "lattice"]
    description: str
    closed_form: bool = False


METRICS: tuple[Metric, ...] = (
    Metric("end_to_end_ratio", "1", "float", "filament", "L/L0 of the final shape", True),
    Metric(
        "morphology",
        "",
        "str",
        "filament",
        "straight / twisted rod / helix / coil (median curvature and material twist); null "
        "where the fitted helix does not describe the shape, as in summary.json",
        True,
    ),
    Metric("curvature", "1/mm", "float", "filament", "median curvature of the final shape", True),
    Metric("torsion", "1/mm", "float", "filament", "torsion of the closed-form helix", True),
    Metric("morphology_parameter", "1", "float", "filament", "Λ = K/|τ| of the closed form", True),
    Metric("helix_radius", "mm", "float", "filament", "radius of the fitted helix", True),
    Metric("helix_pitch", "mm", "float", "filament", "pitch of the fitted helix", True),
    Metric("helix_turns", "1", "float", "filament", "turns of the fitted helix"),
    Metric("handedness", "1", "int", "filament", "+1 right, -1 left, 0 planar (fitted helix)"),
    Metric(
        "closed_form_end_to_end_ratio",
        "1",
        "float",
        "filament",
        "L/L0 of the closed-form helix if infinitely long (axis advance per arc length; 0 for a "
        "ring however short)",
    ),
    Metric("closed_form_morphology", "", "str", "filament", "label of the closed-form helix"),
    Metric(
        "closed_form_curvature",
        "1/mm",
        "float",
        "filament",
        "curvature of the closed-form helix (per current length)",
    ),
    Metric("min_clearance", "diameters", "float", "filament", "closest non-adjacent segments"),
    Metric("stable", "", "bool", "filament", "last step verified stable (null: not checked)"),
    Metric("energy", "N mm", "float", "filament", "elastic energy at the last step"),
    Metric("iterations", "1", "int", "filament", "Newton iterations over the ramp"),
    Metric("residual", "1", "float", "filament", "relative residual at the last step"),
    Metric("area_ratio", "1", "float", "lattice", "projected area A/A0"),
    Metric("gaussian_sign", "1", "int", "lattice", "+1 dome, -1 saddle, 0 flat"),
    Metric("characteristic_curvature", "1/mm", "float", "lattice", "√|k₁k₂| of the surface fit"),
    Metric("edge_strain", "1", "float", "lattice", "mean end-to-end strain of the edges"),
    Metric("min_clearance", "diameters", "float", "lattice", "closest non-adjacent segments"),
    Metric("stable", "", "bool", "lattice", "last step verified stable (null: not checked)"),
    Metric("energy", "N mm", "float", "lattice", "elastic energy at the last step"),
    Metric("iterations", "1", "int", "lattice", "Newton iterations over the ramp"),
    Metric("residual", "1", "float", "lattice", "relative residual at the last step"),
)

_OUTPUT = re.compile(r"^(?:filaments\[(\d+)\]\.)?([a-z_]+)$")


def _metric(name: str, scope: str) -> Metric | None:
    return next((m for m in METRICS if m.name == name and m.scope == scope), None)


def check_outputs(outputs: list[str], design: Any, method: str) -> None:
    """Raise :class:`InvalidParameterError` unless every output is collectable from ``design``.

    Parameters
    ----------
    outputs
        Output names (see module docstring).
    design
        The base :class:`~rotomorph.io.designfile.Design`.
    method
        ``"rod"`` or ``"closed_form"``.
    """
    scope = "lattice" if design.lattice is not None else "filament"
    if design.lattice is not None and design.filaments:
        raise InvalidParameterError("design", "a sweep design has filaments or a lattice, not both")
    if method == "closed_form" and scope == "lattice":
        raise InvalidParameterError(
            "settings.method", "closed_form handles filaments only; use method = 'rod'"
        )
    for i, out in enumerate(outputs):
        m = _OUTPUT.match(out)
        known = sorted(
            {k.name for k in METRICS if k.scope == scope and (method == "rod" or k.closed_form)}
        )
        if m is None or (m.group(1) is not None and scope == "lattice"):
            raise InvalidParameterError(f"outputs[{i}]", f"{out!r}: unknown; known: {known}")
        index, name = m.group(1), m.group(2)
        if name not in known:
            raise InvalidParameterError(
                f"outputs[{i}]", f"{out!r} is not available for {scope} runs ({method}); {known}"
            )
        if scope == "filament":
            count = len(design.filaments)
            if index is None and count > 1:
                raise InvalidParameterError(
                    f"outputs[{i}]",
                    f"the design has {count} filaments; name one, e.g. filaments[0].{name}",
                )
            if index is not None and int(index) >= count:
                raise InvalidParameterError(
                    f"outputs[{i}]", f"the design has {count} filament(s); no filaments[{index}]"
                )


def select_output(metrics: Mapping[str, Any], output: str) -> Any:
    """The value of ``output`` in a run's stored ``metrics`` (``None`` when absent)."""
    m = _OUTPUT.match(output)
    if m is None:
        return None
    if "lattice" in metrics:
        return metrics["lattice"].get(m.group(2))
    filaments = metrics.get("filaments") or []
    i = int(m.group(1) or 0)
    return filaments[i].get(m.group(2)) if i < len(filaments) else None


def is_physical(metrics: Mapping[str, Any]) -> bool | None:
    """The run's physical-state verdict as a flag: True (yes), False (no), None (unknown)."""
    verdict = (metrics.get("physical") or {}).get("verdict")
    return {"yes": True, "no": False}.get(str(verdict))


def physical_reason(metrics: Mapping[str, Any]) -> str | None:
    """Why a run's states are (not, or not known to be) physical."""
    return (metrics.get("physical") or {}).get("reason")


def _number(x: Any) -> float | None:
    x = float(x)
    return x if np.isfinite(x) else None


@functools.lru_cache(maxsize=4)
@functools.lru_cache(maxsize=8)
def filament_model(name: str) -> Any:
    """The :class:`~rotomorph.materials.natural.FilamentModel` a sweep's settings name.

    ``calibrated`` and the physical priors come from
    :func:`rotomorph.materials.natural.named_model`; ``calibrated-without-<group>`` is the
    joint calibration leaving that measured group out
    (:func:`rotomorph.materials.calibrate.paper_calibration`, about 1.5 s, once per process),
    evaluated on the section mesh of the calibrated model.
    """
    from rotomorph.materials.calibrate import CALIBRATION_GROUPS
    from rotomorph.materials.natural import MODEL_NAMES, named_model

    if name in MODEL_NAMES:
        return named_model(name)
    prefix = "calibrated-without-"
    group = name.removeprefix(prefix)
    if name.startswith(prefix) and group in CALIBRATION_GROUPS:
        import dataclasses

        from rotomorph.materials.calibrate import paper_calibration

        model = paper_calibration(exclude=(group,)).chosen.model
        return dataclasses.replace(model, resolution=named_model("calibrated").resolution)
    raise InvalidParameterError("settings.filament_model", f"unknown model {name!r}")


def _last_flag(flags: Any) -> bool | None:
    """The last step's stability verdict (``None``: not checked or not reported)."""
    flags = tuple(flags or ())
    return None if not flags or flags[-1] is None else bool(flags[-1])


def filament_metrics(sim: Any, summary: Mapping[str, Any]) -> dict[str, Any]:
    """Metrics of one :class:`~rotomorph.simulate.filament.FilamentSimulation`.

    Parameters
    ----------
    sim
        The filament's simulation.
    summary
        Its entry in the described run's ``metadata["filaments"]``
        (:func:`rotomorph.simulate.run_data.describe_run`): clearance and verdict.
    """
    from rotomorph.simulate.design import shape_label

    helix = sim.helix
    closed = sim.closed_form
    stable = _last_flag(sim.stable)
    clearance = summary.get("min_clearance_diameters")
    return {
        "end_to_end_ratio": _number(sim.final_ratio),
        "morphology": shape_label(sim),
        "curvature": _number(np.nanmedian(sim.curvature[-1])),
        "torsion": None if helix is None else _number(helix.torsion),
        "morphology_parameter": None,
        "helix_radius": None if helix is None else _number(helix.radius),
        "helix_pitch": None if helix is None else _number(helix.pitch),
        "helix_turns": None if helix is None else _number(helix.turns),
        "handedness": None if helix is None else int(helix.handedness),
        "closed_form_end_to_end_ratio": None
        if closed is None
        else _number(closed.end_to_end_ratio),
        "closed_form_morphology": None if closed is None else str(closed.label),
        "closed_form_curvature": None if closed is None else _number(closed.curvature),
        "min_clearance": None if clearance is None else _number(clearance),
        "stable": stable,
        "energy": _number(sim.energy[-1]),
        "iterations": int(np.sum(sim.iterations)),
        "residual": _number(sim.residual[-1]),
        "physical": summary.get("physical"),
    }


def closed_form_metrics(shape: Any) -> dict[str, Any]:
    """Metrics of a closed-form :class:`~rotomorph.materials.morphology.HelixShape`."""
    return {
        "end_to_end_ratio": _number(shape.end_to_end_ratio),
        "morphology": str(shape.label),
        "curvature": _number(shape.curvature),
        "torsion": _number(shape.torsion),
        "morphology_parameter": _number(shape.morphology_parameter),
        "helix_radius": _number(shape.radius),
        "helix_pitch": _number(shape.pitch),
        "min_clearance": None,
        "stable": None,
    }


def lattice_metrics(sim: Any) -> dict[str, Any]:
    """Metrics of a lattice :class:`~rotomorph.simulate.design.DesignSimulation` (last step)."""
    sc = sim.scalars
    return {
        "area_ratio": _number(sc["area_ratio"][-1]),
        "gaussian_sign": int(sc["gaussian_sign"][-1]),
        "characteristic_curvature": _number(sc["characteristic_curvature"][-1]),
        "edge_strain": _number(sc["edge_strain"][-1]),
        "min_clearance": _number(sc["min_clearance"][-1]),
        "stable": _last_flag(getattr(sim.lattice, "stable", ())),
        "energy": _number(sc["energy"][-1]),
        "iterations": int(np.sum(sc["iterations"])),
        "residual": _number(sc["residual"][-1]),
    }

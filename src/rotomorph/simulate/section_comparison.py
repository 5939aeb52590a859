"""The finite-strain section against the linear one on the never-fitted groups.

One function per quantity, each cheap enough to run by hand (the report is not re-run): the
joint calibration refitted with either section law (:func:`refit`), the sinusoid pair's
free-shape end-to-end ratios at the nominal nuisance sample (:func:`sinusoid_pair`) and the
3 × 3 quick lattices' final area ratios without contact (:func:`quick_lattice_areas`).
:func:`compare_section_models` puts them together; the numbers are recorded in
``docs/validation.md``. The free shapes are the zero-energy ones: where one passes through
itself (clearance below the filament diameter) the report's counted value is a self-contact
solve instead, which is flagged here and not run.
"""

from __future__ import annotations

import dataclasses
from typing import Any

from rotomorph.materials.finite_section import SECTION_MODELS, SectionModel
from rotomorph.materials.natural import FilamentModel


def refit(section_model: SectionModel) -> Any:
    """The joint calibration of the paper's filament groups with ``section_model``
    (:func:`rotomorph.materials.calibrate.paper_calibration`'s groups, parameters, branches
    and priors; only the section law differs). Returns the ``JointCalibration``."""
    from rotomorph.materials.calibrate import (
        FIT_RESOLUTION,
        PREFERRED_BRANCH_REASON,
        paper_base_model,
        paper_groups,
        paper_parameters,
    )
    from rotomorph.materials.inference import joint_calibrate

    base = dataclasses.replace(paper_base_model(FIT_RESOLUTION), section_model=section_model)
    return joint_calibrate(
        paper_groups(),
        paper_parameters(),
        base,
        branch="modulus_ratio",
        preferred="above",
        preference_reason=PREFERRED_BRANCH_REASON,
    )


def sinusoid_pair(model: FilamentModel) -> dict[str, dict[str, float | bool]]:
    """Free-shape end-to-end ratio (1), self-clearance (mm) and whether the free shape passes
    through itself, for the expanding (active outer) and contracting (active inner)
    sinusoid at the nominal nuisance sample and the report's finer node spacing."""
    from rotomorph.simulate import nuisance_filaments as nf
    from rotomorph.simulate.nuisance import nominal_sample
    from rotomorph.simulate.validation import at_resolution

    sample = nominal_sample()
    spacing = (nf.FLIP_SPACINGS if sample.flip_length > 0 else nf.STEP_SPACINGS)[1]
    m = at_resolution(model)
    out: dict[str, dict[str, float | bool]] = {}
    for side, name in (("outer", "expanding"), ("inner", "contracting")):
        radius = float(nf.sinusoid_program(side, sample, spacing).radius)
        clearance = nf.self_clearance(side, m, sample, spacing)
        out[name] = {
            "ratio": nf.sinusoid_ratio(side, m, sample, spacing),
            "clearance": clearance,
            "self_contact": bool(clearance < 2.0 * radius),
        }
    return out


def quick_lattice_areas(model: FilamentModel) -> dict[str, float | None]:
    """Final area ratio (1) of the expanding and contracting 3 × 3 lattices of the report's
    quick mode (3 heating steps, coarser ghost nodes, no contact), or ``None`` where the
    solver failed."""
    from rotomorph.simulate.report import LATTICE_GHOSTS, _heat
    from rotomorph.simulate.validation import at_resolution

    ghosts = LATTICE_GHOSTS[True][0]
    out: dict[str, float | None] = {}
    for pattern in ("expanding", "contracting"):
        _, res, _ = _heat(pattern, True, 3, at_resolution(model), ghosts)
        out[pattern] = None if res is None else float(res.final_area_ratio)
    return out


def compare_section_models(*, refitted: bool = True) -> dict[str, dict[str, Any]]:
    """Per section law: the refit's χ² (data part) and chosen parameters, the sinusoid pair
    and the quick lattices, each from that law's own refit (``refitted``) or from the stored
    calibrated default with only the law changed."""
    out: dict[str, dict[str, Any]] = {}
    for law in SECTION_MODELS:
        if refitted:
            fit = refit(law).chosen
            model, record = fit.model, {"chi2_data": fit.chi2_data, "values": fit.values}
        else:
            model, record = dataclasses.replace(FilamentModel(), section_model=law), {}
        record["sinusoids"] = sinusoid_pair(model)
        record["lattices"] = quick_lattice_areas(model)
        out[law] = record
    return out

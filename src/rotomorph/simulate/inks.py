"""Which filament model a run uses: the design's materials file, or the paper's inks.

A design that names a materials file (``materials = "inks.toml"``) is computed with that file's
inks and with the model of each filament's (or the lattice's) ink pair
(:meth:`~rotomorph.materials.parameter_set.MaterialSet.filament_model`); a design that names
none, with the paper's (:class:`~rotomorph.materials.natural.FilamentModel`). ``simulate``,
``predict``, sweeps and the app resolve the model here, so all of them compute a design alike.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

from rotomorph.errors import InvalidParameterError
from rotomorph.materials.natural import FilamentModel, named_model

__all__ = ["design_model", "materials_record"]


def design_model(
    design: Any, active: str, passive: str, model: FilamentModel | str | None = None
) -> FilamentModel | None:
    """The filament model of one ink pair of ``design``.

    Parameters
    ----------
    design
        A validated design (its ``material_set`` may be ``None``: the paper's inks).
    active, passive
        The pair's ink names.
    model
        ``None``: the pair's calibrated model from the design's materials file (``None`` for
        a design without one: the package default). A name (``"calibrated"``,
        ``"warner-terentjev"``, ``"room-temperature"``): that model built on the pair's.
        A :class:`FilamentModel`: used as given, looking its inks up in the design's file.
    """
    inks = getattr(design, "material_set", None)
    if model is None:
        return None if inks is None else inks.filament_model(active, passive)
    if isinstance(model, str):
        base = None if inks is None else inks.filament_model(active, passive)
        return named_model(model, base)
    if not isinstance(model, FilamentModel):
        raise InvalidParameterError("model", f"must be a FilamentModel or its name; got {model!r}")
    if inks is not None and model.materials is None:
        return replace(model, materials=inks)
    return model


def materials_record(design: Any) -> dict[str, Any]:
    """What a run records about the inks it used: the design's materials file (name, version,
    sha256, source) or the package's default (the paper's inks)."""
    inks = getattr(design, "material_set", None)
    if inks is None:
        from rotomorph.materials.parameter_set import default_materials

        return {**default_materials().record(), "default": True}
    return {**inks.record(), "default": False}

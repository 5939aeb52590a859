"""Materials as parameter sets: the default file is today's model, every value has its unit and
provenance, files round-trip, bad files give one-line errors naming the key."""

from __future__ import annotations

import copy
import dataclasses
import hashlib
import math
from importlib import resources

import pytest

from rotomorph.errors import MaterialError
from rotomorph.io.materials_file import (
    load_materials,
    materials_schema,
    materials_toml,
    parse_materials_bytes,
    save_materials,
)
from rotomorph.materials.calibrate import paper_calibration
from rotomorph.materials.lab_tables import data_sha256
from rotomorph.materials.material import get_material
from rotomorph.materials.natural import CALIBRATED, FilamentModel
from rotomorph.materials.parameter_set import default_materials, materials_from_mapping

try:
    import tomllib
except ModuleNotFoundError:  # pragma: no cover
    import tomli as tomllib  # type: ignore[no-redef]

PAPER = default_materials()
TEXT = resources.files("rotomorph.materials").joinpath("data/paper_inks.toml").read_text("utf-8")
DOC = tomllib.loads(TEXT)


def test_the_default_file_is_the_default_model_and_registry() -> None:
    model = PAPER.filament_model("lce", "acrylate")
    default = FilamentModel()
    assert dataclasses.replace(model, materials=None) == default  # every field, exactly
    assert model.materials is PAPER and default.materials is None
    assert model.modulus_ratio == CALIBRATED["modulus_ratio"] == 3.9764259028134044
    assert model.strain_model.order_points == ((0.25, 0.150), (3.0, 0.230))
    for name in ("lce", "acrylate"):
        registered, from_file = get_material(name), PAPER.material(name)
        assert registered == from_file
    lce = PAPER.material("lce")
    assert (lce.youngs_modulus, lce.youngs_modulus_spread, lce.transition_temperature) == (
        29.67,
        2.55,
        90.0,
    )


def test_stored_calibration_is_a_fresh_one_of_the_hashed_tables() -> None:
    fresh = paper_calibration().chosen.values
    lce, acr = PAPER.ink("lce"), PAPER.ink("acrylate")
    stored = {
        "modulus_ratio": lce.actuated_modulus_ratio.value,  # type: ignore[union-attr]
        "strain_model.gain": lce.strain_gain.value,  # type: ignore[union-attr]
        "strain_model.threshold": lce.strain_threshold.value,  # type: ignore[union-attr]
        "passive_strain": acr.free_strain.value,  # type: ignore[union-attr]
    }
    for name, value in fresh.items():
        assert stored[name] == pytest.approx(value, rel=1e-6), name
    tables = ("janus_curvature", "pure_lce_length", "composite_length", "normalized_length")
    files = [*tables, "order_parameter"]
    data = [
        resources.files("rotomorph.materials").joinpath(f"data/{n}.csv").read_bytes() for n in files
    ]
    assert PAPER.document.calibration is not None
    assert PAPER.document.calibration.data_sha256 == data_sha256(data)


def test_the_stored_covariance_is_the_calibrations_and_propagates_alike() -> None:
    import numpy as np

    from rotomorph.materials.calibrate import janus_curvature

    fit = PAPER.calibration_fit("lce", "acrylate")
    fresh = paper_calibration().chosen
    assert fit is not None and [p.name for p in fit.parameters] == [
        p.name for p in fresh.parameters
    ]
    sym = 0.5 * (fresh.covariance + fresh.covariance.T)
    assert np.allclose(fit.covariance, sym, rtol=1e-6, atol=1e-15)

    def curvature(model: FilamentModel) -> np.ndarray:
        return janus_curvature(model, np.array([0.5, 3.0]))

    assert np.allclose(fit.propagate(curvature)[1], fresh.propagate(curvature)[1], rtol=1e-6)
    # another passive ink: its free strain is not the calibrated one, so it is left out
    doc = copy.deepcopy(DOC)
    doc["inks"]["other"] = copy.deepcopy(doc["inks"]["acrylate"])
    other = materials_from_mapping(doc).calibration_fit("lce", "other")
    assert other is not None and "passive_strain" not in [p.name for p in other.parameters]


def test_every_value_has_unit_provenance_and_source_and_tni_is_a_placeholder() -> None:
    rows = PAPER.values()
    assert len(rows) >= 20
    assert {r.provenance for r in rows} <= {"measured", "cited", "assumed", "calibrated"}
    assert all(r.unit and len(r.source) > 10 for r in rows)
    tni = next(r for r in rows if r.owner == "lce" and r.key == "transition_temperature")
    assert tni.provenance == "assumed" and "PLACEHOLDER" in tni.source and tni.value == 90.0
    calibrated = {r.key for r in rows if r.provenance == "calibrated"}
    assert calibrated == {
        "actuated_modulus_ratio",
        "strain_gain",
        "strain_threshold",
        "free_strain",
    }
    assert not any(r.provenance == "measured" for r in rows)  # the paper's values are cited


def test_files_round_trip_and_hash_their_content(tmp_path) -> None:
    path = save_materials(PAPER, tmp_path / "inks.toml")
    again = load_materials(path)
    assert again == PAPER and again.sha256 == PAPER.sha256 and again.source == str(path)
    assert tomllib.loads(path.read_text("utf-8"))["inks"]["lce"]["kind"] == "active"
    renamed = copy.deepcopy(DOC)
    renamed["description"] = "another description"
    assert materials_from_mapping(renamed).sha256 != PAPER.sha256
    assert materials_schema()["properties"]["inks"]
    assert "relative_to" in materials_toml(PAPER)


def test_units_are_converted_on_reading() -> None:
    doc = copy.deepcopy(DOC)
    doc["inks"]["acrylate"]["youngs_modulus"].update(value=570.0, sd=70.0, unit="kPa")
    doc["inks"]["lce"]["transition_temperature"].update(value=363.15, unit="K")
    doc["nozzle"]["filament_radius"].update(value=300.0, unit="um")
    doc["inks"]["lce"]["order_parameter"].update(speed=[15.0, 180.0], speed_unit="mm/min")
    inks = materials_from_mapping(doc)
    acr = inks.material("acrylate")
    assert acr.youngs_modulus == pytest.approx(0.57) and acr.youngs_modulus_spread == pytest.approx(
        0.07
    )
    assert inks.material("lce").transition_temperature == pytest.approx(90.0)
    assert inks.document.nozzle.filament_radius.value == pytest.approx(0.3)
    points = [x for pair in inks.order_points("lce") for x in pair]
    assert points == pytest.approx([0.25, 0.15, 3.0, 0.23])


def test_the_ratio_is_kept_relative_to_its_passive_ink() -> None:
    doc = copy.deepcopy(DOC)
    stiff = copy.deepcopy(doc["inks"]["acrylate"])
    stiff["youngs_modulus"]["value"] = 1.14
    doc["inks"]["stiffer"] = stiff
    inks = materials_from_mapping(doc)
    m = inks.modulus_ratio("lce", "acrylate")
    assert m == 3.9764259028134044
    assert inks.modulus_ratio("lce", "stiffer") == pytest.approx(m / 2.0)
    assert inks.filament_model("lce", "stiffer").modulus_ratio == pytest.approx(m / 2.0)
    with pytest.raises(MaterialError, match="passive ink"):
        inks.filament_model("acrylate", "lce")
    with pytest.raises(MaterialError, match=r"its inks: lce, acrylate, stiffer"):
        inks.material("pla")


def _set(doc: dict, path: str, value: object) -> dict:
    out = copy.deepcopy(doc)
    node = out
    keys = path.split(".")
    for k in keys[:-1]:
        node = node[k]
    if value is _DELETE:
        del node[keys[-1]]
    else:
        node[keys[-1]] = value
    return out


_DELETE = object()


@pytest.mark.parametrize(
    ("path", "value", "field", "message"),
    [
        (
            "inks.lce.youngs_modulus.unit",
            "kN",
            "inks.lce.youngs_modulus.unit",
            "not a unit of modulus",
        ),
        ("inks.lce.youngs_modulus.unit", _DELETE, "inks.lce.youngs_modulus.unit", "is required"),
        ("inks.lce.density.provenance", "guessed", "inks.lce.density.provenance", "measured"),
        ("inks.lce.density.source", "", "inks.lce.density.source", "at least 1"),
        ("inks.lce.density.value", "1.1", "inks.lce.density.value", "without quotes"),
        ("inks.lce.density.value", -1.0, "inks.lce.density.value", "must lie in"),
        ("inks.lce.colour", "red", "inks.lce.colour", "unknown key"),
        ("inks.lce.kind", "smart", "inks.lce", "'active' or 'passive'"),
        ("inks.lce.strain_gain", _DELETE, "inks.lce.strain_gain", "required by strain_law"),
        (
            "inks.lce.actuated_modulus_ratio.relative_to",
            "lce",
            "inks.lce.actuated_modulus_ratio.relative_to",
            "not a passive ink",
        ),
        (
            "inks.acrylate.free_strain.temperature",
            150.0,
            "inks.acrylate.free_strain.temperature",
            "actuation temperature",
        ),
        ("inks.lce.order_parameter.value", [0.2, 1.5], "inks.lce.order_parameter.value", "[0, 1)"),
        (
            "inks.lce.order_parameter.speed",
            [3.0, 3.0],
            "inks.lce.order_parameter.speed",
            "distinct",
        ),
        (
            "conditions.actuation_temperature.value",
            20.0,
            "conditions.actuation_temperature.value",
            "exceed",
        ),
        (
            "inks.lce.transition_width.unit",
            "mm",
            "inks.lce.transition_width.unit",
            "temperature difference",
        ),
        ("schema_version", 2, "schema_version", "1"),
        ("calibration.covariance", [[1.0]], "calibration.covariance", "one row"),
        (
            "calibration.parameters",
            ["lce.strain_gain", "pla.strain_gain", "lce.strain_threshold", "acrylate.free_strain"],
            "calibration.parameters",
            "names no value",
        ),
    ],
)
def test_bad_materials_give_one_line_naming_the_key(path, value, field, message) -> None:
    with pytest.raises(MaterialError) as err:
        materials_from_mapping(_set(DOC, path, value))
    text = str(err.value)
    assert err.value.field == field and message in text and "\n" not in text, text


def test_bad_files_are_refused_in_one_line(tmp_path) -> None:
    with pytest.raises(MaterialError, match="not UTF-8"):
        parse_materials_bytes(TEXT.replace("tensile", "t\xe9nsile").encode("latin-1"), "x.toml")
    with pytest.raises(MaterialError, match="not valid TOML"):
        parse_materials_bytes(b"schema_version = = 1", "x.toml")
    with pytest.raises(MaterialError, match="schema_version"):
        parse_materials_bytes(b'name = "x"', "x.toml")
    with pytest.raises(MaterialError, match="no such materials file"):
        load_materials(tmp_path / "missing.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text(TEXT.replace('unit = "MPa"', 'unit = "psi"', 1), encoding="utf-8")
    with pytest.raises(MaterialError) as err:
        load_materials(bad)
    assert str(err.value).startswith(f"{bad}: inks.lce.youngs_modulus.unit: 'psi'")
    assert hashlib.sha256(TEXT.encode()).hexdigest()  # the package file itself stays readable
    assert math.isfinite(
        load_materials(save_materials(PAPER, tmp_path / "ok.toml")).material("lce").density
    )

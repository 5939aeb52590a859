"""Materials registry, blends and the shipped measured tables."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rotomorph.errors import InvalidParameterError, MaterialError
from rotomorph.materials import (
    Material,
    blend_material,
    get_material,
    known_materials,
    load_table,
    register_material,
    table_names,
)


def test_paper_inks_have_measured_values() -> None:
    lce, acr = get_material("lce"), get_material("acrylate")
    assert get_material("LCE ") is lce
    assert lce.kind == "active" and acr.kind == "passive"
    assert lce.youngs_modulus == pytest.approx(29.67) and lce.youngs_modulus_spread == 2.55
    assert acr.youngs_modulus == pytest.approx(0.57)
    assert lce.glass_transition == pytest.approx(-2.71)
    assert acr.glass_transition == pytest.approx(-63.12)
    assert lce.actuation_length == pytest.approx(0.67)
    assert acr.actuation_length == pytest.approx(1.03)
    assert acr.transition_temperature is None
    assert lce.youngs_modulus / acr.youngs_modulus == pytest.approx(52.05, rel=1e-3)
    assert acr.free_strain("engineering") == pytest.approx(0.03)
    assert acr.free_strain("hencky") == pytest.approx(math.log(1.03))
    assert lce.shear_modulus == pytest.approx(29.67 / 3.0)
    assert any("PLACEHOLDER" in a for a in lce.assumptions)
    assert all("density" in " ".join(m.assumptions) for m in (lce, acr))
    assert "paper-inks" in lce.source[0]  # the materials file the values come from
    assert any("Fig. 1D/E" in line for line in lce.source)


def test_unknown_material_lists_known_names() -> None:
    with pytest.raises(MaterialError, match=r"known: .*acrylate.*lce"):
        get_material("pdms")


def test_register_and_overwrite() -> None:
    mat = Material("test_ink_x", "passive", 2.0, 0.45, -50.0, None, 1.01, 1.2)
    register_material(mat)
    assert get_material("test_ink_x") is mat
    assert "test_ink_x" in known_materials()
    with pytest.raises(MaterialError, match="overwrite=True"):
        register_material(mat)
    stiffer = Material("test_ink_x", "passive", 3.0, 0.45, -50.0, None, 1.01, 1.2)
    assert register_material(stiffer, overwrite=True) is get_material("test_ink_x")


@pytest.mark.parametrize(
    ("field", "kwargs"),
    [
        ("youngs_modulus", {"youngs_modulus": -1.0}),
        ("poisson_ratio", {"poisson_ratio": 0.6}),
        ("kind", {"kind": "smart"}),
        ("transition_temperature", {"kind": "active", "transition_temperature": None}),
        ("actuation_length", {"actuation_length": float("nan")}),
        ("glass_transition", {"glass_transition": -300.0}),
    ],
)
def test_material_validation_names_the_field(field: str, kwargs: dict) -> None:
    base = dict(
        name="x",
        kind="passive",
        youngs_modulus=1.0,
        poisson_ratio=0.5,
        glass_transition=0.0,
        transition_temperature=None,
        actuation_length=1.0,
        density=1.0,
    )
    base.update(kwargs)
    with pytest.raises(MaterialError, match=field):
        Material(**base)


def test_blends_are_flagged_placeholders_between_bounds() -> None:
    acr = get_material("acrylate")
    b10, b4 = get_material("acrylate_1to10"), get_material("acrylate_1to4")
    assert acr.youngs_modulus < b10.youngs_modulus < b4.youngs_modulus
    assert any("PLACEHOLDER" in a for a in b4.assumptions)
    # logarithmic rule: ln E = phi ln Es + (1 - phi) ln Ep, phi = 1/5
    es = 100.0
    assert b4.youngs_modulus == pytest.approx(math.exp(0.2 * math.log(es) + 0.8 * math.log(0.57)))
    v = blend_material(acr, 50.0, 1, 4, rule="voigt").youngs_modulus
    r = blend_material(acr, 50.0, 1, 4, rule="reuss").youngs_modulus
    g = blend_material(acr, 50.0, 1, 4).youngs_modulus
    assert v == pytest.approx(0.2 * 50 + 0.8 * 0.57)
    assert r < g < v
    with pytest.raises(MaterialError, match="passive"):
        blend_material(get_material("lce"), 50.0, 1, 4)
    with pytest.raises(MaterialError, match="rule"):
        blend_material(acr, 50.0, 1, 4, rule="magic")  # type: ignore[arg-type]


def test_tables_load_with_sources() -> None:
    names = table_names()
    for expected in (
        "order_parameter",
        "janus_curvature",
        "pure_lce_length",
        "composite_length",
        "normalized_length",
        "sinusoid_end_to_end",
        "lattice_area",
    ):
        assert expected in names
    for name in names:
        t = load_table(name)
        assert len(t) >= 2
        assert all(s.strip() for s in t.source)
        assert np.all(t.spread > 0)
    jc = load_table("janus_curvature")
    np.testing.assert_allclose(jc.x, [0.25, 0.5, 1.75, 3.0])
    np.testing.assert_allclose(jc.value, [0.13, 0.23, 0.47, 0.59])
    np.testing.assert_allclose(jc.spread, [0.02, 0.01, 0.05, 0.04])
    assert set(jc.unit) == {"1/mm"}
    np.testing.assert_allclose(load_table("pure_lce_length").value, [0.80, 0.86, 0.91, 0.87])
    np.testing.assert_allclose(load_table("composite_length").value, [0.22, 0.98])
    np.testing.assert_allclose(load_table("sinusoid_end_to_end").value, [1.37, 0.64])
    np.testing.assert_allclose(load_table("sinusoid_end_to_end").spread, [0.07, 0.05])
    np.testing.assert_allclose(load_table("lattice_area").value, [99, -28])
    np.testing.assert_allclose(load_table("order_parameter").value, [0.150, 0.230])
    assert jc.near(1.75) == 2
    sub = jc.select([0, 3])
    np.testing.assert_allclose(sub.x, [0.25, 3.0])
    with pytest.raises(InvalidParameterError, match="available"):
        load_table("nope")
    with pytest.raises(InvalidParameterError):
        jc.near(7.0)

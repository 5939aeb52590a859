"""Heating ramps: homogeneous lattices, dome and saddle signs, readings, supports, gravity."""

from __future__ import annotations

import numpy as np
import pytest

from rotomorph.design.lattices import sinusoidal_lattice
from rotomorph.errors import InvalidParameterError
from rotomorph.lattice import (
    ACTUATIONS,
    AdditiveCurvature,
    CurvatureScaling,
    ThermalActuation,
    free_edge_ratio,
    get_actuation,
    heat_lattice,
    lattice_gravity,
    lattice_model,
    perturbed_state,
)
from rotomorph.lattice.heating import segment_clearance

SHORT = {"swapped": CurvatureScaling("swapped", end=0.3), "additive": AdditiveCurvature(end=0.3)}


@pytest.mark.parametrize("actuation", ["swapped", "additive"])
def test_homogeneous_lattice_area_is_free_edge_ratio_squared(actuation):
    lat = sinusoidal_lattice(pattern="expanding")
    res = heat_lattice(lat, actuation=actuation, steps=4)
    ratio = free_edge_ratio(lat, actuation=actuation)
    assert res.energy[-1] < 1e-12
    assert res.area_ratio[-1] == pytest.approx(ratio**2, rel=1e-2)
    assert res.area_ratio[-1] > 1.5  # the sheet expands
    assert np.ptp(res.positions[-1][:, 2]) < 1e-3 * lat.spacing  # and stays planar
    assert res.positions.shape == (5, 425, 3)
    assert res.edge_ratios.shape == (5, 40)
    assert np.allclose(res.edge_ratios[-1], ratio, rtol=1e-6)
    assert res.mean_edge_strain[-1] == pytest.approx(ratio - 1.0, rel=1e-6)


def test_contracting_lattice_contracts_without_contact():
    lat = sinusoidal_lattice(pattern="contracting")
    res = heat_lattice(lat, actuation="swapped", steps=4)
    assert res.area_ratio[-1] < 0.72  # far below the paper's jammed -28 % (notes C2)
    assert res.area_ratio[-1] == pytest.approx(
        free_edge_ratio(lat, actuation="swapped") ** 2, rel=1e-2
    )
    assert res.first_overlap() is not None  # filaments pass through each other (no contact)


@pytest.mark.parametrize("actuation", ["swapped", "additive"])
@pytest.mark.parametrize("pattern,sign", [("dome", 1), ("saddle", -1)])
def test_dome_and_saddle_signs_do_not_depend_on_the_seed(pattern, sign, actuation):
    lat = sinusoidal_lattice(pattern=pattern)
    for seed in (0, 1, 2):
        res = heat_lattice(lat, actuation=SHORT[actuation], steps=6, seed=seed)
        assert res.gaussian_sign[0] == 0
        assert res.gaussian_sign[-1] == sign
        assert res.characteristic_curvature[-1] > 0.05  # 1/mm, clearly curved


def test_literal_reading_inverts_the_paper():
    """Reading (a) (c multiplies the curvature) turns the dome pattern into a saddle (Q4)."""
    literal = CurvatureScaling("literal", end=0.3)
    dome = heat_lattice(sinusoidal_lattice(pattern="dome"), actuation=literal, steps=6)
    assert dome.gaussian_sign[-1] == -1
    flat = heat_lattice(sinusoidal_lattice(pattern="expanding"), actuation=literal, steps=3)
    assert flat.area_ratio[-1] < 1.0  # the "expanding" lattice contracts


def test_readings_and_names():
    assert set(ACTUATIONS) == {"literal", "swapped", "radius", "additive", "thermal", "program"}
    for name in ACTUATIONS:
        assert get_actuation(name).name == name
    sw = CurvatureScaling("swapped")
    assert sw.factors(0.75) == (0.25, 1.75)
    assert CurvatureScaling("radius").factors(0.5) == pytest.approx((2 / 3, 2.0))
    with pytest.raises(InvalidParameterError, match="reading"):
        CurvatureScaling("squared")  # type: ignore[arg-type]
    with pytest.raises(InvalidParameterError, match="actuation"):
        get_actuation("melt")
    with pytest.raises(InvalidParameterError, match="end"):
        CurvatureScaling("radius", end=1.0)
    # junction pairs and the twist keep their printed values
    lm = lattice_model(sinusoidal_lattice(pattern="dome"))
    model = sw.natural(lm, 0.5)
    junction = lm.model.stencils.junction
    assert np.array_equal(model.natural_curvature2[junction], lm.printed[1][junction])
    assert np.array_equal(model.natural_twist, lm.printed[2])


def test_thermal_mode_is_flat_when_cold_and_expands_hot():
    lat = sinusoidal_lattice(pattern="expanding")
    act = ThermalActuation(start=25.0, end=175.0)
    lm = lattice_model(lat)
    assert act.fraction(lm, 25.0) < 1e-2
    assert act.fraction(lm, 175.0) > 0.99
    res = heat_lattice(lat, actuation=act, steps=4)
    assert res.parameter[-1] == 175.0
    assert res.area_ratio[-1] > 1.2


def test_clamped_boundary_and_gravity():
    lat = sinusoidal_lattice(n=3, ghost_nodes=4, pattern="expanding")
    res = heat_lattice(lat, actuation="swapped", steps=2, supports="clamped-boundary")
    assert res.area_ratio[-1] == pytest.approx(1.0, abs=0.05)  # the frame holds it
    g = lattice_gravity(lat)
    cold = CurvatureScaling("swapped", end=0.0)
    kw = {"actuation": cold, "steps": 1, "supports": "clamped-boundary"}
    sag = heat_lattice(lat, gravity=g, **kw)
    ref = heat_lattice(lat, **kw)
    centre = lat.branch_index(1, 1)
    # sags under its buoyancy-reduced weight
    assert sag.positions[-1][centre, 2] < ref.positions[-1][centre, 2]
    with pytest.raises(InvalidParameterError, match="supports"):
        heat_lattice(lat, gravity=g)
    with pytest.raises(InvalidParameterError, match="steps"):
        heat_lattice(lat, steps=0)


def test_perturbed_state_keeps_frames_consistent():
    lm = lattice_model(sinusoidal_lattice(n=3, ghost_nodes=2))
    dz = np.linspace(0, 0.1, lm.model.network.n_nodes)
    s = perturbed_state(lm.model, dz)
    assert np.allclose(s.positions[:, 2], dz)
    assert np.allclose(np.einsum("ij,ij->i", s.tangents, s.directors), 0.0, atol=1e-12)
    assert np.allclose(np.linalg.norm(s.tangents, axis=1), 1.0)
    with pytest.raises(InvalidParameterError, match="dz"):
        perturbed_state(lm.model, np.zeros(3))


def test_segment_clearance():
    pts = np.array([[0, 0, 0], [1, 0, 0], [0.5, -0.5, 0.3], [0.5, 0.5, (0.3).__float__()]])
    edges = np.array([[0, 1], [2, 3]])
    assert segment_clearance(pts, edges, 0.1, cap=10.0) == pytest.approx(3.0)
    assert segment_clearance(pts, edges, 0.1) == 2.0  # capped


def test_segment_clearance_equals_the_contact_distance_of_any_pair():
    """Random, nearly parallel and parallel pairs, most with closest points at an end (the
    crossing above has both inside): the clearance is the contact layer's segment distance
    (a separate, compiled implementation). Without the re-clamp of s after clamping t the
    clearance came out up to 2.5 mm too large on these, i.e. overlaps reported as clear."""
    from rotomorph.contact.distance import pair_distances

    rng = np.random.default_rng(0)
    edges, quad = np.array([[0, 1], [2, 3]]), np.array([[0, 1, 2, 3]])
    for k in range(60):
        pts = rng.normal(size=(4, 3))
        if k % 3:  # parallel (k % 3 == 2) or nearly so
            pts[3] = pts[2] + (pts[1] - pts[0]) * rng.uniform(0.3, 2.0)
            pts[3] += (k % 3 == 1) * 1e-3 * rng.normal(size=3)
        want = pair_distances(pts, quad)[0]
        assert segment_clearance(pts, edges, 1.0, cap=100.0) == pytest.approx(want, abs=1e-12)

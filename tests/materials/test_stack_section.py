"""The fused stack of printed layers as one section: mesh, stiffness, torsion, natural strains."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from rotomorph.errors import InvalidParameterError
from rotomorph.materials.janus import filament_section
from rotomorph.materials.stack import stack_mesh, stack_section

R, EA, EP = 0.3, 2.1, 1.0
SQRT_HALF = float(np.sqrt(0.5))


def test_one_layer_is_the_janus_disk() -> None:
    one, disk = stack_section(R, 1, 0.0, EA, EP), filament_section(R, EA, EP)
    for name in ("axial_stiffness", "bending_stiffness1", "bending_stiffness2"):
        assert getattr(one, name) == pytest.approx(getattr(disk, name), rel=1e-12)
    assert one.twist_stiffness == pytest.approx(disk.twist_stiffness, rel=1e-4)
    state = (0.3, -0.2, 0.1, 0.01)  # a helical director: eigen-twist and all
    for a, b in zip(one.natural_strains(*state), disk.natural_strains(*state), strict=True):
        np.testing.assert_allclose(a, b, rtol=1e-4, atol=1e-9)


@pytest.mark.parametrize("direction", [(0.0, 1.0), (1.0, 0.0), (0.6, 0.8)])
def test_touching_layers_are_the_bonded_composite_beam(direction) -> None:  # type: ignore[no-untyped-def]
    """Disks one diameter apart: the section's bending matrix is N I_1 + EA_1 Σ o_k² s sᵀ
    (parallel axes), its torsion constant N C_1 (a line carries no shear), and the natural
    curvature of identical layers the composite beam's (N I_1 + EA_1 S)⁻¹ N I_1 κ_1."""
    n, h = 3, 2.0 * R
    s = np.asarray(direction) / np.linalg.norm(direction)
    stack, layer = stack_section(R, n, h, EA, EP, direction=direction), filament_section(R, EA, EP)
    offsets = (np.arange(n) - 1.0) * h
    i1 = layer.axial.bending_matrix
    expected = n * i1 + layer.axial_stiffness * np.sum(offsets**2) * np.outer(s, s)
    # (the layers' circles are polygons turned to the stacking direction: for a direction
    # between the axes they differ from the disk's by its polygon error)
    tol = 1e-10 if 0.0 in direction else 1e-6
    scale = float(np.abs(expected).max())
    np.testing.assert_allclose(stack.axial.bending_matrix, expected, rtol=0, atol=tol * scale)
    assert stack.axial_stiffness == pytest.approx(n * layer.axial_stiffness, rel=tol)
    assert stack.twist_stiffness == pytest.approx(n * layer.twist_stiffness, rel=2e-4)
    for state in ((0.0, -0.2, 0.1, 0.01), (0.0, -0.3, 0.05, 0.02)):
        eps, kappa, _ = stack.natural_strains(*state)
        eps1, kappa1, _ = layer.natural_strains(*state)
        assert eps[0] == pytest.approx(eps1[0], rel=10 * tol)
        composite = np.linalg.solve(expected, n * i1 @ kappa1[0])
        size = float(np.abs(composite).max())
        np.testing.assert_allclose(kappa[0], composite, rtol=0, atol=10 * tol * size)


def test_fusing_adds_torsion_and_the_mesh_converges() -> None:
    """Overlapping layers fuse over a band: the torsion constant rises above N C_1 and keeps
    rising with the overlap. The neck's re-entrant corners slow the mesh convergence (C / 3 C_1
    at h = 0.5 mm: 1.343, 1.317, 1.311, 1.310 at 32, 96, 192, 256 boundary vertices): the
    default mesh is within 1 % of the finest."""
    layer = filament_section(R, EA, EP)
    ratio = [
        stack_section(R, 3, h, EA, EP).twist_stiffness / (3 * layer.twist_stiffness)
        for h in (0.6, 0.55, 0.5, 0.4)
    ]
    assert ratio[0] == pytest.approx(1.0, abs=2e-4)
    assert all(b > a for a, b in itertools.pairwise(ratio))
    assert 1.25 < ratio[2] < 1.4
    c = [stack_section(R, 3, 0.5, EA, EP, resolution=k).twist_stiffness for k in (32, 96, 192)]
    assert abs(c[1] - c[2]) < 0.01 * c[2] and abs(c[1] - c[2]) < 0.5 * abs(c[0] - c[2])


def test_the_mesh_conforms_to_every_chord() -> None:
    """Every triangle lies in one layer and one phase: its vertices are inside its layer's
    disk and on its phase's side of the interface chord (within round-off)."""
    for h, direction in ((0.45, (0.0, 1.0)), (0.45, (0.6, 0.8)), (0.6, (1.0, 0.0))):
        sm = stack_mesh(R, 3, h, 0.5, direction, 48)
        pts = sm.mesh.points[sm.mesh.triangles]  # (T, 3, 2)
        local = pts - sm.centres[sm.layer][:, None, :]
        assert np.all(np.linalg.norm(local, axis=2) <= R * (1 + 1e-9))
        side = np.where(sm.mesh.active[:, None], local[..., 0], -local[..., 0])
        assert np.all(side >= -1e-9)
        total = float(sm.mesh.areas.sum())
        if h == 0.6:
            assert total == pytest.approx(3 * np.pi * R**2, rel=5e-3)  # 48-gons
        else:  # two lenses fewer
            lens = 2 * R**2 * np.arccos(h / (2 * R)) - 0.5 * h * np.sqrt(4 * R**2 - h**2)
            assert total == pytest.approx(3 * np.pi * R**2 - 2 * lens, rel=5e-3)


def test_layers_that_do_not_touch_are_refused() -> None:
    with pytest.raises(InvalidParameterError, match="layer_height"):
        stack_section(R, 3, 0.61, EA, EP)
    with pytest.raises(InvalidParameterError, match="direction"):
        stack_section(R, 3, 0.6, EA, EP, direction=(0.0, 0.0))


@pytest.mark.parametrize("direction", [(0.0, 1.0), (1.0, 0.0)])
def test_touching_layers_fold_onto_one_layer(direction) -> None:  # type: ignore[no-untyped-def]
    """Touching identical layers are solved on one layer's quadrature (a third of the work):
    the same natural strains, curved-bar changes and twist as the whole section's to round-off,
    and a printed curvature along the stacking direction goes to the whole section."""
    from rotomorph.materials.stack import FoldedStackSection

    folded = stack_section(R, 3, 0.6, EA, EP, direction=direction)
    assert isinstance(folded, FoldedStackSection) and folded.full is not None
    full = folded.full
    assert 3 * len(folded.axial.points) == len(full.axial.points)
    rng = np.random.default_rng(5)
    n = 8
    states = np.column_stack([
        0.3 * rng.standard_normal(n), -0.2 + 0.02 * rng.standard_normal(n),
        0.1 + 0.01 * rng.standard_normal(n), np.full(n, 0.02),
    ])  # fmt: skip
    a, b = folded._solve_states(states), full._solve_states(states)
    np.testing.assert_allclose(a, b, rtol=0, atol=1e-12 * np.abs(b).max())
    across = np.zeros((n, 2))
    across[:, 0 if direction == (0.0, 1.0) else 1] = 1.5 * rng.standard_normal(n)
    for k0 in (across, 0.5 * rng.standard_normal((n, 2))):  # perpendicular, then any
        got = folded.curved_strains(*states.T, k0)
        want = full.curved_strains(*states.T, k0)
        for x, y in zip(got, want, strict=True):
            np.testing.assert_allclose(x, y, rtol=0, atol=1e-12 * np.abs(y).max())
    assert folded.twist_stiffness == full.twist_stiffness

"""Stacked printed layers: the fused stack as one section, not N copies of one filament."""

from __future__ import annotations

import numpy as np
import pytest

from rotomorph.design.lattices import sinusoidal_lattice
from rotomorph.lattice.actuation import ProgramActuation
from rotomorph.lattice.model import lattice_model, stack_moment


def test_stack_moment() -> None:
    assert stack_moment(1, 0.6) == 0.0
    assert stack_moment(2, 0.6) == pytest.approx(2 * 0.3**2)
    assert stack_moment(3, 0.6) == pytest.approx(2 * 0.6**2)


@pytest.fixture(scope="module")
def models():  # type: ignore[no-untyped-def]
    lat = sinusoidal_lattice(3, pattern="contracting")
    return (
        lat,
        lattice_model(lat, stiffness="janus", layers=1),
        lattice_model(lat, stiffness="janus"),
    )


def test_touching_layers_are_the_bonded_composite_beam(models) -> None:  # type: ignore[no-untyped-def]
    """Layers one diameter apart touch on a line: the fused section's bending stiffness
    follows the parallel-axis theorem exactly, its torsion constant is N C (no shear across
    a line) to the mesh's accuracy."""
    lat, one, three = models
    n, m1, m3 = lat.layers, one.model, three.model
    assert n == 3 and three.stacked and not one.stacked
    ea = np.asarray(m1.axial_stiffness)
    expected = n * np.asarray(m1.bending_stiffness1) + ea * stack_moment(n, lat.layer_height)
    assert np.allclose(m3.bending_stiffness1, expected, rtol=1e-12)
    for name in ("bending_stiffness2", "axial_stiffness"):
        assert np.allclose(getattr(m3, name), n * np.asarray(getattr(m1, name)), rtol=1e-12)
    assert np.allclose(m3.twist_stiffness, n * np.asarray(m1.twist_stiffness), rtol=1e-4)
    # the stack resists curling out of its plane about ten times more than in it
    ratio = np.asarray(m3.bending_stiffness1) / np.asarray(m3.bending_stiffness2)
    assert np.all(ratio > 8.0)
    assert np.all(one.vertical_share == 1.0)
    assert np.all((three.vertical_share > 0.0) & (three.vertical_share < 0.2))


def test_fused_layers_twist_stiffer_than_touching_ones() -> None:
    """Layers closer than a diameter overlap in a fused band: the section's torsion constant
    grows above N C (it carries shear across the band), its area and out-of-plane bending
    stiffness shrink with the overlap."""
    touch = lattice_model(sinusoidal_lattice(3), stiffness="janus").model
    fused = lattice_model(sinusoidal_lattice(3, layer_height=0.5), stiffness="janus").model
    c = np.asarray(fused.twist_stiffness) / np.asarray(touch.twist_stiffness)
    assert np.all(c > 1.25) and np.all(c < 1.4)
    assert np.all(np.asarray(fused.axial_stiffness) < np.asarray(touch.axial_stiffness))
    assert np.all(np.asarray(fused.bending_stiffness1) < np.asarray(touch.bending_stiffness1))


def test_layers_that_do_not_touch_are_refused() -> None:
    from rotomorph.errors import InvalidParameterError

    with pytest.raises(InvalidParameterError, match="layer_height"):
        lattice_model(sinusoidal_lattice(3, layer_height=0.7), stiffness="janus")


def test_the_stack_shares_only_the_vertical_natural_curvature(models) -> None:  # type: ignore[no-untyped-def]
    """Every layer prints the same program: the fused stack's in-plane natural curvature and
    twist are the layer's, its curvature toward z the stiffness-weighted share (touching
    layers: the bonded beam's algebra, to the mesh's accuracy)."""
    _, one, three = models
    act = ProgramActuation()
    a, b = act.natural(one, 175.0), act.natural(three, 175.0)
    k1p, _, _ = one.printed
    assert np.allclose(b.natural_curvature2, a.natural_curvature2, rtol=1e-6, atol=1e-9)
    assert np.allclose(b.natural_twist, a.natural_twist, rtol=1e-6, atol=1e-9)
    d1 = np.asarray(a.natural_curvature1) - k1p
    # (ideal step flips: no vertex sits with its active side up, so nothing curls toward z;
    # the stack's share of a curvature toward z is tested on the section itself)
    scale = float(np.abs(np.asarray(a.natural_curvature2)).max())
    assert np.allclose(
        np.asarray(b.natural_curvature1) - k1p,
        three.vertical_share * d1,
        rtol=1e-6,
        atol=1e-7 * scale,
    )
    assert np.allclose(b.rest_length, a.rest_length, rtol=1e-9)


def test_paper_stiffness_keeps_the_multiplier() -> None:
    lat = sinusoidal_lattice(3)
    one = lattice_model(lat, layers=1).model
    three = lattice_model(lat).model
    assert np.allclose(three.bending_stiffness1, 3 * np.asarray(one.bending_stiffness1))

"""Stacked printed layers: a bonded composite beam, not N copies of one filament."""

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


def test_stack_stiffness_follows_the_parallel_axis_theorem(models) -> None:  # type: ignore[no-untyped-def]
    lat, one, three = models
    n, m1, m3 = lat.layers, one.model, three.model
    assert n == 3
    ea = np.asarray(m1.axial_stiffness)
    expected = n * np.asarray(m1.bending_stiffness1) + ea * stack_moment(n, lat.layer_height)
    assert np.allclose(m3.bending_stiffness1, expected, rtol=1e-12)
    for name in ("bending_stiffness2", "twist_stiffness", "axial_stiffness"):
        assert np.allclose(getattr(m3, name), n * np.asarray(getattr(m1, name)), rtol=1e-12)
    # the stack resists curling out of its plane about ten times more than in it
    ratio = np.asarray(m3.bending_stiffness1) / np.asarray(m3.bending_stiffness2)
    assert np.all(ratio > 8.0)
    assert np.all(one.vertical_share == 1.0)
    assert np.all((three.vertical_share > 0.0) & (three.vertical_share < 0.2))


def test_stack_shares_only_the_vertical_natural_curvature(models) -> None:  # type: ignore[no-untyped-def]
    _, one, three = models
    act = ProgramActuation()
    a, b = act.natural(one, 175.0), act.natural(three, 175.0)
    k1p, _, _ = one.printed
    assert np.allclose(b.natural_curvature2, a.natural_curvature2, rtol=1e-12, atol=1e-15)
    assert np.allclose(b.natural_twist, a.natural_twist, rtol=1e-12, atol=1e-15)
    d1 = np.asarray(a.natural_curvature1) - k1p
    assert np.allclose(
        np.asarray(b.natural_curvature1) - k1p, three.vertical_share * d1, atol=1e-14
    )


def test_paper_stiffness_keeps_the_multiplier() -> None:
    lat = sinusoidal_lattice(3)
    one = lattice_model(lat, layers=1).model
    three = lattice_model(lat).model
    assert np.allclose(three.bending_stiffness1, 3 * np.asarray(one.bending_stiffness1))

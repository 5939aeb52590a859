"""A dome lattice printed perfectly flat, with no symmetry-breaking noise, still rises: the flat
equilibrium is a saddle above a finite actuation and the solver leaves it (it used to return
the flat state as the result). The paper's curvature-scaling reading ('swapped') keeps every
natural curvature in the plane, so the flat state is an exact equilibrium at every step."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from rotomorph.design.lattices import sinusoidal_lattice
from rotomorph.lattice.heating import RAMP_OPTIONS, heat_lattice

ACT = "swapped"


@pytest.fixture(scope="module")
def dome():
    return sinusoidal_lattice(n=5, ghost_nodes=4, pattern="dome")


def test_flat_dome_without_noise_rises_and_every_step_is_stable(dome):
    flat = heat_lattice(dome, actuation=ACT, steps=4, perturbation=0.0)
    assert all(flat.stable)
    assert (flat.gaussian_sign[1:] == 1).all()
    assert np.isfinite(flat.lowest_eigenvalue[1:]).all() and (flat.lowest_eigenvalue[1:] > 0).all()
    # the same dome as from the default perturbed start (up to which side it rises to)
    noisy = heat_lattice(dome, actuation=ACT, steps=4)
    assert flat.area_ratio[-1] == pytest.approx(noisy.area_ratio[-1], rel=1e-4)
    assert flat.characteristic_curvature[-1] == pytest.approx(
        noisy.characteristic_curvature[-1], rel=1e-3
    )


def test_without_the_check_the_flat_saddle_point_is_returned(dome):
    """The regression the check removes: the flat state reported as an equilibrium."""
    plain = replace(RAMP_OPTIONS, check_stability=False)
    flat = heat_lattice(dome, actuation=ACT, steps=4, perturbation=0.0, options=plain)
    assert (flat.gaussian_sign == 0).all() and np.ptp(flat.positions[-1][:, 2]) == 0.0
    assert not any(flat.stable[1:])

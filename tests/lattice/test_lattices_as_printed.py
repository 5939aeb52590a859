"""The report's lattices as printed: no two layers of their stacks ever interpenetrate.

The contact-resolved ramps whose states the paper report counts and draws (the 5 x 5
contracting, dome and saddle lattices on the bath floor under buoyant weight, at the counted
resolution of 20 ghost nodes per edge, with its path check and lift-off bisection): every state
of every ramp is admissible and physical. Slow (about 1.2 min of CPU).
"""

from __future__ import annotations

import pytest

from rotomorph.simulate.report import (
    LATTICE_GHOSTS,
    LATTICE_STEPS,
    LIFT_OFF_TOLERANCE,
    PATH_CHECK_FACTOR,
    _heat,
    calibrated_model,
)


@pytest.mark.slow
@pytest.mark.parametrize("pattern", ["contracting", "dome", "saddle"])
def test_every_counted_state_keeps_its_layers_apart(pattern: str) -> None:
    ghosts = LATTICE_GHOSTS[False][1]  # the counted resolution
    fm, _ = calibrated_model()
    tol = LIFT_OFF_TOLERANCE if pattern in ("dome", "saddle") else None
    lattice, res, why = _heat(
        pattern, False, LATTICE_STEPS, fm, ghosts, True,
        lift_off_tolerance=tol, path_check=PATH_CHECK_FACTOR,
    )  # fmt: skip
    assert res is not None, why
    assert lattice.layers == 3 and res.contact.stack.count == 3
    assert res.stack_overlaps is not None
    assert res.stack_overlaps.tolist() == [0] * len(res.parameter)
    assert all(res.physical), res.stable
    # the contact barrier ends at touching and is infinite 1 % of the diameter inside it
    # (Contact.offset's default): pressed stacks settle within a small part of that
    assert float(res.min_clearance.min()) >= 0.995

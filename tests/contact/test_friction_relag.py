"""Friction that acts: within a load step the lag is re-evaluated at the solution (IPC's outer
loop), so a contact that forms during the step carries friction.

Exact case: the simply supported beam of ``test_contact_mechanics`` pressed onto the crossing
rod (contact force ``F_c = P - 48 EI delta0 / L^3``) and pushed along the rod by ``Q`` in the
same step. Its lateral stiffness at mid-span is ``k = 48 EI / L^3`` (pinned ends, the same
``EI`` both ways). With Coulomb friction ``mu``: below ``mu F_c`` the contact sticks (the beam
moves less than the smoothing slip), above it slides with the friction force ``mu F_c``, so the
mid-span moves ``(Q - mu F_c) / k``. Lagged once at the step's start, where nothing touches, it
has no friction at all and moves ``Q / k``.
"""

from __future__ import annotations

import numpy as np
import pytest
from tests.contact.test_contact_mechanics import R, _beam_on_rod

from rotomorph.contact import Contact, ContactPotential
from rotomorph.contact.friction import lag_change
from rotomorph.design.network import Network
from rotomorph.errors import InvalidParameterError
from rotomorph.lattice.heating import FRICTION_LAG_TOL, relag_friction
from rotomorph.solve.loads import Loads
from rotomorph.solve.static import solve_static

MU = 0.5


def _pushed(along: float):  # type: ignore[no-untyped-def]
    """The beam at 3 x its closing load pushed along the rod by ``along`` x mu F_c: the
    step's first solve (friction lagged at the unloaded start) and the re-lagged one."""
    model, supports, loads, closing, nb = _beam_on_rod(3.0)
    mid = nb // 2
    force = 2.0 * closing  # F_c
    push = along * MU * force
    loads = Loads(forces=((mid, (0.0, push, -3.0 * closing)),))
    contact = Contact(radius=R, friction=MU)
    first = solve_static(model, supports, loads, contact=contact)
    final, spent = relag_friction(
        model, supports, loads, model.reference_state(), first, contact, None
    )
    stiffness = 48 * (np.pi * R**4 / 4) / 40.0**3
    return first, final, spent, mid, push, force, stiffness


def test_a_contact_formed_within_the_step_sticks_below_the_coulomb_bound():
    first, final, spent, mid, push, _, stiffness = _pushed(0.5)
    assert first.positions[mid, 1] == pytest.approx(push / stiffness, rel=0.01)  # no friction
    assert spent > 0 and final.stable
    assert abs(final.positions[mid, 1]) < final.contact.slip  # sticks
    # the lag at the solution is the one it was solved with: converged
    pot = final.contact
    assert pot.friction_lag is not None
    again = pot.lag(pot.friction_lag.start[: pot.n_nodes], at=final.positions)
    assert lag_change(pot.friction_lag, again) <= FRICTION_LAG_TOL


def test_a_contact_formed_within_the_step_slides_with_the_coulomb_force():
    first, final, _, mid, push, force, stiffness = _pushed(1.5)
    assert first.positions[mid, 1] == pytest.approx(push / stiffness, rel=0.01)
    lagged = final.contact.friction_lag.normal_force.sum()
    assert lagged == pytest.approx(force, rel=0.01)  # the contact force, lagged
    assert final.positions[mid, 1] == pytest.approx((push - MU * force) / stiffness, rel=0.01)


def test_lag_change_measures_normal_forces_and_normals():
    net = Network(np.array([[0.0, 0, 0], [1, 0, 0], [0.5, -1, 0.995], [0.5, 1, 0.995]]),
                  np.array([[0, 1], [2, 3]]))  # fmt: skip
    printed = net.nodes + np.array([[0, 0, 0]] * 2 + [[0, 0, 5.0]] * 2)
    pot = ContactPotential(Contact(radius=0.5, friction=0.3), Network(printed, net.edges))
    x = np.ascontiguousarray(net.nodes)
    a = pot.lag(x)
    assert a.count == 1 and lag_change(a, a) == 0.0
    pressed = x.copy()
    pressed[2:, 2] -= 0.002  # pressed harder
    b = pot.lag(x, at=pressed)
    assert np.array_equal(b.start, a.start)  # slips still from x
    ratio = b.normal_force[0] / a.normal_force[0]
    assert ratio > 1 and lag_change(a, b) == pytest.approx((ratio - 1) / ratio, rel=1e-12)
    tilted = x.copy()
    tilted[2, 2] += 0.004  # the upper rod tilts: the contact normal turns, the force stays
    tilted[3, 2] -= 0.004
    c = pot.lag(x, at=tilted)
    assert 0 < lag_change(a, c) < 0.1
    apart = x.copy()
    apart[2:, 2] += 0.1
    assert lag_change(a, pot.lag(x, at=apart)) == 1.0  # the contact is gone


def test_a_friction_lag_needs_friction_of_its_own_coefficient():
    net = Network(np.array([[0.0, 0, 0], [1, 0, 0]]), np.array([[0, 1]]))
    lag = ContactPotential(Contact(radius=0.1, friction=0.3), net).lag(net.nodes)
    Contact(radius=0.1, friction=0.3, friction_lag=lag)
    for bad in (dict(friction=0.0), dict(friction=0.4)):
        with pytest.raises(InvalidParameterError, match="friction_lag"):
            Contact(radius=0.1, friction_lag=lag, **bad)

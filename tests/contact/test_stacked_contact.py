"""Contact of printed stacks: layer capsules on the material director, exact derivatives."""

from __future__ import annotations

import numpy as np
import pytest

from rotomorph.contact import Contact, ContactPotential, Floor
from rotomorph.contact.stack import Stack
from rotomorph.contact.stacked import StackedContact
from rotomorph.design.network import Network
from rotomorph.errors import InvalidParameterError
from rotomorph.geometry import parallel_transport, unit

R = 0.3
STACK = Stack.layered(3, 0.6)


def _crossing(gap: float, n: int = 6, tilt: float = 0.0):  # type: ignore[no-untyped-def]
    """A rod along x and a rod along y ``gap`` above it (mm), ``n`` segments each."""
    s = np.linspace(-2.0, 2.0, n + 1)
    a = np.column_stack([s, np.zeros_like(s), tilt * s])
    b = np.column_stack([np.zeros_like(s), s, np.full_like(s, gap)])
    nodes = np.vstack([a, b])
    ea = np.column_stack([np.arange(n), np.arange(1, n + 1)])
    edges = np.vstack([ea, ea + n + 1])
    return Network(nodes, edges)


def _frames(x, theta, t_base, d1_base, edges):  # type: ignore[no-untyped-def]
    """The rod objective's frames: tangents, reference directors transported in time from the
    base, material directors turned by theta."""
    t = unit(x[edges[:, 1]] - x[edges[:, 0]])
    d1 = unit(parallel_transport(d1_base, t_base, t))
    d1 = unit(d1 - np.einsum("ij,ij->i", d1, t)[:, None] * t)
    d2 = np.cross(t, d1)
    c, s = np.cos(theta)[:, None], np.sin(theta)[:, None]
    m1 = c * d1 + s * d2
    return t, m1, np.cross(t, m1)


@pytest.fixture(params=[False, True], ids=["pair", "pair-and-floor"])
def stacked_pair(rng, request):  # type: ignore[no-untyped-def]
    """Two crossing stacks whose layers are inside the activation distance, in a random
    twisted and bent configuration (not the printed one); with a floor the lower stack's
    bottom layer rests on it too."""
    net = _crossing(3.0)
    edges = net.edges
    up = np.tile([0.0, 0.0, 1.0], (net.n_edges, 1))
    # the barrier acts from touching (its zone ends there) to the offset inside it
    floor = (Floor(height=-0.6 - R + 0.025),) if request.param else ()
    contact = Contact(radius=R, stack=STACK, activation_distance=0.05, obstacles=floor)
    pot = StackedContact(contact, net, up, force_scale=1e-3)
    x = _crossing(1.8 - 0.025).nodes + 0.003 * rng.standard_normal((net.n_nodes, 3))
    t0 = unit(x[edges[:, 1]] - x[edges[:, 0]])
    d1 = unit(up - np.einsum("ij,ij->i", up, t0)[:, None] * t0)  # near the sheet normal
    theta = 0.01 * rng.standard_normal(net.n_edges)
    return pot, x, theta, t0, d1


def _energy(pot, x, theta, t0, d1):  # type: ignore[no-untyped-def]
    frames = _frames(x, theta, t0, d1, pot.edges)
    return pot.evaluate_blocks(x, frames, False, 0)[0]


def test_one_layer_is_refused_by_the_stacked_binding_and_a_stack_by_the_plain_one() -> None:
    net = _crossing(3.0)
    with pytest.raises(InvalidParameterError, match="StackedContact"):
        ContactPotential(Contact(radius=R, stack=STACK), net)
    with pytest.raises(InvalidParameterError, match=r"Contact\.stack"):
        Contact(radius=R, stack=(0.0, 0.6))  # type: ignore[arg-type]


def test_the_layers_are_inside_the_activation_distance(stacked_pair) -> None:  # type: ignore[no-untyped-def]
    pot, x, theta, t0, d1 = stacked_pair
    frames = _frames(x, theta, t0, d1, pot.edges)
    e, _, gth, blocks = pot.evaluate_blocks(x, frames, True, 1)
    assert np.isfinite(e) and e > 0.0
    assert np.abs(gth).max() > 0.0  # the layers' forces twist the segments
    assert blocks is not None and len(blocks.keys) > 0


def test_gradient_matches_finite_differences(stacked_pair) -> None:  # type: ignore[no-untyped-def]
    pot, x, theta, t0, d1 = stacked_pair
    # re-base the frames at x (the objective evaluates derivatives at its base)
    t, _, _ = _frames(x, theta, t0, d1, pot.edges)
    base_d1 = unit(parallel_transport(d1, t0, t))
    frames = _frames(x, theta, t, base_d1, pot.edges)
    _, gx, gth, _ = pot.evaluate_blocks(x, frames, True, 0)
    h = 1e-6
    fd_x = np.zeros_like(x)
    for i in range(len(x)):
        for k in range(3):
            xp, xm = x.copy(), x.copy()
            xp[i, k] += h
            xm[i, k] -= h
            fd_x[i, k] = (
                _energy(pot, xp, theta, t, base_d1) - _energy(pot, xm, theta, t, base_d1)
            ) / (2 * h)
    fd_t = np.zeros_like(theta)
    for e in range(len(theta)):
        tp, tm = theta.copy(), theta.copy()
        tp[e] += h
        tm[e] -= h
        fd_t[e] = (_energy(pot, x, tp, t, base_d1) - _energy(pot, x, tm, t, base_d1)) / (2 * h)
    scale = max(np.abs(fd_x).max(), np.abs(fd_t).max())
    assert np.abs(gx - fd_x).max() < 1e-6 * scale
    assert np.abs(gth - fd_t).max() < 1e-6 * scale


def _dense(blocks, n):  # type: ignore[no-untyped-def]
    rows, cols, vals = blocks.triplets()
    out = np.zeros((n, n))
    np.add.at(out, (rows, cols), vals)
    return out


def test_hessian_matches_finite_differences_of_the_gradient(stacked_pair) -> None:  # type: ignore[no-untyped-def]
    pot, x, theta, t0, d1 = stacked_pair
    t, _, _ = _frames(x, theta, t0, d1, pot.edges)
    base_d1 = unit(parallel_transport(d1, t0, t))
    nn, ne = len(x), len(theta)
    n = 3 * nn + ne
    _, _, _, blocks = pot.evaluate_blocks(x, _frames(x, theta, t, base_d1, pot.edges), True, 1)
    H = _dense(blocks, n)
    assert np.allclose(H, H.T, atol=1e-9 * np.abs(H).max())

    def grad(q):  # type: ignore[no-untyped-def]
        xq, thq = q[: 3 * nn].reshape(-1, 3), q[3 * nn :]
        # the gradient at q, frames re-based at q (what the objective computes there)
        tq, _, _ = _frames(xq, thq, t, base_d1, pot.edges)
        d1q = unit(parallel_transport(base_d1, t, tq))
        d1q = unit(d1q - np.einsum("ij,ij->i", d1q, tq)[:, None] * tq)
        # theta measured from the transported d1 keeps the same m1
        _, gx, gth, _ = pot.evaluate_blocks(xq, _frames(xq, thq, tq, d1q, pot.edges), True, 0)
        return np.concatenate([gx.ravel(), gth])

    q0 = np.concatenate([x.ravel(), theta])
    h = 1e-6
    fd = np.zeros((n, n))
    for j in range(n):
        qp, qm = q0.copy(), q0.copy()
        qp[j] += h
        qm[j] -= h
        fd[:, j] = (grad(qp) - grad(qm)) / (2 * h)
    fd = 0.5 * (fd + fd.T)
    assert np.abs(H - fd).max() < 1e-5 * np.abs(fd).max()
    # the convex mode drops the frames' indefinite second variation and stays semidefinite
    _, _, _, convex = pot.evaluate_blocks(x, _frames(x, theta, t, base_d1, pot.edges), False, 2)
    assert np.linalg.eigvalsh(_dense(convex, n)).min() > -1e-9 * np.abs(H).max()


def test_forces_and_moments_balance(stacked_pair) -> None:  # type: ignore[no-untyped-def]
    """The layers of two stacks push each other apart: the contact forces on the rods' nodes
    and on the floor balance, and the energy is invariant to a rigid translation (without a
    floor)."""
    pot, x, theta, t0, d1 = stacked_pair
    t, m1, m2 = _frames(x, theta, t0, d1, pot.edges)
    f = pot.forces((x, m1))
    floors = pot.obstacle_forces((x, m1))  # what the lattice exerts on the floor, if any
    total = f.sum(axis=0) + sum(floors, np.zeros(3))
    assert np.abs(total).max() < 1e-9 * np.abs(f).max()
    n = pot.n_nodes // 2
    assert f[:n, 2].sum() < 0.0 < f[n:, 2].sum()  # the lower rod pushed down, the upper up
    if not floors:
        e0 = pot.evaluate_blocks(x, (t, m1, m2), False, 0)[0]
        e1 = pot.evaluate_blocks(x + np.array([3.0, -1.0, 2.0]), (t, m1, m2), False, 0)[0]
        assert e1 == pytest.approx(e0, rel=1e-12)


def test_a_stack_rests_on_its_bottom_layer() -> None:
    net = _crossing(5.0)
    up = np.tile([0.0, 0.0, 1.0], (net.n_edges, 1))
    floor = Floor(height=-0.6 - 1.005 * R)  # under the bottom layer of the lower rod
    pot = StackedContact(Contact(radius=R, stack=STACK, obstacles=(floor,)), net, up)
    x = net.nodes
    pot.check_admissible((x, up))
    d, dmin = pot.distances((x, up))
    assert np.min(d / dmin) == pytest.approx(1.005, rel=1e-9)
    low = Floor(height=-0.6 - 0.9 * R)  # cuts through the bottom layer
    with pytest.raises(InvalidParameterError, match="layers of the printed stack"):
        StackedContact(Contact(radius=R, stack=STACK, obstacles=(low,)), net, up).check_admissible(
            (x, up)
        )
    with pytest.raises(InvalidParameterError, match="material frames"):
        pot.clearance(x)


@pytest.mark.parametrize("moved", [0.0, 0.3])
def test_the_broad_phase_through_the_segments_finds_the_layer_networks_pairs(rng, moved):  # type: ignore[no-untyped-def]
    """The stack's broad phase (a sweep over each segment's box around its layers) proposes
    exactly the pairs a sweep over the layer network itself does, static and swept."""
    from rotomorph.contact.broadphase import near_pairs
    from rotomorph.design.lattices import sinusoidal_lattice

    lat = sinusoidal_lattice(3, ghost_nodes=6)
    net = lat.network
    up = np.tile([0.0, 0.0, 1.0], (net.n_edges, 1))
    layers = StackedContact(Contact(radius=R, stack=STACK), net, up).layers
    x0 = layers.network.nodes + 0.3 * rng.standard_normal(layers.network.nodes.shape)
    x1 = x0 + moved * rng.standard_normal(x0.shape)
    extra = 0.5 * (layers.dhat + layers._pad)
    args = (x0, x1, layers.edges, layers._incident, layers.radius + extra,
            layers.node_radius + extra, layers.excluded)  # fmt: skip
    mine, theirs = layers._near(*args), near_pairs(*args)
    assert len(mine[0]) > 0 and len(mine[1]) > 0
    for a, b in zip(mine, theirs, strict=True):
        assert {tuple(p) for p in a} == {tuple(p) for p in b}
        assert len(a) == len(b)


def test_a_single_layer_lattice_keeps_the_plain_contact() -> None:
    """A lattice printed in one layer presents one capsule per segment, as before the stack."""
    from rotomorph.design.lattices import sinusoidal_lattice
    from rotomorph.lattice.heating import contact_settings

    one = sinusoidal_lattice(3, layers=1)
    settings = contact_settings(one, one.network.nodes, True, True, 0.0)
    assert settings is not None and settings.stack.is_single
    assert settings.floor is not None
    assert settings.floor.height == pytest.approx(-1.005 * one.radius)
    three = contact_settings(sinusoidal_lattice(3), one.network.nodes, True, True, 0.0)
    assert three is not None and three.stack == STACK
    assert three.floor is not None and three.floor.height == pytest.approx(-0.6 - 1.005 * R)


def test_contact_ratios_count_only_the_layer_pairs_that_carry_force() -> None:
    """Two crossing stacks: their facing layers just apart (0.5 % of a diameter outside
    touching) carry no force and are not among the contact ratios, though they are within the
    activation distance of touching; pressed 0.3 % inside touching they carry force and are."""
    net = _crossing(3.0)
    up = np.tile([0.0, 0.0, 1.0], (net.n_edges, 1))
    pot = StackedContact(Contact(radius=R, stack=STACK), net, up, force_scale=1e-3)
    touching = 2 * R + 2 * 0.6  # centre lines of the rods when the facing layers touch
    apart = (_crossing(touching + 0.005 * 2 * R).nodes, up)
    d, contact_distance = pot.distances(apart)
    assert np.any(d < contact_distance + pot.layers.dhat)  # near, yet apart
    assert len(pot.contact_ratios(apart)) == 0
    assert pot.active_contacts(apart) == 0
    pressed = (_crossing(touching - 0.003 * 2 * R).nodes, up)
    ratios = pot.contact_ratios(pressed)
    assert len(ratios) == pot.active_contacts(pressed) > 0
    assert np.min(ratios) == pytest.approx(0.997, abs=1e-9)
    assert np.all(ratios < 1.0)

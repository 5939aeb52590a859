"""Closed rods (rings): topology, exact derivatives across the closing vertex, a ring relaxing
to its natural circle, Hoppe's in-plane ring eigenvalues and Michell's twisted-ring instability."""

from __future__ import annotations

import numpy as np
import pytest
from _rod_builders import anisotropic_model, displaced_objective

from rotomorph.design.network import Network
from rotomorph.errors import InvalidDesignError
from rotomorph.rod.model import Model
from rotomorph.solve.linalg import BandedMatrix
from rotomorph.solve.stability import stability
from rotomorph.solve.static import solve_static

N, R = 48, 5.0  # nodes, radius (mm)


def circle(n: int = N, radius: float = R, stretch: float = 1.0) -> np.ndarray:
    phi = 2 * np.pi * np.arange(n) / n
    return np.c_[radius * stretch * np.cos(phi), radius * np.sin(phi) / stretch, 0 * phi]


def ring(points: np.ndarray, b1: float, b2: float, c: float, ea: float) -> Model:
    return Model.ring(
        points,
        bending_stiffness1=b1,
        bending_stiffness2=b2,
        twist_stiffness=c,
        axial_stiffness=ea,
    )


def test_ring_topology_and_errors():
    net = Network.ring(circle(6))
    assert net.is_ring and net.n_edges == 6 and not Network.chain(circle(6)).is_ring
    model = ring(circle(6), 1.0, 1.0, 1.0, 10.0)
    st = model.stencils
    # every vertex, the closing one (node 0) included, sees its edges in the ring's direction
    assert st.count == 6 and np.all(st.sign_e == 1) and np.all(st.sign_f == 1)
    assert (st.edge_e[0], st.edge_f[0]) == (5, 0)
    with pytest.raises(InvalidDesignError, match="repeats the first"):
        Network.ring(np.vstack([circle(6), circle(6)[:1]]))
    with pytest.raises(InvalidDesignError, match="N >= 3"):
        Network.ring(circle(2))


def test_printed_ring_is_stress_free_and_stable():
    model = ring(circle(), 1.0, 2.0, 0.8, 1e3)
    res = solve_static(model)
    assert res.iterations == 0 and res.stable
    # the closing vertex carries no twist or curvature jump: the default natural fields are
    # uniform around the ring
    k1, k2, tw = model.reference_strains()
    assert np.ptp(k2) < 1e-12 and np.abs(k1).max() < 1e-12 and np.abs(tw).max() < 1e-12


@pytest.mark.parametrize("which", ["gradient", "hessian"])
def test_ring_derivatives_match_central_differences(rng, which):
    pts = circle(9) + rng.normal(0, 0.3, (9, 3))
    model = anisotropic_model(Network.ring(pts), rng)
    obj, q = displaced_objective(model, rng)
    _, g, H = obj.evaluate(q, True, True)
    h = 1e-6
    if which == "gradient":
        fd = np.array(
            [
                (
                    obj.evaluate(q + h * e, False, False)[0]
                    - obj.evaluate(q - h * e, False, False)[0]
                )
                / (2 * h)
                for e in np.eye(len(q))
            ]
        )
        assert np.linalg.norm(g - fd) <= 1e-6 * np.linalg.norm(g)
    else:
        H = H.to_dense() if isinstance(H, BandedMatrix) else H.toarray()
        J = np.column_stack(
            [
                (obj.evaluate(q + h * e, True, False)[1] - obj.evaluate(q - h * e, True, False)[1])
                / (2 * h)
                for e in np.eye(len(q))
            ]
        )
        assert np.linalg.norm(H - 0.5 * (J + J.T)) <= 1e-6 * np.linalg.norm(H)


def test_ellipse_with_natural_curvature_relaxes_to_the_circle():
    """Printed as an ellipse, given the rest lengths and natural turning angles of a regular
    N-gon (natural curvature = turning angle per printed Voronoi length, 2 tan(pi/N) in the
    discrete rod): the free ring relaxes to that polygon, stress-free, certified stable."""
    pts = circle(stretch=1.15)
    proto = ring(pts, 1.0, 2.0, 0.8, 1e3)
    _, k2, _ = proto.reference_strains()
    lengths = proto.network.edge_lengths
    voronoi = 0.5 * (np.roll(lengths, 1) + lengths)  # stencil k: edges k - 1 and k
    side = 2 * np.pi * R / N
    model = Model.ring(
        pts,
        bending_stiffness1=1.0,
        bending_stiffness2=2.0,
        twist_stiffness=0.8,
        axial_stiffness=1e3,
        natural_curvature1=np.zeros(N),
        natural_curvature2=np.sign(k2) * 2 * np.tan(np.pi / N) / voronoi,
        natural_twist=np.zeros(N),
        rest_length=np.full(N, side),
    )
    res = solve_static(model)
    assert res.stable and res.eigenvalues[0] > 0
    assert res.energy == pytest.approx(0.0, abs=1e-10 * side)
    x = res.positions
    radii = np.linalg.norm(x - x.mean(axis=0), axis=1)
    np.testing.assert_allclose(radii, side / (2 * np.sin(np.pi / N)), rtol=1e-7)
    assert np.ptp(x[:, 2]) < 1e-9


def test_hoppe_in_plane_ring_eigenvalues():
    """Stress-free ring of unit mass per length, in-plane bending stiffness B2:
    lambda_n = B2 n^2 (n^2 - 1)^2 / (R^4 (n^2 + 1)) (Hoppe 1871), each a double eigenvalue."""
    b2 = 2.0
    model = ring(circle(64), 1.0, b2, 0.8, 1e4)
    res = stability(model, count=10)
    assert res.rigid_modes == 6 and res.stable
    in_plane = [
        lam
        for lam, d in zip(res.eigenvalues, res.modes.displacements, strict=True)
        if np.abs(d[:, 2]).max() < 1e-8 * np.abs(d).max()
    ]
    n = np.array([2, 2, 3, 3])
    hoppe = b2 * n**2 * (n**2 - 1) ** 2 / (R**4 * (n**2 + 1))
    np.testing.assert_allclose(in_plane[:4], hoppe, rtol=1e-2)


def test_michell_twisted_ring_instability():
    """A naturally straight isotropic rod closed into a ring with natural twist tau: the flat
    circle is stable for tau R < sqrt(3) B / C and unstable above (Michell 1889). The twist sits
    in the closure (the ring's link is fixed), so this fails if the closing vertex is wrong."""
    b, c = 1.0, 0.8
    base = ring(circle(64), b, b, c, 1e4)
    zero = np.zeros(64)
    critical = np.sqrt(3) * b / (c * R)
    lowest = {}
    for f in (0.95, 1.05):
        model = base.with_natural(curvature1=zero, curvature2=zero, twist=np.full(64, f * critical))
        res = stability(model, count=3)
        assert res.stable == (f < 1)
        # skip the neutral mode (turning every material frame alike about the centre line)
        lowest[f] = res.eigenvalues[np.abs(res.eigenvalues) > 1e-9][0]
    crossing = 0.95 + 0.1 * lowest[0.95] / (lowest[0.95] - lowest[1.05])
    assert crossing == pytest.approx(1.0, abs=0.015)

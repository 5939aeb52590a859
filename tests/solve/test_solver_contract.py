"""Solver contract: invariances, junction consistency, bad input, non-convergence, Newton on
Rosenbrock with pinned iteration counts."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import rosen, rosen_der, rosen_hess

from rotomorph.design.network import Network
from rotomorph.errors import ConvergenceError, InvalidDesignError, InvalidParameterError
from rotomorph.rod.cases import HelixCase
from rotomorph.rod.model import Model
from rotomorph.solve.loads import Gravity, Loads, Supports
from rotomorph.solve.newton import FunctionObjective, NewtonOptions, minimize
from rotomorph.solve.objective import RodObjective
from rotomorph.solve.result import Status
from rotomorph.solve.static import solve_static


def helix_model(n: int) -> Model:
    return HelixCase().model(n)


def _rotation(rng):
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    return q * np.sign(np.linalg.det(q))


def test_energy_is_invariant_under_rigid_motion(rng):
    model = helix_model(31)
    rot, shift = _rotation(rng), rng.normal(size=3)
    x0 = model.network.nodes + 0.01 * rng.normal(size=model.network.nodes.shape)
    moved = Model(
        Network.chain(x0 @ rot.T + shift), *_stiffness(model), directors=model.directors @ rot.T
    )
    ref = Model(Network.chain(x0), *_stiffness(model), directors=model.directors)
    ref = ref.with_natural(model.natural_curvature1, model.natural_curvature2, model.natural_twist)
    moved = moved.with_natural(
        model.natural_curvature1, model.natural_curvature2, model.natural_twist
    )
    e = [
        RodObjective(m, m.reference_state(), Supports(), Loads()).evaluate(
            RodObjective(m, m.reference_state(), Supports(), Loads()).vector(), False, False
        )[0]
        for m in (ref, moved)
    ]
    assert e[1] == pytest.approx(e[0], rel=1e-12)


def _stiffness(model):
    return (
        model.bending_stiffness1,
        model.bending_stiffness2,
        model.twist_stiffness,
        model.axial_stiffness,
    )


def test_printed_state_has_zero_energy_and_gradient(rng):
    pts = np.cumsum(rng.normal(size=(12, 3)), axis=0)
    model = Model.chain(
        pts,
        bending_stiffness1=1.0,
        bending_stiffness2=2.0,
        twist_stiffness=0.7,
        axial_stiffness=30.0,
    )
    obj = RodObjective(model, model.reference_state(), Supports(), Loads())
    f, g, _ = obj.evaluate(obj.vector(), True, False)
    assert abs(f) < 1e-20 and np.abs(g).max() < 1e-12
    assert solve_static(model).iterations == 0


def test_two_collinear_segments_at_a_junction_reproduce_the_rod(rng):
    pts = np.cumsum(rng.normal(size=(6, 3)) * 0.3 + [1, 0, 0], axis=0)
    rod = Network.chain(pts)
    flagged = Network(pts, rod.edges, branch=np.isin(np.arange(6), [2]))
    from rotomorph.geometry import space_parallel_directors

    iso = dict(
        bending_stiffness1=1.3,
        bending_stiffness2=1.3,
        twist_stiffness=0.8,
        axial_stiffness=40.0,
        directors=space_parallel_directors(pts),
    )
    m_rod, m_jun = Model(rod, **iso), Model(flagged, **iso)
    assert m_jun.stencils.junction.sum() == 1
    q_noise = None
    out = []
    for m in (m_rod, m_jun):
        obj = RodObjective(m, m.reference_state(), Supports(), Loads())
        q = obj.vector()
        if q_noise is None:
            q_noise = 0.05 * rng.normal(size=q.shape)
        out.append(obj.evaluate(q + q_noise, True, False))
    assert out[1][0] == pytest.approx(out[0][0], rel=1e-12)
    np.testing.assert_allclose(out[1][1], out[0][1], rtol=0, atol=1e-12 * np.abs(out[0][1]).max())


def test_stencil_stiffness_is_the_edge_mean_and_isotropic_at_junctions():
    """Per-stencil (B1, B2, C) by hand: the mean of the two edges' values; at a junction (its
    two edges' frames need not agree) the bending stiffness is the isotropic mean of all four
    values. Every other test of a junction uses B1 = B2, where dropping that would not show."""
    pts = np.c_[np.arange(6.0), 0.1 * np.arange(6.0) ** 2, np.zeros(6)]
    net = Network(pts, Network.chain(pts).edges, branch=np.isin(np.arange(6), [2]))
    model = Model(
        net,
        bending_stiffness1=np.array([1.0, 2.0, 3.0, 4.0, 5.0]),
        bending_stiffness2=np.array([10.0, 20.0, 30.0, 40.0, 50.0]),
        twist_stiffness=np.array([0.1, 0.2, 0.3, 0.4, 0.5]),
        axial_stiffness=40.0,
    )
    assert model.stencils.junction.tolist() == [False, True, False, False]  # edges 1 and 2
    b1, b2, c = model.stencil_stiffness
    np.testing.assert_allclose(b1, [1.5, (2 + 3 + 20 + 30) / 4, 3.5, 4.5], rtol=1e-15)
    np.testing.assert_allclose(b2, [15.0, (2 + 3 + 20 + 30) / 4, 35.0, 45.0], rtol=1e-15)
    np.testing.assert_allclose(c, [0.15, 0.25, 0.35, 0.45], rtol=1e-15)


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"bending_stiffness1": -1.0}, "Model.bending_stiffness1"),
        ({"twist_stiffness": 0.0}, "Model.twist_stiffness"),
        ({"axial_stiffness": np.nan}, "Model.axial_stiffness"),
        ({"natural_curvature1": np.full(4, 0.1)}, "Model.natural_curvature1"),
        ({"rest_length": np.zeros(4)}, "Model.rest_length"),
    ],
)
def test_bad_model_input_names_the_field(kwargs, field):
    pts = np.c_[np.arange(5.0), np.zeros(5), np.zeros(5)]
    base = dict(
        bending_stiffness1=1.0, bending_stiffness2=1.0, twist_stiffness=1.0, axial_stiffness=10.0
    )
    base.update(kwargs)
    with pytest.raises(InvalidParameterError, match=field.replace(".", r"\.")):
        Model.chain(pts, **base)


def test_bad_geometry_raises_design_errors():
    with pytest.raises(InvalidDesignError, match="N >= 3"):
        Network.chain(np.zeros((2, 3)))
    with pytest.raises(InvalidDesignError, match="zero length"):
        Network.chain(np.array([[0, 0, 0], [1, 0, 0], [1, 0, 0.0]]))
    with pytest.raises(InvalidDesignError, match="finite"):
        Network.chain(np.array([[0, 0, 0], [1, np.nan, 0], [2, 0, 0.0]]))


def test_free_body_under_net_load_is_refused():
    model = helix_model(11)
    with pytest.raises(InvalidParameterError, match="Supports"):
        solve_static(model, loads=Loads(gravity=Gravity(density=1.1, area=0.28)))
    with pytest.raises(InvalidParameterError, match=r"Loads\.forces"):
        solve_static(model, Supports(pinned_nodes=[0]), Loads(forces=[(99, (0, 0, 1))]))


def test_non_convergence_raises_with_diagnostics():
    with pytest.raises(ConvergenceError) as err:
        solve_static(helix_model(101), options=NewtonOptions(max_iterations=3))
    res = err.value.result
    assert res.status is Status.MAX_ITERATIONS and res.iterations == 3 and res.residual > 1e-9
    assert err.value.state.positions.shape == (101, 3)


def test_newton_on_rosenbrock():
    obj = FunctionObjective(rosen, rosen_der, rosen_hess)
    res = minimize(obj, np.array([-1.2, 1.0]))
    assert res.converged
    np.testing.assert_allclose(res.x, [1.0, 1.0], atol=1e-8)
    assert res.iterations <= 25  # pinned (classic Newton + line search needs ~21)
    res5 = minimize(obj, np.full(5, 0.5))
    assert res5.converged and np.allclose(res5.x, 1.0, atol=1e-8)


def test_newton_escapes_a_saddle_to_a_minimum():
    # f = x^4/4 - x^2/2 + y^2/2 has a saddle at 0 and minima at x = +-1
    def f(z):
        return z[0] ** 4 / 4 - z[0] ** 2 / 2 + z[1] ** 2 / 2

    def g(z):
        return np.array([z[0] ** 3 - z[0], z[1]])

    def h(z):
        return np.diag([3 * z[0] ** 2 - 1, 1.0])

    res = minimize(FunctionObjective(f, g, h), np.array([1e-3, 0.5]))
    assert res.converged and abs(abs(res.x[0]) - 1) < 1e-8


def test_line_search_failure_is_reported_not_looped():
    # an objective whose gradient points uphill: every step fails the line search; the solver
    # must raise the shift through its shifted path and give up with LINE_SEARCH_FAILED
    def f(z):
        return float(z @ z)

    def g(z):
        return -2 * z

    def h(z):
        return 2 * np.eye(len(z))

    res = minimize(FunctionObjective(f, g, h), np.array([1.0, -2.0]))
    assert res.status is Status.LINE_SEARCH_FAILED
    assert res.iterations < 20

"""Shared builders for rod-core tests."""

from __future__ import annotations

import numpy as np

from rotomorph.design.network import Network
from rotomorph.rod.model import Model
from rotomorph.solve.loads import Loads, Supports
from rotomorph.solve.objective import RodObjective


def random_chain(rng: np.random.Generator, n: int, turn: float = 1.2) -> np.ndarray:
    """A random polyline of n nodes whose consecutive edges turn by up to ``turn`` rad."""
    pts = [np.zeros(3)]
    t = np.array([1.0, 0.0, 0.0])
    for _ in range(n - 1):
        axis = rng.normal(size=3)
        axis -= axis @ t * t
        axis /= np.linalg.norm(axis)
        ang = rng.uniform(0.2, turn)
        t = np.cos(ang) * t + np.sin(ang) * np.cross(axis, t)
        pts.append(pts[-1] + rng.uniform(0.5, 1.5) * t)
    return np.array(pts)


def anisotropic_model(network: Network, rng: np.random.Generator) -> Model:
    """A model with B1 != B2, non-uniform natural fields and stiff-but-finite stretching."""
    ne = network.n_edges
    base = Model(network, 1.0, 1.0, 1.0, 50.0)
    s = base.stencils.count
    return Model(
        network,
        bending_stiffness1=rng.uniform(0.5, 2.0, ne),
        bending_stiffness2=rng.uniform(2.0, 4.0, ne),
        twist_stiffness=rng.uniform(0.3, 1.0, ne),
        axial_stiffness=rng.uniform(20.0, 60.0, ne),
        natural_curvature1=rng.normal(0.0, 0.5, s),
        natural_curvature2=rng.normal(0.0, 0.5, s),
        natural_twist=rng.normal(0.0, 0.5, s),
        rest_length=network.edge_lengths * rng.uniform(0.8, 1.2, ne),
    )


def displaced_objective(model: Model, rng: np.random.Generator, scale: float = 0.3):
    """Objective re-based at a strongly displaced and twisted configuration; returns (obj, q)."""
    obj = RodObjective(model, model.reference_state(), Supports(), Loads())
    q0 = obj.vector()
    lay = model.layout
    dq = np.zeros(lay.count)
    dq[(lay.pos[:, None] + np.arange(3)).ravel()] = rng.normal(0, scale, 3 * model.network.n_nodes)
    dq[lay.theta] = rng.uniform(-1.5, 1.5, model.network.n_edges)
    q = q0 + dq[obj.free]
    obj.set_base(obj.state(q))
    return obj, q

"""Exact sensitivities of the energy gradient to natural values, against central differences."""

from __future__ import annotations

import numpy as np
import pytest
from _rod_builders import anisotropic_model, displaced_objective, random_chain

from rotomorph.design.network import Network
from rotomorph.rod.model import Model
from rotomorph.rod.sensitivity import natural_sensitivity


def _junction_network() -> Network:
    nodes = np.array(
        [[0, 0, 0], [1, 0.1, 0], [2, 0.3, 0.2], [-1, 0, 0.1], [0, 1, -0.1], [0, -1.1, 0.2]],
        dtype=float,
    )
    edges = np.array([[0, 1], [1, 2], [3, 0], [0, 4], [5, 0]])
    return Network(nodes, edges)


def _with_integrated(model: Model, k1, k2, tw, rest) -> Model:
    trial = model.with_natural(rest_length=rest)
    # whatever length the model integrates pointwise values over: measure it
    ones = np.ones(trial.stencils.count)
    v = trial.with_natural(curvature1=ones).integrated_natural()[0]
    return trial.with_natural(curvature1=k1 / v, curvature2=k2 / v, twist=tw / v)


def _full_gradient(model: Model, state) -> np.ndarray:
    from rotomorph.solve.loads import Loads, Supports
    from rotomorph.solve.objective import RodObjective

    obj = RodObjective(model, state, Supports(), Loads())
    _, g, _ = obj.evaluate(obj.vector(), True, 0)
    return g


@pytest.mark.parametrize("which", ["chain", "junctions"])
def test_natural_sensitivity_matches_central_differences(which):
    rng = np.random.default_rng(7)
    net = Network.chain(random_chain(rng, 7)) if which == "chain" else _junction_network()
    model = anisotropic_model(net, rng)
    obj, _ = displaced_objective(model, rng)
    state = obj.base
    lam = rng.normal(size=model.layout.count)
    sens = natural_sensitivity(model, state, lam)
    k1, k2, tw = (np.array(a) for a in model.integrated_natural())
    rest = np.array(model.rest_length)
    base = [k1, k2, tw, rest]
    analytic = [sens.curvature1, sens.curvature2, sens.twist, sens.rest_length]
    h = 1e-6
    for which_param in range(4):
        for i in range(len(base[which_param])):
            plus = [a.copy() for a in base]
            minus = [a.copy() for a in base]
            plus[which_param][i] += h
            minus[which_param][i] -= h
            gp = _full_gradient(_with_integrated(model, *plus), state)
            gm = _full_gradient(_with_integrated(model, *minus), state)
            fd = lam @ (gp - gm) / (2 * h)
            scale = max(1.0, abs(fd))
            assert analytic[which_param][i] == pytest.approx(fd, abs=1e-6 * scale), (
                which_param,
                i,
            )

"""Stable minima: the answer does not depend on how rigid motions are removed, and a column
buckles exactly when the Euler load is exceeded (the straight state turns into a saddle)."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from rotomorph.analysis.shape import fit_helix
from rotomorph.rod.cases import HelixCase
from rotomorph.rod.model import Model
from rotomorph.solve.loads import Loads, Supports
from rotomorph.solve.static import solve_static


def test_free_and_clamped_free_helix_are_the_same_shape():
    case = HelixCase()
    model = case.model(81)
    free = fit_helix(solve_static(model).positions)
    clamped = fit_helix(solve_static(model, Supports.clamp_ends(81)).positions)
    pinned = fit_helix(solve_static(model, Supports(pinned_nodes=[40])).positions)
    for other in (clamped, pinned):
        assert other.radius == pytest.approx(free.radius, rel=1e-6)
        assert abs(other.pitch) == pytest.approx(abs(free.pitch), rel=1e-6)


@pytest.mark.parametrize(("factor", "buckles"), [(0.8, False), (1.3, True)])
def test_clamped_free_column_buckles_only_above_the_euler_load(factor, buckles):
    n, length, B = 41, 10.0, 1e-2
    s = np.linspace(0, length, n)
    model = Model.chain(
        np.c_[s, 0 * s, 0 * s],
        bending_stiffness1=B,
        bending_stiffness2=B,
        twist_stiffness=B / 1.5,
        axial_stiffness=1e4,
    )
    p_cr = np.pi**2 * B / (4 * length**2)  # clamped-free (Euler), effective length 2L
    # start from a straight column with a tiny lateral imperfection of the tip
    state = model.reference_state()
    x = state.positions.copy()
    x[:, 1] = 1e-6 * (s / length) ** 2
    t = np.diff(x, axis=0)
    t /= np.linalg.norm(t, axis=1, keepdims=True)
    d1 = state.directors - np.sum(state.directors * t, axis=1, keepdims=True) * t
    d1 /= np.linalg.norm(d1, axis=1, keepdims=True)
    start = replace(state, positions=x, tangents=t, directors=d1)
    res = solve_static(
        model,
        Supports.clamp_ends(n),
        Loads(forces=[(n - 1, (-factor * p_cr, 0.0, 0.0))]),
        initial=start,
    )
    assert res.stable
    deflection = float(np.hypot(res.positions[-1, 1], res.positions[-1, 2]))
    if buckles:
        assert deflection > 0.2 * length
    else:
        assert deflection < 1e-6 * length

"""A heating result of the default print-program actuation survives pickling (a sweep or a
process pool sends results between processes)."""

from __future__ import annotations

import pickle

import numpy as np

from rotomorph.design.lattices import sinusoidal_lattice
from rotomorph.lattice.heating import heat_lattice


def test_a_program_actuated_result_round_trips_through_pickle():
    res = heat_lattice(sinusoidal_lattice(n=2, ghost_nodes=2), steps=1)
    back = pickle.loads(pickle.dumps(res))
    np.testing.assert_array_equal(back.positions, res.positions)
    assert back.final_area_ratio == res.final_area_ratio
    # the lattice model behind it still evaluates its natural field after loading (the
    # derived program attributes are re-read, not carried through the pickle)
    from rotomorph.lattice.actuation import get_actuation

    act = get_actuation(res.actuation)
    a, b = act.natural(res.model, 100.0), act.natural(back.model, 100.0)
    for name in ("natural_curvature1", "natural_curvature2", "natural_twist"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))

"""The report's Fig. 4 sweeps on its full grid (what ``rotomorph paper`` computes) say what
``docs/published-simulation.md`` says: 151 values each, the onsets on the floor and weightless,
and the logged run's stretch flat on the floor while the free lattice is a saddle.

The sweeps are computed once into the run's result cache. On the xdist workers this test
starts beside the report's unit (``tests/conftest.py``, ``start_rank``), so the README's
``rotomorph paper`` finds them computed instead of computing them after everything else on its
own worker."""

from __future__ import annotations

import numpy as np
import pytest

from rotomorph.lattice.published import LOGGED_STRETCH, STRETCHES
from rotomorph.simulate.report_published import report_sweeps


@pytest.mark.slow
def test_full_sweeps_reach_both_ends_with_the_documented_onsets():
    floor, free = report_sweeps(quick=False)
    for sweep in (floor, free):
        # continuation reached both ends of the authors' range, value by value
        np.testing.assert_allclose(sweep.stretch, STRETCHES, rtol=0, atol=1e-9)
        assert len(sweep.physical) == len(STRETCHES)
        assert sweep.stack_overlaps is not None  # every state checked for interpenetration
    # docs/published-simulation.md: their weight delays the lift-off past the buckling
    assert (free.first(-1), free.first(+1)) == (-0.10, 0.09)
    assert (floor.first(-1), floor.first(+1)) == (-0.19, 0.15)
    k, j = floor.at(LOGGED_STRETCH), free.at(LOGGED_STRETCH)
    assert floor.stretch[k] == LOGGED_STRETCH == free.stretch[j]
    assert int(floor.gaussian_sign[k]) == 0 and int(free.gaussian_sign[j]) == -1

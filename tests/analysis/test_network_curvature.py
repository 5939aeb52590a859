"""network_relative_curvature_change (stacked chains) equals the per-chain definition."""

from __future__ import annotations

import numpy as np
import pytest

from rotomorph.analysis.curvature import (
    discrete_curvature,
    network_relative_curvature_change,
    relative_curvature_change,
)
from rotomorph.errors import InvalidParameterError


def _per_chain(pos, ref, chains):
    floor = 1e-9 * max(discrete_curvature(ref[c]).max(initial=0.0) for c in chains)
    total, count = np.zeros(len(pos)), np.zeros(len(pos))
    for c in chains:
        v = relative_curvature_change(pos[c], ref[c], floor=floor)
        ok = np.isfinite(v)
        np.add.at(total, c[ok], v[ok])
        np.add.at(count, c[ok], 1.0)
    out = np.full(len(pos), np.nan)
    out[count > 0] = total[count > 0] / count[count > 0]
    return out


def test_matches_the_per_chain_definition_with_mixed_lengths_and_shared_nodes():
    rng = np.random.default_rng(3)
    s = np.linspace(0, 3, 40)
    ref = np.column_stack([s, np.sin(2 * s), 0.2 * s**2])
    pos = ref + rng.normal(scale=0.05, size=ref.shape)
    chains = [np.arange(0, 12), np.arange(11, 23), np.arange(22, 30), np.arange(29, 40), [5, 6]]
    chains = [np.asarray(c) for c in chains] + [np.array([3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14])]
    got = network_relative_curvature_change(pos, ref, chains)
    np.testing.assert_allclose(got, _per_chain(pos, ref, chains), rtol=1e-13, equal_nan=True)
    assert np.isfinite(got[1:11]).all() and np.isnan(got[0])


def test_repeated_points_are_refused():
    ref = np.array([[0.0, 0, 0], [1, 0, 0], [1, 0, 0], [2, 1, 0]])
    with pytest.raises(InvalidParameterError, match="zero length"):
        network_relative_curvature_change(ref, ref, [np.arange(4)])

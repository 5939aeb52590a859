"""Segments of node chains, looked up for many chains at once."""

from __future__ import annotations

import itertools

import numpy as np

from rotomorph.simulate.run_data import chain_segments, chains_segments


def _by_dict(edges: np.ndarray, chain: np.ndarray) -> np.ndarray:
    lookup = {(int(a), int(b)): j for j, (a, b) in enumerate(edges)}
    lookup.update({(int(b), int(a)): j for j, (a, b) in enumerate(edges)})
    return np.array(
        [lookup.get((int(a), int(b)), -1) for a, b in itertools.pairwise(chain)], dtype=np.int64
    )


def test_chains_segments_matches_a_lookup_table() -> None:
    rng = np.random.default_rng(0)
    for _ in range(100):
        n = int(rng.integers(2, 12))
        pairs = rng.integers(0, n, (int(rng.integers(1, 20)), 2))
        pairs = np.unique(np.sort(pairs[pairs[:, 0] != pairs[:, 1]], axis=1), axis=0)
        if not len(pairs):
            continue
        flip = rng.random(len(pairs)) < 0.5
        pairs[flip] = pairs[flip][:, ::-1]  # either orientation
        chains = [rng.integers(0, n + 2, int(rng.integers(0, 8))) for _ in range(4)]
        for chain, got in zip(chains, chains_segments(pairs, chains), strict=True):
            assert np.array_equal(got, _by_dict(pairs, chain))
            assert np.array_equal(chain_segments(pairs, chain), got)

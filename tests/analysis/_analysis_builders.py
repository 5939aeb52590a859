"""Shared builders for the analysis tests: exact curves and the paper's sinusoidal lattice."""

from __future__ import annotations

import numpy as np


def sinusoidal_lattice(n: int = 5, spacing: float = 10.0, amplitude: float = 2.2, ghosts: int = 10):
    """The paper's square lattice: positions (N, 3) and edge chains (ends included)."""
    branch = np.array([[spacing * i, spacing * j, 0.0] for i in range(n) for j in range(n)])
    nodes = [branch]
    chains = []
    next_index = n * n
    s = np.arange(1, ghosts + 1)
    for i in range(n):
        for j in range(n):
            k = n * i + j
            for di, dj in ((1, 0), (0, 1)):
                if i + di >= n or j + dj >= n:
                    continue
                m = n * (i + di) + (j + dj)
                t = (branch[m] - branch[k]) / spacing
                normal = np.cross([0.0, 0.0, 1.0], t)
                ghost = (
                    branch[k]
                    + np.outer(s * spacing / (ghosts + 1), t)
                    + np.outer(amplitude * np.sin(2 * np.pi * s / (ghosts + 1)), normal)
                )
                nodes.append(ghost)
                ids = np.arange(next_index, next_index + ghosts)
                next_index += ghosts
                chains.append(np.concatenate([[k], ids, [m]]))
    return np.concatenate(nodes), chains


def random_rotation(seed: int) -> np.ndarray:
    q, r = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    if np.linalg.det(q) < 0:
        q[:, 0] *= -1
    return q


def helix_points(radius: float, rise: float, turns: float, count: int, sign: int = 1):
    """Helix (r cos θ, sign r sin θ, rise θ), θ in [0, 2π turns]; pitch = 2π rise (mm)."""
    theta = np.linspace(0.0, 2 * np.pi * turns, count)
    return np.stack([radius * np.cos(theta), sign * radius * np.sin(theta), rise * theta], axis=1)

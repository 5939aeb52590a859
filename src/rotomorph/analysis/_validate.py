"""Argument checks shared by the analysis modules (private)."""

from __future__ import annotations

import numpy as np

from rotomorph._typing import FloatArray, IntArray
from rotomorph.errors import InvalidParameterError


def as_points(points: object, field: str, *, min_count: int = 0) -> FloatArray:
    """Return ``points`` as a finite float array ``(N, 3)`` with ``N >= min_count``."""
    pts = np.asarray(points, dtype=float)
    if pts.size == 0 and min_count == 0:
        return pts.reshape(0, 3)
    if pts.ndim != 2 or pts.shape[1] != 3:
        raise InvalidParameterError(field, f"must have shape (N, 3) in mm; got {pts.shape}")
    if len(pts) < min_count:
        raise InvalidParameterError(field, f"needs at least {min_count} points; got {len(pts)}")
    bad = ~np.isfinite(pts).all(axis=1)
    if bad.any():
        raise InvalidParameterError(
            field, f"must be finite; point {int(np.flatnonzero(bad)[0])} is not"
        )
    return pts


def as_index(indices: object, field: str, n_points: int) -> IntArray:
    """Return ``indices`` as a 1-D int64 array of valid indices into ``n_points`` points."""
    idx = np.asarray(indices)
    if idx.size == 0:
        return np.zeros(0, dtype=np.int64)
    if idx.ndim != 1 or not np.issubdtype(idx.dtype, np.integer):
        raise InvalidParameterError(field, f"must be a 1-D array of node indices; got {idx!r}")
    idx = idx.astype(np.int64)
    if idx.min() < 0 or idx.max() >= n_points:
        raise InvalidParameterError(
            field, f"indices must lie in [0, {n_points - 1}]; got {idx.min()}..{idx.max()}"
        )
    return idx

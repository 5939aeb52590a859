r"""Where a rigid body laid on a floor comes to rest: quasi-static toppling of a point set.

A rigid body on a horizontal plane under its weight is at rest when the vertical through its
centre of mass meets the support polygon (the convex hull of its points on the plane);
otherwise it turns about the point of that polygon nearest to the vertical — an edge of the
polygon (the axis runs along it) or a corner (the axis is horizontal, across the offset) —
lowering its centre of mass, until another point touches the plane. Repeating this until the
vertical meets the support polygon is the quasi-static toppling sequence of a convex
polyhedron (the stable faces and the toppling graph of part orienting, Boothroyd, Redford,
Poli & Murch, *Mech. Mach. Theory* 7, 1972; Goldberg, *Algorithmica* 10, 1993). Each turn
lowers the centre of mass, so the sequence ends, on a face whose vertical through the centre
of mass falls inside it (or on a pivot exactly below it).

Used to lay a buckled lattice on the bath floor in the pose it rolls into under its weight
before its elastic equilibrium is solved: the rigid part of the settling, done geometrically.
"""

from __future__ import annotations

import numpy as np

from rotomorph._typing import FloatArray
from rotomorph.errors import InvalidParameterError
from rotomorph.geometry import best_rotation, plane_basis

__all__ = ["resting_rotation"]

#: Most turns of one toppling sequence (each lowers the centre of mass; a few suffice).
MAX_TURNS = 64


def resting_rotation(
    points: FloatArray, weights: FloatArray, normal: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """Rotation that topples ``points`` into a resting pose on a plane of normal ``normal``.

    Where the body balances on a point or on a segment (the vertical through its centre of
    mass meets a support of no area: an unstable rigid equilibrium, e.g. a saddle on its two
    low corners), it is tipped each way (across the segment; along two horizontal axes from a
    point), each toppled on, and the pose with the lower centre of mass kept (the first on a
    tie).

    Parameters
    ----------
    points
        Positions ``(n, 3)`` (mm) of the rigid body; its lowest points (along ``normal``)
        touch the plane at the start.
    weights
        Non-negative weight of each point ``(n,)`` (any unit): the centre of mass is their
        weighted mean.
    normal
        Upward normal of the plane ``(3,)``.

    Returns
    -------
    rotation, translation
        ``(3, 3)`` rotation ``R`` and ``(3,)`` translation ``t`` (mm): the resting pose is
        ``x @ R.T + t``, its lowest points at the height of the start's lowest point.
    """
    x0 = np.array(points, dtype=float)
    w = np.asarray(weights, dtype=float)
    n = np.asarray(normal, dtype=float)
    n = n / np.linalg.norm(n)
    total = float(w.sum())
    if x0.ndim != 2 or x0.shape[1] != 3 or len(w) != len(x0) or not total > 0:
        raise InvalidParameterError(
            "points", "must be (n, 3) with n non-negative weights of positive sum"
        )
    size = float(np.ptp(x0, axis=0).max()) or 1.0
    body = _Body(w / total, n, float((x0 @ n).min()), 1e-9 * size)
    x = body.topple(x0, depth=2)
    # the rigid motion x0 -> x (exact up to round-off)
    c0, c1 = body.weights @ x0, body.weights @ x
    R = best_rotation(x0 - c0, x - c1)
    return R, c1 - c0 @ R.T


class _Body:
    """A rigid point set's weights (normalised), the plane's normal and height, a tolerance."""

    def __init__(self, weights: FloatArray, normal: FloatArray, base: float, tol: float):
        self.weights, self.n, self.base, self.tol = weights, normal, base, tol

    def centre_height(self, x: FloatArray) -> float:
        return float(self.weights @ x @ self.n) - self.base

    def topple(self, x: FloatArray, depth: int) -> FloatArray:
        """``x`` toppled until it rests (branching ``depth`` times at balanced points)."""
        n, tol = self.n, self.tol
        for _ in range(MAX_TURNS):
            c = self.weights @ x
            support = x[x @ n - self.base <= tol]
            q, area = _nearest_on_support(support, c, n)
            offset = (c - q) - ((c - q) @ n) * n  # horizontal offset of the centre of mass
            if np.linalg.norm(offset) > tol:
                x = self.turn(x, q, offset / np.linalg.norm(offset))
                continue
            if area > tol * tol or depth <= 0:
                return x  # at rest on a face (or out of branches)
            # balanced on a point or a segment: tip each way, keep the lower pose
            if len(support) > 1 and float(np.ptp(support, axis=0).max()) > tol:
                j = int(np.argmax(np.linalg.norm(support - support[0], axis=1)))
                along = support[j] - support[0]
                across = np.cross(n, along / np.linalg.norm(along))
                tips = [across, -across]
            else:
                e1, e2 = plane_basis(n).T
                tips = [e1, -e1, e2, -e2]
            best: FloatArray | None = None
            for h in tips:
                y = self.topple(self.turn(x, q, h), depth - 1)
                if best is None or self.centre_height(y) < self.centre_height(best) - tol:
                    best = y
            assert best is not None
            return best
        return x

    def turn(self, x: FloatArray, q: FloatArray, h: FloatArray) -> FloatArray:
        """``x`` turned about the horizontal axis ``n x h`` through ``q`` (points on the ``h``
        side going down) until another point touches the plane."""
        n = self.n
        r = x - q
        a = r @ n  # height above the plane
        s = r @ h  # reach along h: those points descend
        down = s > self.tol
        if not np.any(down):
            return x
        angle = float(np.min(np.arctan2(a[down], s[down])))
        y = q + r @ _rotation(np.cross(n, h), angle).T
        return y + (self.base - float((y @ n).min())) * n  # keep the lowest point on the plane


def _rotation(axis: FloatArray, angle: float) -> FloatArray:
    """Rotation matrix about the unit ``axis`` by ``angle`` (rad), right-handed."""
    k = axis / np.linalg.norm(axis)
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + np.sin(angle) * K + (1.0 - np.cos(angle)) * (K @ K)


def _nearest_on_support(
    support: FloatArray, c: FloatArray, n: FloatArray
) -> tuple[FloatArray, float]:
    """The point of the support polygon (convex hull of ``support`` in the plane) nearest to
    the vertical through ``c``, on the plane, and the polygon's area (mm²)."""
    e1, e2 = plane_basis(n).T
    origin = support[0] - (support[0] @ n) * n
    uv = np.column_stack(((support - origin) @ e1, (support - origin) @ e2))
    target = np.array([(c - origin) @ e1, (c - origin) @ e2])
    poly = uv[_hull_2d(uv)]
    best = _nearest_in_polygon(poly, target)
    area = 0.0
    if len(poly) >= 3:
        nxt = np.roll(poly, -1, axis=0)
        area = 0.5 * float(np.sum(poly[:, 0] * nxt[:, 1] - nxt[:, 0] * poly[:, 1]))
    return origin + best[0] * e1 + best[1] * e2 + (support[0] @ n) * n, area


def _hull_2d(uv: FloatArray) -> list[int]:
    """Indices of the convex hull of 2-D points, counter-clockwise (Andrew's monotone chain);
    collinear and repeated points give the extreme ones."""
    order = sorted(range(len(uv)), key=lambda i: (uv[i, 0], uv[i, 1]))
    if len(order) <= 2:
        return order

    def cross(o: int, a: int, b: int) -> float:
        return float(
            (uv[a, 0] - uv[o, 0]) * (uv[b, 1] - uv[o, 1])
            - (uv[a, 1] - uv[o, 1]) * (uv[b, 0] - uv[o, 0])
        )

    lower: list[int] = []
    for i in order:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], i) <= 0.0:
            lower.pop()
        lower.append(i)
    upper: list[int] = []
    for i in reversed(order):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], i) <= 0.0:
            upper.pop()
        upper.append(i)
    return lower[:-1] + upper[:-1]


def _nearest_in_polygon(poly: FloatArray, t: FloatArray) -> FloatArray:
    """Nearest point to ``t`` of the convex polygon ``poly`` (counter-clockwise vertices; one
    vertex or a segment when degenerate): ``t`` itself when inside."""
    m = len(poly)
    if m >= 3:
        edges = np.roll(poly, -1, axis=0) - poly
        rel = t - poly
        if np.all(edges[:, 0] * rel[:, 1] - edges[:, 1] * rel[:, 0] >= 0.0):
            return t.copy()
    best, dist = poly[0].copy(), float(np.linalg.norm(t - poly[0]))
    for i in range(m if m >= 3 else m - 1):
        a, b = poly[i], poly[(i + 1) % m]
        ab = b - a
        u = float(np.clip((t - a) @ ab / max(float(ab @ ab), 1e-300), 0.0, 1.0))
        p = a + u * ab
        d = float(np.linalg.norm(t - p))
        if d < dist:
            best, dist = p, d
    return best

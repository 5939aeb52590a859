"""Which contact shape for a printed stack: accuracy against the stack itself, and cost.

A segment of a lattice printed in N layers is N round filaments of radius r whose centre lines
lie at offsets o_k along the segment's material director (touching on a line at a layer
height of one diameter). Its surface is the union of N capsules. Three candidate contact
shapes are compared on random pairs of stacked segments near contact:

* ``capsules``: one capsule per layer (the stack itself: N² segment distances per pair);
* ``rounded-rectangle``: the capsule swept along the director over the outermost offsets
  (the stack's convex hull; the distance between two parallelograms: 16 edge pairs and 8
  corner-to-face projections per pair);
* ``one-capsule``: one capsule of radius r on the centre line (one segment distance).

For each: the error of the gap (distance between the surfaces) against the stack's, in layer
radii (median and largest), the share of configurations that touch in one shape and not in
the other, and the primitive distance evaluations per pair. One JSON line per shape.

Run: ``python benchmarks/stack_shape.py [--pairs N]``.
"""

from __future__ import annotations

import json
import sys
import time

import numpy as np

R, LAYERS, HEIGHT, LENGTH = 0.3, 3, 0.6, 0.5


def _segment_distance(p0, p1, q0, q1):  # type: ignore[no-untyped-def]
    """Distance between segments (exact, clamped closest points; numpy, one pair)."""
    a, b, w = p1 - p0, q1 - q0, p0 - q0
    aa, bb, ab, aw, bw = a @ a, b @ b, a @ b, a @ w, b @ w
    den = aa * bb - ab * ab
    candidates = []
    if den > 1e-14 * aa * bb:
        s = (ab * bw - bb * aw) / den
        t = (aa * bw - ab * aw) / den
        if 0 <= s <= 1 and 0 <= t <= 1:
            candidates.append(np.linalg.norm(w + s * a - t * b))
    for s in (0.0, 1.0):
        t = np.clip((ab * s + bw) / bb, 0.0, 1.0)
        candidates.append(np.linalg.norm(w + s * a - t * b))
    for t in (0.0, 1.0):
        s = np.clip((ab * t - aw) / aa, 0.0, 1.0)
        candidates.append(np.linalg.norm(w + s * a - t * b))
    return min(candidates)


def _point_face(p, corner, u, v):  # type: ignore[no-untyped-def]
    """Distance from p to the parallelogram corner + [0,1] u + [0,1] v (inf if its foot falls
    outside)."""
    m = np.array([[u @ u, u @ v], [u @ v, v @ v]])
    s, t = np.linalg.solve(m, np.array([u @ (p - corner), v @ (p - corner)]))
    if 0 <= s <= 1 and 0 <= t <= 1:
        return float(np.linalg.norm(p - corner - s * u - t * v))
    return float("inf")


def _parallelogram_distance(c1, u1, v1, c2, u2, v2):  # type: ignore[no-untyped-def]
    """Distance between two parallelograms (their edges pairwise, corners against faces)."""

    def edges(c, u, v):  # type: ignore[no-untyped-def]
        pts = [c, c + u, c + u + v, c + v]
        return [(pts[i], pts[(i + 1) % 4]) for i in range(4)], pts

    e1, k1 = edges(c1, u1, v1)
    e2, k2 = edges(c2, u2, v2)
    d = min(_segment_distance(a, b, c, e) for a, b in e1 for c, e in e2)
    d = min(d, *(_point_face(p, c2, u2, v2) for p in k1), *(_point_face(p, c1, u1, v1) for p in k2))
    return d


def _random_pair(rng):  # type: ignore[no-untyped-def]
    """Two stacked segments (start, direction, director) near contact in random poses."""
    out = []
    for _ in range(2):
        t = rng.standard_normal(3)
        t /= np.linalg.norm(t)
        m = np.cross(t, rng.standard_normal(3))
        m /= np.linalg.norm(m)
        out.append((rng.uniform(-0.3, 0.3, 3), t * LENGTH, m))
    # move the second one so that the centre lines are 0.6 - 2.2 mm apart
    (p0, a, _), (_, b, m2) = out
    shift = rng.uniform(0.6, 2.2) * rng.standard_normal(3) / np.sqrt(3.0)
    out[1] = (p0 + 0.5 * a + shift - 0.5 * b, b, m2)
    return out


def main(pairs: int = 4000) -> None:
    rng = np.random.default_rng(2026)
    offsets = (np.arange(LAYERS) - 0.5 * (LAYERS - 1)) * HEIGHT
    ext = offsets.max()
    gaps = {"capsules": [], "rounded-rectangle": [], "one-capsule": []}
    cost = {k: 0.0 for k in gaps}
    for _ in range(pairs):
        (p0, a, m), (q0, b, n) = _random_pair(rng)
        c0 = time.process_time()
        d = min(
            _segment_distance(p0 + o * m, p0 + a + o * m, q0 + w * n, q0 + b + w * n)
            for o in offsets
            for w in offsets
        )
        cost["capsules"] += time.process_time() - c0
        gaps["capsules"].append(d - 2 * R)
        c0 = time.process_time()
        d = _parallelogram_distance(p0 - ext * m, a, 2 * ext * m, q0 - ext * n, b, 2 * ext * n)
        cost["rounded-rectangle"] += time.process_time() - c0
        gaps["rounded-rectangle"].append(d - 2 * R)
        c0 = time.process_time()
        gaps["one-capsule"].append(_segment_distance(p0, p0 + a, q0, q0 + b) - 2 * R)
        cost["one-capsule"] += time.process_time() - c0
    true = np.array(gaps["capsules"])
    near = true < 4 * R  # the configurations that matter: surfaces within two diameters
    evaluations = {"capsules": LAYERS**2, "rounded-rectangle": 24, "one-capsule": 1}
    for name, g in gaps.items():
        err = (np.array(g) - true)[near] / R
        touch = (np.array(g) < 0)[near] != (true < 0)[near]
        print(
            json.dumps(
                {
                    "shape": name,
                    "pairs": int(near.sum()),
                    "gap_error_median_r": round(float(np.median(np.abs(err))), 4),
                    "gap_error_max_r": round(float(np.abs(err).max()), 4),
                    "touch_disagrees": round(float(touch.mean()), 4),
                    "distance_evaluations_per_pair": evaluations[name],
                    "numpy_us_per_pair": round(1e6 * cost[name] / pairs, 1),
                }
            ),
            flush=True,
        )


if __name__ == "__main__":
    args = sys.argv[1:]
    main(int(args[args.index("--pairs") + 1]) if "--pairs" in args else 4000)

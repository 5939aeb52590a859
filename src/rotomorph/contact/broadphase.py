"""Broad phase of the contact model: which segment pairs and node–segment pairs may be near.

Every segment and every node gets an axis-aligned bounding box over the positions ``x0`` and
``x1`` (the same for a static query; the start and end of a straight step for a swept one,
which bounds the whole path since a box is convex), grown by its share of the search distance.
A sort-and-sweep along the widest axis proposes the pairs whose grown boxes overlap; a pair is
kept when the Euclidean distance between its boxes is below the sum of the two shares and the
network allows it to touch (:mod:`rotomorph.contact.exclusion`: graph neighbours and printed
fusions never touch). The box distance is a lower bound on the centre-line distance at any
point of the path, so no pair that may come within reach is dropped. Compiled, O(n log n) plus
the overlaps.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from rotomorph._typing import FloatArray, IntArray

__all__ = ["near_pairs"]


@njit(cache=True)
def _key_rows(keys, ne):  # pragma: no cover - compiled
    """Row pointers of the sorted keys ``lo * ne + hi`` by ``lo``: the keys of segment ``lo``
    are ``keys[ptr[lo]:ptr[lo + 1]]``."""
    ptr = np.zeros(ne + 1, dtype=np.int64)
    for t in range(keys.shape[0]):
        ptr[keys[t] // ne + 1] += 1
    for e in range(ne):
        ptr[e + 1] += ptr[e]
    return ptr


@njit(cache=True)
def _excluded_in_row(keys, ptr, a, b, ne):  # pragma: no cover - compiled
    """Whether segments ``a`` and ``b`` may not touch (the same segment or a key in ``keys``),
    by a scan of the (few) keys of the lower one."""
    lo = min(a, b)
    hi = max(a, b)
    if lo == hi:
        return True
    k = lo * ne + hi
    for t in range(ptr[lo], ptr[lo + 1]):
        if keys[t] >= k:
            return keys[t] == k
    return False


@njit(cache=True)
def _grow(buf, count):  # pragma: no cover - compiled
    if count < buf.shape[0]:
        return buf
    out = np.empty((2 * buf.shape[0], 2), dtype=np.int64)
    for r in range(count):  # a loop: a slice copy compiles shape checks with messages (~5 s)
        out[r, 0] = buf[r, 0]
        out[r, 1] = buf[r, 1]
    return out


@njit(cache=True)
def _near_pairs(x0, x1, edges, incident, seg_share, node_share, keys):  # pragma: no cover
    ne = edges.shape[0]
    nn = x0.shape[0]
    m = ne + nn
    lo = np.empty((m, 3))
    hi = np.empty((m, 3))
    share = np.empty(m)
    for e in range(ne):
        a, b = edges[e, 0], edges[e, 1]
        for k in range(3):
            lo[e, k] = min(x0[a, k], x0[b, k], x1[a, k], x1[b, k])
            hi[e, k] = max(x0[a, k], x0[b, k], x1[a, k], x1[b, k])
        share[e] = seg_share[e]
    for n in range(nn):
        for k in range(3):
            lo[ne + n, k] = min(x0[n, k], x1[n, k])
            hi[ne + n, k] = max(x0[n, k], x1[n, k])
        share[ne + n] = node_share[n]
    # sweep along the axis of widest spread
    axis = 0
    widest = -1.0
    for k in range(3):
        w = lo[:, k].max() - lo[:, k].min()
        if w > widest:
            widest, axis = w, k
    start = lo[:, axis] - share
    order = np.argsort(start)
    ptr = _key_rows(keys, ne)
    # the boxes in sweep order, contiguous (the inner loop reads them in that order)
    lo_s = np.empty((m, 3))
    hi_s = np.empty((m, 3))
    share_s = np.empty(m)
    start_s = np.empty(m)
    for ii in range(m):
        i = order[ii]
        for k in range(3):
            lo_s[ii, k] = lo[i, k]
            hi_s[ii, k] = hi[i, k]
        share_s[ii] = share[i]
        start_s[ii] = start[i]
    seg = np.empty((max(4 * ne, 16), 2), dtype=np.int64)
    node = np.empty((max(4 * ne, 16), 2), dtype=np.int64)
    ns = np.int64(0)  # not the literal 0: one compiled _grow, not one per literal
    nq = np.int64(0)
    for ii in range(m):
        i = order[ii]
        end = hi_s[ii, axis] + share_s[ii]
        i_node = i >= ne
        for jj in range(ii + 1, m):
            if start_s[jj] > end:
                break
            j = order[jj]
            if i_node and j >= ne:
                continue  # node against node: carried by the segments
            reach = share_s[ii] + share_s[jj]
            # a gap along one axis of at least the reach rejects the pair (then g2 >= reach^2)
            g2 = 0.0
            far = False
            for k in range(3):
                g = max(lo_s[jj, k] - hi_s[ii, k], lo_s[ii, k] - hi_s[jj, k], 0.0)
                if g >= reach:
                    far = True
                    break
                g2 += g * g
            if far or g2 >= reach * reach:
                continue
            if not i_node and j < ne:
                if not _excluded_in_row(keys, ptr, i, j, ne):
                    seg = _grow(seg, ns)
                    seg[ns, 0] = min(i, j)
                    seg[ns, 1] = max(i, j)
                    ns += 1
                continue
            n, e = (i - ne, j) if i_node else (j - ne, i)
            ok = True
            for c in range(incident.shape[1]):
                f = incident[n, c]
                if f >= 0 and _excluded_in_row(keys, ptr, f, e, ne):
                    ok = False
                    break
            if ok:
                node = _grow(node, nq)
                node[nq, 0] = n
                node[nq, 1] = e
                nq += 1
    return seg[:ns].copy(), node[:nq].copy()


def near_pairs(
    x0: FloatArray,
    x1: FloatArray,
    edges: IntArray,
    incident: IntArray,
    seg_share: FloatArray,
    node_share: FloatArray,
    excluded: IntArray,
) -> tuple[IntArray, IntArray]:
    """Segment pairs and node–segment pairs that may come within reach on ``x0 -> x1``.

    Parameters
    ----------
    x0, x1
        Node positions ``(N, 3)`` at the start and end of a straight step (mm); pass the same
        array twice for one configuration.
    edges
        Segments ``(E, 2)``.
    incident
        Segments at each node ``(N, K)``, -1 padded.
    seg_share, node_share
        Each segment's and node's share of the search distance (mm), e.g. ``r + (d̂ + m) / 2``:
        a pair is proposed when its boxes come closer than the sum of the two shares.
    excluded
        Sorted keys ``a * E + b`` (``a < b``) of segment pairs that never touch; a node is not
        paired with a segment that any segment at the node may not touch (its own included).

    Returns
    -------
    segment pairs ``(P, 2)`` with ``a < b``, and node–segment pairs ``(Q, 2)`` (node, segment).
    """
    seg, node = _near_pairs(
        np.ascontiguousarray(x0, dtype=float),
        np.ascontiguousarray(x1, dtype=float),
        np.ascontiguousarray(edges, dtype=np.int64),
        np.ascontiguousarray(incident, dtype=np.int64),
        np.ascontiguousarray(seg_share, dtype=float),
        np.ascontiguousarray(node_share, dtype=float),
        np.ascontiguousarray(excluded, dtype=np.int64),
    )
    return seg, node

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

A sweep window along one axis holds every box of its slab, and on a lattice most of them are
far apart along the other two axes; so each window is first reduced, without branches, to
the boxes whose gaps along those two axes are below the reach (the same per-axis tests as the
full one, so nothing passes the full test that this drops), and only those get the full test
and the exclusion lookup. The segments a box may not touch are marked once per box (an array
stamped with its sweep position), so each lookup is one read. The pairs come out in the order
of the plain sweep.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from rotomorph._typing import FloatArray, IntArray
from rotomorph.contact.distance import BOUND_MARGIN

__all__ = ["near_pairs", "near_subset", "stack_exclusion_masks", "stack_near_pairs", "within_reach"]


@njit(cache=True)
def _partners(keys, ne):  # pragma: no cover - compiled
    """The excluded partners of each segment, both ways, from the keys ``lo * ne + hi``:
    segment ``e``'s are ``partner[ptr[e]:ptr[e + 1]]``."""
    ptr = np.zeros(ne + 1, dtype=np.int64)
    for t in range(keys.shape[0]):
        a = keys[t] // ne
        ptr[a + 1] += 1
        ptr[keys[t] - a * ne + 1] += 1
    for e in range(ne):
        ptr[e + 1] += ptr[e]
    fill = ptr[:-1].copy()
    partner = np.empty(ptr[ne], dtype=np.int64)
    for t in range(keys.shape[0]):
        a = keys[t] // ne
        b = keys[t] - a * ne
        partner[fill[a]] = b
        fill[a] += 1
        partner[fill[b]] = a
        fill[b] += 1
    return ptr, partner


@njit(cache=True)
def _mark(stamp, tag, e, ptr, partner):  # pragma: no cover - compiled
    """``stamp[f] = tag`` for segment ``e`` and every segment it may not touch."""
    stamp[e] = tag
    for t in range(ptr[e], ptr[e + 1]):
        stamp[partner[t]] = tag


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
def _boxes(x0, x1, edges, seg_share, node_share):  # pragma: no cover - compiled
    """Boxes ``lo``, ``hi`` (M, 3) and shares (M,) of the segments, then the nodes, over the
    positions ``x0`` and ``x1``, and the axis along which their lower corners spread most."""
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
    axis = 0
    widest = -1.0
    for k in range(3):
        w = lo[:, k].max() - lo[:, k].min()
        if w > widest:
            widest, axis = w, k
    return lo, hi, share, axis


@njit(cache=True)
def _boxes_near(lo, hi, share, i, j):  # pragma: no cover - compiled
    """Whether boxes ``i`` and ``j`` (rows of ``lo``, ``hi``) lie closer than the sum of their
    shares: a gap along one axis of at least that rejects the pair (then the squared gap is
    too). Indices, not row views: a view per call costs more than the test."""
    reach = share[i] + share[j]
    g2 = 0.0
    for k in range(3):
        g = max(lo[j, k] - hi[i, k], lo[i, k] - hi[j, k], 0.0)
        if g >= reach:
            return False
        g2 += g * g
    return g2 < reach * reach


@njit(cache=True)
def _near_pairs(x0, x1, edges, incident, seg_share, node_share, keys):  # pragma: no cover
    ne = edges.shape[0]
    lo, hi, share, axis = _boxes(x0, x1, edges, seg_share, node_share)
    m = share.shape[0]
    # sweep along the axis of widest spread
    start = lo[:, axis] - share
    order = np.argsort(start)
    ptr, partner = _partners(keys, ne)
    stamp = np.full(ne, -1, dtype=np.int64)  # sweep position whose exclusions are marked
    a1 = (axis + 1) % 3
    a2 = (axis + 2) % 3
    # the boxes in sweep order, contiguous (the inner loops read them in that order), and
    # their extents along the two other axes as separate arrays
    lo_s = np.empty((m, 3))
    hi_s = np.empty((m, 3))
    share_s = np.empty(m)
    start_s = np.empty(m)
    is_seg = np.empty(m, dtype=np.bool_)
    lo1 = np.empty(m)
    hi1 = np.empty(m)
    lo2 = np.empty(m)
    hi2 = np.empty(m)
    for ii in range(m):
        i = order[ii]
        for k in range(3):
            lo_s[ii, k] = lo[i, k]
            hi_s[ii, k] = hi[i, k]
        share_s[ii] = share[i]
        start_s[ii] = start[i]
        is_seg[ii] = i < ne
        lo1[ii], hi1[ii] = lo[i, a1], hi[i, a1]
        lo2[ii], hi2[ii] = lo[i, a2], hi[i, a2]
    hits = np.empty(m, dtype=np.int64)
    seg = np.empty((max(4 * ne, 16), 2), dtype=np.int64)
    node = np.empty((max(4 * ne, 16), 2), dtype=np.int64)
    ns = np.int64(0)  # not the literal 0: one compiled _grow, not one per literal
    nq = np.int64(0)
    for ii in range(m):
        i = order[ii]
        end = hi_s[ii, axis] + share_s[ii]
        i_seg = is_seg[ii]
        si, l1, h1, l2, h2 = share_s[ii], lo1[ii], hi1[ii], lo2[ii], hi2[ii]
        # the window: the boxes in it whose gaps along the other two axes are below the
        # reach (the per-axis tests of _boxes_near, same operations), node against node
        # left out; written without branches, as most fail unpredictably
        c = 0
        for jj in range(ii + 1, m):
            if start_s[jj] > end:
                break
            reach = si + share_s[jj]
            g1 = max(lo1[jj] - h1, l1 - hi1[jj], 0.0)
            g2 = max(lo2[jj] - h2, l2 - hi2[jj], 0.0)
            hits[c] = jj
            c += (g1 < reach) & (g2 < reach) & (i_seg | is_seg[jj])
        marked = False
        for t in range(c):
            jj = hits[t]
            if not _boxes_near(lo_s, hi_s, share_s, ii, jj):
                continue
            if not marked:  # the segments that box i may not touch: stamp[f] == ii
                if i_seg:
                    _mark(stamp, ii, i, ptr, partner)
                else:
                    for f in incident[i - ne]:
                        if f >= 0:
                            _mark(stamp, ii, f, ptr, partner)
                marked = True
            j = order[jj]
            if j < ne:
                if stamp[j] == ii:
                    continue
                if i_seg:
                    seg = _grow(seg, ns)
                    seg[ns, 0] = min(i, j)
                    seg[ns, 1] = max(i, j)
                    ns += 1
                else:
                    node = _grow(node, nq)
                    node[nq, 0] = i - ne
                    node[nq, 1] = j
                    nq += 1
                continue
            ok = True
            for f in incident[j - ne]:
                if f >= 0 and stamp[f] == ii:
                    ok = False
                    break
            if ok:
                node = _grow(node, nq)
                node[nq, 0] = j - ne
                node[nq, 1] = i
                nq += 1
    return seg[:ns].copy(), node[:nq].copy()


@njit(cache=True)
def _in_window(lo, hi, share, i, j, axis):  # pragma: no cover - compiled
    """Whether the sweep of :func:`_near_pairs` compares boxes ``i`` and ``j``: the later
    start along ``axis`` is not past the end of the box that starts first."""
    start_i = lo[i, axis] - share[i]
    start_j = lo[j, axis] - share[j]
    return start_j <= hi[i, axis] + share[i] and start_i <= hi[j, axis] + share[j]


@njit(cache=True)
def _near_subset(x0, x1, edges, seg_share, node_share, seg, node):  # pragma: no cover
    ne = edges.shape[0]
    lo, hi, share, axis = _boxes(x0, x1, edges, seg_share, node_share)
    keep_seg = np.zeros(seg.shape[0], dtype=np.bool_)
    for p in range(seg.shape[0]):
        a, b = seg[p, 0], seg[p, 1]
        keep_seg[p] = _in_window(lo, hi, share, a, b, axis) and _boxes_near(lo, hi, share, a, b)
    keep_node = np.zeros(node.shape[0], dtype=np.bool_)
    for p in range(node.shape[0]):
        a, b = ne + node[p, 0], node[p, 1]
        keep_node[p] = _in_window(lo, hi, share, a, b, axis) and _boxes_near(lo, hi, share, a, b)
    return keep_seg, keep_node


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


def near_subset(
    x0: FloatArray,
    x1: FloatArray,
    edges: IntArray,
    seg_share: FloatArray,
    node_share: FloatArray,
    pairs: tuple[IntArray, IntArray],
) -> tuple[IntArray, IntArray]:
    """The pairs among ``pairs`` that :func:`near_pairs` proposes on ``x0 -> x1`` with these
    shares: the same box tests in the same floating-point operations, so when ``pairs`` holds
    every pair that :func:`near_pairs` would propose (e.g. a broad phase with larger shares
    around positions close enough), the result is exactly its set (in the order of ``pairs``).

    Parameters
    ----------
    x0, x1, edges, seg_share, node_share
        As for :func:`near_pairs`.
    pairs
        Segment pairs ``(P, 2)`` and node–segment pairs ``(Q, 2)`` from an earlier broad phase
        (their exclusions already applied).

    Returns
    -------
    the segment pairs and node–segment pairs kept, in their order in ``pairs``.
    """
    seg, node = pairs
    keep_seg, keep_node = _near_subset(
        np.ascontiguousarray(x0, dtype=float),
        np.ascontiguousarray(x1, dtype=float),
        np.ascontiguousarray(edges, dtype=np.int64),
        np.ascontiguousarray(seg_share, dtype=float),
        np.ascontiguousarray(node_share, dtype=float),
        np.ascontiguousarray(seg, dtype=np.int64).reshape(-1, 2),
        np.ascontiguousarray(node, dtype=np.int64).reshape(-1, 2),
    )
    return seg[keep_seg], node[keep_node]


@njit(cache=True)
def _within_reach(quads, dist, move, reach):  # pragma: no cover - compiled
    keep = np.empty(quads.shape[0], dtype=np.int64)
    n = 0
    for p in range(quads.shape[0]):
        lower = (
            dist[p]
            - max(move[quads[p, 0]], move[quads[p, 1]])
            - max(move[quads[p, 2]], move[quads[p, 3]])
        )
        if lower <= reach[p] * (1.0 + BOUND_MARGIN):
            keep[n] = p
            n += 1
    return keep[:n].copy()


def within_reach(
    quads: IntArray, dist: FloatArray, move: FloatArray, reach: FloatArray
) -> IntArray:
    """Indices (ascending) of the pairs ``quads`` that may now be closer than ``reach``.

    A point of a segment is a convex combination of its end nodes, so it has moved at most the
    larger of their motions: a pair's distance is now at least its distance ``dist`` at the
    earlier positions less the largest motion of each side. Pairs whose lower bound clears
    ``reach`` by the relative ``BOUND_MARGIN`` (far above round-off) are left out.

    Parameters
    ----------
    quads
        Pairs ``(P, 4)``: node indices ``p0, p1, q0, q1`` (a repeated index: a point).
    dist
        Their centre-line distances at the earlier positions ``(P,)`` (mm).
    move
        Each node's motion since ``(M,)`` (mm; 0 for fixed obstacle points).
    reach
        Distance below which a pair counts ``(P,)`` (mm).
    """
    return _within_reach(  # type: ignore[no-any-return]
        np.ascontiguousarray(quads, dtype=np.int64),
        np.ascontiguousarray(dist, dtype=float),
        np.ascontiguousarray(move, dtype=float),
        np.ascontiguousarray(reach, dtype=float),
    )


@njit(cache=True)
def _stack_near_pairs(
    x0, x1, edges, seg_share, node_share, n_edges, real_keys, part_keys, part_masks
):  # pragma: no cover - compiled
    nv = edges.shape[0]
    layers = nv // n_edges
    lo, hi, share, axis = _boxes(x0, x1, edges, seg_share, node_share)
    # each network segment's box: the union of its layers' boxes (their end points' boxes lie
    # inside), with the largest share
    rlo = np.empty((n_edges, 3))
    rhi = np.empty((n_edges, 3))
    rshare = np.zeros(n_edges)
    for e in range(n_edges):
        for k in range(3):
            rlo[e, k] = np.inf
            rhi[e, k] = -np.inf
        for m in range(layers):
            a = m * n_edges + e
            for k in range(3):
                rlo[e, k] = min(rlo[e, k], lo[a, k])
                rhi[e, k] = max(rhi[e, k], hi[a, k])
            rshare[e] = max(rshare[e], share[a], share[nv + 2 * a], share[nv + 2 * a + 1])
    raxis = 0
    widest = -1.0
    for k in range(3):
        w = rlo[:, k].max() - rlo[:, k].min()
        if w > widest:
            widest, raxis = w, k
    start = np.empty(n_edges)
    for e in range(n_edges):
        start[e] = rlo[e, raxis] - rshare[e]
    order = np.argsort(start)
    ptr, partner = _partners(real_keys, n_edges)
    stamp = np.full(n_edges, -1, dtype=np.int64)
    # the partly excluded pairs: each segment's partners and their masks (bit k * N + l set:
    # layer k of the lower segment and layer l of the higher may not touch)
    pptr, ppartner = _partners(part_keys, n_edges)
    pmask = np.empty(ppartner.shape[0], dtype=np.int64)
    fill = pptr[:-1].copy()
    for t in range(part_keys.shape[0]):
        a = part_keys[t] // n_edges
        b = part_keys[t] - a * n_edges
        pmask[fill[a]] = part_masks[t]
        fill[a] += 1
        pmask[fill[b]] = part_masks[t]
        fill[b] += 1
    pstamp = np.full(n_edges, -1, dtype=np.int64)
    mask_of = np.zeros(n_edges, dtype=np.int64)
    seg = np.empty((max(4 * nv, 16), 2), dtype=np.int64)
    node = np.empty((max(4 * nv, 16), 2), dtype=np.int64)
    ns = np.int64(0)
    nq = np.int64(0)
    for ii in range(n_edges):
        e = order[ii]
        end = rhi[e, raxis] + rshare[e]
        marked = False
        for jj in range(ii + 1, n_edges):
            f = order[jj]
            if start[f] > end:
                break
            if not _boxes_near(rlo, rhi, rshare, e, f):
                continue
            if not marked:
                _mark(stamp, ii, e, ptr, partner)
                for t in range(pptr[e], pptr[e + 1]):
                    pstamp[ppartner[t]] = ii
                    mask_of[ppartner[t]] = pmask[t]
                marked = True
            if stamp[f] == ii:
                continue  # every layer pair of the two segments is excluded
            mask = mask_of[f] if pstamp[f] == ii else 0
            # the layer pairs: the tests of _near_pairs on the layer network's own boxes; an
            # end point's box lies inside its layer's (same share), so it is near another
            # layer only if its layer is
            for m in range(layers):
                a = m * n_edges + e
                for q in range(layers):
                    bit = m * layers + q if e < f else q * layers + m
                    if (mask >> bit) & 1:
                        continue
                    b = q * n_edges + f
                    if not (
                        _in_window(lo, hi, share, a, b, axis) and _boxes_near(lo, hi, share, a, b)
                    ):
                        continue
                    seg = _grow(seg, ns)
                    seg[ns, 0] = min(a, b)
                    seg[ns, 1] = max(a, b)
                    ns += 1
                    for side in range(2):
                        own, other = (a, b) if side == 0 else (b, a)
                        for end_ in range(2):
                            v = 2 * own + end_
                            if _in_window(lo, hi, share, nv + v, other, axis) and _boxes_near(
                                lo, hi, share, nv + v, other
                            ):
                                node = _grow(node, nq)
                                node[nq, 0] = v
                                node[nq, 1] = other
                                nq += 1
    return seg[:ns].copy(), node[:nq].copy()


def stack_exclusion_masks(
    excluded: IntArray, n_edges: int, layers: int
) -> tuple[IntArray, IntArray, IntArray]:
    """The layer network's excluded keys (``a * V + b``, ``V = N E``) seen per network segment
    pair: the sorted keys ``e * E + f`` (``e < f``) of the pairs whose layer pairs are all
    excluded, and of those only partly excluded with a bit mask each (bit ``k N + l``: layer
    k of e and layer l of f may not touch). Pairs of one segment are left out (never
    proposed)."""
    if layers * layers > 63:
        raise ValueError(f"at most 7 layers fit a 64-bit mask; got {layers}")
    nv = n_edges * layers
    a, b = excluded // nv, excluded % nv
    sa, sb = a % n_edges, b % n_edges
    ka, kb = a // n_edges, b // n_edges
    keep = sa != sb
    sa, sb, ka, kb = sa[keep], sb[keep], ka[keep], kb[keep]
    lo_first = sa < sb
    e, f = np.where(lo_first, sa, sb), np.where(lo_first, sb, sa)
    k, m = np.where(lo_first, ka, kb), np.where(lo_first, kb, ka)
    key = e * n_edges + f
    bits = np.left_shift(np.int64(1), (k * layers + m).astype(np.int64))
    uniq, inv = np.unique(key, return_inverse=True)
    masks = np.zeros(len(uniq), dtype=np.int64)
    np.bitwise_or.at(masks, inv, bits)
    full = masks == (1 << (layers * layers)) - 1
    return (
        uniq[full].astype(np.int64),
        uniq[~full].astype(np.int64),
        masks[~full].astype(np.int64),
    )


def stack_near_pairs(
    x0: FloatArray,
    x1: FloatArray,
    edges: IntArray,
    seg_share: FloatArray,
    node_share: FloatArray,
    *,
    n_edges: int,
    masks: tuple[IntArray, IntArray, IntArray],
) -> tuple[IntArray, IntArray]:
    """:func:`near_pairs` of a layer network (:mod:`rotomorph.contact.stack`: segment
    ``v = k E + e`` is layer k of network segment e, its end points ``2 v`` and ``2 v + 1``),
    found through the network's segments: a sweep over each segment's box around all its
    layers proposes segment pairs (``real_excluded``: the pairs of which every layer pair is
    excluded), and each proposed pair's layer pairs and their end points get the tests of
    :func:`near_pairs` on their own boxes. The same pairs as :func:`near_pairs` on the layer
    network (a layer's box lies inside its segment's, with no larger share), in another
    order, at a cost that grows with the network rather than with its layers.

    Parameters
    ----------
    x0, x1, edges, seg_share, node_share
        As for :func:`near_pairs`, of the layer network.
    n_edges
        Segments of the network E.
    masks
        The layer network's exclusion per segment pair (:func:`stack_exclusion_masks`).
    """
    full, part, bits = masks
    return _stack_near_pairs(  # type: ignore[no-any-return]
        np.ascontiguousarray(x0, dtype=float),
        np.ascontiguousarray(x1, dtype=float),
        np.ascontiguousarray(edges, dtype=np.int64),
        np.ascontiguousarray(seg_share, dtype=float),
        np.ascontiguousarray(node_share, dtype=float),
        int(n_edges),
        np.ascontiguousarray(full, dtype=np.int64),
        np.ascontiguousarray(part, dtype=np.int64),
        np.ascontiguousarray(bits, dtype=np.int64),
    )

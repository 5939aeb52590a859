"""Compiled supernodal Cholesky factorization on a fixed pattern, with its triangular solves.

A *supernode* is a run of consecutive columns ``f, ..., l - 1`` of the Cholesky factor ``L``
that share one row pattern below the diagonal block: column ``j`` has the rows of column
``j + 1`` plus ``j`` itself, and ``j + 1`` is its parent in the elimination tree. Its part of
``L`` is then one dense ``rows × (l - f)`` panel (column-major, the first ``l - f`` rows being
the supernode's own columns) and the factorization works on dense columns instead of single
entries (Ng & Peyton, *SIAM J. Sci. Comput.* 14, 1993; Davis, *Direct Methods for Sparse
Linear Systems*, SIAM 2006, §9.1). On a rod network the node triples and the chains between
junctions give supernodes of 3 to 7 columns, and the top separators larger ones.

The numeric phase is left-looking: each supernode gathers the updates of the supernodes below
it that touch its columns (kept in linked lists by the next row each one reaches), then factors
its panel; a non-positive pivot stops it and reports that the matrix is not positive definite.
Every entry gets the same operations as the textbook column Cholesky
``L[i, j] = (A[i, j] - sum_k L[i, k] L[j, k]) / L[j, j]``; only the order of the sums differs
from a scalar code, so the factors agree to round-off.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def ereach(k, bp, bi, parent, s, w):  # pragma: no cover - compiled
    """Pattern of row k of L (columns < k) in s[top:], topologically ordered."""
    n = s.shape[0]
    top = n
    w[k] = k
    for p in range(bp[k], bp[k + 1]):
        i = bi[p]
        if i > k:
            continue
        length = 0
        while w[i] != k:
            s[length] = i
            length += 1
            w[i] = k
            i = parent[i]
        while length > 0:
            top -= 1
            length -= 1
            s[top] = s[length]
    return top


@njit(cache=True)
def supernodes(n, bp, bi, parent, lp):  # pragma: no cover - compiled
    """Supernodal structure of the factor of the matrix whose upper triangle is ``bp, bi``.

    Returns ``first, rp, ri, px, snode, dst, diag``: supernode ``s`` has the columns
    ``first[s]:first[s + 1]`` and the rows ``ri[rp[s]:rp[s + 1]]`` (ascending, its own columns
    first), and its panel starts at ``px[s]`` in the factor's value array (column-major);
    ``snode[j]`` is the supernode of column j, ``dst[p]`` where entry ``p`` of the upper
    triangle lands (as the lower entry ``(bi[p]``'s column, its row), ``diag[j]`` where the
    diagonal entry ``(j, j)`` lands.
    """
    count = lp[1:] - lp[:-1]
    starts = np.empty(n + 1, dtype=np.int64)
    ns = 0
    for j in range(n):
        if j == 0 or not (parent[j - 1] == j and count[j - 1] == count[j] + 1):
            starts[ns] = j
            ns += 1
    starts[ns] = n
    first = starts[: ns + 1].copy()
    snode = np.empty(n, dtype=np.int64)
    rp = np.zeros(ns + 1, dtype=np.int64)
    px = np.zeros(ns + 1, dtype=np.int64)
    for s in range(ns):
        f, width = first[s], first[s + 1] - first[s]
        snode[f : first[s + 1]] = s
        rp[s + 1] = rp[s] + count[f]
        px[s + 1] = px[s] + count[f] * width
    # rows of each supernode's first column, found row by row (ascending)
    ri = np.empty(rp[ns], dtype=np.int64)
    fill = rp[:-1].copy()
    stack = np.empty(n, dtype=np.int64)
    mark = -np.ones(n, dtype=np.int64)
    for k in range(n):
        top = ereach(k, bp, bi, parent, stack, mark)
        for t in range(top, n):
            i = stack[t]
            if first[snode[i]] == i:
                ri[fill[snode[i]]] = k
                fill[snode[i]] += 1
        s = snode[k]
        if first[s] == k:
            ri[fill[s]] = k
            fill[s] += 1
    # where each upper-triangle entry (row i <= column j) lands: L[j, i], found supernode by
    # supernode with the entries listed by row (a counting sort) and a row -> position map
    by_row = np.zeros(n + 1, dtype=np.int64)
    for p in range(bp[n]):
        by_row[bi[p] + 1] += 1
    for i in range(n):
        by_row[i + 1] += by_row[i]
    entries = np.empty(bp[n], dtype=np.int64)
    column = np.empty(bp[n], dtype=np.int64)
    slot = by_row[:-1].copy()
    for j in range(n):
        for p in range(bp[j], bp[j + 1]):
            entries[slot[bi[p]]] = p
            column[slot[bi[p]]] = j
            slot[bi[p]] += 1
    dst = np.empty(bp[n], dtype=np.int64)
    position = np.empty(n, dtype=np.int64)
    for s in range(ns):
        nr = rp[s + 1] - rp[s]
        for t in range(nr):
            position[ri[rp[s] + t]] = t
        for i in range(first[s], first[s + 1]):
            for q in range(by_row[i], by_row[i + 1]):
                dst[entries[q]] = px[s] + (i - first[s]) * nr + position[column[q]]
    diag = np.empty(n, dtype=np.int64)
    for j in range(n):
        s = snode[j]
        local = j - first[s]
        diag[j] = px[s] + local * (rp[s + 1] - rp[s]) + local
    return first, rp, ri, px, snode, dst, diag


@njit(cache=True)
def factor_numeric(data, src, shift, first, rp, ri, px, snode, dst, diag, lx):  # pragma: no cover
    """Supernodal Cholesky of ``B + diag(shift)`` into ``lx``; False at a non-positive pivot.

    ``B``'s upper triangle entry ``p`` is ``data[src[p]]``.
    """
    ns = first.shape[0] - 1
    n = snode.shape[0]
    lx[:] = 0.0
    for p in range(src.shape[0]):
        lx[dst[p]] = data[src[p]]
    for j in range(n):
        lx[diag[j]] += shift[j]
    head = -np.ones(ns, dtype=np.int64)
    link = np.empty(ns, dtype=np.int64)
    nextrow = np.empty(ns, dtype=np.int64)
    relmap = np.empty(n, dtype=np.int64)
    rel = np.empty(n, dtype=np.int64)
    acc = np.empty(n)
    for s in range(ns):
        f, last = first[s], first[s + 1]
        width = last - f
        r0 = rp[s]
        nr = rp[s + 1] - r0
        base = px[s]
        for t in range(nr):
            relmap[ri[r0 + t]] = t
        # updates from the supernodes below that reach columns f .. last - 1
        d = head[s]
        while d != -1:
            following = link[d]
            d0 = rp[d]
            nrd = rp[d + 1] - d0
            wd = first[d + 1] - first[d]
            bd = px[d]
            p = nextrow[d]
            p2 = p
            while p2 < nrd and ri[d0 + p2] < last:
                p2 += 1
            for i in range(p, nrd):
                rel[i] = relmap[ri[d0 + i]]
            for j in range(p, p2):
                # column ri[d0 + j] of s, rows j .. nrd - 1 of d: sum over d's columns
                m = nrd - j
                upd = acc[:m]
                upd[:] = 0.0
                for k in range(wd):
                    src_col = lx[bd + k * nrd + j : bd + (k + 1) * nrd]
                    ljk = src_col[0]
                    for i in range(m):
                        upd[i] += src_col[i] * ljk
                target = lx[base + (ri[d0 + j] - f) * nr : base + (ri[d0 + j] - f + 1) * nr]
                where = rel[j:nrd]
                for i in range(m):
                    target[where[i]] -= upd[i]
            if p2 < nrd:
                nextrow[d] = p2
                t = snode[ri[d0 + p2]]
                link[d] = head[t]
                head[t] = d
            d = following
        # the dense panel (column-major): left-looking column Cholesky
        for j in range(width):
            col = lx[base + j * nr + j : base + (j + 1) * nr]
            for k in range(j):
                src_col = lx[base + k * nr + j : base + (k + 1) * nr]
                ljk = src_col[0]
                for i in range(nr - j):
                    col[i] -= src_col[i] * ljk
            pivot = col[0]
            if not pivot > 0.0:
                return False
            pivot = np.sqrt(pivot)
            col[0] = pivot
            for i in range(1, nr - j):
                col[i] /= pivot
        if nr > width:
            nextrow[s] = width
            t = snode[ri[r0 + width]]
            link[s] = head[t]
            head[t] = s
    return True


@njit(cache=True)
def solve_numeric(first, rp, ri, px, lx, perm, b):  # pragma: no cover - compiled
    """Solve ``L L^T y = b[perm]`` and return ``x`` with ``x[perm] = y``."""
    ns = first.shape[0] - 1
    n = perm.shape[0]
    y = np.empty(n)
    for i in range(n):
        y[i] = b[perm[i]]
    work = np.empty(n)
    for s in range(ns):
        f = first[s]
        width = first[s + 1] - f
        nr = rp[s + 1] - rp[s]
        rows = ri[rp[s] + width : rp[s + 1]]
        below = work[: nr - width]
        below[:] = 0.0
        for j in range(width):
            col = lx[px[s] + j * nr : px[s] + (j + 1) * nr]
            yj = y[f + j] / col[j]
            y[f + j] = yj
            for i in range(j + 1, width):
                y[f + i] -= col[i] * yj
            tail = col[width:]
            for i in range(nr - width):
                below[i] += tail[i] * yj
        for i in range(nr - width):
            y[rows[i]] -= below[i]
    for s in range(ns - 1, -1, -1):
        f = first[s]
        width = first[s + 1] - f
        nr = rp[s + 1] - rp[s]
        rows = ri[rp[s] + width : rp[s + 1]]
        below = work[: nr - width]
        for i in range(nr - width):
            below[i] = y[rows[i]]
        for j in range(width - 1, -1, -1):
            col = lx[px[s] + j * nr : px[s] + (j + 1) * nr]
            v = y[f + j]
            for i in range(j + 1, width):
                v -= col[i] * y[f + i]
            tail = col[width:]
            for i in range(nr - width):
                v -= tail[i] * below[i]
            y[f + j] = v / col[j]
    out = np.empty(n)
    for i in range(n):
        out[perm[i]] = y[i]
    return out

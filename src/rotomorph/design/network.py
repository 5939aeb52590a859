"""Rod networks: nodes joined by straight segments (a single filament is a one-chain network).

A :class:`Network` is pure geometry and topology. Mechanics (stiffness, natural curvature) is
attached later by :class:`rotomorph.rod.model.Model`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from rotomorph._display import compact_display
from rotomorph._typing import BoolArray, FloatArray, IntArray
from rotomorph.errors import InvalidDesignError


@compact_display()
@dataclass(frozen=True, eq=False)
class Network:
    """Nodes (mm) joined by segments; every segment is one discrete-rod edge.

    Parameters
    ----------
    nodes
        Node positions ``(N, 3)`` in mm.
    edges
        Segment end-node indices ``(E, 2)``; the segment points from ``edges[j, 0]`` to
        ``edges[j, 1]``.
    branch
        ``(N,)`` booleans marking branch nodes (junctions). At a branch node every unique pair of
        incident segments forms an isotropic bend-twist stencil; at any other node of degree two
        the two segments form an ordinary rod vertex. Default: nodes of degree >= 3.

    Raises
    ------
    InvalidDesignError
        Non-finite positions, out-of-range or repeated indices, self-loops or zero-length segments.
    """

    nodes: FloatArray
    edges: IntArray
    branch: BoolArray = field(default=None)  # type: ignore[arg-type]  # set by __post_init__

    def __post_init__(self) -> None:
        nodes = np.array(self.nodes, dtype=float)
        if nodes.ndim != 2 or nodes.shape[1] != 3:
            raise InvalidDesignError(
                "Network.nodes", f"must have shape (N, 3) in mm; got {nodes.shape}"
            )
        bad = ~np.isfinite(nodes).all(axis=1)
        if bad.any():
            raise InvalidDesignError(
                "Network.nodes", f"must be finite; node {int(np.flatnonzero(bad)[0])} is not"
            )
        edges = np.array(self.edges, dtype=np.int64).reshape(-1, 2)
        if len(edges) == 0:
            raise InvalidDesignError("Network.edges", "needs at least one segment")
        if edges.min() < 0 or edges.max() >= len(nodes):
            raise InvalidDesignError("Network.edges", f"indices must lie in [0, {len(nodes) - 1}]")
        loops = edges[:, 0] == edges[:, 1]
        if loops.any():
            raise InvalidDesignError(
                "Network.edges", f"segment {int(np.flatnonzero(loops)[0])} joins a node to itself"
            )
        key = np.sort(edges, axis=1)
        if len(np.unique(key, axis=0)) != len(key):
            raise InvalidDesignError("Network.edges", "a pair of nodes is joined twice")
        lengths = np.linalg.norm(nodes[edges[:, 1]] - nodes[edges[:, 0]], axis=1)
        short = lengths <= 1e-12 * max(1.0, float(np.abs(nodes).max()))
        if short.any():
            raise InvalidDesignError(
                "Network.edges",
                f"segment {int(np.flatnonzero(short)[0])} has zero length; remove repeated points",
            )
        degree = np.bincount(edges.ravel(), minlength=len(nodes))
        if self.branch is None:
            branch = degree >= 3
        else:
            branch = np.array(self.branch, dtype=bool).reshape(-1)
            if branch.shape != (len(nodes),):
                raise InvalidDesignError(
                    "Network.branch", f"must have one flag per node ({len(nodes)})"
                )
        for name, value in (("nodes", nodes), ("edges", edges), ("branch", branch)):
            value.setflags(write=False)
            object.__setattr__(self, name, value)

    @classmethod
    def chain(cls, points: FloatArray) -> Network:
        """A single filament through ``points`` ``(N, 3)`` (mm), ``N >= 3``."""
        pts = np.asarray(points, dtype=float)
        if pts.ndim != 2 or pts.shape[1] != 3 or len(pts) < 3:
            raise InvalidDesignError(
                "points", f"a filament needs an (N, 3) array with N >= 3; got shape {pts.shape}"
            )
        n = len(pts)
        edges = np.stack([np.arange(n - 1), np.arange(1, n)], axis=1)
        return cls(pts, edges)

    @classmethod
    def ring(cls, points: FloatArray) -> Network:
        """A closed filament (a ring) through ``points`` ``(N, 3)`` (mm), ``N >= 3``.

        Segment ``j`` joins point ``j`` to point ``j + 1`` and the last one joins the last point
        back to the first (do not repeat the first point at the end). Every node, the first
        included, is an ordinary rod vertex whose incoming segment is the one before it, so a
        ring has ``N`` segments and ``N`` bend–twist stencils (stencil ``k`` at node ``k``).
        """
        pts = np.asarray(points, dtype=float)
        if pts.ndim != 2 or pts.shape[1] != 3 or len(pts) < 3:
            raise InvalidDesignError(
                "points", f"a ring needs an (N, 3) array with N >= 3; got shape {pts.shape}"
            )
        n = len(pts)
        if np.linalg.norm(pts[-1] - pts[0]) <= 1e-12 * max(1.0, float(np.abs(pts).max())):
            raise InvalidDesignError(
                "points", "the last point repeats the first; a ring closes by itself, drop it"
            )
        edges = np.stack([np.arange(n), (np.arange(n) + 1) % n], axis=1)
        return cls(pts, edges)

    @property
    def is_ring(self) -> bool:
        """True for a single closed filament as made by :meth:`ring`."""
        n = self.n_nodes
        return (
            self.n_edges == n
            and not self.branch.any()
            and np.array_equal(self.edges[:, 0], np.arange(n))
            and np.array_equal(self.edges[:, 1], (np.arange(n) + 1) % n)
        )

    @property
    def n_nodes(self) -> int:
        """Number of nodes."""
        return len(self.nodes)

    @property
    def n_edges(self) -> int:
        """Number of segments."""
        return len(self.edges)

    @property
    def degree(self) -> IntArray:
        """Number of segments at each node ``(N,)``."""
        return np.bincount(self.edges.ravel(), minlength=self.n_nodes)

    @property
    def edge_lengths(self) -> FloatArray:
        """Segment lengths ``(E,)`` in mm."""
        return np.linalg.norm(self.nodes[self.edges[:, 1]] - self.nodes[self.edges[:, 0]], axis=1)

    def with_nodes(self, nodes: FloatArray) -> Network:
        """The same topology with new node positions ``(N, 3)`` (mm)."""
        return Network(nodes, self.edges, self.branch)

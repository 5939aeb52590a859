r"""The paper's square lattice of sinusoidal edges (Methods, "Numerical simulation").

Layout and numbering
--------------------
* Branch nodes ``k = n*i + j`` (row-major) at :math:`(l\,i, l\,j, 0)`, ``i, j = 0..n-1``; they are
  nodes ``0 .. n²-1`` of the :class:`~rotomorph.design.network.Network`.
* Lattice edges (``2 n (n-1)``; 40 for n = 5), always oriented from the lower to the higher
  branch index, so the tangent T is +x or +y:
  first the x-edges ``(i, j) -> (i+1, j)`` ordered by ``j`` then ``i``, then the y-edges
  ``(i, j) -> (i, j+1)`` ordered by ``i`` then ``j``.
* Ghost nodes of lattice edge ``e`` (paper's formula: N = ẑ × T on EVERY edge):

  .. math:: v(s) = v_{start} + T\,s\,l/(n_g+1) + N\,A\sin(2\pi s/(n_g+1)),\quad s = 1..n_g,

  numbered ``n² + e*n_g + (s-1)``. Each edge is one sine period, so branch nodes are inflection
  points. Network segments run in chain order along each edge, in edge order.
* Modes: ``'expanding'`` = active on the outer side of the edge's curvature (straightens),
  ``'contracting'`` = active inner (curls) [PAPER]; the active side flips by π at each inflection.
* Print programs: every line of edges along x (fixed ``j``) and along y (fixed ``i``) is one
  continuous filament printed in +x / +y, so program edges have the network's orientation.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Literal, Union, cast

import numpy as np

from rotomorph._display import compact_display
from rotomorph._typing import BoolArray, FloatArray, IntArray
from rotomorph.design.network import Network
from rotomorph.design.path import Path
from rotomorph.design.program import PrintProgram, active_side_angle
from rotomorph.errors import InvalidDesignError

__all__ = ["ASSUMED_FIELDS", "MODES", "PATTERNS", "Lattice", "sinusoidal_lattice"]

#: Geometric inputs of the paper's lattice that the paper does not give (mm): every result that
#: depends on them is a consequence of these assumptions, not of a measurement.
ASSUMED_FIELDS = ("spacing", "amplitude", "radius")

MODES = ("expanding", "contracting")
PATTERNS = ("expanding", "contracting", "dome", "saddle")
Centre = Literal["central_cells", "interior"]
Pattern = Union[str, Sequence[str], Mapping[Union[int, tuple[int, int]], str]]  # noqa: UP007


def _edge_list(n: int) -> IntArray:
    ex = [(n * i + j, n * (i + 1) + j) for j in range(n) for i in range(n - 1)]
    ey = [(n * i + j, n * i + j + 1) for i in range(n) for j in range(n - 1)]
    return np.array(ex + ey, dtype=np.int64)


def _central(n: int, edges: IntArray, centre: str) -> BoolArray:
    i, j = np.divmod(edges, n)
    interior = (i > 0) & (i < n - 1) & (j > 0) & (j < n - 1)
    if centre == "central_cells":
        # both end nodes strictly inside: the 2x2 central cells for n = 5 (12 edges)
        return cast(BoolArray, interior.all(axis=1))  # (E, 2) -> (E,): an array
    if centre == "interior":
        # every edge not on the perimeter (24 of 40 for n = 5)
        along_x = j[:, 0] == j[:, 1]
        on_border = np.where(
            along_x, (j[:, 0] == 0) | (j[:, 0] == n - 1), (i[:, 0] == 0) | (i[:, 0] == n - 1)
        )
        return ~on_border
    raise InvalidDesignError("centre", f"must be 'central_cells' or 'interior'; got {centre!r}")


def _modes(pattern: Pattern, n: int, edges: IntArray, centre: str) -> tuple[str, ...]:
    m = len(edges)
    if isinstance(pattern, str):
        if pattern in MODES:
            return (pattern,) * m
        if pattern in ("dome", "saddle"):
            inner = "expanding" if pattern == "dome" else "contracting"
            outer = "contracting" if pattern == "dome" else "expanding"
            return tuple(inner if c else outer for c in _central(n, edges, centre))
        raise InvalidDesignError(
            "pattern",
            f"must be one of {PATTERNS}, a list of {m} modes or a per-edge map; got {pattern!r}",
        )
    seq: Sequence[str]
    if isinstance(pattern, Mapping):
        index = {(int(a), int(b)): e for e, (a, b) in enumerate(edges)}
        out: list[str | None] = [None] * m
        for key, mode in pattern.items():
            if isinstance(key, tuple):
                e = index.get((min(key), max(key)))
                if e is None:
                    raise InvalidDesignError("pattern", f"{key} is not a lattice edge")
            else:
                e = int(key)
                if not 0 <= e < m:
                    raise InvalidDesignError("pattern", f"edge {e} outside [0, {m - 1}]")
            out[e] = mode
        if None in out:
            raise InvalidDesignError(
                "pattern", f"per-edge map misses edge {out.index(None)}; give all {m} edges"
            )
        seq = cast(list[str], out)  # no None left (checked above)
    else:
        seq = pattern
    modes = tuple(seq)
    if len(modes) != m:
        raise InvalidDesignError(
            "pattern", f"needs one mode per lattice edge ({m}); got {len(modes)}"
        )
    for e, mode in enumerate(modes):
        if mode not in MODES:
            raise InvalidDesignError(f"pattern[{e}]", f"must be one of {MODES}; got {mode!r}")
    return modes


def _edge_speeds(values: Sequence[float], m: int) -> tuple[float, ...]:
    try:
        speeds = np.asarray(values, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise InvalidDesignError("edge_speeds", "must be a list of numbers (mm/s)") from None
    if speeds.shape != (m,):
        raise InvalidDesignError(
            "edge_speeds", f"needs one speed per lattice edge ({m}); got {speeds.size}"
        )
    for e, v in enumerate(speeds):
        if not (np.isfinite(v) and v > 0):
            raise InvalidDesignError(f"edge_speeds[{e}]", f"must be > 0 mm/s; got {v}")
    return tuple(float(v) for v in speeds)


@compact_display()
@dataclass(frozen=True, eq=False)
class Lattice:
    """A sinusoidal lattice: network, per-edge chains and modes, printing parameters.

    Build it with :func:`sinusoidal_lattice`; see the module docstring for the numbering.

    Attributes
    ----------
    network
        Nodes (mm), segments and branch flags (the first ``n²`` nodes).
    n, spacing, amplitude, ghost_nodes
        Grid size, node spacing l (mm), sine amplitude A (mm), ghost nodes per edge n_g.
    edge_nodes
        ``(E, 2)`` start and end branch node of each lattice edge.
    edge_chains
        One array per lattice edge: node indices start branch → ghosts → end branch.
    edge_mode
        ``'expanding'`` or ``'contracting'`` per lattice edge.
    layers, layer_height
        Number of printed layers and their spacing in z (mm).
    speed, radius, active_fraction, active_material, passive_material
        Printing parameters of every filament (mm/s, mm, –, names).
    flip_length
        Arc length (mm) over which the nozzle turns the active side by π at each inflection
        (0: a step, the ideal sharp flip; a machine with rotation limit ω_max needs at least
        π v / ω_max).
    edge_speeds
        Print speed of each lattice edge ``(E,)`` (mm/s), or None for ``speed`` everywhere
        (:attr:`speeds`). The speed sets how strongly an edge actuates (the calibrated speed
        law of :mod:`rotomorph.materials.process`).

    Notes
    -----
    The paper does not give A, l (= the wavelength: one period per edge) or the filament
    radius; :data:`ASSUMED_FIELDS` names them so outputs can flag them as assumptions.
    """

    network: Network
    n: int
    spacing: float
    amplitude: float
    ghost_nodes: int
    edge_nodes: IntArray
    edge_chains: tuple[IntArray, ...]
    edge_mode: tuple[str, ...]
    layers: int = 3
    layer_height: float = 0.6
    speed: float = 3.0
    radius: float = 0.3
    active_fraction: float = 0.5
    active_material: str = "lce"
    passive_material: str = "acrylate"
    flip_length: float = 0.0
    edge_speeds: tuple[float, ...] | None = None
    _cache: dict = field(default_factory=dict, repr=False, compare=False)

    # ----------------------------------------------------------------- branch nodes
    @property
    def branch_indices(self) -> IntArray:
        """Indices of the ``n²`` branch nodes (``0 .. n²-1``)."""
        return np.flatnonzero(self.network.branch)

    @property
    def branch_positions(self) -> FloatArray:
        """Branch node positions ``(n², 3)`` (mm)."""
        return self.network.nodes[self.branch_indices]

    def branch_index(self, i: int, j: int) -> int:
        """Node index of the branch node at grid position ``(i, j)``, at ``(l i, l j)``."""
        if not (0 <= i < self.n and 0 <= j < self.n):
            raise InvalidDesignError("(i, j)", f"must lie in [0, {self.n - 1}]²; got {(i, j)}")
        return self.n * i + j

    @property
    def n_junction_pairs(self) -> int:
        """Number of segment pairs at branch nodes, Σ deg(deg-1)/2 (94 for n = 5)."""
        d = self.network.degree[self.network.branch]
        return int(np.sum(d * (d - 1) // 2))

    @property
    def edge_direction(self) -> tuple[str, ...]:
        """``'x'`` or ``'y'`` per lattice edge."""
        e = self.edge_nodes
        return tuple("y" if b - a == 1 else "x" for a, b in e)

    # ----------------------------------------------------------------- printing
    @property
    def speeds(self) -> FloatArray:
        """Print speed of every lattice edge ``(E,)`` (mm/s): ``edge_speeds`` or ``speed``."""
        if self.edge_speeds is None:
            return np.full(len(self.edge_nodes), self.speed)
        return np.array(self.edge_speeds, dtype=float)

    def _lines(self) -> list[list[int]]:
        """Lattice edges grouped into continuous filaments: x-lines by j, then y-lines by i."""
        m = self.n - 1
        nx = self.n * m
        return [list(range(j * m, (j + 1) * m)) for j in range(self.n)] + [
            list(range(nx + i * m, nx + (i + 1) * m)) for i in range(self.n)
        ]

    def _edge_points(self, edges: IntArray, subdivide: int) -> FloatArray:
        """Points ``(len(edges), k, 3)`` of lattice edges at ghost parameter s = 0, 1/k, ...,
        n_g+1 (mm), k = (n_g+1)·subdivide + 1."""
        ends = self.edge_nodes[edges]
        start = self.network.nodes[ends[:, 0]]
        t = (self.network.nodes[ends[:, 1]] - start) / self.spacing
        nrm = np.cross([0.0, 0.0, 1.0], t)
        per = self.ghost_nodes + 1
        s = np.arange(per * subdivide + 1) / subdivide
        return (
            start[:, None, :]
            + (s * self.spacing / per)[None, :, None] * t[:, None, :]
            + (self.amplitude * np.sin(2 * np.pi * s / per))[None, :, None] * nrm[:, None, :]
        )

    @property
    def line_edges(self) -> list[list[int]]:
        """Lattice edges of every printed line, in printing order (x-lines by j, then y-lines
        by i)."""
        return self._lines()

    def _vertex_edges(self, line: list[int], subdivide: int) -> IntArray:
        """Lattice edge whose speed each vertex of a line's program carries: that of the move
        leaving it (the last vertex: its edge's)."""
        per_edge = (self.ghost_nodes + 1) * subdivide
        return np.append(np.repeat(np.asarray(line, dtype=np.int64), per_edge), line[-1])

    def line_speed_edges(self) -> list[IntArray]:
        """Per printed line (as :meth:`line_programs`), the lattice edge whose speed each of its
        program vertices carries (:attr:`speeds` indexed by it gives the vertex speeds)."""
        return [self._vertex_edges(line, 1) for line in self._lines()]

    def line_programs(self) -> list[tuple[PrintProgram, IntArray]]:
        """The printed lines of one layer at network resolution, with their segments.

        Returns ``(program, segments)`` per line (x-lines by j, then y-lines by i): program
        edge k is network segment ``segments[k]``, so program vertex k is that segment's first
        node (the lattice's natural field comes from these programs).
        """
        progs = self.print_programs(1)[: len(self._lines())]
        per = self.ghost_nodes + 1
        out = []
        for prog, line in zip(progs, self._lines(), strict=True):
            out.append((prog, (np.asarray(line)[:, None] * per + np.arange(per)).ravel()))
        return out

    def print_programs(self, subdivide: int = 4) -> list[PrintProgram]:
        """One :class:`PrintProgram` per line and layer (``2 n · layers``), layer by layer.

        Parameters
        ----------
        subdivide
            Toolpath vertices per network segment (>= 1): the program follows the paper's sine
            formula at ghost parameter steps 1/subdivide, so every network node is a program
            vertex (index ``subdivide * m`` along the line) and the nozzle flips over one short
            toolpath edge rather than a whole network segment.

        Notes
        -----
        Each line's nozzle keeps the active half outer (expanding edges) or inner (contracting
        edges) of the local curvature, flipping by π at inflections (see
        :meth:`PrintProgram.sinusoid_with_active_side`). Every move along lattice edge ``e``
        runs at ``speeds[e]``: a vertex carries the speed of the move that leaves it (the
        branch node between two edges that of the next edge). Layer ``k`` lies at
        ``z = k * layer_height`` (mm). Lines are printed x-lines (by j) then y-lines (by i), each
        in +x / +y.
        """
        if int(subdivide) != subdivide or subdivide < 1:
            raise InvalidDesignError("subdivide", f"must be an integer >= 1; got {subdivide}")
        key = ("programs", int(subdivide))
        if key not in self._cache:
            base = []
            edge_speed = self.speeds
            expanding = np.array([m == "expanding" for m in self.edge_mode])
            for line in self._lines():
                pts = self._edge_points(np.asarray(line), subdivide)
                sgn = np.where(expanding[line], 1.0, -1.0)
                pieces = [pts[0, :1], pts[:, 1:].reshape(-1, 3)]
                side = np.concatenate([sgn[:1], np.repeat(sgn, pts.shape[1] - 1)])
                speed = edge_speed[self._vertex_edges(line, subdivide)]
                path = Path(np.concatenate(pieces))
                alpha = active_side_angle(path, side, self.flip_length)
                base.append(
                    PrintProgram.from_interface_angle(
                        path,
                        speed if self.edge_speeds is not None else self.speed,
                        alpha,
                        radius=self.radius,
                        active_fraction=self.active_fraction,
                        active_material=self.active_material,
                        passive_material=self.passive_material,
                        step_flips=self.flip_length == 0,
                    )
                )
            self._cache[key] = [
                p.with_layer(k, k * self.layer_height) for k in range(self.layers) for p in base
            ]
        return list(self._cache[key])

    @property
    def segment_side(self) -> IntArray:
        """Active side per network segment ``(n_segments,)``: +1 on the left of the segment's
        direction (−d2), −1 on the right, 0 where the flip falls inside the segment.

        From the sign of the sine's printed curvature at the segment's midpoint parameter
        s + ½ (left turn > 0) times +1 (expanding, active outer) or −1 (contracting, inner);
        with an even ``ghost_nodes`` the mid-edge inflection lies inside one segment (0).
        """
        per = self.ghost_nodes + 1
        sine = np.sin(2 * np.pi * (np.arange(per) + 0.5) / per)
        # curvature of A sin along N = z x T (left) is -A k² sin: left turn where sin < 0
        turn = np.where(np.abs(sine) < 1e-9, 0.0, -np.sign(sine))
        if self.amplitude == 0:
            turn[:] = 0.0
        out = []
        for mode in self.edge_mode:
            outer = 1.0 if mode == "expanding" else -1.0
            # active outer of a left turn = right side = -1
            out.append(-outer * turn)
        return np.concatenate(out).astype(np.int64)

    @property
    def interface_angle(self) -> FloatArray:
        """Design interface angle α per network segment ``(n_segments,)`` (rad).

        α = −π/2 (active on the left, n = −d2), +π/2 (right) or 0 on a segment that contains
        the flip (n = d1 = +z, midway through the π rotation); convention of
        :mod:`rotomorph.design.program`. The flip at a branch node is a step at the node.
        """
        return -0.5 * np.pi * self.segment_side.astype(float)

    @property
    def segment_mode(self) -> tuple[str, ...]:
        """Mode of each network segment (its lattice edge's mode)."""
        per = self.ghost_nodes + 1
        return tuple(m for m in self.edge_mode for _ in range(per))


def sinusoidal_lattice(
    n: int = 5,
    spacing: float = 5.0,
    amplitude: float = 1.25,
    ghost_nodes: int = 10,
    pattern: Pattern = "expanding",
    *,
    centre: Centre = "central_cells",
    layers: int = 3,
    layer_height: float = 0.6,
    speed: float = 3.0,
    radius: float = 0.3,
    active_fraction: float = 0.5,
    active_material: str = "lce",
    passive_material: str = "acrylate",
    flip_length: float = 0.0,
    edge_speeds: Sequence[float] | None = None,
) -> Lattice:
    """The paper's n × n lattice of one-period sinusoidal edges (module docstring).

    Parameters
    ----------
    n
        Branch nodes per side (>= 2); the paper uses 5 (25 nodes, 40 edges).
    spacing
        Node spacing l (mm), > 0. Not given in the paper; default 5 mm.
    amplitude
        Sine amplitude A (mm), >= 0 (0 gives straight edges); default 1.25 mm (A/l = 0.25;
        not given in the paper).
    ghost_nodes
        Ghost nodes per edge n_g (>= 1); paper: 10 (425 nodes in all for n = 5).
    pattern
        ``'expanding'``, ``'contracting'``, ``'dome'`` (expanding centre, contracting rest),
        ``'saddle'`` (the inverse), a sequence of one mode per lattice edge, or a map from edge
        index or branch-node pair ``(a, b)`` to mode.
    centre
        Which edges are "central" for dome/saddle: ``'central_cells'`` (default; both
        end nodes off the perimeter, 12 edges for n = 5) or ``'interior'`` (every edge not on
        the perimeter, 24 edges).
    layers, layer_height
        Printed layers (paper: 3) and their z spacing (mm).
    speed, radius, active_fraction, active_material, passive_material
        Printing parameters: v (mm/s), R (mm), active area fraction, material names.
    flip_length
        Arc length (mm, >= 0) of each π flip of the active side (0: a step).
    edge_speeds
        One print speed per lattice edge (mm/s, each > 0), in edge order; default ``speed``
        on every edge.

    Raises
    ------
    InvalidDesignError
        Any parameter out of range, an unknown pattern or mode.
    """
    if int(n) != n or n < 2:
        raise InvalidDesignError("n", f"must be an integer >= 2; got {n}")
    if int(ghost_nodes) != ghost_nodes or ghost_nodes < 1:
        raise InvalidDesignError("ghost_nodes", f"must be an integer >= 1; got {ghost_nodes}")
    if int(layers) != layers or layers < 1:
        raise InvalidDesignError("layers", f"must be an integer >= 1; got {layers}")
    for name, value, lo in (
        ("spacing", spacing, 0.0),
        ("layer_height", layer_height, 0.0),
        ("speed", speed, 0.0),
        ("radius", radius, 0.0),
    ):
        if not (np.isfinite(value) and value > lo):
            raise InvalidDesignError(name, f"must be > 0 (mm or mm/s); got {value}")
    if not (np.isfinite(flip_length) and flip_length >= 0):
        raise InvalidDesignError("flip_length", f"must be >= 0 mm; got {flip_length}")
    if not (np.isfinite(amplitude) and amplitude >= 0):
        raise InvalidDesignError("amplitude", f"must be >= 0 mm; got {amplitude}")
    n, ghost_nodes, layers = int(n), int(ghost_nodes), int(layers)
    edges = _edge_list(n)
    modes = _modes(pattern, n, edges, centre)
    speeds = None if edge_speeds is None else _edge_speeds(edge_speeds, len(edges))
    ii, jj = np.divmod(np.arange(n * n), n)
    branch_xyz = np.column_stack([spacing * ii, spacing * jj, np.zeros(n * n)])
    s = np.arange(1, ghost_nodes + 1, dtype=float)
    per = ghost_nodes + 1
    # every edge at once (the same operations per element as one edge at a time)
    t = (branch_xyz[edges[:, 1]] - branch_xyz[edges[:, 0]]) / spacing
    nrm = np.cross(np.array([0.0, 0.0, 1.0]), t)  # N = z x T on every edge
    ghosts = (
        branch_xyz[edges[:, 0]][:, None, :]
        + (s * spacing / per)[None, :, None] * t[:, None, :]
        + (amplitude * np.sin(2 * np.pi * s / per))[None, :, None] * nrm[:, None, :]
    ).reshape(-1, 3)
    inner = n * n + np.arange(len(edges))[:, None] * ghost_nodes + np.arange(ghost_nodes)
    chain_table = np.column_stack([edges[:, 0], inner, edges[:, 1]])
    chain_table.setflags(write=False)
    chains = list(chain_table)
    segments = np.column_stack([chain_table[:, :-1].ravel(), chain_table[:, 1:].ravel()])
    nodes = np.concatenate([branch_xyz, ghosts])
    branch = np.zeros(len(nodes), dtype=bool)
    branch[: n * n] = True
    network = Network(nodes, segments, branch)
    edges.setflags(write=False)
    return Lattice(
        network,
        n,
        float(spacing),
        float(amplitude),
        ghost_nodes,
        edges,
        tuple(chains),
        modes,
        layers,
        float(layer_height),
        float(speed),
        float(radius),
        float(active_fraction),
        active_material,
        passive_material,
        float(flip_length),
        speeds,
    )

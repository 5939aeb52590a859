r"""Contact of a rod network with itself and with rigid obstacles, as one energy term.

:class:`Contact` holds the settings (a value); :class:`ContactPotential` binds them to a
network and evaluates, on node positions ``x`` (N, 3) in mm,

* the barrier energy (:mod:`rotomorph.contact.barrier`) of every segment pair allowed to touch
  (:mod:`rotomorph.contact.exclusion`) and of every segment near an obstacle, with its exact
  gradient and Hessian (COO triplets on the position coordinates ``3 i + k``);
* a step bound along a straight step, provably short of where the barrier is infinite
  (:mod:`rotomorph.contact.ccd`);
* contact forces, the clearance ``d / (r_a + r_b)`` and the number of active contacts.

The barrier acts in a zone of depth ``d̂`` (the activation distance) that ends where the
surfaces touch, ``d = r_a + r_b``: it is zero while they are apart and infinite at
``r_a + r_b - offset`` (``offset = d̂`` by default), so a pressed contact settles a fraction of
``d̂`` inside touching and the filaments behave as thick as printed.

Obstacle geometry enters as fixed extra points: a sphere is a zero-length segment at its centre
with contact distance ``r + R``; a cylinder is its axis segment with ``r + R``; a floor is a
plane touched at the nodes (a segment's lowest point above a plane is one of its ends, so that
is exact).
"""

from __future__ import annotations

import weakref
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from rotomorph._typing import FloatArray, IntArray
from rotomorph.contact.barrier import barrier, pair_barrier, plane_barrier
from rotomorph.contact.broadphase import near_pairs, near_subset, within_reach
from rotomorph.contact.ccd import pair_step_bound, plane_step_bound
from rotomorph.contact.distance import (
    box_excess,
    box_growth,
    closest_parameters,
    node_motions,
    pair_distances,
)
from rotomorph.contact.exclusion import excluded_pairs
from rotomorph.contact.friction import FrictionLag, friction_energy
from rotomorph.contact.obstacles import Cylinder, Floor, Obstacle, Sphere
from rotomorph.contact.stack import Stack
from rotomorph.design.network import Network
from rotomorph.errors import InvalidParameterError

__all__ = ["Contact", "ContactPotential", "HessianBlocks", "InfeasibleContactError"]

#: barrier force of a pair at half the activation distance, in units of the reference force
ACTIVATION_FORCE = 1.0
#: conservative-advancement sub-steps per pair before a step counts as not provably free
#: (a pair sliding a distance L at gap g needs about L / (0.9 g) of them)
MAX_SUBSTEPS = 100_000
#: IPC's edge-edge mollifier threshold relative to ``|a|^2 |b|^2`` (sin² of about 1.8 degrees)
MOLLIFIER = 1e-3
#: default activation distance relative to the smallest contact distance: the depth of the zone,
#: ending where the surfaces touch, in which the barrier acts (chosen by measurement,
#: docs/contact.md: a contact carrying the reference force settles half of it inside touching)
DEFAULT_ACTIVATION = 0.01
#: margin of the reused candidate set (Verlet list) relative to the smallest contact distance
PAD = 1.0
#: how far (per coordinate, relative to the activation distance) a path's end may leave the
#: boxes swept by the last step bound for its candidates to be reused (``path_is_free``)
SWEPT_SLACK = 0.25


_NO_INT = np.zeros(0, dtype=np.int64)
_NO_PAIRS = np.zeros((0, 2), dtype=np.int64)
_NO_POINTS = np.zeros((0, 3))  # a gradient argument that is not written
_NO_BLOCKS = np.zeros((0, 3, 3))  # Hessian blocks that are not written


class InfeasibleContactError(InvalidParameterError):
    """A configuration handed to the contact model already interpenetrates."""


@dataclass(frozen=True)
class Contact:
    """Contact settings of a filament network.

    Parameters
    ----------
    radius
        Filament radius (mm): scalar or one value per segment. Two segments touch when their
        centre lines are ``r_a + r_b`` apart.
    obstacles
        Rigid :class:`~rotomorph.contact.obstacles.Floor`, ``Sphere`` and ``Cylinder`` objects.
    self_contact
        Whether segments of the network touch each other (default True).
    activation_distance
        Depth ``d̂`` of the zone in which the barrier acts (mm); default 3 % of the smallest
        contact distance. The zone ends where the surfaces touch (``d = r_a + r_b``) and the
        barrier is infinite ``offset`` below where it ends, at ``r_a + r_b + d̂ - offset``.
    offset
        How far inside ``r_a + r_b`` the barrier is infinite (mm, ``0 <= offset <
        min(radius)``); default the activation distance: the barrier acts from the moment the
        surfaces touch, a pressed contact settles at ``r_a + r_b`` less a fraction of ``d̂``
        (none before touching) and no pair comes closer than ``r_a + r_b - d̂``. With 0
        the surfaces never overlap, and a pressed contact settles up to ``d̂`` apart (the
        filaments behave thicker by up to ``d̂``).
    stiffness
        Barrier stiffness κ (N/mm⁵); default: chosen by the solver from the problem's force
        scale so that a pair at half the activation distance carries a typical nodal force.
    stiffness_scale
        Multiplier of that default stiffness (dimensionless, > 0; default 1); ignored when
        ``stiffness`` is given.
    reach
        Graph distance (mm) below which segments count as neighbours and never touch; default
        ``π max(r_a + r_b) / 2`` (:mod:`rotomorph.contact.exclusion`).
    friction
        Coulomb friction coefficient μ (dimensionless, ≥ 0) for every contact; default 0.
    slip
        Tangential displacement (mm) over which lagged friction ramps from sticking to sliding
        (IPC's ε_v for a quasi-static step); default 1e-3 of the smallest contact distance.
    friction_lag
        The lagged friction of a solve (:meth:`ContactPotential.lag`): its normal forces,
        closest points and tangent bases, and the start its slips are measured from. Default
        None: lagged at the solve's initial state, which is also the start. A heating ramp
        passes the lag re-evaluated at the last solution, with the step's start kept, until
        it no longer changes (:func:`rotomorph.lattice.heating.heat_lattice`).
    stack
        The shape each segment presents: one capsule of ``radius`` on the centre line
        (default), or a printed stack of layers of that radius offset along the segment's
        material director (:class:`~rotomorph.contact.stack.Stack`; bound by
        :class:`~rotomorph.contact.stacked.StackedContact`).
    """

    radius: float | Sequence[float] | FloatArray
    obstacles: tuple[Obstacle, ...] = ()
    self_contact: bool = True
    activation_distance: float | None = None
    stiffness: float | None = None
    offset: float | None = None
    stiffness_scale: float = 1.0
    reach: float | None = None
    friction: float = 0.0
    slip: float | None = None
    friction_lag: FrictionLag | None = field(default=None, repr=False, compare=False)
    stack: Stack = field(default_factory=Stack)
    _radius: FloatArray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        r = np.array(self.radius, dtype=float).reshape(-1)
        if r.size == 0 or not np.all(np.isfinite(r)) or np.any(r <= 0):
            raise InvalidParameterError("Contact.radius", "must be finite and > 0 mm")
        object.__setattr__(self, "_radius", r)
        obs = tuple(self.obstacles)
        for k, o in enumerate(obs):
            if not isinstance(o, (Floor, Sphere, Cylinder)):
                raise InvalidParameterError(
                    f"Contact.obstacles[{k}]", f"must be a Floor, Sphere or Cylinder; got {o!r}"
                )
        object.__setattr__(self, "obstacles", obs)
        for name in ("activation_distance", "stiffness", "reach", "slip"):
            v = getattr(self, name)
            if v is not None and not (np.isfinite(v) and v > 0):
                raise InvalidParameterError(f"Contact.{name}", f"must be > 0 or None; got {v}")
        if self.offset is not None and not (
            np.isfinite(self.offset) and 0 <= self.offset < float(r.min())
        ):
            raise InvalidParameterError(
                "Contact.offset",
                f"must be >= 0 mm and below the smallest radius {float(r.min()):.4g} mm "
                f"(None: the activation distance); got {self.offset}",
            )
        if not (np.isfinite(self.stiffness_scale) and self.stiffness_scale > 0):
            raise InvalidParameterError(
                "Contact.stiffness_scale",
                f"must be > 0 (1: the default stiffness); got {self.stiffness_scale}",
            )
        if not (np.isfinite(self.friction) and self.friction >= 0):
            raise InvalidParameterError(
                "Contact.friction", f"must be >= 0 (0: frictionless); got {self.friction}"
            )
        if self.friction_lag is not None and not (
            isinstance(self.friction_lag, FrictionLag)
            and self.friction > 0
            and self.friction_lag.coefficient == self.friction
        ):
            raise InvalidParameterError(
                "Contact.friction_lag",
                "must be a FrictionLag of these settings (ContactPotential.lag) and needs "
                "friction > 0; None lags at the initial state",
            )
        if not isinstance(self.stack, Stack):
            raise InvalidParameterError(
                "Contact.stack", f"must be a rotomorph.contact.stack.Stack; got {self.stack!r}"
            )

    def radii(self, n_edges: int) -> FloatArray:
        """Radius per segment ``(E,)`` (mm)."""
        r = self._radius
        if r.size == 1:
            return np.full(n_edges, float(r[0]))
        if r.size != n_edges:
            raise InvalidParameterError(
                "Contact.radius", f"needs a scalar or {n_edges} values (one per segment)"
            )
        return r.copy()

    @property
    def floor(self) -> Floor | None:
        """The first floor among the obstacles, if any."""
        return next((o for o in self.obstacles if isinstance(o, Floor)), None)

    def with_obstacles(self, obstacles: Sequence[Obstacle]) -> Contact:
        """The same settings with other obstacles (e.g. moved ones)."""
        from dataclasses import replace

        return replace(self, obstacles=tuple(obstacles))


@dataclass(frozen=True, eq=False)
class _Candidates:
    """Pairs near contact at one configuration (indices into the extended point array)."""

    quads: IntArray  # (P, 4) p0 p1 q0 q1 (p0 = p1: a node against a segment)
    dmin: FloatArray  # where the barrier is infinite: the contact distance less the offset
    weight: FloatArray
    mollify: FloatArray  # edge-edge mollifier threshold (0: none)
    floors: tuple[tuple[IntArray, FloatArray, FloatArray], ...]  # per floor: nodes, dmin, weight

    @property
    def floor_nodes(self) -> IntArray:
        return np.concatenate([f[0] for f in self.floors]) if self.floors else _NO_INT

    @property
    def floor_dmin(self) -> FloatArray:
        return np.concatenate([f[1] for f in self.floors]) if self.floors else np.zeros(0)


@dataclass(frozen=True, eq=False)
class _NearSet:
    """The network's own pairs found by a broad phase at ``x`` with margin ``pad``, kept for
    reuse (a Verlet list)."""

    x: FloatArray  # (N, 3) positions they were found at
    pad: float  # margin (mm)
    pairs: tuple[IntArray, IntArray]  # segment pairs and node–segment pairs

    def covers(self, x0: FloatArray, x1: FloatArray) -> bool:
        """Whether :attr:`pairs` holds every pair that a broad phase without margin proposes
        on the straight step ``x0 -> x1``.

        Every coordinate of ``x0`` and ``x1`` lies within ``δ_k`` (per axis ``k``) of its
        node's coordinate in :attr:`x`, so each box over the step lies within the box at
        :attr:`x` grown by ``δ`` per axis and the Euclidean gap of two such boxes is at least
        the gap at :attr:`x` less ``2 |δ|``. With ``2 |δ|`` below the pad, a pair the step's
        broad phase proposes (gap below the sum of its shares) was proposed at :attr:`x`
        (gap below the shares plus the pad); a relative slack of 1e-6 covers round-off.
        """
        if x0.shape != self.x.shape or len(x0) == 0:
            return False
        delta = box_growth(x0, x1, self.x)
        return bool(2.0 * float(np.sqrt(delta @ delta)) <= (1.0 - 1e-6) * self.pad)


@dataclass(frozen=True, eq=False)
class _Reuse:
    """The padded candidate set of :meth:`ContactPotential.candidates`, kept for reuse."""

    near: _NearSet
    cand: _Candidates
    dist: FloatArray  # centre-line distance of every candidate pair where found (mm)


@dataclass(frozen=True, eq=False)
class HessianBlocks:
    """The contact Hessian as local blocks on node coordinates ``3 i + k``.

    ``pair[p]`` (12 x 12) couples the nodes ``quads[p]`` (indices of the extended point array:
    those ``>= n_nodes`` are fixed obstacle points and carry no unknowns); ``node[q]`` (3 x 3)
    is the floor block of node ``nodes[q]``.
    """

    n_nodes: int
    quads: IntArray  # (P, 4)
    pair: FloatArray  # (P, 12, 12)
    nodes: IntArray  # (Q,)
    node: FloatArray  # (Q, 3, 3)

    def triplets(self) -> tuple[IntArray, IntArray, FloatArray]:
        """Rows, columns and values of the non-zero entries on the network's coordinates."""
        n3 = 3 * self.n_nodes
        dof = (self.quads[:, :, None] * 3 + np.arange(3)).reshape(-1, 12)
        rows = np.repeat(dof, 12, axis=1).ravel()
        cols = np.tile(dof, (1, 12)).ravel()
        vals = self.pair.reshape(-1)
        fdof = (self.nodes[:, None] * 3 + np.arange(3)).reshape(-1, 3)
        frows = np.repeat(fdof, 3, axis=1).ravel()
        fcols = np.tile(fdof, (1, 3)).ravel()
        rows = np.concatenate([rows, frows])
        cols = np.concatenate([cols, fcols])
        vals = np.concatenate([vals, self.node.reshape(-1)])
        keep = (rows < n3) & (cols < n3) & (vals != 0)
        return rows[keep], cols[keep], vals[keep]


class ContactPotential:
    """:class:`Contact` bound to a network: energy, derivatives and step bounds on positions.

    Parameters
    ----------
    contact
        The settings.
    network
        The printed network (its node positions decide the fused pairs).
    force_scale
        Typical nodal force (N) used for the default stiffness.
    excluded
        Sorted keys of the segment pairs that never touch; default
        :func:`~rotomorph.contact.exclusion.excluded_pairs` of the network (a network of layer
        capsules passes its stack's, :func:`~rotomorph.contact.stack.stack_exclusion`).
    broad_phase
        The broad phase of the network's own pairs, with the arguments and results of
        :func:`~rotomorph.contact.broadphase.near_pairs` (the default); a layer network passes
        :func:`~rotomorph.contact.broadphase.stack_near_pairs`, the same pairs found faster.
    """

    def __init__(
        self,
        contact: Contact,
        network: Network,
        force_scale: float = 1.0,
        excluded: IntArray | None = None,
        broad_phase: Callable[..., tuple[IntArray, IntArray]] | None = None,
    ) -> None:
        if not contact.stack.is_single:
            raise InvalidParameterError(
                "Contact.stack",
                "a stack of layers is bound by rotomorph.contact.stacked.StackedContact "
                "(it needs the segments' material frames)",
            )
        self.contact = contact
        self.network = network
        self._near = near_pairs if broad_phase is None else broad_phase
        edges = np.ascontiguousarray(network.edges, dtype=np.int64)
        self.edges = edges
        n, ne = network.n_nodes, network.n_edges
        self.n_nodes = n
        self.radius = contact.radii(ne)
        length = np.linalg.norm(network.nodes[edges[:, 1]] - network.nodes[edges[:, 0]], axis=1)
        self.length = length
        node_r = np.zeros(n)
        np.maximum.at(node_r, edges[:, 0], self.radius)
        np.maximum.at(node_r, edges[:, 1], self.radius)
        self.node_radius = node_r
        vor = np.zeros(n)
        np.add.at(vor, edges[:, 0], 0.5 * length)
        np.add.at(vor, edges[:, 1], 0.5 * length)
        self.node_length = vor
        dmin_small = 2.0 * float(self.radius.min())
        self.dhat = float(contact.activation_distance or DEFAULT_ACTIVATION * dmin_small)
        self.offset = self.dhat if contact.offset is None else float(contact.offset)
        if self.offset >= float(self.radius.min()):
            raise InvalidParameterError(
                "Contact.offset",
                f"the offset {self.offset:.4g} mm (default: the activation distance) must be "
                f"below the smallest radius {float(self.radius.min()):.4g} mm",
            )
        self.slip = float(contact.slip or 1e-3 * dmin_small)
        if excluded is not None:
            self.excluded = np.ascontiguousarray(excluded, dtype=np.int64)
        elif contact.self_contact:
            self.excluded = _excluded(network, edges, self.radius, self.dhat, contact.reach)
        else:
            self.excluded = np.zeros(0, dtype=np.int64)
        pts: list[tuple[float, float, float]] = []
        kinds: list[tuple[str, Sphere | Cylinder]] = []
        for o in contact.obstacles:
            if isinstance(o, Sphere):
                pts += [o.centre, o.centre]
                kinds.append(("sphere", o))
            elif isinstance(o, Cylinder):
                pts += [o.start, o.end]
                kinds.append(("cylinder", o))
        self._obstacle_points = np.array(pts, dtype=float).reshape(-1, 3)
        self._round = [o for _, o in kinds]
        self._floors = [o for o in contact.obstacles if isinstance(o, Floor)]
        self._floor_normals = [np.asarray(f.normal, dtype=float) for f in self._floors]
        if contact.stiffness is not None:
            self.kappa = float(contact.stiffness)
        else:
            # a pair at half the activation distance carries force_scale:
            # F = kappa w |b'(zhat/2)| 2 d with |b'(zhat/2)| = (1/2 + ln 2) zhat  (barrier
            # module), d the barrier's own contact distance
            w = float(np.median(length))
            wall = dmin_small - self.offset
            zhat = (2.0 * wall + self.dhat) * self.dhat
            self.kappa = contact.stiffness_scale * float(
                ACTIVATION_FORCE * force_scale / (w * (0.5 + np.log(2.0)) * zhat * 2 * wall)
            )
        self._max_length = float(length.max())
        self._dmin_max = 2.0 * float(self.radius.max())
        self._lag: FrictionLag | None = None
        # broad-phase cache: reference positions, padded margin, candidates found there
        self._cache: _Reuse | None = None
        # the last step bound's start, end and candidates (reused by path_is_free)
        # (with each candidate pair's distance at the start, NaN until a bound needs it)
        self._swept: tuple[FloatArray, FloatArray, _Candidates, FloatArray] | None = None
        # reuse a candidate set over node motions up to a radius (half the pad): measured on
        # the 5 x 5 heating ramps, a diameter saves a fifth to a third of the sweeps at the
        # cost of larger ones (docs/contact.md)
        self._pad = PAD * dmin_small
        deg = np.bincount(edges.ravel(), minlength=n)
        inc = -np.ones((n, max(int(deg.max()), 1)), dtype=np.int64)
        # each node's segments in the order they appear in ``edges`` (a stable sort by node)
        flat = edges.ravel()
        order = np.argsort(flat, kind="stable")
        at = flat[order]
        first = np.concatenate([[0], np.cumsum(deg)[:-1]])
        inc[at, np.arange(len(flat)) - first[at]] = order // 2
        self._incident = inc  # segments at each node, -1 padded

    # ------------------------------------------------------------------ friction
    def set_lag(self, x0: FloatArray) -> None:
        """Lag friction at ``x0`` (the previous equilibrium): normal forces, closest points
        and tangent bases of every contact carrying force are frozen for the next solve, and
        slips are measured from ``x0``; or the settings' own ``friction_lag``. Without
        friction (μ = 0) this does nothing."""
        if self.contact.friction == 0:
            self._lag = None
        elif self.contact.friction_lag is not None:
            lag = self.contact.friction_lag
            if lag.start.shape != (self.n_nodes + len(self._obstacle_points), 3):
                raise InvalidParameterError(
                    "Contact.friction_lag", "was lagged on another network or other obstacles"
                )
            self._lag = lag
        else:
            self._lag = self.lag(x0)

    @property
    def friction_lag(self) -> FrictionLag | None:
        """The lagged friction of the current solve (None without friction)."""
        return self._lag

    def lag(self, x0: FloatArray, at: FloatArray | None = None) -> FrictionLag:
        """The :class:`~rotomorph.contact.friction.FrictionLag` of configuration ``at``
        (default ``x0``) with slips measured from ``x0``: the contacts carrying force at
        ``at``, their normal forces, closest points and tangent bases there (IPC's lagged
        quantities, re-evaluated at the last solution of a step while its start is kept)."""
        x0 = np.ascontiguousarray(x0, dtype=float)
        start = self._extended(x0).copy()  # kept by the lag
        if at is not None:
            x0 = np.ascontiguousarray(at, dtype=float)
        cand = self.candidates(x0)
        xe = self._extended(x0)
        near = np.flatnonzero(pair_distances(xe, cand.quads) < cand.dmin + self.dhat)
        quads = cand.quads[near]
        st = np.array([closest_parameters(xe[i], xe[j], xe[k], xe[m]) for i, j, k, m in quads])
        st = st.reshape(-1, 2)
        w = np.stack([1.0 - st[:, 0], st[:, 0], -(1.0 - st[:, 1]), -st[:, 1]], axis=1)
        r = np.einsum("pn,pnk->pk", w, xe[quads])
        d = np.linalg.norm(r, axis=1)
        lam = self._normal_forces(d, cand.dmin[near], cand.weight[near])
        on = lam > 0
        nodes, weights, force = [quads[on]], [w[on]], [lam[on]]
        normals = [r[on] / d[on, None]]
        for f, (fn, fd, fw) in zip(self._floors, cand.floors, strict=True):
            lam = self._normal_forces(f.height_of(x0[fn]), fd, fw)
            on = lam > 0
            nodes.append(np.repeat(fn[on, None], 4, axis=1))
            weights.append(np.tile([1.0, 0.0, 0.0, 0.0], (int(on.sum()), 1)))
            force.append(lam[on])
            normals.append(np.tile(np.asarray(f.normal, dtype=float), (int(on.sum()), 1)))
        bases = _plane_bases(np.concatenate(normals))
        return FrictionLag(
            nodes=np.ascontiguousarray(np.concatenate(nodes), dtype=np.int64).reshape(-1, 4),
            weights=np.concatenate(weights).reshape(-1, 4),
            bases=bases,
            normal_force=np.concatenate(force),
            start=start,
            coefficient=float(self.contact.friction),
            slip=self.slip,
        )

    def _normal_forces(self, d: FloatArray, dmin: FloatArray, weight: FloatArray) -> FloatArray:
        """Barrier force magnitudes ``kappa w |b'(z)| 2 d`` of pairs at distances ``d`` (N)."""
        zhat = (2.0 * dmin + self.dhat) * self.dhat
        z = d * d - dmin * dmin
        slope = np.array([barrier(zk, hk)[1] for zk, hk in zip(z, zhat, strict=True)])
        return np.asarray(self.kappa * weight * -slope.reshape(-1) * 2.0 * d)

    # ------------------------------------------------------------------ candidates
    def _extended(self, x: FloatArray) -> FloatArray:
        """Nodes and obstacle points ``(N + O, 3)`` (read only: ``x`` itself when ``O = 0``)."""
        if not len(self._obstacle_points):
            return np.ascontiguousarray(x, dtype=float)
        return np.ascontiguousarray(np.vstack([x, self._obstacle_points]), dtype=float)

    def candidates(self, x: FloatArray, margin: float = 0.0) -> _Candidates:
        """Pairs and floor nodes whose distance may be below contact + activation + ``margin``.

        The set found at one configuration with a padded margin is reused while no node has
        moved more than half the pad since (a pair's distance changes by at most the sum of its
        two largest node motions), so the line-search trials and the accepted iterate of a
        Newton step share one broad phase.
        """
        return self._reused(x, margin)[0].cand

    def _reused(self, x: FloatArray, margin: float = 0.0) -> tuple[_Reuse, FloatArray | None]:
        """The reused candidate set of :meth:`candidates` and each point's motion since it was
        found (mm, ``(N + O,)``, 0 for obstacle points; None when found here)."""
        cache = self._cache
        if cache is not None and cache.near.x.shape == x.shape:
            moved = np.empty(len(x) + len(self._obstacle_points))
            move = float(node_motions(x, cache.near.x, moved))
            if 2.0 * move + margin <= cache.near.pad:
                return cache, moved
        pad = max(float(margin), self._pad)
        near = _NearSet(x.copy(), pad, self._self_pairs(x, x, pad))
        cand = self._build_candidates(x, pad, own=near.pairs)
        dist = pair_distances(self._extended(x), cand.quads)
        self._cache = _Reuse(near=near, cand=cand, dist=dist)
        return self._cache, None

    def _self_pairs(
        self, x0: FloatArray, x1: FloatArray, margin: float
    ) -> tuple[IntArray, IntArray]:
        """The broad phase's segment pairs and node–segment pairs on ``x0 -> x1`` within
        contact + activation + ``margin`` (none without self-contact)."""
        if not (self.contact.self_contact and len(self.edges) > 1):
            return _NO_PAIRS, _NO_PAIRS
        extra = 0.5 * (self.dhat + margin)
        return self._near(
            x0, x1, self.edges, self._incident, self.radius + extra, self.node_radius + extra,
            self.excluded,
        )  # fmt: skip

    def _swept_pairs(self, x: FloatArray, dx: FloatArray) -> tuple[IntArray, IntArray]:
        """:meth:`_self_pairs` along the step ``x -> x + dx`` without margin: picked out of the
        reused candidate set by the same box tests when that set covers the step
        (:meth:`_NearSet.covers`; the same pairs as a fresh broad phase), else a fresh one."""
        x1 = x + dx
        cache = self._cache
        if (
            cache is not None
            and self.contact.self_contact
            and len(self.edges) > 1
            and cache.near.covers(x, x1)
        ):
            extra = 0.5 * self.dhat
            return near_subset(
                x, x1, self.edges, self.radius + extra, self.node_radius + extra, cache.near.pairs
            )
        return self._self_pairs(x, x1, 0.0)

    def _build_candidates(
        self,
        x: FloatArray,
        margin: float,
        step: FloatArray | None = None,
        own: tuple[IntArray, IntArray] | None = None,
    ) -> _Candidates:
        """Candidates at ``x`` within ``margin``; with ``step``, along the straight path
        ``x -> x + step`` (swept boxes for the network's own pairs, the step's largest node
        motion added to ``margin`` for obstacles). ``own``: the network's own pairs as
        :meth:`_self_pairs` finds them for these arguments (default: found here)."""
        edges = self.edges
        quads: list[IntArray] = []
        dmins: list[FloatArray] = []
        weights: list[FloatArray] = []
        molls: list[FloatArray] = []

        def add(q: IntArray, d: FloatArray, w: FloatArray, m: FloatArray) -> None:
            quads.append(q)
            dmins.append(d)
            weights.append(w)
            molls.append(m)

        if own is None:
            own = self._self_pairs(x, x if step is None else x + step, margin)
        pairs, ns = own
        if len(pairs):
            k, j = pairs[:, 0], pairs[:, 1]
            L = self.length
            add(
                np.concatenate([edges[k], edges[j]], axis=1),
                self.radius[k] + self.radius[j] - self.offset,
                0.5 * (L[k] + L[j]),
                MOLLIFIER * (L[k] * L[j]) ** 2,
            )
        if len(ns):  # nodes against segments: they carry side-by-side (parallel) contact
            node, seg = ns[:, 0], ns[:, 1]
            add(
                np.stack([node, node, edges[seg, 0], edges[seg, 1]], axis=1),
                self.node_radius[node] + self.radius[seg] - self.offset,
                self.node_length[node],
                np.zeros(len(node)),
            )
        if step is not None and len(step):
            margin += _largest_norm(step)
        if self._round:
            mid = 0.5 * (x[edges[:, 0]] + x[edges[:, 1]])
        half = 0.5 * self._max_length
        n = self.n_nodes
        for io, o in enumerate(self._round):
            a = np.asarray(o.start if isinstance(o, Cylinder) else o.centre)
            b = np.asarray(o.end if isinstance(o, Cylinder) else o.centre)
            dist = _point_segment_distance(mid, a, b)
            near = np.flatnonzero(dist <= self.radius + o.radius + self.dhat + half + margin)
            q = np.array([n + 2 * io, n + 2 * io + 1])
            axis2 = float(np.sum((b - a) ** 2))
            add(
                np.concatenate([edges[near], np.tile(q, (len(near), 1))], axis=1),
                self.radius[near] + o.radius - self.offset,
                self.length[near],
                MOLLIFIER * self.length[near] ** 2 * axis2,
            )
            if isinstance(o, Cylinder):  # nodes against the axis (a filament along the rod)
                nodes = np.unique(edges[near])
                add(
                    np.stack(
                        [nodes, nodes, np.full(len(nodes), q[0]), np.full(len(nodes), q[1])], 1
                    ),
                    self.node_radius[nodes] + o.radius - self.offset,
                    self.node_length[nodes],
                    np.zeros(len(nodes)),
                )
        floors = []
        for f in self._floors:
            h = f.height_of(x)
            near = np.flatnonzero(h <= self.node_radius + self.dhat + margin)
            floors.append(
                (
                    np.ascontiguousarray(near, dtype=np.int64),
                    np.ascontiguousarray(self.node_radius[near] - self.offset),
                    np.ascontiguousarray(self.node_length[near]),
                )
            )
        cat = np.concatenate
        return _Candidates(
            quads=np.ascontiguousarray(cat(quads) if quads else np.zeros((0, 4)), dtype=np.int64),
            dmin=np.ascontiguousarray(cat(dmins) if dmins else np.zeros(0)),
            weight=np.ascontiguousarray(cat(weights) if weights else np.zeros(0)),
            mollify=np.ascontiguousarray(cat(molls) if molls else np.zeros(0)),
            floors=tuple(floors),
        )

    # ------------------------------------------------------------------ energy
    def evaluate(
        self, x: FloatArray, need_grad: bool, need_hess: int
    ) -> tuple[float, FloatArray | None, tuple[IntArray, IntArray, FloatArray] | None]:
        """Energy (N mm), gradient ``(N, 3)`` (N) and Hessian triplets on coordinates ``3i+k``.

        ``need_hess``: 0 none, 1 exact, 2 projected to positive semidefinite per pair. The energy
        is inf (and no derivatives are returned) when anything touches or interpenetrates.
        """
        energy, g, blocks = self.evaluate_blocks(x, need_grad, need_hess)
        return energy, g, None if blocks is None else blocks.triplets()

    def evaluate_blocks(
        self, x: FloatArray, need_grad: bool, need_hess: int
    ) -> tuple[float, FloatArray | None, HessianBlocks | None]:
        """:meth:`evaluate` with the Hessian as its local blocks (:class:`HessianBlocks`)."""
        x = np.ascontiguousarray(x, dtype=float)
        reuse, move = self._reused(x)
        cand = reuse.cand
        xe = self._extended(x)
        grad = np.zeros_like(xe) if need_grad else _NO_POINTS  # (written only with need_grad)
        # the pairs that may be within reach: their distance where the candidates were found
        # less their nodes' motions since (the others carry no energy)
        if move is None:
            move = np.zeros(len(xe))
        near = within_reach(cand.quads, reuse.dist, move, cand.dmin + self.dhat)
        quads, dmin = cand.quads[near], cand.dmin[near]
        weight, mollify = cand.weight[near], cand.mollify[near]
        dist = np.empty(len(near))
        energy = pair_barrier(
            xe, quads, dmin, weight, mollify, self.dhat, self.kappa, need_grad, 0, grad,
            np.empty((0, 12, 12)), dist,
        )  # fmt: skip
        if not np.isfinite(energy):
            return np.inf, None, None
        if need_hess:  # Hessian blocks of the active pairs only (the candidate set is padded)
            active = np.flatnonzero(dist < dmin + self.dhat)
            quads = np.ascontiguousarray(quads[active])
            hloc = np.zeros((len(active), 12, 12))
            if len(active):
                pair_barrier(
                    xe, quads, dmin[active], weight[active], mollify[active], self.dhat,
                    self.kappa, False, int(need_hess), grad, hloc, np.empty(len(active)),
                )  # fmt: skip
        blocks = []
        for normal, f, (nodes, dmin, weight) in zip(
            self._floor_normals, self._floors, cand.floors, strict=True
        ):
            blk = np.zeros((len(nodes), 3, 3)) if need_hess else _NO_BLOCKS
            e = plane_barrier(
                xe, nodes, normal, f.height, dmin, weight, self.dhat, self.kappa, need_grad,
                int(need_hess), grad, blk, np.empty(len(nodes)),
            )  # fmt: skip
            if not np.isfinite(e):
                return np.inf, None, None
            energy += e
            blocks.append(blk)
        if self._lag is not None:
            ef, gf, hf = friction_energy(self._lag, xe, need_grad, bool(need_hess))
            energy += ef
            if gf is not None:
                grad += gf
            if need_hess and hf is not None and len(self._lag.nodes):
                quads = np.concatenate([quads, self._lag.nodes])
                hloc = np.concatenate([hloc, hf])
        g = grad[: self.n_nodes] if need_grad else None
        hess = None
        if need_hess:
            hess = HessianBlocks(
                n_nodes=self.n_nodes,
                quads=np.ascontiguousarray(quads, dtype=np.int64),
                pair=np.ascontiguousarray(hloc),
                nodes=np.ascontiguousarray(cand.floor_nodes, dtype=np.int64),
                node=np.ascontiguousarray(
                    np.concatenate(blocks) if blocks else np.zeros((0, 3, 3))
                ),
            )
        return float(energy), g, hess

    # ------------------------------------------------------------------ step bounds
    def step_bound(self, x: FloatArray, dx: FloatArray, close_fraction: float = 0.9) -> float:
        """Largest fraction ``t`` of the straight step ``x -> x + dx`` that is provably free of
        contact, stopping where a pair has closed ``close_fraction`` of its gap."""
        x = np.ascontiguousarray(x, dtype=float)
        dx = np.ascontiguousarray(dx, dtype=float)
        disp = _largest_norm(dx)
        if disp == 0.0:
            return 1.0
        cand = self._build_candidates(x, 0.0, step=dx, own=self._swept_pairs(x, dx))
        dist0 = np.full(len(cand.quads), np.nan)
        self._swept = (x.copy(), x + dx, cand, dist0)
        return self._bound_on(x, dx, cand, close_fraction, dist0)

    def _bound_on(
        self,
        x: FloatArray,
        dx: FloatArray,
        cand: _Candidates,
        close_fraction: float,
        dist0: FloatArray,
    ) -> float:
        """:meth:`step_bound` over the candidate pairs ``cand`` of the step; ``dist0``: their
        distances at ``x`` where known (NaN: not yet; filled as needed)."""
        xe = self._extended(x)
        if len(xe) == len(dx):  # no obstacle points
            dxe = np.ascontiguousarray(dx, dtype=float)
        else:
            dxe = np.zeros_like(xe)
            dxe[: self.n_nodes] = dx
        t = pair_step_bound(xe, dxe, cand.quads, cand.dmin, close_fraction, MAX_SUBSTEPS, dist0)
        for normal, f, (nodes, dmin, _) in zip(
            self._floor_normals, self._floors, cand.floors, strict=True
        ):
            bound = plane_step_bound(xe, dxe, nodes, normal, f.height, dmin, close_fraction)
            t = min(t, bound)
        return float(t)

    def path_is_free(self, x0: FloatArray, x1: FloatArray) -> bool:
        """Whether the straight path ``x0 -> x1`` provably never touches.

        A line-search trial ends near the step its step bound swept from the same start. If
        every node of ``x1`` lies within ``SWEPT_SLACK`` activation distances (per coordinate)
        of the box its node swept there, that step's candidates are reused: they hold every
        pair whose swept boxes came within contact plus the activation distance, and the new
        boxes lie within ``2 sqrt(3) SWEPT_SLACK < 1`` activation distances of the old ones,
        so no pair left out can touch along ``x0 -> x1`` (obstacles: the step's largest motion
        grows by less than the activation distance).
        """
        x0 = np.ascontiguousarray(x0, dtype=float)
        x1 = np.ascontiguousarray(x1, dtype=float)
        swept = self._swept
        if swept is not None and swept[0].shape == x0.shape and np.array_equal(swept[0], x0):
            start, end, cand, dist0 = swept
            if len(x1) == 0 or float(box_excess(start, end, x1)) <= SWEPT_SLACK * self.dhat:
                return self._bound_on(x0, x1 - x0, cand, 1.0, dist0) >= 1.0
        return self.step_bound(x0, x1 - x0, close_fraction=1.0) >= 1.0

    # ------------------------------------------------------------------ measures
    def forces(self, x: FloatArray) -> FloatArray:
        """Contact force on every node ``(N, 3)`` (N): minus the barrier gradient. The
        measures take node positions or a rod ``State`` (as a stacked contact does)."""
        x = _positions(x)
        _, g, _ = self.evaluate(x, True, 0)
        if g is None:
            raise InfeasibleContactError("positions", "filaments touch or interpenetrate")
        return -g

    def obstacle_forces(self, x: FloatArray) -> list[FloatArray]:
        """Resultant contact force on each obstacle ``(3,)`` (N), in ``contact.obstacles`` order
        (e.g. the force a gripper's lattice exerts on each rod). Friction is not included."""
        x = np.ascontiguousarray(_positions(x), dtype=float)
        cand = self.candidates(x)
        xe = self._extended(x)
        n = self.n_nodes
        out: list[FloatArray] = []
        round_k = floor_k = 0
        for o in self.contact.obstacles:
            grad = np.zeros_like(xe)
            if isinstance(o, Floor):
                nodes, dmin, weight = cand.floors[floor_k]
                floor_k += 1
                e = plane_barrier(
                    xe, nodes, np.asarray(o.normal), o.height, dmin, weight, self.dhat,
                    self.kappa, True, 0, grad, np.zeros((0, 3, 3)), np.empty(len(nodes)),
                )  # fmt: skip
                force = grad[:n].sum(axis=0)  # minus the force the floor exerts on the nodes
            else:
                q = n + 2 * round_k
                round_k += 1
                mine = np.flatnonzero(cand.quads[:, 2] == q)
                e = pair_barrier(
                    xe, np.ascontiguousarray(cand.quads[mine]), cand.dmin[mine],
                    cand.weight[mine], cand.mollify[mine], self.dhat, self.kappa, True, 0,
                    grad, np.zeros((0, 12, 12)), np.empty(len(mine)),
                )  # fmt: skip
                force = -(grad[q] + grad[q + 1])
            if not np.isfinite(e):
                raise InfeasibleContactError("positions", "a filament touches an obstacle")
            out.append(force)
        return out

    def distances(self, x: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Centre-line distances of the candidate pairs near contact and their contact
        distances ``r_a + r_b`` (mm); floors as node heights and radii."""
        d, wall = self._distances(x)
        return d, wall + self.offset

    def _distances(self, x: FloatArray) -> tuple[FloatArray, FloatArray]:
        """:meth:`distances` with the distances at which the barrier is infinite."""
        x = np.ascontiguousarray(_positions(x), dtype=float)
        cand = self.candidates(x, margin=self._dmin_max)
        d = pair_distances(self._extended(x), cand.quads)
        heights = [f.height_of(x[g[0]]) for f, g in zip(self._floors, cand.floors, strict=True)]
        dist = np.concatenate([d, *heights]) if heights else d
        return dist, np.concatenate([cand.dmin, cand.floor_dmin])

    def clearance(self, x: FloatArray) -> float:
        """Smallest ``d / (r_a + r_b)`` over allowed pairs and obstacles (2.0 when none is near;
        below 1 by less than ``offset / (r_a + r_b)`` for a pressed contact)."""
        d, dmin = self.distances(x)
        return float(min(2.0, (d / dmin).min())) if len(d) else 2.0

    def contact_ratios(self, x: FloatArray) -> FloatArray:
        """``d / (r_a + r_b)`` of every pair (and floor node: height over radius) carrying
        contact force, i.e. inside the barrier's zone: how far pressed contacts are from just
        touching (1; with the default offset in ``(1 - offset / (r_a + r_b), 1)``)."""
        d, wall = self._distances(x)
        on = d < wall + self.dhat
        return np.asarray(d[on] / (wall[on] + self.offset))

    def active_contacts(self, x: FloatArray) -> int:
        """Pairs (and floor nodes) inside the activation distance (carrying force)."""
        d, wall = self._distances(x)
        return int(np.count_nonzero(d < wall + self.dhat))

    def check_admissible(self, x: FloatArray, field: str = "initial") -> None:
        """Raise :class:`InfeasibleContactError` if ``x`` reaches where the barrier is infinite
        (``r_a + r_b - offset``; a pressed contact of an earlier equilibrium lies above it)."""
        d, dmin = self._distances(x)
        bad = np.flatnonzero(d <= dmin)
        if len(bad):
            k = int(bad[np.argmin((d / dmin)[bad])])
            raise InfeasibleContactError(
                field,
                f"{len(bad)} contact pair(s) already interpenetrate (closest at {d[k]:.4g} mm, "
                f"not above {dmin[k]:.4g} mm = r_a + r_b - Contact.offset); start from a "
                "separated configuration, move the obstacles away, or widen Contact.reach",
            )


#: excluded pairs per network (a frozen value) and contact settings: the solves of a heating
#: ramp bind the same network once per step
_EXCLUDED: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _excluded(
    network: Network, edges: IntArray, radius: FloatArray, dhat: float, reach: float | None
) -> IntArray:
    """:func:`~rotomorph.contact.exclusion.excluded_pairs` of ``network``, remembered per
    network and settings (shared: never written to)."""
    per = _EXCLUDED.setdefault(network, {})
    key = (radius.tobytes(), float(dhat), reach)
    if key not in per:
        per[key] = excluded_pairs(network.nodes, edges, radius, dhat, reach)
    return per[key]  # type: ignore[no-any-return]


def _plane_bases(normals: FloatArray) -> FloatArray:
    """:func:`rotomorph.geometry.plane_basis` of each unit normal ``(K, 3) -> (K, 3, 2)``, with
    the same choice of first axis."""
    n = np.asarray(normals, dtype=float).reshape(-1, 3)
    a = np.cross(n, [1.0, 0.0, 0.0])
    flat = np.linalg.norm(a, axis=1) < 0.5
    a[flat] = np.cross(n[flat], [0.0, 1.0, 0.0])
    a /= np.linalg.norm(a, axis=1, keepdims=True)
    return np.stack([a, np.cross(n, a)], axis=2)


def _positions(x: FloatArray) -> FloatArray:
    """Node positions of ``x``: positions themselves, or a rod ``State``'s."""
    return np.asarray(getattr(x, "positions", x), dtype=float)


def _largest_norm(v: FloatArray) -> float:
    """Largest row norm of ``v`` (N, 3) (mm; 0 when empty), NumPy's sums and square roots
    (the largest root is the root of the largest sum), compiled."""
    return float(node_motions(v, np.zeros_like(v), np.empty(len(v))))


def _point_segment_distance(p: FloatArray, a: FloatArray, b: FloatArray) -> FloatArray:
    ab = b - a
    L2 = float(ab @ ab)
    t = np.zeros(len(p)) if L2 == 0 else np.clip((p - a) @ ab / L2, 0.0, 1.0)
    return np.linalg.norm(p - (a + t[:, None] * ab), axis=1)

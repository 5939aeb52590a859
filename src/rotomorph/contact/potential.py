r"""Contact of a rod network with itself and with rigid obstacles, as one energy term.

:class:`Contact` holds the settings (a value); :class:`ContactPotential` binds them to a
network and evaluates, on node positions ``x`` (N, 3) in mm,

* the barrier energy (:mod:`rotomorph.contact.barrier`) of every segment pair allowed to touch
  (:mod:`rotomorph.contact.exclusion`) and of every segment near an obstacle, with its exact
  gradient and Hessian (COO triplets on the position coordinates ``3 i + k``);
* a provably collision-free step bound along a straight step (:mod:`rotomorph.contact.ccd`);
* contact forces, the clearance ``d / (r_a + r_b)`` and the number of active contacts.

Obstacle geometry enters as fixed extra points: a sphere is a zero-length segment at its centre
with contact distance ``r + R``; a cylinder is its axis segment with ``r + R``; a floor is a
plane touched at the nodes (a segment's lowest point above a plane is one of its ends, so that
is exact).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from scipy.spatial import cKDTree

from rotomorph._typing import FloatArray, IntArray
from rotomorph.contact.barrier import pair_barrier, plane_barrier
from rotomorph.contact.ccd import pair_step_bound, plane_step_bound
from rotomorph.contact.distance import pair_distances
from rotomorph.contact.exclusion import excluded_pairs
from rotomorph.contact.obstacles import Cylinder, Floor, Obstacle, Sphere
from rotomorph.design.network import Network
from rotomorph.errors import InvalidParameterError

__all__ = ["Contact", "ContactPotential", "InfeasibleContactError"]

#: barrier force of a pair at half the activation distance, in units of the reference force
ACTIVATION_FORCE = 1.0
#: default activation distance relative to the smallest contact distance
DEFAULT_ACTIVATION = 0.01


_NO_INT = np.zeros(0, dtype=np.int64)


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
        Gap ``d - (r_a + r_b)`` below which the barrier acts (mm); default 1 % of the smallest
        contact distance. Equilibrium gaps lie in ``(0, activation_distance)``.
    stiffness
        Barrier stiffness κ (N/mm⁵); default: chosen by the solver from the problem's force
        scale so that a pair at half the activation distance carries a typical nodal force.
    reach
        Graph distance (mm) below which segments count as neighbours and never touch; default
        ``π max(r_a + r_b) / 2`` (:mod:`rotomorph.contact.exclusion`).
    friction
        Coulomb friction coefficient μ (dimensionless, ≥ 0) for every contact; default 0.
    slip
        Tangential displacement (mm) over which lagged friction ramps from sticking to sliding
        (IPC's ε_v for a quasi-static step); default 1e-3 of the smallest contact distance.
    """

    radius: float | Sequence[float] | FloatArray
    obstacles: tuple[Obstacle, ...] = ()
    self_contact: bool = True
    activation_distance: float | None = None
    stiffness: float | None = None
    reach: float | None = None
    friction: float = 0.0
    slip: float | None = None
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
        if not (np.isfinite(self.friction) and self.friction >= 0):
            raise InvalidParameterError(
                "Contact.friction", f"must be >= 0 (0: frictionless); got {self.friction}"
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

    quads: IntArray  # (P, 4) p0 p1 q0 q1
    dmin: FloatArray
    weight: FloatArray
    floors: tuple[tuple[IntArray, FloatArray, FloatArray], ...]  # per floor: nodes, dmin, weight

    @property
    def floor_nodes(self) -> IntArray:
        return np.concatenate([f[0] for f in self.floors]) if self.floors else _NO_INT

    @property
    def floor_dmin(self) -> FloatArray:
        return np.concatenate([f[1] for f in self.floors]) if self.floors else np.zeros(0)


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
    """

    def __init__(self, contact: Contact, network: Network, force_scale: float = 1.0) -> None:
        self.contact = contact
        self.network = network
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
        self.slip = float(contact.slip or 1e-3 * dmin_small)
        self.excluded = (
            excluded_pairs(network.nodes, edges, self.radius, self.dhat, contact.reach)
            if contact.self_contact
            else np.zeros(0, dtype=np.int64)
        )
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
        if contact.stiffness is not None:
            self.kappa = float(contact.stiffness)
        else:
            # a pair at gap dhat/2 carries force_scale: F = kappa w |b'(zhat/2)| 2 dmin with
            # |b'(zhat/2)| = (1/2 + ln 2) zhat  (barrier module)
            w = float(np.median(length))
            zhat = (2.0 * dmin_small + self.dhat) * self.dhat
            self.kappa = float(
                ACTIVATION_FORCE * force_scale / (w * (0.5 + np.log(2.0)) * zhat * 2 * dmin_small)
            )
        self._max_length = float(length.max())
        self._dmin_max = 2.0 * float(self.radius.max())

    # ------------------------------------------------------------------ candidates
    def _extended(self, x: FloatArray) -> FloatArray:
        return np.ascontiguousarray(np.vstack([x, self._obstacle_points]), dtype=float)

    def candidates(self, x: FloatArray, margin: float = 0.0) -> _Candidates:
        """Pairs and floor nodes whose distance may be below contact + activation + ``margin``."""
        edges = self.edges
        quads: list[IntArray] = []
        dmins: list[FloatArray] = []
        weights: list[FloatArray] = []
        p0, p1 = x[edges[:, 0]], x[edges[:, 1]]
        mid = 0.5 * (p0 + p1)
        half = 0.5 * self._max_length
        if self.contact.self_contact and len(edges) > 1:
            reach = self._dmin_max + self.dhat + 2 * half + margin
            pairs = cKDTree(mid).query_pairs(reach, output_type="ndarray").reshape(-1, 2)
            if len(pairs):
                pairs = np.sort(pairs, axis=1)
                keys = pairs[:, 0] * len(edges) + pairs[:, 1]
                pos = np.searchsorted(self.excluded, keys)
                pos = np.minimum(pos, max(len(self.excluded) - 1, 0))
                hit = (
                    self.excluded[pos] == keys if len(self.excluded) else np.zeros(len(keys), bool)
                )
                pairs = pairs[~hit]
                quads.append(np.concatenate([edges[pairs[:, 0]], edges[pairs[:, 1]]], axis=1))
                dmins.append(self.radius[pairs[:, 0]] + self.radius[pairs[:, 1]])
                weights.append(0.5 * (self.length[pairs[:, 0]] + self.length[pairs[:, 1]]))
        n = self.n_nodes
        for k, o in enumerate(self._round):
            a = np.asarray(o.start if isinstance(o, Cylinder) else o.centre)
            b = np.asarray(o.end if isinstance(o, Cylinder) else o.centre)
            dist = _point_segment_distance(mid, a, b)
            near = np.flatnonzero(dist <= self.radius + o.radius + self.dhat + half + margin)
            q = np.array([n + 2 * k, n + 2 * k + 1])
            quads.append(np.concatenate([edges[near], np.tile(q, (len(near), 1))], axis=1))
            dmins.append(self.radius[near] + o.radius)
            weights.append(self.length[near])
        floors = []
        for f in self._floors:
            h = f.height_of(x)
            near = np.flatnonzero(h <= self.node_radius + self.dhat + margin)
            floors.append(
                (
                    np.ascontiguousarray(near, dtype=np.int64),
                    np.ascontiguousarray(self.node_radius[near]),
                    np.ascontiguousarray(self.node_length[near]),
                )
            )
        cat = np.concatenate
        return _Candidates(
            quads=np.ascontiguousarray(cat(quads) if quads else np.zeros((0, 4)), dtype=np.int64),
            dmin=np.ascontiguousarray(cat(dmins) if dmins else np.zeros(0)),
            weight=np.ascontiguousarray(cat(weights) if weights else np.zeros(0)),
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
        x = np.ascontiguousarray(x, dtype=float)
        cand = self.candidates(x)
        xe = self._extended(x)
        grad = np.zeros_like(xe)
        P = len(cand.quads)
        hloc = np.zeros((P, 12, 12)) if need_hess else np.zeros((0, 12, 12))
        dist = np.empty(P)
        energy = pair_barrier(
            xe, cand.quads, cand.dmin, cand.weight, self.dhat, self.kappa,
            need_grad, int(need_hess), grad, hloc, dist,
        )  # fmt: skip
        if not np.isfinite(energy):
            return np.inf, None, None
        blocks = []
        for f, (nodes, dmin, weight) in zip(self._floors, cand.floors, strict=True):
            blk = np.zeros((len(nodes) if need_hess else 0, 3, 3))
            e = plane_barrier(
                xe, nodes, np.asarray(f.normal), f.height, dmin, weight, self.dhat, self.kappa,
                need_grad, int(need_hess), grad, blk, np.empty(len(nodes)),
            )  # fmt: skip
            if not np.isfinite(e):
                return np.inf, None, None
            energy += e
            blocks.append(blk)
        fl_h = np.concatenate(blocks) if blocks else np.zeros((0, 3, 3))
        g = grad[: self.n_nodes] if need_grad else None
        hess = self._triplets(cand, hloc, fl_h) if need_hess else None
        return float(energy), g, hess

    def _triplets(
        self, cand: _Candidates, hloc: FloatArray, fl_h: FloatArray
    ) -> tuple[IntArray, IntArray, FloatArray]:
        n3 = 3 * self.n_nodes
        dof = (cand.quads[:, :, None] * 3 + np.arange(3)).reshape(-1, 12)
        active = (
            np.flatnonzero(np.abs(hloc).reshape(len(hloc), -1).max(axis=1) > 0)
            if len(hloc)
            else np.zeros(0, dtype=np.int64)
        )
        dof = dof[active]
        rows = np.repeat(dof, 12, axis=1).ravel()
        cols = np.tile(dof, (1, 12)).ravel()
        vals = hloc[active].reshape(-1)
        fdof = (cand.floor_nodes[:, None] * 3 + np.arange(3)).reshape(-1, 3)
        frows = np.repeat(fdof, 3, axis=1).ravel()
        fcols = np.tile(fdof, (1, 3)).ravel()
        rows = np.concatenate([rows, frows])
        cols = np.concatenate([cols, fcols])
        vals = np.concatenate([vals, fl_h.reshape(-1)])
        keep = (rows < n3) & (cols < n3) & (vals != 0)
        return rows[keep], cols[keep], vals[keep]

    # ------------------------------------------------------------------ step bounds
    def step_bound(self, x: FloatArray, dx: FloatArray, close_fraction: float = 0.9) -> float:
        """Largest fraction ``t`` of the straight step ``x -> x + dx`` that is provably free of
        contact, stopping where a pair has closed ``close_fraction`` of its gap."""
        x = np.ascontiguousarray(x, dtype=float)
        dx = np.ascontiguousarray(dx, dtype=float)
        disp = float(np.sqrt((dx**2).sum(axis=1)).max()) if len(dx) else 0.0
        if disp == 0.0:
            return 1.0
        cand = self.candidates(x, margin=2.0 * disp)
        xe = self._extended(x)
        dxe = np.zeros_like(xe)
        dxe[: self.n_nodes] = dx
        t = pair_step_bound(xe, dxe, cand.quads, cand.dmin, close_fraction, 200)
        for f, (nodes, dmin, _) in zip(self._floors, cand.floors, strict=True):
            bound = plane_step_bound(
                xe, dxe, nodes, np.asarray(f.normal), f.height, dmin, close_fraction
            )
            t = min(t, bound)
        return float(t)

    def path_is_free(self, x0: FloatArray, x1: FloatArray) -> bool:
        """Whether the straight path ``x0 -> x1`` provably never touches."""
        return self.step_bound(x0, np.asarray(x1) - np.asarray(x0), close_fraction=1.0) >= 1.0

    # ------------------------------------------------------------------ measures
    def forces(self, x: FloatArray) -> FloatArray:
        """Contact force on every node ``(N, 3)`` (N): minus the barrier gradient."""
        _, g, _ = self.evaluate(x, True, 0)
        if g is None:
            raise InfeasibleContactError("positions", "filaments touch or interpenetrate")
        return -g

    def distances(self, x: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Centre-line distances of the candidate pairs near contact and their contact
        distances ``r_a + r_b`` (mm); floors as node heights and radii."""
        x = np.ascontiguousarray(x, dtype=float)
        cand = self.candidates(x, margin=self._dmin_max)
        d = pair_distances(self._extended(x), cand.quads)
        heights = [f.height_of(x[g[0]]) for f, g in zip(self._floors, cand.floors, strict=True)]
        dist = np.concatenate([d, *heights]) if heights else d
        return dist, np.concatenate([cand.dmin, cand.floor_dmin])

    def clearance(self, x: FloatArray) -> float:
        """Smallest ``d / (r_a + r_b)`` over allowed pairs and obstacles (2.0 when none is near)."""
        d, dmin = self.distances(x)
        return float(min(2.0, (d / dmin).min())) if len(d) else 2.0

    def active_contacts(self, x: FloatArray) -> int:
        """Pairs (and floor nodes) inside the activation distance (carrying force)."""
        d, dmin = self.distances(x)
        return int(np.count_nonzero(d < dmin + self.dhat))

    def check_admissible(self, x: FloatArray, field: str = "initial") -> None:
        """Raise :class:`InfeasibleContactError` if ``x`` touches or interpenetrates."""
        d, dmin = self.distances(x)
        bad = np.flatnonzero(d <= dmin)
        if len(bad):
            k = int(bad[np.argmin((d / dmin)[bad])])
            raise InfeasibleContactError(
                field,
                f"{len(bad)} contact pair(s) already touch or interpenetrate (closest at "
                f"{d[k]:.4g} mm < {dmin[k]:.4g} mm); start from a separated configuration, move "
                "the obstacles away, or widen Contact.reach",
            )


def _point_segment_distance(p: FloatArray, a: FloatArray, b: FloatArray) -> FloatArray:
    ab = b - a
    L2 = float(ab @ ab)
    t = np.zeros(len(p)) if L2 == 0 else np.clip((p - a) @ ab / L2, 0.0, 1.0)
    return np.linalg.norm(p - (a + t[:, None] * ab), axis=1)

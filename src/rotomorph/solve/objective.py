"""The rod network as a Newton objective: energy, gradient and Hessian of free DOFs.

Each evaluation is relative to a *base* configuration (the last accepted iterate): reference
frames are transported in time from the base, reference twists unwrapped from the base's.
Positions and twist angles of fixed DOFs keep their base values.
"""

from __future__ import annotations

import weakref
from typing import cast

import numpy as np

from rotomorph._typing import BoolArray, FloatArray, IntArray
from rotomorph.contact.obstacles import Floor
from rotomorph.contact.potential import Contact, HessianBlocks, InfeasibleContactError
from rotomorph.contact.stacked import DofBlocks, StackedContact
from rotomorph.errors import InvalidParameterError
from rotomorph.rod.assembly import (
    evaluate_network,
    material_frames,
    reference_twist,
    scatter_banded,
    scatter_sparse,
    transport_frames,
)
from rotomorph.rod.model import Model
from rotomorph.rod.state import State
from rotomorph.solve.contact_term import ContactTerm, HessianPattern, tangent_rigid_modes
from rotomorph.solve.linalg import BandedMatrix, SparseMatrix
from rotomorph.solve.loads import Loads, Supports
from rotomorph.solve.pattern import hessian_pattern
from rotomorph.solve.retraction import (
    EdgeRotationRetraction,
    join_step,
    max_edge_rotation,
    remove_rigid_motion,
    split_step,
)
from rotomorph.solve.sparse_cholesky import analyse_pattern

BANDED_LIMIT = 64  # half-bandwidth above which the sparse path is used
_EPS = float(np.finfo(float).eps)


class RodObjective:
    """Static equilibrium of a :class:`~rotomorph.rod.model.Model` as an objective."""

    has_convex_hessian = True  # the Gauss–Newton part of the stencil Hessians

    def __init__(
        self,
        model: Model,
        state: State,
        supports: Supports,
        loads: Loads,
        contact: Contact | None = None,
    ) -> None:
        self.model = model
        net, st, lay = model.network, model.stencils, model.layout
        self._edges = np.ascontiguousarray(net.edges)
        n, ne = net.n_nodes, net.n_edges
        fixed = np.zeros(lay.count, dtype=bool)
        for j in supports.clamped_edges:
            j = _check_index("Supports.clamped_edges", j, ne)
            for node in net.edges[j]:
                fixed[lay.pos[node] + np.arange(3)] = True
            fixed[lay.theta[j]] = True
        for node in supports.pinned_nodes:
            node = _check_index("Supports.pinned_nodes", node, n)
            fixed[lay.pos[node] + np.arange(3)] = True
        for j in supports.fixed_twist_edges:
            fixed[lay.theta[_check_index("Supports.fixed_twist_edges", j, ne)]] = True
        self.free: IntArray = np.flatnonzero(~fixed)
        topo = _topology(model, fixed)
        self._retraction = topo["retraction"]
        reduced = -np.ones(lay.count, dtype=np.int64)
        reduced[self.free] = np.arange(len(self.free))
        self._reduced = reduced
        self._pos_index = (lay.pos[:, None] + np.arange(3)).ravel()
        self._theta_index = lay.theta
        self._st_dofs, self._ed_dofs = topo["dofs"]
        b1, b2, c = model.stencil_stiffness
        self._stiff = (np.ascontiguousarray(b1), np.ascontiguousarray(b2), np.ascontiguousarray(c))
        k1, k2, tw = model.integrated_natural()
        self._natural = (
            np.ascontiguousarray(k1),
            np.ascontiguousarray(k2),
            np.ascontiguousarray(tw),
        )
        self._vor = np.ascontiguousarray(model.voronoi_length)
        self._st_edges = np.ascontiguousarray(np.stack([st.edge_e, st.edge_f], axis=1))
        self._st_signs = np.ascontiguousarray(np.stack([st.sign_e, st.sign_f], axis=1))
        self._st_params = np.ascontiguousarray(np.stack([b1, b2, c, self._vor, k1, k2, tw], 1))
        self._ed_params = np.ascontiguousarray(
            # Model.__post_init__ turns every per-edge field into an array
            np.stack(
                [cast(FloatArray, model.axial_stiffness), cast(FloatArray, model.rest_length)],
                axis=1,
            )
        )
        self._external = self._external_forces(loads)
        self._has_forces = bool(np.any(self._external))
        self._st_nodes = np.ascontiguousarray(st.nodes)
        self._moment_edges, self._moments = self._edge_moments(loads)
        if (
            supports.is_free
            and (contact is None or not contact.obstacles)
            and np.linalg.norm(self._external[self._pos_index].reshape(-1, 3).sum(0)) > 0
        ):
            raise InvalidParameterError(
                "Supports",
                "a free body under a net external force has no equilibrium; "
                "pin or clamp at least one node, or give it obstacles to rest on (contact)",
            )
        # work buffers
        self._grad = np.zeros(lay.count)
        self._st_hess = np.zeros((st.count, 11, 11))
        self._ed_hess = np.zeros((ne, 6, 6))
        self._t = np.empty((ne, 3))
        self._d1 = np.empty((ne, 3))
        self._m1 = np.empty((ne, 3))
        self._m2 = np.empty((ne, 3))
        self._mref = np.empty(st.count)
        self._setup_matrix(topo)
        self._fixed_mask = fixed
        self._contact: ContactTerm | None = None
        self._contact_hess: HessianBlocks | DofBlocks | None = None
        # with friction the floor holds a free body in every direction wherever it touches, and
        # spheres and cylinders hold it in directions that depend on where it touches them: no
        # rigid motion is projected out (one that stays free has zero energy and is handled by
        # the shift, like any singular direction)
        self._held = contact is not None and (
            (contact.floor is not None and contact.friction > 0)
            or any(not isinstance(o, Floor) for o in contact.obstacles)
        )
        # a frictionless floor alone leaves a free body its in-plane rigid motions (projected)
        self._floor_normal = (
            None if contact is None or contact.floor is None or self._held else contact.floor
        )
        self.set_base(state)
        self._setup_scales(loads)
        if contact is not None:
            self._contact = ContactTerm(
                contact,
                net,
                lay.pos,
                reduced,
                force_scale=max(
                    self.force_scale / np.sqrt(n),
                    float(np.abs(self._external[self._pos_index]).max(initial=0.0)),
                ),
                # one grown Hessian pattern per network and support set (e.g. a whole ramp)
                pattern=topo.setdefault("contact_pattern", HessianPattern()),
                # a printed stack: its layers lie along the material director (twist angles)
                theta_dof=lay.theta,
                directors=np.asarray(model.directors),
            )
            # a stacked contact reads the layers off the frames: it takes the state
            pot = self._contact.potential
            if isinstance(pot, StackedContact):
                pot.check_admissible(state, "initial")
                pot.set_lag(state)  # friction lagged per solve
            else:
                pot.check_admissible(state.positions, "initial")
                pot.set_lag(state.positions)

    @property
    def contact(self):  # type: ignore[no-untyped-def]
        """The bound :class:`~rotomorph.contact.potential.ContactPotential`, or None."""
        return None if self._contact is None else self._contact.potential

    # ------------------------------------------------------------------ set-up
    def _external_forces(self, loads: Loads) -> FloatArray:
        net, lay = self.model.network, self.model.layout
        f = np.zeros(lay.count)
        for node, force in loads.forces:
            node = _check_index("Loads.forces", node, net.n_nodes)
            vec = _vector("Loads.forces", force)
            f[lay.pos[node] + np.arange(3)] += vec
        if loads.gravity is not None:
            # mass is what was printed: the weight per printed length times the printed length
            # (the network's), whatever the natural rest length the actuation gives the edge
            w = loads.gravity.line_weight(net.n_edges) * net.edge_lengths
            d = np.asarray(loads.gravity.direction, float)
            d = d / np.linalg.norm(d)
            for end in (0, 1):
                for k in range(3):
                    np.add.at(f, lay.pos[net.edges[:, end]] + k, 0.5 * w * d[k])
        return f

    def _edge_moments(self, loads: Loads) -> tuple[IntArray, FloatArray]:
        net = self.model.network
        edges, vecs = [], []
        for node, moment in loads.moments:
            node = _check_index("Loads.moments", node, net.n_nodes)
            starts = np.flatnonzero(net.edges[:, 0] == node)
            ends = np.flatnonzero(net.edges[:, 1] == node)
            cand = starts if len(starts) else ends
            if not len(cand):
                raise InvalidParameterError("Loads.moments", f"node {node} has no edge")
            edges.append(int(cand[0]))
            vecs.append(_vector("Loads.moments", moment))
        return np.array(edges, dtype=np.int64), np.array(vecs, dtype=float).reshape(-1, 3)

    def _setup_matrix(self, topo: dict) -> None:
        self.bandwidth = topo["bandwidth"]
        self.banded = topo["banded"]
        nfree = len(self.free)
        if self.banded:
            self._ab = np.zeros((self.bandwidth + 1, nfree), order="F")
            return
        self._st_slot, self._ed_slot, self._csc_pattern = topo["sparse"]
        self._data = np.zeros(len(self._csc_pattern[0]))
        self._topo = topo

    def _setup_scales(self, loads: Loads) -> None:
        net = self.model.network
        rest = cast(FloatArray, self.model.rest_length)  # an array after Model.__post_init__
        ext = np.ptp(net.nodes, axis=0).max() or float(rest.sum())
        self.length_scale = float(max(ext, rest.max()))
        lmean = float(rest.mean())
        b1, b2, c = self._stiff
        stiff = np.maximum(np.maximum(b1, b2), c)
        k1, k2, tw = self._natural
        kint = np.sqrt(k1**2 + k2**2 + tw**2) + self._vor / self.length_scale
        self.force_scale = float(
            np.sqrt(np.sum((stiff / self._vor * kint / lmean) ** 2))
            + np.abs(self._external).sum()
            + (np.linalg.norm(self._moments, axis=1).sum() / lmean if len(self._moments) else 0)
        )
        self.energy_scale = float(
            np.sum(0.5 * stiff / self._vor * kint**2)
            + np.abs(self._external).sum() * self.length_scale
            + (np.linalg.norm(self._moments, axis=1).sum() if len(self._moments) else 0.0)
        )
        lay = self.model.layout
        # each coordinate gets half of every edge at it, the edges' first ends first (the
        # order of np.add.at over ends and coordinates: the same sums)
        half = 0.5 * rest
        ends = lay.pos[np.concatenate([net.edges[:, 0], net.edges[:, 1]])]
        weights = np.concatenate([half, half])
        m = np.zeros(lay.count)
        for k in range(3):
            m += np.bincount(ends + k, weights, minlength=lay.count)
        # a twist angle is weighted like the rotation of its edge (length^3), so that the
        # shift damps twisting and bending rotations alike at every mesh size
        m[lay.theta] = rest**3
        self._metric = m[self.free]
        self._node_metric = m[lay.pos]
        self._theta_metric = m[lay.theta]
        self._layout_metric: FloatArray | None = None  # the metric on every layout DOF
        self._free_body = not self._fixed_mask.any()
        wt = np.ones(lay.count)
        wt[lay.theta] = 1.0 / lmean
        self._weights = wt[self.free]
        # forces per unit of position round-off: axial EA / l and bending B / (l_vor l^2)
        ea = cast(FloatArray, self.model.axial_stiffness)
        self._roundoff_stiffness = float(
            np.sqrt(np.sum((ea / rest) ** 2) + np.sum((stiff / self._vor**3) ** 2))
        )

    # ------------------------------------------------------------------ state handling
    def set_base(self, state: State) -> None:
        """Make ``state`` the base of later evaluations."""
        self.base = state
        self._last: tuple[FloatArray, FloatArray, FloatArray] | None = None
        u = np.empty(self.model.layout.count)
        u[self._pos_index] = state.positions.ravel()
        u[self._theta_index] = state.theta
        self._u_base = u
        self._base_m1: FloatArray | None = None  # the base's material directors, when needed
        self._floor: float | None = None  # residual_floor() of this base, when asked

    def vector(self, state: State | None = None) -> FloatArray:
        """Free-DOF vector of ``state`` (default: the base)."""
        if state is None:
            return self._u_base[self.free].copy()
        u = self._u_base.copy()
        u[self._pos_index] = state.positions.ravel()
        u[self._theta_index] = state.theta
        return u[self.free]

    def _unpack(self, q: FloatArray) -> tuple[FloatArray, FloatArray]:
        u = self._u_base.copy()
        u[self.free] = q
        return u[self._pos_index].reshape(-1, 3), u[self._theta_index]

    def state(self, q: FloatArray) -> State:
        """The configuration of free-DOF vector ``q`` (frames transported from the base)."""
        pos, theta = self._unpack(q)
        t, d1 = np.empty_like(self._t), np.empty_like(self._d1)
        transport_frames(pos, self._edges, self.base.tangents, self.base.directors, t, d1)
        st = self.model.stencils
        mref = np.empty(st.count)
        reference_twist(self._st_edges, self._st_signs, t, d1, self.base.reference_twist, mref)
        return State(positions=pos, theta=theta, tangents=t, directors=d1, reference_twist=mref)

    def accept(self, q: FloatArray) -> None:
        """Re-base at ``q`` (time-parallel transport of the frames)."""
        last = self._last
        if last is not None and last[0] is q:
            # the line search has just evaluated q: reuse its transported frames
            _, pos, theta = last
            self.set_base(
                State(
                    positions=pos,
                    theta=theta,
                    tangents=self._t.copy(),
                    directors=self._d1.copy(),
                    reference_twist=self._mref.copy(),
                )
            )
        else:
            self.set_base(self.state(q))

    # ------------------------------------------------------------------ objective
    def evaluate(self, q: FloatArray, need_grad: bool, need_hess: int):  # type: ignore[no-untyped-def]
        """Total potential energy (N mm), gradient and Hessian of the free DOFs.

        ``need_hess``: 0 none, 1 exact Hessian, 2 Gauss–Newton Hessian (positive semidefinite).
        """
        u = self._u_base.copy()
        u[self.free] = q
        pos = u[self._pos_index].reshape(-1, 3)
        theta = u[self._theta_index]
        self._last = (q, pos, theta)
        try:
            energy = self._evaluate_network(pos, theta, need_grad, int(need_hess))
        except ZeroDivisionError:
            if need_grad or need_hess:
                raise
            return np.inf, None, None
        if self._contact is not None:
            # (the frames of this configuration, filled by the network evaluation above)
            frames = (self._t, self._m1, self._m2) if self._contact.stacked else None
            if not (need_grad or need_hess):
                # a line-search trial: the straight path from the accepted iterate must be
                # provably free of contact, else the trial counts as infinite energy
                dirs = (self._base_directors(), self._m1) if frames is not None else None
                if not self._contact.path_is_free(self.base.positions, pos, dirs):
                    return np.inf, None, None
            ce, cg, cth, ch = self._contact.evaluate(pos, need_grad, int(need_hess), frames)
            if not np.isfinite(ce):
                if need_grad or need_hess:
                    raise InfeasibleContactError(
                        "positions", "an iterate touches or interpenetrates (solver bug)"
                    )
                return np.inf, None, None
            energy += ce
            if cg is not None:
                self._grad[self._pos_index] += cg
            if cth is not None:  # a stacked contact twists the segments
                self._grad[self._theta_index] += cth
            self._contact_hess = ch
        return self._finish(u, pos, theta, energy, need_grad, need_hess)

    def _evaluate_network(self, pos, theta, need_grad, need_hess):  # type: ignore[no-untyped-def]
        base, lay = self.base, self.model.layout
        return evaluate_network(
            pos,
            theta,
            base.tangents,
            base.directors,
            base.reference_twist,
            self._t,
            self._d1,
            self._m1,
            self._m2,
            self._mref,
            self._edges,
            self._st_nodes,
            self._st_edges,
            self._st_signs,
            self._st_params,
            self._ed_params,
            lay.pos,
            lay.theta,
            lay.count,
            need_grad,
            need_hess,
            self._grad,
            self._st_hess,
            self._ed_hess,
        )

    def _finish(self, u, pos, theta, energy, need_grad, need_hess):  # type: ignore[no-untyped-def]
        grad = self._grad
        if self._has_forces:
            energy -= float(self._external @ u)
            if need_grad:
                grad = grad - self._external
        if not need_grad:
            grad = None
        if len(self._moments):
            energy += self._moment_terms(pos, theta, grad, need_hess)
        if grad is not None:
            grad = grad[self.free]
            if grad is self._grad:  # pragma: no cover - fancy indexing always copies
                grad = grad.copy()
        hess = self._hessian() if need_hess else None
        return float(energy), grad, hess

    def _moment_terms(self, pos, theta, grad, need_hess):  # type: ignore[no-untyped-def]
        """Dead moments: potential -M.(t_base x t) - (M.t_base)(theta - theta_base).

        Exact to second order in the rotation from the base, so the equilibrium and the Newton
        Hessian at the base are exact.
        """
        lay, edges = self.model.layout, self._edges
        energy = 0.0
        for j, M in zip(self._moment_edges, self._moments, strict=True):
            a, b = edges[j]
            e = pos[b] - pos[a]
            ln = np.linalg.norm(e)
            t = e / ln
            tb = self.base.tangents[j]
            cvec = np.cross(M, tb)
            mt = float(M @ tb)
            energy += -float(cvec @ t) - mt * (theta[j] - self.base.theta[j])
            P = np.eye(3) - np.outer(t, t)
            if grad is not None:
                ge = -(P @ cvec) / ln
                grad[lay.pos[a] + np.arange(3)] -= ge
                grad[lay.pos[b] + np.arange(3)] += ge
                grad[lay.theta[j]] -= mt
            if need_hess == 1:  # the Gauss–Newton mode leaves this indefinite term out
                h = (np.outer(t, P @ cvec) + np.outer(P @ cvec, t) + (cvec @ t) * P) / ln**2
                blk = np.block([[h, -h], [-h, h]])
                self._ed_hess[j] += blk
        return energy

    def _hessian(self):  # type: ignore[no-untyped-def]
        if self.banded:
            scatter_banded(
                self._st_hess,
                self._st_dofs,
                self._ed_hess,
                self._ed_dofs,
                self._reduced,
                self.bandwidth,
                self._ab,
            )
            banded = BandedMatrix(self._ab.copy(order="F"), self.bandwidth)
            if self._contact is not None and self._contact_hess is not None:
                return self._contact.add_to(banded, self._contact_hess)
            return banded
        scatter_sparse(self._st_hess, self._st_slot, self._ed_hess, self._ed_slot, self._data)
        indices, indptr = self._csc_pattern
        if self._topo.get("symbolic") is None:
            self._topo["symbolic"] = analyse_pattern(indptr, indices)
        rod = SparseMatrix.from_arrays(self._data.copy(), indices, indptr, self._topo["symbolic"])
        if self._contact is not None and self._contact_hess is not None:
            return self._contact.add_to(rod, self._contact_hess)
        return rod

    def project(self, d: FloatArray) -> FloatArray:
        """Remove the rigid motion from a step of a free body (M-orthogonal projection).

        Rigid motions of an unsupported network (translations; rotations, which also turn
        every material frame by ``omega . t`` about its tangent) are exact zero-energy modes;
        any component a factorization puts along them is round-off. With any support the step
        is returned unchanged (the remaining modes are handled by the shift).
        """
        if not self._free_body or self._held:
            return d
        du = np.zeros(self.model.layout.count)
        du[self.free] = d
        if self._floor_normal is not None:
            return self._project_tangent(du)
        dx = np.ascontiguousarray(du[self._pos_index].reshape(-1, 3))
        dth = np.ascontiguousarray(du[self._theta_index])
        remove_rigid_motion(
            self.base.positions, dx, self._node_metric, self.base.tangents, dth, self._theta_metric
        )
        du[self._pos_index] = dx.ravel()
        du[self._theta_index] = dth
        return du[self.free]

    def _project_tangent(self, du: FloatArray) -> FloatArray:
        """Remove the rigid motions tangent to the floor (M-orthogonal projection)."""
        assert self._floor_normal is not None
        lay = self.model.layout
        U = tangent_rigid_modes(
            self.base.positions,
            self.base.tangents,
            np.asarray(self._floor_normal.normal),
            lay.pos,
            lay.theta,
            lay.count,
        )
        if self._layout_metric is None:
            m = np.zeros(lay.count)
            m[self._pos_index] = np.repeat(self._node_metric, 3)
            m[self._theta_index] = self._theta_metric
            self._layout_metric = m
        Um = U * self._layout_metric
        G = Um @ U.T
        c = np.linalg.solve(G, Um @ du)
        return (du - c @ U)[self.free]

    def shift_floor(self, g: FloatArray) -> float:
        """Smallest modified-Newton shift for a free body, 0 otherwise.

        A small rigid rotation ``omega`` of an unbalanced body changes the energy at second
        order by at most ``|omega|^2 sum |F_i| |r_i|`` (``F`` the nodal forces, ``r`` the
        arms about the metric-weighted centroid), against ``|omega|^2 sum m_i |r_i|^2`` in the
        metric: their ratio bounds how negative the rigid directions can be.
        """
        if not self._free_body:
            return 0.0
        gf = np.zeros(self.model.layout.count)
        gf[self.free] = g
        force = np.linalg.norm(gf[self._pos_index].reshape(-1, 3), axis=1)
        m = self._node_metric
        x = self.base.positions
        arm = np.linalg.norm(x - m @ x / m.sum(), axis=1)
        return 2.0 * float(force @ arm) / max(float(m @ arm**2), 1e-300)

    def residual_floor(self) -> float:
        """Round-off floor of the weighted gradient norm at the base (N).

        Positions carry a relative round-off of ``eps``; an edge vector of length ``l`` far
        from the origin is known to ``eps |x|``, so a stretching force ``EA (|e|/l0 - 1)`` to
        ``EA eps |x| / l`` and a bending force to ``B eps |x| / (l_vor l^2)``. Their root sum
        of squares, times a safety factor 8, is the smallest residual the arithmetic resolves:
        a nearly inextensible rod far from the origin cannot reach a tighter ``rtol``.
        """
        if self._floor is None:  # once per base: every iteration asks
            x = float(np.abs(self.base.positions).max())
            self._floor = 8.0 * _EPS * max(x, self.length_scale) * (self._roundoff_stiffness)
        return self._floor

    def curvature_step_scale(self, q: FloatArray, v: FloatArray) -> float:
        """Multiple of ``v`` that turns the most-turned edge by 0.2 rad."""
        angle = self._max_edge_rotation(v)
        return 0.2 / angle if angle > 0 else 0.0

    def max_step(self, q: FloatArray, d: FloatArray) -> float:
        """Largest step fraction that turns no edge by more than one radian."""
        angle = self._max_edge_rotation(d)
        bound = 1.0 if angle <= 1.0 else 1.0 / angle
        if self._contact is not None:
            du = np.zeros(self.model.layout.count)
            du[self.free] = d
            pos, theta = self._unpack(q)
            dpos = du[self._pos_index].reshape(-1, 3)
            dirs = None
            if self._contact.stacked:  # the layers' directors at both ends of the step
                end = self._directors_at(pos + bound * dpos, theta + bound * du[self._theta_index])
                dirs = (self._directors_at(pos, theta), end)
            bound = min(bound, self._contact.step_bound(pos, bound * dpos, dirs) * bound)
        return bound

    def _base_directors(self) -> FloatArray:
        """Material directors m1 of the base ``(E, 3)`` (computed once per base)."""
        if self._base_m1 is None:
            self._base_m1 = self.base.material_directors()[0]
        return self._base_m1

    def _directors_at(self, pos: FloatArray, theta: FloatArray) -> FloatArray:
        """Material directors m1 ``(E, 3)`` of a configuration (frames transported from the
        base, as every evaluation takes them)."""
        ne = len(self._edges)
        t, d1, m1, m2 = (np.empty((ne, 3)) for _ in range(4))
        transport_frames(
            np.ascontiguousarray(pos), self._edges, self.base.tangents, self.base.directors, t, d1
        )
        material_frames(t, d1, np.ascontiguousarray(theta, dtype=float), m1, m2)
        return m1

    def _max_edge_rotation(self, d: FloatArray) -> float:
        du = np.zeros(self.model.layout.count)
        du[self.free] = d
        return float(
            max_edge_rotation(
                self.base.positions,
                np.ascontiguousarray(du[self._pos_index].reshape(-1, 3)),
                self._edges,
            )
        )

    def convex_hessian(self, q: FloatArray):  # type: ignore[no-untyped-def]
        """Gauss–Newton Hessian at ``q``: positive semidefinite, for indefinite iterates."""
        pos, theta = self._unpack(q)
        self._evaluate_network(pos, theta, False, 2)
        if self._contact is not None:
            frames = (self._t, self._m1, self._m2) if self._contact.stacked else None
            self._contact_hess = self._contact.evaluate(pos, False, 2, frames)[3]
        return self._hessian()

    def metric(self) -> FloatArray:
        """Lumped metric: Voronoi length per position DOF, length x C/EA per twist angle."""
        return self._metric

    def weights(self) -> FloatArray:
        """1 for forces (N); 1/(mean edge length) for moments (N mm)."""
        return self._weights

    def retract(self, q: FloatArray, d: FloatArray, alpha: float) -> FloatArray:
        """Step along ``d``: edges rotated (see :mod:`~rotomorph.solve.retraction`), twist
        angles moved linearly; fixed DOFs keep their values."""
        lay = self.model.layout
        u, du = np.empty(lay.count), np.empty(lay.count)
        pos, dpos = np.empty((len(lay.pos), 3)), np.empty((len(lay.pos), 3))
        split_step(self._u_base, self.free, q, d, lay.pos, u, du, pos, dpos)
        out = np.empty(len(self.free))
        join_step(
            u, du, alpha, self._retraction(pos, dpos, alpha), lay.pos, lay.theta, self.free, out
        )
        return out

    def rigid_modes(self) -> FloatArray:
        """Rigid motions of a free body at the base ``(n_free, 6)``; ``(n_free, 0)`` if supported,
        ``(n_free, 3)`` (the motions along it) on a floor.

        Three translations and three rotations about the metric-weighted centroid; a rotation
        ``omega`` moves node ``i`` by ``omega x r_i`` and adds ``omega . t_j`` to the twist
        angle of edge ``j`` (the material frame turns with the body). These are the exact
        zero-energy directions the stability test removes.
        """
        if not self._free_body or self._held:
            return np.zeros((len(self.free), 0))
        lay = self.model.layout
        if self._floor_normal is not None:  # on a floor only the motions along it are free
            return tangent_rigid_modes(
                self.base.positions,
                self.base.tangents,
                np.asarray(self._floor_normal.normal),
                lay.pos,
                lay.theta,
                lay.count,
            ).T[self.free]
        x = self.base.positions
        m = self._node_metric
        r = x - m @ x / m.sum()
        modes = np.zeros((lay.count, 6))
        node = np.zeros((len(x), 3, 6))  # per node and coordinate
        node[:, [0, 1, 2], [0, 1, 2]] = 1.0
        # rotations about the axes e_k: e_k x r
        node[:, 1, 3], node[:, 2, 3] = -r[:, 2], r[:, 1]
        node[:, 0, 4], node[:, 2, 4] = r[:, 2], -r[:, 0]
        node[:, 0, 5], node[:, 1, 5] = -r[:, 1], r[:, 0]
        modes[self._pos_index] = node.reshape(-1, 6)
        modes[lay.theta, 3:] = self.base.tangents
        return modes[self.free]


_TOPOLOGY: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _topology(model: Model, fixed: BoolArray) -> dict:
    """Matrix structure and retraction of a network with given fixed DOFs (cached: a heating
    ramp solves the same topology many times with different natural fields)."""
    per_net = _TOPOLOGY.setdefault(model.network, {})
    key = fixed.tobytes()
    if key in per_net:
        return per_net[key]
    lay, st, net = model.layout, model.stencils, model.network
    reduced = -np.ones(lay.count, dtype=np.int64)
    free = np.flatnonzero(~fixed)
    reduced[free] = np.arange(len(free))
    rs, re_ = reduced[lay.stencil_dofs(st)], reduced[lay.edge_dofs(net.edges)]
    spans = []
    for r in (rs, re_):
        if r.size:
            hi = np.max(np.where(r >= 0, r, -1), axis=1)
            lo = np.min(np.where(r >= 0, r, np.iinfo(np.int64).max), axis=1)
            ok = hi >= 0
            spans.append(int(np.max(hi[ok] - lo[ok])) if ok.any() else 0)
    bandwidth = int(max(spans)) if spans else 0
    dofs = (lay.stencil_dofs(st), lay.edge_dofs(net.edges))
    topo: dict = {
        "bandwidth": bandwidth,
        "banded": bandwidth <= BANDED_LIMIT,
        "sparse": None,
        "dofs": dofs,
    }
    if not topo["banded"]:
        topo["sparse"] = hessian_pattern(*dofs, reduced)
    fixed_nodes = np.flatnonzero(fixed[lay.pos[:, None] + np.arange(3)].all(axis=1))
    topo["retraction"] = EdgeRotationRetraction(
        np.ascontiguousarray(net.edges), net.n_nodes, fixed_nodes
    )
    per_net[key] = topo
    return topo


def _check_index(field: str, value: object, n: int) -> int:
    i = int(value)  # type: ignore[call-overload]
    if not 0 <= i < n:
        raise InvalidParameterError(field, f"index {i} is out of range [0, {n - 1}]")
    return i


def _vector(field: str, value: object) -> FloatArray:
    v = np.asarray(value, dtype=float)
    if v.shape != (3,) or not np.isfinite(v).all():
        raise InvalidParameterError(field, f"needs finite 3-vectors; got {value!r}")
    return v

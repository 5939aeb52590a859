r"""Natural values of a lattice as smooth functions of per-edge print settings.

Design variables
----------------
Per lattice edge ``e``: a mode variable :math:`c_e \in [-1, 1]` (+1 expanding = active half on
the outer side of the wave, −1 contracting = inner) and the print speed :math:`v_e` (mm/s).
Between the printable modes the natural values are the linear blend of the two (the continuous
relaxation of the gradient phase); the speed enters through the calibrated speed law of the
materials chain, exactly as the forward simulation's ``program`` actuation uses it.

Why the blend is exact at printable settings
--------------------------------------------
The ``program`` actuation (:class:`rotomorph.lattice.actuation.ProgramActuation`) gives every
rod vertex a curvature and twist increment from the section law at the vertex's speed ``u`` and
rotation number :math:`\omega^* = R\,d\alpha_n/ds`, which does not depend on the speed. At a
fixed :math:`\omega^*` the section law is linear in the free strains
:math:`\sigma(u) = (\varepsilon_\parallel(u), \varepsilon_\perp(u), \varepsilon_p)` of the
speed law, so a vertex increment is :math:`\sum_q U_q\,\sigma_q(u)`, with the unit responses
:math:`U_q` read off the actuation itself with unit strains. A junction stencil couples two
edges; its unit responses are tabulated for the four mode combinations and blended bilinearly.
A segment's centre-line strain :math:`\varepsilon_c` is evaluated directly from the section law
at the segment's mean speed and rotation number, as the chain does; its rest length is the
printed length times :math:`e^{\varepsilon_c}` (Hencky) or :math:`1 + \varepsilon_c`, plus
the change the printed curvature makes at its end vertices (the curved-bar section of
:mod:`rotomorph.materials.section`): linear in the vertex's free strains, tabulated per mode
with unit strains and blended like the stencils. The blend is checked against the forward
actuation at random modes and speeds when it is built.

Derivatives
-----------
:meth:`LatticeBlend.gradient` contracts adjoint products with the exact derivatives of these
expressions; the only derivatives not in closed form are those of the scalar speed law
:math:`\sigma(u)` and of the section's axial strain in :math:`\omega^*`, taken by central
differences with a relative step of 1e-6 (truncation error about 1e-12 relative: the
calibrated law is linear in :math:`\ln v`).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from rotomorph._typing import FloatArray, IntArray
from rotomorph.design.lattices import Lattice, sinusoidal_lattice
from rotomorph.errors import InvalidParameterError
from rotomorph.lattice.actuation import (
    Actuation,
    ProgramActuation,
    default_stiffness,
    get_actuation,
)
from rotomorph.lattice.model import lattice_model
from rotomorph.materials.natural import (
    DIRECTOR_HELIX_SENSE,
    FilamentModel,
    actuation_increments,
    edge_shares,
)
from rotomorph.rod.model import Model

__all__ = ["LatticeBlend", "lattice_blend", "with_settings"]

_REL_STEP = 1e-6


@dataclass(frozen=True)
class _MarkedStrains:
    """A strain law giving (ε∥, ε⊥) at the speed ``marker`` (every speed when ``None``) and zero
    at any other speed: the unit responses of the vertices printed at that speed."""

    parallel: float
    perpendicular: float
    marker: float | None
    measure: Any

    def active_strains(self, speed: Any) -> tuple[FloatArray, FloatArray]:
        u = np.asarray(speed, dtype=float)
        hit = np.ones(u.shape, dtype=bool) if self.marker is None else u == self.marker
        return np.where(hit, self.parallel, 0.0), np.where(hit, self.perpendicular, 0.0)


@dataclass(frozen=True, eq=False)
class _Chain:
    """The speed law and the section's axial strain of one lattice's materials."""

    model: FilamentModel
    lattice: Lattice
    temperature: float

    def strains(self, speed: FloatArray) -> FloatArray:
        """Free LCE strains ``(n, 2)`` (ε∥, ε⊥) at full actuation for speeds ``(n,)``."""
        u = np.asarray(speed, dtype=float)
        e_par, e_perp, _ = self.model.strains(u, self.model.material(self.lattice.passive_material))
        return np.stack([np.broadcast_to(e_par, u.shape), np.broadcast_to(e_perp, u.shape)], 1)

    @property
    def passive_strain(self) -> float:
        """Free strain ε_p of the passive ink at full actuation (dimensionless)."""
        return float(self.model.strains(1.0, self.model.material(self.lattice.passive_material))[2])

    def strain_rates(self, speed: FloatArray) -> FloatArray:
        """d(strains)/d(speed) ``(n, 2)`` (s/mm), central differences (module docstring)."""
        u = np.asarray(speed, dtype=float)
        h = _REL_STEP * u
        return (self.strains(u + h) - self.strains(u - h)) / (2.0 * h)[:, None]

    def _materials(self) -> tuple[Any, Any]:
        lat = self.lattice
        return self.model.material(lat.active_material), self.model.material(lat.passive_material)

    def strains_at(self, speed: FloatArray) -> FloatArray:
        """Free strains ``(n, 3)`` (ε∥, ε⊥, ε_p) reached at the actuation temperature."""
        u = np.asarray(speed, dtype=float)
        e_par, e_perp, eps_p = self.model.strains_at(u, *self._materials(), self.temperature)
        return np.stack(
            [np.broadcast_to(e_par, u.shape), np.broadcast_to(e_perp, u.shape),
             np.full(u.shape, float(eps_p))], axis=1,
        )  # fmt: skip

    def strains_at_rates(self, speed: FloatArray) -> FloatArray:
        """d(:meth:`strains_at`)/d(speed) ``(n, 3)`` (s/mm), central differences."""
        u = np.asarray(speed, dtype=float)
        h = _REL_STEP * u
        return (self.strains_at(u + h) - self.strains_at(u - h)) / (2.0 * h)[:, None]

    def axial_units(self, omega_star: FloatArray) -> FloatArray:
        """Centre-line strain ε_c ``(n, 3)`` of segments at rotation numbers ``omega_star`` per
        unit free strain (ε∥, ε⊥, ε_p): the section law is linear in them at fixed ω*."""
        lat = self.lattice
        section = self.model.section(
            *self._materials(), lat.radius, lat.active_fraction, self.temperature
        )
        w = np.asarray(omega_star, dtype=float).reshape(-1)
        eye = np.repeat(np.eye(3), len(w), axis=0)
        eps_c, _, _ = section.natural_strains(np.tile(w, 3), eye[:, 0], eye[:, 1], eye[:, 2])
        return np.asarray(eps_c, dtype=float).reshape(3, len(w)).T


@dataclass(frozen=True, eq=False)
class LatticeBlend:
    """Natural values of a lattice as functions of per-edge modes ``c`` and speeds ``v``.

    Attributes
    ----------
    lattice
        The printed geometry (its own pattern and speeds are irrelevant).
    model
        The printed rod model (natural values = printed; stiffness of the forward simulation).
    printed
        Integrated natural values ``(S, 3)`` of the printed state.
    units
        ``(S, 2, 2, 3, 5)``: integrated natural increment of every stencil for its two edges'
        modes ``[mode of edge_a, mode of edge_b]`` (index 0 expanding, 1 contracting) per unit
        free strain (last axis: ε∥ and ε⊥ of the vertices printed at edge a's speed, the same
        at edge b's speed, ε_p); zero on unactuated stencils.
    stencil_edges
        ``(S, 2)`` lattice edges ``(a, b)`` of each stencil's two segments.
    segment_edge
        ``(E,)`` lattice edge of every network segment.
    segment_speed_edges
        ``(E, 2)`` lattice edges whose speeds the segment's two vertices carry.
    segment_rate
        ``(E, 2)`` half the smooth nozzle-angle rate dα_n/ds at the segment's two vertices
        times ``R`` and the helix sense: ω* of the segment is
        ``(u_a r_a + u_b r_b) / ((u_a + u_b)/2)``.
    segment_units
        ``(E, 3)`` centre-line strain per unit free strain of the segments printed at one
        speed (their ω* does not depend on it); NaN on segments between two speeds.
    segment_curved
        ``(E, 2, 2, 3)``: the printed curvature's change of each segment's centre-line strain
        from its vertex ``r`` (axis 1), for its edge printed expanding / contracting (axis 2),
        per unit full-actuation free strain (ε∥, ε⊥, ε_p) at that vertex's speed (edge weights
        included).
    speeds
        Default speeds ``(n_edges,)`` (mm/s), the lattice's own.
    """

    lattice: Lattice
    model: Model
    printed: FloatArray
    units: FloatArray
    stencil_edges: IntArray
    segment_edge: IntArray
    segment_speed_edges: IntArray
    segment_rate: FloatArray
    segment_units: FloatArray
    segment_curved: FloatArray
    speeds: FloatArray
    chain: _Chain = field(repr=False)
    factor: FloatArray = field(repr=False)
    hencky: bool = True

    @property
    def n_edges(self) -> int:
        """Number of lattice edges."""
        return len(self.lattice.edge_chains)

    @property
    def printed_length(self) -> FloatArray:
        """Printed segment lengths ``(E,)`` (mm)."""
        return np.asarray(self.model.rest_length, dtype=float)

    def _weights(self, c: FloatArray) -> tuple[FloatArray, FloatArray]:
        c = np.asarray(c, dtype=float)
        ca, cb = c[self.stencil_edges[:, 0]], c[self.stencil_edges[:, 1]]
        wa = np.stack([0.5 * (1 + ca), 0.5 * (1 - ca)], axis=1)
        wb = np.stack([0.5 * (1 + cb), 0.5 * (1 - cb)], axis=1)
        return wa, wb

    def _speeds(self, v: FloatArray | None) -> FloatArray:
        return self.speeds if v is None else np.asarray(v, dtype=float)

    def _sources(self, v: FloatArray) -> FloatArray:
        """``(S, 5)``: (ε∥, ε⊥) at the speed of each stencil's edge a, then of edge b, then ε_p."""
        sa = self.chain.strains(v[self.stencil_edges[:, 0]])
        sb = self.chain.strains(v[self.stencil_edges[:, 1]])
        sp = np.full((len(sa), 1), self.chain.passive_strain)
        return np.concatenate([sa, sb, sp], axis=1)

    def _segment_state(self, v: FloatArray) -> tuple[FloatArray, FloatArray]:
        ua, ub = v[self.segment_speed_edges[:, 0]], v[self.segment_speed_edges[:, 1]]
        mean = 0.5 * (ua + ub)
        omega = (ua * self.segment_rate[:, 0] + ub * self.segment_rate[:, 1]) / mean
        return omega, mean

    @property
    def _mixed(self) -> Any:
        return np.isnan(self.segment_units[:, 0])

    def _axial(self, v: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        """ω*, mean speed and unit centre-line strains ``(E, 3)`` of every segment."""
        omega, mean = self._segment_state(v)
        units = self.segment_units.copy()
        mixed = self._mixed
        units[mixed] = self.chain.axial_units(omega[mixed])
        return omega, mean, units

    def _free(self, speed: FloatArray) -> FloatArray:
        """``(n, 3)`` free strains (ε∥, ε⊥, ε_p) the unit responses multiply (as the stencils')."""
        sig = self.chain.strains(speed)
        return np.concatenate([sig, np.full((len(sig), 1), self.chain.passive_strain)], axis=1)

    def _curved(self, c: FloatArray, v: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Curved-section strain change of every segment ``(E,)`` and its derivatives: per
        segment and end ``r`` the mode derivative ``(E, 2)`` and the strain-weighted unit
        response ``(E, 2, 3)`` that multiplies d(free strain)/d(speed)."""
        c = np.asarray(c, dtype=float)
        ce = c[self.segment_edge]
        w = np.stack([0.5 * (1 + ce), 0.5 * (1 - ce)], axis=1)  # (E, 2) modes
        total = np.zeros(len(ce))
        d_mode = np.zeros((len(ce), 2))
        blended = np.zeros((len(ce), 2, 3))
        for r in (0, 1):
            sig = self._free(v[self.segment_speed_edges[:, r]])
            unit = self.segment_curved[:, r]  # (E, 2 modes, 3)
            per_mode = np.einsum("emq,eq->em", unit, sig)
            total += np.sum(w * per_mode, axis=1)
            d_mode[:, r] = 0.5 * (per_mode[:, 0] - per_mode[:, 1])
            blended[:, r] = np.einsum("em,emq->eq", w, unit)
        return total, d_mode, blended

    def natural(
        self, c: FloatArray, v: FloatArray | None = None, t: float = 1.0
    ) -> tuple[FloatArray, FloatArray]:
        """Integrated naturals ``(S, 3)`` and rest lengths ``(E,)`` at modes ``c``, speeds
        ``v`` (mm/s; default the lattice's) and ramp fraction ``t`` (0 printed, 1 actuated)."""
        v = self._speeds(v)
        wa, wb = self._weights(c)
        inc = np.einsum("si,sj,sijkq,sq->sk", wa, wb, self.units, self._sources(v))
        _, mean, units = self._axial(v)
        curved, _, _ = self._curved(c, v)
        eps = t * (np.sum(units * self.chain.strains_at(mean), axis=1) + curved)
        stretch = np.exp(eps) if self.hencky else 1.0 + eps
        return self.printed + t * inc, self.printed_length * stretch

    def gradient(
        self,
        c: FloatArray,
        v: FloatArray | None,
        products: FloatArray,
        rest_products: FloatArray,
    ) -> tuple[FloatArray, FloatArray]:
        """``d/dc`` and ``d/dv`` of ``sum(products * naturals) + sum(rest_products * rest)``
        at t = 1: ``(n_edges,)`` each (the second per mm/s).

        ``products`` ``(S, 3)`` and ``rest_products`` ``(E,)`` are e.g. the adjoint products
        ``lambda^T dg/d(natural)`` of :func:`rotomorph.rod.sensitivity.natural_sensitivity`.
        """
        v = self._speeds(v)
        wa, wb = self._weights(c)
        sig = self._sources(v)
        dw = np.array([0.5, -0.5])
        da = np.einsum("i,sj,sijkq,sq->sk", dw, wb, self.units, sig)
        db = np.einsum("si,j,sijkq,sq->sk", wa, dw, self.units, sig)
        gc = np.zeros(self.n_edges)
        gv = np.zeros(self.n_edges)
        np.add.at(gc, self.stencil_edges[:, 0], np.sum(products * da, axis=1))
        np.add.at(gc, self.stencil_edges[:, 1], np.sum(products * db, axis=1))
        # speeds of the two source edges of every stencil
        blended = np.einsum("si,sj,sijkq->skq", wa, wb, self.units)
        weights = np.einsum("sk,skq->sq", products, blended)
        for r in (0, 1):
            edge = self.stencil_edges[:, r]
            rates = self.chain.strain_rates(v[edge])
            np.add.at(gv, edge, np.sum(weights[:, 2 * r : 2 * r + 2] * rates, axis=1))
        # rest lengths: eps_c = units(omega*(ua, ub)) . strains(mean(ua, ub)), chain rule
        omega, mean, units = self._axial(v)
        sig_seg = self.chain.strains_at(mean)
        curved, d_mode, curved_units = self._curved(c, v)
        eps = np.sum(units * sig_seg, axis=1) + curved
        rest = self.printed_length * (np.exp(eps) if self.hencky else 1.0 + eps)
        d_rest = rest if self.hencky else self.printed_length
        d_mean = np.sum(units * self.chain.strains_at_rates(mean), axis=1)
        d_omega = np.zeros_like(omega)
        mixed = self._mixed
        if mixed.any():
            w = omega[mixed]
            h_w = _REL_STEP * np.maximum(np.abs(w), 1.0)
            du = (self.chain.axial_units(w + h_w) - self.chain.axial_units(w - h_w)) / (
                2 * h_w[:, None]
            )
            d_omega[mixed] = np.sum(du * sig_seg[mixed], axis=1)
        r_a, r_b = self.segment_rate[:, 0], self.segment_rate[:, 1]
        # omega = (ua ra + ub rb) / mean with mean = (ua + ub)/2
        dom_a = r_a / mean - 0.5 * omega / mean
        dom_b = r_b / mean - 0.5 * omega / mean
        w = rest_products * d_rest
        np.add.at(gv, self.segment_speed_edges[:, 0], w * (d_omega * dom_a + 0.5 * d_mean))
        np.add.at(gv, self.segment_speed_edges[:, 1], w * (d_omega * dom_b + 0.5 * d_mean))
        # the curved-section change: the segment's edge mode, each end vertex's speed
        np.add.at(gc, self.segment_edge, w * d_mode.sum(axis=1))
        for r in (0, 1):
            edge = self.segment_speed_edges[:, r]
            rates = self.chain.strain_rates(v[edge])  # the passive strain does not depend on v
            np.add.at(gv, edge, w * np.sum(curved_units[:, r, :2] * rates, axis=1))
        return gc, gv

    def rod(self, c: FloatArray, v: FloatArray | None = None, t: float = 1.0) -> Model:
        """The rod model at modes ``c``, speeds ``v`` (mm/s) and ramp fraction ``t``."""
        k, rest = self.natural(c, v, t)
        trial = self.model.with_natural(rest_length=rest)
        return trial.with_natural(
            curvature1=k[:, 0] / self.factor,
            curvature2=k[:, 1] / self.factor,
            twist=k[:, 2] / self.factor,
        )


def with_settings(
    lattice: Lattice, modes: FloatArray | dict[int, str], speeds: FloatArray | None = None
) -> Lattice:
    """``lattice`` printed with per-edge ``modes`` (±1 or a map edge → mode name) and, if
    given, per-edge ``speeds`` (mm/s); every other setting kept."""
    if isinstance(modes, dict):
        pattern: Any = modes
    else:
        pattern = {e: ("expanding" if m > 0 else "contracting") for e, m in enumerate(modes)}
    return sinusoidal_lattice(
        n=lattice.n,
        spacing=lattice.spacing,
        amplitude=lattice.amplitude,
        ghost_nodes=lattice.ghost_nodes,
        pattern=pattern,
        layers=lattice.layers,
        layer_height=lattice.layer_height,
        speed=lattice.speed,
        radius=lattice.radius,
        active_fraction=lattice.active_fraction,
        active_material=lattice.active_material,
        passive_material=lattice.passive_material,
        flip_length=lattice.flip_length,
        edge_speeds=None if speeds is None else [float(s) for s in speeds],
    )


def _values(model: Model) -> FloatArray:
    return np.stack(model.integrated_natural(), axis=1)


def _segment_edges(lattice: Lattice) -> IntArray:
    net = lattice.network
    seg_lookup = {(int(min(a, b)), int(max(a, b))): j for j, (a, b) in enumerate(net.edges)}
    out = np.full(net.n_edges, -1, dtype=np.int64)
    for e, chain in enumerate(lattice.edge_chains):
        for a, b in itertools.pairwise(chain):
            out[seg_lookup[(int(min(a, b)), int(max(a, b)))]] = e
    return out


def lattice_blend(
    lattice: Lattice, actuation: str | Actuation | None = None, *, seed: int = 0
) -> LatticeBlend:
    """Build the :class:`LatticeBlend` of ``lattice`` for the ``program`` actuation.

    The unit responses of every stencil for the four mode combinations of its two edges are
    read off the actuation with unit strains, on a few patterns (uniform ones, then random
    ones until every combination is seen); a combination seen twice must give the same values,
    else the actuation is not local to the two edges and the blend refuses it. Finally the
    blend is compared with the forward actuation at random modes and speeds.

    Raises
    ------
    InvalidParameterError
        An actuation other than ``program`` (the others do not follow per-edge speeds), or
        a blend that does not reproduce the forward actuation.
    """
    act = get_actuation(actuation if actuation is not None else "program")
    if not isinstance(act, ProgramActuation):
        raise InvalidParameterError(
            "actuation",
            f"inverse design follows the print program; use 'program', not {act.name!r}",
        )
    stiffness, fm = default_stiffness(act)
    fm = FilamentModel() if fm is None else fm
    measure = fm.strain_model.measure
    marked = [
        ProgramActuation(
            act.start,
            act.end,
            filament_model=replace(
                fm, strain_model=_MarkedStrains(*q, 1.0, measure), passive_strain=0.0
            ),
        )
        for q in ((1.0, 0.0), (0.0, 1.0))
    ]
    passive = ProgramActuation(
        act.start,
        act.end,
        filament_model=replace(
            fm, strain_model=_MarkedStrains(0.0, 0.0, 1.0, measure), passive_strain=1.0
        ),
    )
    segment_edge = _segment_edges(lattice)
    base = lattice_model(lattice, stiffness=stiffness, filament_model=fm)
    st = base.model.stencils
    pairs = np.stack([segment_edge[st.edge_e], segment_edge[st.edge_f]], axis=1)
    n_edges = len(lattice.edge_chains)
    printed = _values(base.model)
    # edges alternate between two classes along every printed line, so the two edges of a
    # pass-through pair are told apart by printing one class at the marker speed
    cls = np.zeros(n_edges, dtype=np.int64)
    for line in lattice.line_edges:
        cls[line] = np.arange(len(line)) % 2
    ca, cb = cls[pairs[:, 0]], cls[pairs[:, 1]]
    other = (ca != cb)[:, None]
    rows = np.arange(st.count)
    units = np.full((st.count, 2, 2, 3, 5), np.nan)
    rng = np.random.default_rng(seed)
    same = pairs[:, 0] == pairs[:, 1]
    # uniform patterns give every edge's own values, the alternating ones every pass-through
    # pair's mixed combinations; random ones follow only for combinations still unseen
    patterns = [np.zeros(n_edges, dtype=int), np.ones(n_edges, dtype=int), cls, 1 - cls]
    for _ in range(24):
        if not patterns:
            _zero_unactuated(units)
        if patterns:
            modes = patterns.pop(0)
        elif not np.isnan(units[~same]).any():
            break
        else:
            modes = rng.integers(0, 2, n_edges)
        sign = 1.0 - 2.0 * modes
        resp = np.empty((2, 2, st.count, 3))  # [class printed at the marker, strain, S, 3]
        for r in (0, 1):
            lat = with_settings(lattice, sign, np.where(cls == r, 1.0, 2.0))
            lm = lattice_model(lat, stiffness=stiffness, filament_model=fm)
            for q, a in enumerate(marked):
                resp[r, q] = _values(a.natural(lm, act.end)) - printed
        k = np.stack(
            [
                resp[ca, 0, rows],
                resp[ca, 1, rows],
                np.where(other, resp[cb, 0, rows], 0.0),
                np.where(other, resp[cb, 1, rows], 0.0),
                _values(passive.natural(lm, act.end)) - printed,
            ],
            axis=2,
        )
        ia, ib = modes[pairs[:, 0]], modes[pairs[:, 1]]
        seen = units[rows, ia, ib]
        known = ~np.isnan(seen[:, 0, 0])
        if np.any(np.abs(seen[known] - k[known]) > 1e-9 * (1 + np.abs(k[known]))):
            raise InvalidParameterError(
                "actuation",
                f"{act.name!r} is not local to the two edges of a junction; inverse design "
                "needs an actuation whose natural values depend on each edge's own modes",
            )
        units[rows, ia, ib] = k
    # inside one edge both modes move together: the off-diagonal combinations are the mean of
    # the diagonal ones, which makes the bilinear blend linear there (w+ + w- = 1)
    mean = 0.5 * (units[same, 0, 0] + units[same, 1, 1])
    units[same, 0, 1] = mean
    units[same, 1, 0] = mean
    if np.isnan(units).any():
        raise InvalidParameterError("lattice", "could not sample every mode combination")
    # where the speeds are: each stencil's vertex, each segment's two vertices
    speed_edges = lattice.line_speed_edges()
    n_seg = lattice.network.n_edges
    seg_speed = np.zeros((n_seg, 2), dtype=np.int64)
    seg_rate = np.zeros((n_seg, 2))
    for (prog, segs), vedges in zip(lattice.line_programs(), speed_edges, strict=True):
        rate = np.asarray(prog.director_rotation) / np.asarray(prog.speed)
        seg_speed[segs] = np.stack([vedges[:-1], vedges[1:]], axis=1)
        half = 0.5 * DIRECTOR_HELIX_SENSE * prog.radius * rate
        seg_rate[segs] = np.stack([half[:-1], half[1:]], axis=1)
    ones = np.ones(st.count)
    chain = _Chain(fm, lattice, float(act.end))
    seg_curved = _segment_curved(lattice, fm, float(act.end))
    single = seg_speed[:, 0] == seg_speed[:, 1]
    seg_units = np.full((n_seg, 3), np.nan)
    seg_units[single] = chain.axial_units(seg_rate[single].sum(axis=1))
    blend = LatticeBlend(
        lattice=lattice,
        model=base.model,
        printed=printed,
        units=units,
        stencil_edges=pairs,
        segment_edge=segment_edge,
        segment_speed_edges=seg_speed,
        segment_rate=seg_rate,
        segment_units=seg_units,
        segment_curved=seg_curved,
        speeds=lattice.speeds,
        chain=chain,
        factor=np.asarray(base.model.with_natural(curvature1=ones).integrated_natural()[0]),
        hencky=measure == "hencky",
    )
    _check_blend(blend, act, stiffness, fm, rng)
    return blend


def _segment_curved(lattice: Lattice, fm: FilamentModel, temperature: float) -> FloatArray:
    """``(E, 2, 2, 3)`` curved-section strain change of every segment from its vertex ``r``, for
    its edge expanding / contracting, per unit free strain (:attr:`LatticeBlend.segment_curved`):
    read off :func:`~rotomorph.materials.natural.actuation_increments` of every printed line
    with uniform modes and unit strain laws. An edge takes the mean of its interior ends."""
    out = np.zeros((lattice.network.n_edges, 2, 2, 3))
    n_edges = len(lattice.edge_chains)
    measure = fm.strain_model.measure
    laws = [
        replace(fm, strain_model=_MarkedStrains(1.0, 0.0, None, measure), passive_strain=0.0),
        replace(fm, strain_model=_MarkedStrains(0.0, 1.0, None, measure), passive_strain=0.0),
        replace(fm, strain_model=_MarkedStrains(0.0, 0.0, None, measure), passive_strain=1.0),
    ]
    for m, sign in enumerate((1.0, -1.0)):
        lat = with_settings(lattice, np.full(n_edges, sign), lattice.speeds)
        for q, law in enumerate(laws):
            for prog, segs in lat.line_programs():
                deps = actuation_increments(prog, temperature=temperature, model=law).curved_strain
                out[segs, 0, m, q], out[segs, 1, m, q] = edge_shares(deps)
    return out


def _zero_unactuated(units: FloatArray) -> None:
    """Fill the unseen combinations of stencils that no seen combination actuates (junction
    cross pairs keep their printed values whatever the modes) with zeros, in place."""
    seen = ~np.isnan(units[:, :, :, 0, 0])
    idle = np.array([np.all(units[s][seen[s]] == 0.0) for s in range(len(units))])
    units[idle & ~seen.all(axis=(1, 2))] = np.nan_to_num(units[idle & ~seen.all(axis=(1, 2))])


def _check_blend(
    blend: LatticeBlend, act: ProgramActuation, stiffness: Any, fm: FilamentModel, rng: Any
) -> None:
    """The blend at printable modes and random speeds equals the forward actuation."""
    lat = blend.lattice
    modes = rng.choice([-1.0, 1.0], blend.n_edges)
    speeds = lat.speed * rng.uniform(0.3, 1.0, blend.n_edges)
    ref = act.natural(
        lattice_model(with_settings(lat, modes, speeds), stiffness=stiffness, filament_model=fm),
        act.end,
    )
    k, rest = blend.natural(modes, speeds)
    ref_rest = np.asarray(ref.rest_length, dtype=float)
    scale = 1e-9 * (1.0 + np.max(np.abs(k)))
    if not (
        np.allclose(k, _values(ref), rtol=0.0, atol=scale)
        and np.allclose(rest, ref_rest, rtol=1e-12, atol=0.0)
    ):
        raise InvalidParameterError(
            "actuation",
            "the per-edge blend does not reproduce the forward actuation of this lattice "
            "(max natural error "
            f"{np.max(np.abs(k - _values(ref))):.3g}, rest length error "
            f"{np.max(np.abs(rest - ref_rest)):.3g} mm)",
        )

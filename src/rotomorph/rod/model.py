"""The discrete elastic rod model of a filament or a rod network.

One model serves both: a single filament is a network with one chain. Per-edge section
properties (bending stiffnesses ``B1`` toward the material director ``m1`` and ``B2`` toward
``m2``, twist stiffness ``C``, axial stiffness ``EA``) and per-stencil natural curvature and twist
are arrays fixed at construction; transforms return new models (:meth:`Model.with_natural`).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import cast

import numpy as np

from rotomorph._display import compact_display
from rotomorph._typing import FloatArray
from rotomorph.design.network import Network
from rotomorph.errors import InvalidParameterError
from rotomorph.geometry import pair_strains, space_parallel_directors
from rotomorph.rod.assembly import reference_twist
from rotomorph.rod.state import State
from rotomorph.rod.stencils import DofLayout, Stencils, build_stencils, dof_layout


def _per_item(name: str, value: object, n: int, positive: bool) -> FloatArray:
    arr = np.array(value, dtype=float)
    if arr.ndim == 0:
        arr = np.full(n, float(arr))
    if arr.shape != (n,):
        raise InvalidParameterError(
            f"Model.{name}", f"must be a scalar or have shape ({n},); got {arr.shape}"
        )
    bad = ~np.isfinite(arr)
    if bad.any():
        raise InvalidParameterError(
            f"Model.{name}", f"must be finite; entry {int(np.flatnonzero(bad)[0])} is not"
        )
    if positive and (arr <= 0).any():
        i = int(np.flatnonzero(arr <= 0)[0])
        raise InvalidParameterError(f"Model.{name}", f"must be > 0; got {arr[i]} at entry {i}")
    arr.setflags(write=False)
    return arr


def _default_directors(network: Network) -> FloatArray:
    deg = network.degree
    e = network.edges
    is_chain = (
        not network.branch.any()
        and deg.max() <= 2
        and np.array_equal(e, np.stack([np.arange(len(e)), np.arange(1, len(e) + 1)], axis=1))
    )
    if is_chain:
        return space_parallel_directors(network.nodes)
    if network.is_ring:  # transported once around the loop; the closing vertex takes the rest
        return space_parallel_directors(np.vstack([network.nodes, network.nodes[:1]]))
    t = network.nodes[e[:, 1]] - network.nodes[e[:, 0]]
    t /= np.linalg.norm(t, axis=1, keepdims=True)
    ref = np.where(np.abs(t[:, 2:3]) < 0.9, [[0.0, 0.0, 1.0]], [[1.0, 0.0, 0.0]])
    d = ref - np.sum(ref * t, axis=1, keepdims=True) * t
    return d / np.linalg.norm(d, axis=1, keepdims=True)


@compact_display()
@dataclass(frozen=True, eq=False)
class Model:
    """Discrete elastic rod model of a network (units: mm, N, MPa).

    Parameters
    ----------
    network
        Reference (printed) geometry and topology.
    bending_stiffness1, bending_stiffness2
        Per-edge bending stiffnesses ``B1`` (bending toward ``m1``) and ``B2`` (toward ``m2``),
        N mm²; scalars broadcast.
    twist_stiffness
        Per-edge torsional stiffness ``C`` (N mm²).
    axial_stiffness
        Per-edge axial stiffness ``EA`` (N); large values make the rod nearly inextensible.
    directors
        Per-edge material director ``m1`` in the reference configuration ``(E, 3)``; projected
        perpendicular to its edge and normalised. For a Janus filament, the interface normal
        pointing into the active half. Default: space-parallel (twist-free) frames for a chain,
        ``+z`` projected on each edge otherwise.
    natural_curvature1, natural_curvature2, natural_twist
        Per-stencil natural curvature toward ``m1``, toward ``m2`` and natural twist: turning
        and twist angle per unit *reference* (printed) arc length (1/mm). The rod uses the
        integrated values ``natural × reference Voronoi length`` (dimensionless angles), so
        they do not change when only the rest lengths do: a uniform natural strain of any
        printed shape is a similarity. Default: those of the reference configuration
        (stress-free as printed).
    rest_length
        Per-edge natural length (mm). Default: reference lengths.

    Notes
    -----
    Junction (branch-node pair) stencils use the isotropic mean ``(B1+B2)/2`` of both edges,
    since the anisotropy axes of two crossing filaments need not align.
    """

    network: Network
    bending_stiffness1: FloatArray | float
    bending_stiffness2: FloatArray | float
    twist_stiffness: FloatArray | float
    axial_stiffness: FloatArray | float
    directors: FloatArray | None = None
    natural_curvature1: FloatArray | None = None
    natural_curvature2: FloatArray | None = None
    natural_twist: FloatArray | None = None
    rest_length: FloatArray | None = None
    stencils: Stencils = field(init=False, repr=False)
    layout: DofLayout = field(init=False, repr=False)

    def __post_init__(self) -> None:
        net = self.network
        ne = net.n_edges
        set_ = object.__setattr__
        for name in (
            "bending_stiffness1",
            "bending_stiffness2",
            "twist_stiffness",
            "axial_stiffness",
        ):
            set_(self, name, _per_item(name, getattr(self, name), ne, positive=True))
        st = build_stencils(net)
        set_(self, "stencils", st)
        set_(self, "layout", dof_layout(net))
        t = net.nodes[net.edges[:, 1]] - net.nodes[net.edges[:, 0]]
        t = t / np.linalg.norm(t, axis=1, keepdims=True)
        d = (
            _default_directors(net)
            if self.directors is None
            else np.array(self.directors, dtype=float)
        )
        if d.shape != (ne, 3) or not np.isfinite(d).all():
            raise InvalidParameterError(
                "Model.directors", f"must be a finite array of shape ({ne}, 3)"
            )
        d = d - np.sum(d * t, axis=1, keepdims=True) * t
        norm = np.linalg.norm(d, axis=1)
        if (norm < 1e-9).any():
            raise InvalidParameterError(
                "Model.directors",
                f"director {int(np.argmin(norm))} is parallel to its edge; give one across it",
            )
        d = d / norm[:, None]
        d.setflags(write=False)
        set_(self, "directors", d)
        rest = net.edge_lengths if self.rest_length is None else self.rest_length
        set_(self, "rest_length", _per_item("rest_length", rest, ne, positive=True))
        k1, k2, tw = self._reference_integrated()
        for name, ref in (
            ("natural_curvature1", k1),
            ("natural_curvature2", k2),
            ("natural_twist", tw),
        ):
            value = getattr(self, name)
            if value is None:
                value = ref / self._reference_voronoi()
            set_(self, name, _per_item(name, value, st.count, positive=False))

    # ------------------------------------------------------------------ geometry helpers
    def _reference_voronoi(self) -> FloatArray:
        lengths = self.network.edge_lengths
        return 0.5 * (lengths[self.stencils.edge_e] + lengths[self.stencils.edge_f])

    def _reference_integrated(self) -> tuple[FloatArray, FloatArray, FloatArray]:
        st, x = self.stencils, self.network.nodes
        e = x[st.nodes[:, 1]] - x[st.nodes[:, 0]]
        f = x[st.nodes[:, 2]] - x[st.nodes[:, 1]]
        d = cast(FloatArray, self.directors)  # set to an array by __post_init__
        return pair_strains(e, f, d[st.edge_e], d[st.edge_f])

    @property
    def voronoi_length(self) -> FloatArray:
        """Per-stencil Voronoi length of rest lengths ``(S,)`` (mm)."""
        r = cast(FloatArray, self.rest_length)  # set to an array by __post_init__
        return 0.5 * (r[self.stencils.edge_e] + r[self.stencils.edge_f])

    @property
    def stencil_stiffness(self) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Per-stencil ``(B1, B2, C)`` (N mm²): edge means; isotropic at junctions."""
        st = self.stencils
        # per-edge arrays once __post_init__ has run
        s1 = cast(FloatArray, self.bending_stiffness1)
        s2 = cast(FloatArray, self.bending_stiffness2)
        sc = cast(FloatArray, self.twist_stiffness)
        b1 = 0.5 * (s1[st.edge_e] + s1[st.edge_f])
        b2 = 0.5 * (s2[st.edge_e] + s2[st.edge_f])
        c = 0.5 * (sc[st.edge_e] + sc[st.edge_f])
        iso = 0.5 * (b1 + b2)
        b1 = np.where(st.junction, iso, b1)
        b2 = np.where(st.junction, iso, b2)
        return b1, b2, c

    def integrated_natural(self) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Natural ``(kappa1, kappa2, tau)`` per stencil, integrated (dimensionless).

        Natural turning and twist angles are material quantities: the pointwise values are per
        unit reference length, so they are integrated over the reference Voronoi length, not
        over the (possibly strained) rest lengths. Multiplying a per-length value by a length
        other than the one it was divided by would make a curved filament lose turning angle
        when its centre-line merely contracts.
        """
        v = self._reference_voronoi()
        # the natural fields are arrays once __post_init__ has run
        k1 = cast(FloatArray, self.natural_curvature1)
        k2 = cast(FloatArray, self.natural_curvature2)
        tw = cast(FloatArray, self.natural_twist)
        return k1 * v, k2 * v, tw * v

    def reference_strains(self) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Pointwise curvatures and twist of the reference configuration (1/mm), per stencil."""
        k1, k2, tw = self._reference_integrated()
        v = self._reference_voronoi()
        return k1 / v, k2 / v, tw / v

    # ------------------------------------------------------------------ transforms
    def with_natural(
        self,
        curvature1: FloatArray | None = None,
        curvature2: FloatArray | None = None,
        twist: FloatArray | None = None,
        rest_length: FloatArray | None = None,
    ) -> Model:
        """A copy with new natural curvatures, twist (1/mm, per stencil) or rest lengths (mm).

        Curvatures and twist are per unit reference length (class docstring): changing only
        ``rest_length`` keeps every natural turning angle. Arguments left ``None`` keep their
        current values.
        """
        return replace(
            self,
            natural_curvature1=self.natural_curvature1 if curvature1 is None else curvature1,
            natural_curvature2=self.natural_curvature2 if curvature2 is None else curvature2,
            natural_twist=self.natural_twist if twist is None else twist,
            rest_length=self.rest_length if rest_length is None else rest_length,
        )

    def reference_state(self) -> State:
        """The printed configuration: reference positions, zero twist angles, set-up frames."""
        net = self.network
        x = np.array(net.nodes, dtype=float)
        t = x[net.edges[:, 1]] - x[net.edges[:, 0]]
        t /= np.linalg.norm(t, axis=1, keepdims=True)
        st = self.stencils
        mref = np.empty(st.count)
        reference_twist(
            np.stack([st.edge_e, st.edge_f], axis=1),
            np.stack([st.sign_e, st.sign_f], axis=1),
            t,
            np.array(self.directors),
            np.zeros(st.count),
            mref,
        )
        return State(
            positions=x,
            theta=np.zeros(net.n_edges),
            tangents=t,
            directors=np.array(self.directors),
            reference_twist=mref,
        )

    @classmethod
    def from_field(cls, points: FloatArray, field: object) -> Model:
        """A printed filament through ``points`` ``(N, 3)`` (mm) with a natural ``field``.

        ``field`` is a :class:`rotomorph.materials.natural.NaturalField` (or anything with its
        attributes): per-edge ``directors``, stiffnesses and ``rest_length``, per-vertex
        ``curvature1``, ``curvature2`` and ``twist`` (1/mm).
        """
        f = field
        return cls.chain(
            np.asarray(points, dtype=float),
            bending_stiffness1=f.bending_stiffness1,  # type: ignore[attr-defined]
            bending_stiffness2=f.bending_stiffness2,  # type: ignore[attr-defined]
            twist_stiffness=f.twist_stiffness,  # type: ignore[attr-defined]
            axial_stiffness=f.axial_stiffness,  # type: ignore[attr-defined]
            directors=f.directors,  # type: ignore[attr-defined]
            natural_curvature1=f.curvature1,  # type: ignore[attr-defined]
            natural_curvature2=f.curvature2,  # type: ignore[attr-defined]
            natural_twist=f.twist,  # type: ignore[attr-defined]
            rest_length=f.rest_length,  # type: ignore[attr-defined]
        )

    @classmethod
    def chain(cls, points: FloatArray, **kwargs: object) -> Model:
        """A single filament through ``points`` ``(N, 3)`` (mm); keywords as for :class:`Model`."""
        return cls(Network.chain(points), **kwargs)  # type: ignore[arg-type]

    @classmethod
    def ring(cls, points: FloatArray, **kwargs: object) -> Model:
        """A closed filament through ``points`` ``(N, 3)`` (mm), the last joined to the first.

        Keywords as for :class:`Model`; per-stencil natural fields have ``N`` entries, entry
        ``k`` at node ``k`` (a chain has ``N - 2``, at its interior nodes). The default
        directors are transported parallel along the loop from the first segment; where they
        return to it rotated (the loop's holonomy), the closing vertex's reference twist carries
        the difference, so the printed ring is stress-free with the default natural twist.
        """
        return cls(Network.ring(points), **kwargs)  # type: ignore[arg-type]

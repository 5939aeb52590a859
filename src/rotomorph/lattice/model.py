r"""The discrete-elastic-rod model of a printed sinusoidal lattice.

Directors
---------
The rod model's material director is ``m1 = +z`` on every segment (the printed sheet's normal),
*not* the interface normal n. Reason: n flips by π at every inflection (each branch node and
mid-edge), and the DER curvature of a stencil is measured in the *average* of its two edges'
frames (Bergou et al. 2010), which vanishes when the two directors differ by π
(``m2e + m2f = 0``): such a stencil has no bending stiffness at all. With ``m1 = n`` the paper's
5 × 5 lattice has 8 spurious zero-energy modes besides the 6 rigid motions (pass-through and
cross junction pairs at τ = π), odd ``ghost_nodes`` many more; with ``m1 = +z`` every printed
twist is 0 and only the 6 rigid modes remain (tested). n is still what the physics uses:
:func:`interface_normals` gives it (the design layer's α rotated from +z; ``+z`` on a segment
that contains the mid-edge flip, where the nozzle is half way through its π rotation), the
anisotropic ``"janus"`` stiffness pairs B_n with bending toward n (B2 on in-plane-n segments,
B1 on flip segments) and the actuation adds curvature toward the active side (below).

Where the active side acts
--------------------------
Actuation is a natural-curvature increment *toward the active side* at every rod vertex
(junction pairs keep their printed values). The flip inside a segment is treated as
a step at the segment's midpoint, which is exactly the boundary between the Voronoi regions of
its two end nodes: each such vertex takes the side of its other (non-flip) segment. A vertex
whose two segments lie on opposite sides (flip at a node) gets side 0 (no increment).

The increment of a pointwise curvature K toward the in-plane side direction
:math:`n_s = s\,(\hat z \times \hat t)` (s = ±1, :math:`\hat t` the printed bisector) is the
integrated curvature binormal :math:`\Delta(\kappa b) = \bar l K\,(\hat t \times n_s)`, projected
on the stencil's averaged material frames exactly as the rod kernels do
(:func:`rotomorph.geometry.pair_strains`): :math:`\Delta\kappa_1 = \tfrac12\Delta(\kappa b)
\cdot(m_2^e + m_2^f)`, :math:`\Delta\kappa_2 = -\tfrac12\Delta(\kappa b)\cdot(m_1^e + m_1^f)`.
:func:`active_side_basis` returns these per unit K.

Stiffness
---------
``"paper"``: isotropic circular section of radius R, B1 = B2 = E πR⁴/4, C = G πR⁴/2 with
G = E/3 (ν = ½; the paper's "diameter a" corrected), EA = E πR².
``"janus"``: B_n (toward m1 = n), B_η, C, EA of the meshed Janus section of
:mod:`rotomorph.materials` at the calibrated actuation modulus ratio, for one printed layer.

Stacked layers
--------------
A lattice printed in N layers (the paper's are three) stacks N copies of every edge at
heights z_k = k h (``layer_height``), each cured onto the one below. With the ``"janus"``
section the rod is that stack on its mid-height centre line, and its section is the fused
stack itself (:mod:`rotomorph.materials.stack`: N Janus disks of radius R, centres h apart,
bonded on a line where h = 2R and fused over the lens where h < 2R): the axial stiffness,
the bending stiffness about both axes and the torsion constant (Saint-Venant, with warping)
of that one section. Where the layers touch on a line (h = 2R, the default) this is the
bonded composite beam (Gere & Goodno, *Mechanics of Materials*, ch. 6):

* bending in the plane (about the vertical axis) and axial stiffness add: N B_in, N EA;
* bending out of the plane (toward z) adds each layer's own stiffness and its axial stiffness
  times the squared distance from the stack's mid-plane (parallel-axis theorem):
  B_z = N B_z,layer + EA Σ_k (z_k − z̄)²; for three layers at h = 2R this is about 12 × the
  in-plane value, so the stack resists curling out of its plane far more than one filament;
* twist: N C (no shear is carried across a line); overlapping layers fuse and twist stiffer
  (1.3 × N C at h = 0.83 · 2R);
* natural strains (:mod:`rotomorph.lattice.actuation`, ``program``): each layer's print
  program gives its eigenstrain field, and the stack's natural curvature, twist and
  centre-line strain are those of the fused section under all of them. A natural curvature
  toward z (where the interface turns through the horizontal) is resisted by the other
  layers' axial stiffness: for touching layers the stack takes the stiffness-weighted share
  N B_z,layer / B_z of one layer's (:attr:`LatticeModel.vertical_share`, used by the
  actuations that add one curvature to every edge; 1 for one layer).

With ``"paper"`` (the paper's own simulation: one circular filament) ``layers`` only
multiplies every stiffness, which does not change unloaded shapes.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Literal

import numpy as np

from rotomorph._typing import BoolArray, FloatArray, IntArray
from rotomorph.design.lattices import Lattice
from rotomorph.design.network import Network
from rotomorph.errors import InvalidParameterError
from rotomorph.geometry import rotate_about_tangent, unit
from rotomorph.materials.material import get_material
from rotomorph.materials.natural import FilamentModel, LayerStack
from rotomorph.rod.model import Model

__all__ = [
    "LatticeModel",
    "Stiffness",
    "active_side_basis",
    "edge_model",
    "interface_normals",
    "lattice_model",
    "paper_modulus",
    "stack_geometry",
    "stack_moment",
    "stencil_sides",
]

Stiffness = Literal["paper", "janus"]


def interface_normals(lattice: Lattice) -> FloatArray:
    """Interface normal n (into the active half) per segment ``(E, 3)``, printed state.

    +z rotated by the design interface angle α about each printed segment tangent; ``+z`` on
    flip segments (α = 0). Not used as the rod director (module docstring).
    """
    net = lattice.network
    t = unit(net.nodes[net.edges[:, 1]] - net.nodes[net.edges[:, 0]])
    z = np.broadcast_to([0.0, 0.0, 1.0], t.shape)
    return rotate_about_tangent(z, t, lattice.interface_angle)


def paper_modulus(filament_model: FilamentModel | None = None) -> float:
    """Mean Janus modulus (E_a + E_p)/2 at actuation (MPa), the default E of ``"paper"``.

    Only stiffness ratios matter for unloaded lattices; this value makes gravity comparable
    between the two stiffness options.
    """
    fm = FilamentModel() if filament_model is None else filament_model
    e_a, e_p = fm.moduli(get_material("lce"), get_material("acrylate"))
    return 0.5 * (e_a + e_p)


def stack_moment(layers: int, layer_height: float) -> float:
    """Σ_k (z_k − z̄)² of ``layers`` centre lines ``layer_height`` apart (mm²).

    The parallel-axis factor of a bonded stack: its out-of-plane bending stiffness exceeds the
    sum of the layers' own by this times one layer's axial stiffness. 0 for one layer.
    """
    z = layer_height * (np.arange(layers) - 0.5 * (layers - 1))
    return float(np.sum(z**2))


def stack_geometry(lattice: Lattice, direction: tuple[float, float]) -> LayerStack:
    """The printed stack of ``lattice`` for the materials layer, stacked along ``direction``
    of the layers' interface frame: (0, 1) where the interface normal lies in the sheet,
    (1, 0) where it is the sheet normal (a flip segment)."""
    return LayerStack(int(lattice.layers), float(lattice.layer_height), direction)


def _stack_stiffness(
    lattice: Lattice, fm: FilamentModel | None
) -> tuple[tuple[float, float, float, float], tuple[float, float, float, float]]:
    """(B toward z, B in the plane, C, EA) of the fused stack for segments whose interface
    normal lies in the sheet and for flip segments (normal along z)."""
    fm = FilamentModel() if fm is None else fm
    active, passive = get_material(lattice.active_material), get_material(lattice.passive_material)
    out = []
    for direction, toward_z in (((0.0, 1.0), 1), ((1.0, 0.0), 0)):
        sec = fm.section(
            active,
            passive,
            lattice.radius,
            lattice.active_fraction,
            stack=stack_geometry(lattice, direction),
        )
        i = sec.axial.bending_matrix
        out.append(
            (
                float(i[toward_z, toward_z]),
                float(i[1 - toward_z, 1 - toward_z]),
                sec.twist_stiffness,
                sec.axial_stiffness,
            )
        )
    return out[0], out[1]


def _stiffness(
    lattice: Lattice, stiffness: str, youngs_modulus: float | None, fm: FilamentModel | None
) -> tuple[float, float, float, float]:
    r = lattice.radius
    if stiffness == "paper":
        e = paper_modulus(fm) if youngs_modulus is None else float(youngs_modulus)
        if not (np.isfinite(e) and e > 0):
            raise InvalidParameterError("youngs_modulus", f"must be > 0 MPa; got {e}")
        b = e * np.pi * r**4 / 4.0
        c = (e / 3.0) * np.pi * r**4 / 2.0
        return b, b, c, e * np.pi * r**2
    if stiffness == "janus":
        if youngs_modulus is not None:
            raise InvalidParameterError(
                "youngs_modulus", "is only used with stiffness='paper'; set FilamentModel instead"
            )
        fm = FilamentModel() if fm is None else fm
        sec = fm.section(
            fm.material(lattice.active_material),
            fm.material(lattice.passive_material),
            r,
            lattice.active_fraction,
        )
        return (
            sec.bending_stiffness1,
            sec.bending_stiffness2,
            sec.twist_stiffness,
            sec.axial_stiffness,
        )
    raise InvalidParameterError("stiffness", f"must be 'paper' or 'janus'; got {stiffness!r}")


def stencil_sides(segment_side: IntArray | FloatArray, model: Model) -> FloatArray:
    """Active side (+1 left, −1 right, 0 none) of every stencil ``(S,)`` (module docstring).

    Parameters
    ----------
    segment_side
        Active side per network segment (+1 left, −1 right, 0 flip inside the segment), as
        :attr:`rotomorph.design.lattices.Lattice.segment_side`.
    model
        The rod model of the same network.

    Junction stencils get 0 (their natural values stay printed).
    """
    st = model.stencils
    side = np.asarray(segment_side, dtype=float)
    se, sf = side[st.edge_e], side[st.edge_f]
    out = np.where(se == 0, sf, np.where(sf == 0, se, np.where(se == sf, se, 0.0)))
    return np.where(st.junction, 0.0, out)


def active_side_basis(
    segment_side: IntArray | FloatArray, model: Model
) -> tuple[FloatArray, FloatArray]:
    """Per-stencil ``(Δκ1, Δκ2)`` of a unit pointwise curvature toward the active side.

    Computed in the printed configuration with the model's directors (module docstring);
    zero on junction stencils and on vertices with no active side.
    """
    st = model.stencils
    x = model.network.nodes
    te = unit(x[st.nodes[:, 1]] - x[st.nodes[:, 0]])
    tf = unit(x[st.nodes[:, 2]] - x[st.nodes[:, 1]])
    m1 = np.asarray(model.directors)
    m1e, m1f = m1[st.edge_e], m1[st.edge_f]
    m2e, m2f = np.cross(te, m1e), np.cross(tf, m1f)
    bis = unit(te + tf)
    side = stencil_sides(segment_side, model)
    n_s = side[:, None] * np.cross([0.0, 0.0, 1.0], bis)
    dkb = np.cross(bis, n_s)  # per unit curvature and unit Voronoi length
    b1 = 0.5 * np.einsum("ij,ij->i", dkb, m2e + m2f)
    b2 = -0.5 * np.einsum("ij,ij->i", dkb, m1e + m1f)
    return b1, b2


@dataclass(frozen=True, eq=False)
class LatticeModel:
    """A lattice with its printed (stress-free) rod model and per-stencil actuation data.

    Attributes
    ----------
    lattice
        The design.
    model
        Rod model of the printed lattice (natural values = printed).
    printed
        Printed pointwise ``(κ1, κ2, τ)`` per stencil (1/mm).
    expanding
        ``(S,)`` True on rod vertices of expanding (active outer) edges.
    rod_vertex
        ``(S,)`` True on ordinary rod vertices (False on junction pairs).
    side_basis
        ``(Δκ1, Δκ2)`` per unit curvature toward the active side (:func:`active_side_basis`).
    segments
        ``(E,)`` the lattice network segment each model edge is (all of them for
        :func:`lattice_model`, one edge's for :func:`edge_model`).
    vertical_share
        ``(S,)`` share of each stencil's out-of-plane bending stiffness that is the layers' own
        (module docstring, *Stacked layers*): a natural curvature toward z of one layer is this
        fraction of the stack's. 1 for one layer or the ``"paper"`` stiffness.
    stacked
        The rod's section is the fused stack of ``lattice.layers`` Janus layers (``"janus"``
        stiffness, more than one layer): an actuation from the print programs solves that
        section (:func:`stack_geometry`).
    """

    lattice: Lattice
    model: Model
    printed: tuple[FloatArray, FloatArray, FloatArray]
    expanding: BoolArray
    rod_vertex: BoolArray
    side_basis: tuple[FloatArray, FloatArray]
    segments: IntArray | None = None
    vertical_share: FloatArray | None = None
    stacked: bool = False

    def vertical(self, dk1: FloatArray) -> FloatArray:
        """One layer's natural-curvature increment toward z (κ1) as the stack's (1/mm)."""
        return dk1 if self.vertical_share is None else self.vertical_share * dk1


def _build(
    lattice: Lattice,
    network: Network,
    segments: IntArray,
    stiffness: str,
    youngs_modulus: float | None,
    filament_model: FilamentModel | None,
    layers: int | None,
) -> LatticeModel:
    n_layers = lattice.layers if layers is None else layers
    if int(n_layers) != n_layers or n_layers < 1:
        raise InvalidParameterError("layers", f"must be an integer >= 1; got {layers}")
    b_n, b_eta, c, ea = _stiffness(lattice, stiffness, youngs_modulus, filament_model)
    side = lattice.segment_side[segments]
    # m1 = +z: bending toward z is about the in-plane axis, i.e. toward the section's eta axis
    # where n lies in the plane, toward n itself on flip segments (n = +z)
    b1 = np.where(side == 0, b_n, b_eta)
    b2 = np.where(side == 0, b_eta, b_n)
    n_layers = int(n_layers)
    stacked = stiffness == "janus" and n_layers > 1
    if stacked:  # the fused stack as one section (module docstring)
        geo = replace(lattice, layers=n_layers, _cache={})
        (bz_in, bp_in, c_in, ea_in), (bz_f, bp_f, c_f, ea_f) = _stack_stiffness(geo, filament_model)
        b_vertical = np.where(side == 0, bz_f, bz_in)
        b_plane = np.where(side == 0, bp_f, bp_in)
        twist = np.where(side == 0, c_f, c_in)
        axial = np.where(side == 0, ea_f, ea_in)
    else:  # one layer, or the paper's isotropic section times the layers
        b_vertical, b_plane = n_layers * b1, n_layers * b2
        twist, axial = np.full(len(side), n_layers * c), np.full(len(side), n_layers * ea)
    model = Model(
        network,
        bending_stiffness1=b_vertical,
        bending_stiffness2=b_plane,
        twist_stiffness=twist,
        axial_stiffness=axial,
        directors=np.tile([0.0, 0.0, 1.0], (len(segments), 1)),
    )
    st = model.stencils
    share = n_layers * b1 / b_vertical
    vertical_share = 0.5 * (share[st.edge_e] + share[st.edge_f])
    vertical_share.setflags(write=False)
    mode = np.asarray(lattice.segment_mode)  # a property built on every access: read it once
    seg_expanding = mode[segments] == "expanding"
    rod_vertex = ~np.asarray(st.junction, dtype=bool)
    expanding = rod_vertex & seg_expanding[st.edge_e]
    for arr in (expanding, rod_vertex):
        arr.setflags(write=False)
    return LatticeModel(
        lattice=lattice,
        model=model,
        printed=model.reference_strains(),
        expanding=expanding,
        rod_vertex=rod_vertex,
        side_basis=active_side_basis(side, model),
        segments=segments,
        vertical_share=vertical_share,
        stacked=stacked,
    )


def lattice_model(
    lattice: Lattice,
    *,
    stiffness: Stiffness = "paper",
    youngs_modulus: float | None = None,
    filament_model: FilamentModel | None = None,
    layers: int | None = None,
) -> LatticeModel:
    """Build the rod model of a printed lattice (module docstring): directors +z.

    Parameters
    ----------
    lattice
        A lattice from :func:`rotomorph.design.lattices.sinusoidal_lattice`.
    stiffness
        ``"paper"`` (isotropic, E πR⁴/4, G = E/3) or ``"janus"`` (materials layer).
    youngs_modulus
        E (MPa) for ``"paper"``; default :func:`paper_modulus`.
    filament_model
        Materials modelling choices for ``"janus"`` (and the default E); default
        :class:`~rotomorph.materials.natural.FilamentModel`.
    layers
        Printed layers stacked on every edge; default ``lattice.layers``. With ``"janus"`` a
        bonded stack (module docstring); with ``"paper"`` a stiffness multiplier, shape-neutral
        without external loads.

    Raises
    ------
    InvalidParameterError
        Unknown stiffness option, non-positive modulus or layers.
    """
    segments = np.arange(lattice.network.n_edges)
    return _build(
        lattice, lattice.network, segments, stiffness, youngs_modulus, filament_model, layers
    )


def edge_model(
    lattice: Lattice,
    edge: int = 0,
    *,
    stiffness: Stiffness = "paper",
    youngs_modulus: float | None = None,
    filament_model: FilamentModel | None = None,
    layers: int | None = None,
) -> LatticeModel:
    """The rod model of one lattice edge printed alone: a free sinusoid (paper Fig. 3C/D).

    Same directors, active sides, mode and stiffness as lattice edge ``edge`` of ``lattice``
    (keywords as :func:`lattice_model`); the returned model's network is that edge's chain,
    nodes renumbered ``0 .. n_g+1``.

    Raises
    ------
    InvalidParameterError
        ``edge`` outside the lattice's edges, or as :func:`lattice_model`.
    """
    n_edges = len(lattice.edge_chains)
    if int(edge) != edge or not 0 <= edge < n_edges:
        raise InvalidParameterError("edge", f"must be an integer in [0, {n_edges - 1}]; got {edge}")
    per = lattice.ghost_nodes + 1
    segments = np.arange(edge * per, (edge + 1) * per)
    chain = lattice.edge_chains[edge]
    network = Network.chain(lattice.network.nodes[chain])
    return _build(lattice, network, segments, stiffness, youngs_modulus, filament_model, layers)

r"""Heating ramps of printed lattices: quasi-static continuation from the flat printed state.

:func:`heat_lattice` ramps an actuation (:mod:`rotomorph.lattice.actuation`) in equal steps,
re-equilibrating each step from the previous equilibrium
(:func:`rotomorph.solve.continuation.continuation`, halving failed steps). Symmetry breaking is
deterministic: the first step starts from the printed state plus an out-of-plane perturbation
``perturbation · l · (bump + 0.25 · noise)`` with a centred Gaussian bump (height 1, width a
third of the lattice) and seeded normal noise. Which *side* a dome rises to may depend on the
seed; the sign of the Gaussian curvature must not (tested on several seeds).

Measurements per step (index 0 = the flat printed state): the normalised projected area of the
boundary loop (paper Fig. 3G), the quadratic-surface fit of the branch nodes (Gaussian sign and
characteristic curvature √|k₁k₂|, Fig. 4), the mean edge strain and every edge's end-to-end
ratio (Fig. 4C/F "strain"), and the smallest distance between non-adjacent
segments relative to the filament diameter, ignoring pairs already closer than a diameter as
printed (fused at junctions). Without ``contact`` filaments may pass through each other: values
< 1 mean they overlap and ``min_clearance`` ≈ 0 flags filaments crossing. With ``contact`` or
``floor`` they touch instead (:mod:`rotomorph.contact`), and a lattice resting on the floor
under its weight takes a lifted equilibrium where one is lower in energy (``branch``).
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Any, Literal

import numpy as np
from scipy.spatial import cKDTree

from rotomorph._display import compact_display
from rotomorph._typing import FloatArray, IntArray
from rotomorph.analysis.area import lattice_boundary_loop, normalized_area
from rotomorph.analysis.curvature import fit_quadratic_surface
from rotomorph.analysis.shape import edge_end_to_end_ratios, end_to_end_ratio
from rotomorph.contact import Contact, Floor, InfeasibleContactError
from rotomorph.contact.stacked import StackedContact
from rotomorph.design.lattices import Lattice
from rotomorph.errors import ConvergenceError, InvalidParameterError
from rotomorph.geometry import parallel_transport, unit
from rotomorph.lattice.actuation import (
    DEFAULT_ACTUATION,
    Actuation,
    default_stiffness,
    get_actuation,
    ramp_value_text,
)
from rotomorph.lattice.admissibility import admissibility, lattice_stack, overlap_counts
from rotomorph.lattice.model import LatticeModel, Stiffness, edge_model, lattice_model
from rotomorph.lattice.paths import (
    SAME_SHAPE_TOL,
    PathCheck,
    check_factor,
    choose_end,
    per_row,
    shape_distance,
    sub_stepped,
)
from rotomorph.lattice.resting import resting_rotation
from rotomorph.rod.assembly import reference_twist
from rotomorph.rod.model import Model
from rotomorph.rod.state import State
from rotomorph.solve.continuation import ContinuationResult, ContinuationStep, continuation
from rotomorph.solve.loads import Gravity, Loads, Supports
from rotomorph.solve.newton import NewtonOptions
from rotomorph.solve.objective import RodObjective
from rotomorph.solve.result import Status
from rotomorph.solve.stability import StabilityResult, stability
from rotomorph.solve.static import StaticResult, solve_static

__all__ = [
    "FRICTION_LAG_TOL",
    "FRICTION_RELAGS",
    "HeatingResult",
    "free_edge_ratio",
    "fused_pairs",
    "heat_lattice",
    "lattice_gravity",
    "perturbed_state",
    "relag_friction",
    "segment_clearance",
]

#: Newton settings of ramp steps: a residual of 1e-7 of the force scale is far below what the
#: shape measures resolve, and it lets Newton stop near a bifurcation from the flat state, where
#: the Hessian is nearly singular and convergence turns linear (a step at the saddle's onset
#: took > 200 iterations at the solver's default 1e-9).
#: Every step is certified stable; the lowest Hessian eigenvalue is kept (one is enough to
#: see a bifurcation coming and costs one shift-invert Lanczos run).
RAMP_OPTIONS = NewtonOptions(rtol=1e-7, max_iterations=300, eigenvalues=1)

SupportsName = Literal["free", "clamped-boundary", "pinned-centre"]

#: Phase messages of long lattice runs (a command line shows them; silent by default).
phase_log = logging.getLogger("rotomorph.progress")
logger = logging.getLogger(__name__)


def perturbed_state(model: Model, dz: FloatArray, base: State | None = None) -> State:
    """``base`` (default the printed state) with node heights raised by ``dz`` ``(N,)`` (mm).

    ``dz`` may also be a full displacement ``(N, 3)`` (mm). Tangents are recomputed, reference
    directors parallel-transported from the base tangents, twist angles kept and reference
    twists unwrapped against the base ones, so the material frames follow without twisting.
    """
    ref = model.reference_state() if base is None else base
    dz = np.asarray(dz, dtype=float)
    n = model.network.n_nodes
    if dz.shape not in ((n,), (n, 3)) or not np.all(np.isfinite(dz)):
        raise InvalidParameterError(
            "dz", f"must be finite with shape ({n},) or ({n}, 3) mm; got {dz.shape}"
        )
    pos = ref.positions.copy()
    if dz.ndim == 1:
        pos[:, 2] += dz
    else:
        pos += dz
    edges = model.network.edges
    t = unit(pos[edges[:, 1]] - pos[edges[:, 0]])
    d1 = unit(parallel_transport(ref.directors, ref.tangents, t))
    st = model.stencils
    mref = np.empty(st.count)
    reference_twist(
        np.stack([st.edge_e, st.edge_f], axis=1),
        np.stack([st.sign_e, st.sign_f], axis=1),
        t,
        d1,
        ref.reference_twist,
        mref,
    )
    return replace(ref, positions=pos, tangents=t, directors=d1, reference_twist=mref)


def symmetry_breaking(lattice: Lattice, amplitude: float, seed: int) -> FloatArray:
    """Out-of-plane perturbation ``(N,)`` (mm): ``amplitude · (bump + 0.25 · noise)``."""
    x = lattice.network.nodes
    centre = x[lattice.branch_indices].mean(axis=0)
    size = lattice.spacing * (lattice.n - 1)
    r2 = np.sum((x[:, :2] - centre[:2]) ** 2, axis=1)
    bump = np.exp(-0.5 * r2 / (size / 3.0) ** 2)
    noise = np.random.default_rng(seed).standard_normal(len(x))
    return amplitude * (bump + 0.25 * noise)


def _pair_distances(
    positions: FloatArray, edges: IntArray, reach: float
) -> tuple[IntArray, FloatArray]:
    """Segment pairs sharing no node whose midpoints lie within ``reach`` plus the longest
    segment, with their exact distances (clamped closest points) (mm)."""
    p0 = positions[edges[:, 0]]
    u = positions[edges[:, 1]] - p0
    mid = p0 + 0.5 * u
    r = reach + float(np.linalg.norm(u, axis=1).max())
    pairs = cKDTree(mid).query_pairs(r, output_type="ndarray").reshape(-1, 2)
    share = (edges[pairs[:, 0]][:, :, None] == edges[pairs[:, 1]][:, None, :]).any(axis=(1, 2))
    pairs = pairs[~share]
    i, j = pairs[:, 0], pairs[:, 1]
    a, b = u[i], u[j]
    w = p0[i] - p0[j]
    aa, bb, ab = (np.einsum("ij,ij->i", *v) for v in ((a, a), (b, b), (a, b)))
    aw, bw = np.einsum("ij,ij->i", a, w), np.einsum("ij,ij->i", b, w)
    den = aa * bb - ab**2
    ok = den > 1e-12 * aa * bb
    s = np.clip(np.where(ok, (ab * bw - bb * aw) / np.where(ok, den, 1.0), 0.0), 0.0, 1.0)
    t = np.clip((ab * s + bw) / bb, 0.0, 1.0)
    s = np.clip((ab * t - aw) / aa, 0.0, 1.0)
    return pairs, np.linalg.norm(w + s[:, None] * a - t[:, None] * b, axis=1)


def segment_clearance(
    positions: FloatArray,
    edges: IntArray,
    diameter: float,
    *,
    cap: float = 2.0,
    ignore: IntArray | None = None,
) -> float:
    """Smallest distance between segments sharing no node, in filament diameters.

    ≥ 1: no two filaments touch; in (0, 1): they overlap (no contact model); ≈ 0: they cross.
    ``cap`` is returned when no pair is closer. ``ignore`` ``(P, 2)`` lists segment pairs
    ``i < j`` to skip (e.g. those already fused where filaments cross at a printed junction).
    """
    pairs, dist = _pair_distances(positions, edges, cap * diameter)
    if ignore is not None and len(ignore) and len(pairs):
        n = len(edges)
        skip = np.isin(pairs[:, 0] * n + pairs[:, 1], ignore[:, 0] * n + ignore[:, 1])
        dist = dist[~skip]
    return float(min(cap, dist.min() / diameter)) if len(dist) else cap


def fused_pairs(positions: FloatArray, edges: IntArray, diameter: float) -> IntArray:
    """Segment pairs ``(P, 2)`` closer than ``diameter`` (mm) in ``positions`` (printed: fused)."""
    pairs, dist = _pair_distances(positions, edges, diameter)
    return pairs[dist < diameter]


@compact_display()
@dataclass(frozen=True, eq=False)
class HeatingResult:
    """A heating ramp of a lattice; per-step arrays have ``steps + 1`` rows (row 0: printed).

    Attributes
    ----------
    parameter
        Ramp parameter (x, dimensionless, or T in °C for ``thermal``).
    positions
        Node positions ``(steps+1, N, 3)`` (mm).
    energy
        Total potential energy of each equilibrium (N mm; :attr:`StaticResult.energy`: elastic,
        minus the work of gravity on the absolute heights, plus contact terms); 0 in row 0,
        which is not the printed state's total.
    iterations
        Newton iterations spent reaching each step (halved sub-steps included).
    halvings
        Deepest step halving used to reach each step.
    residual
        Relative residual of each equilibrium.
    area_ratio
        Projected area of the boundary loop over the printed one (A/A0).
    gaussian_sign
        Sign of the fitted Gaussian curvature of the branch nodes (+1 dome, −1 saddle, 0 flat).
    characteristic_curvature
        √|k₁k₂| of that fit (1/mm).
    mean_edge_strain
        Mean end-to-end strain of the lattice edges (dimensionless).
    edge_ratios
        End-to-end ratio of every lattice edge ``(steps+1, n_edges)``.
    min_clearance
        :func:`segment_clearance` per step (filament diameters).
    wall_time
        Seconds per step (0 for the printed row).
    lattice, model, actuation
        The design, its :class:`LatticeModel` and the actuation's name.
    states
        Rod state per step (row 0: the printed reference state); the material directors give
        the Janus sides.
    stable
        Per step: ``True`` where the solver certified a stable minimum, ``None`` where it did
        not check.
    lowest_eigenvalue
        Lowest Hessian eigenvalue of each equilibrium (N/mm², see
        :mod:`rotomorph.solve.stability`; NaN for row 0 and when not computed): it drops
        toward 0 where the lattice approaches a bifurcation.
    max_axial_strain
        Largest centre-line strain of any edge against its natural length per step (0 for
        row 0; :attr:`rotomorph.solve.static.StaticResult.max_axial_strain`).
    contact
        The contact settings of the ramp (None: filaments may pass through each other).
    contacts_active
        With contact: pairs and floor nodes carrying contact force at each step.
    floor_lift
        With a floor: the largest rise of a node above its printed height at each step (mm).
    lift_energy_gap
        With ``branch="lowest"`` on a floor under weight: total energy of the best lifted
        equilibrium found minus that of the resting one at each step where the lattice rested
        on the floor and its unsupported lowest mode was unstable (N mm; negative: the lifted
        branch was taken); NaN where no lifted equilibrium was probed or found. A step's row
        holds the lowest gap probed within it (at the step itself or at a halved or path-check
        sub-step on the way to it).
    lift_off_bracket, buckling_bracket
        With ``lift_off_tolerance``: ramp-parameter intervals ``(lo, hi)`` holding the
        lift-off (at ``lo`` the lattice rests and no lower lifted state was found, at ``hi``
        one was) and the buckling of the weightless flat lattice (its lowest mode stable at
        ``lo``, unstable at ``hi``); None where not refined or not reached. Their difference
        is the delay the weight causes.
    path_check
        With ``path_check > 1``: the :class:`~rotomorph.lattice.paths.PathCheck` (both ramps'
        final energies and which was kept); None without.
    stack_overlaps
        Layer pairs of the printed stack that interpenetrate at each step
        (:func:`rotomorph.lattice.admissibility.admissibility`; 0: admissible); None for
        results made before the check existed.
    """

    parameter: FloatArray
    positions: FloatArray
    energy: FloatArray
    iterations: IntArray
    halvings: IntArray
    residual: FloatArray
    area_ratio: FloatArray
    gaussian_sign: IntArray
    characteristic_curvature: FloatArray
    mean_edge_strain: FloatArray
    edge_ratios: FloatArray
    min_clearance: FloatArray
    wall_time: FloatArray
    lattice: Lattice
    model: LatticeModel
    actuation: str
    states: tuple[State, ...] = ()
    stable: tuple[bool | None, ...] = ()
    lowest_eigenvalue: FloatArray = field(default_factory=lambda: np.zeros(0))
    max_axial_strain: FloatArray = field(default_factory=lambda: np.zeros(0))
    contact: Contact | None = None
    contacts_active: IntArray | None = None
    floor_lift: FloatArray | None = None
    lift_energy_gap: FloatArray | None = None
    lift_off_bracket: tuple[float, float] | None = None
    buckling_bracket: tuple[float, float] | None = None
    path_check: PathCheck | None = None
    stack_overlaps: IntArray | None = None

    @property
    def admissible(self) -> tuple[bool | None, ...]:
        """Per step: no two layers of the printed stack interpenetrate (None: not checked)."""
        if self.stack_overlaps is None:
            return (None,) * len(self.parameter)
        return tuple(bool(c == 0) for c in self.stack_overlaps)

    @property
    def physical(self) -> tuple[bool, ...]:
        """Per step: a physical state (converged, certified stable and admissible)."""
        return tuple(
            s is True and a is True for s, a in zip(self.stable, self.admissible, strict=True)
        )

    @property
    def final_area_ratio(self) -> float:
        """A/A0 at the end of the ramp."""
        return float(self.area_ratio[-1])

    @property
    def total_iterations(self) -> int:
        """Newton iterations over the whole ramp."""
        return int(self.iterations.sum())

    def last_contact_free(self, threshold: float = 1.0) -> int:
        """Index of the last ramp step before filaments come closer than ``threshold``
        diameters (the last step if they never do)."""
        hit = np.flatnonzero(self.min_clearance < threshold)
        return int(max(hit[0] - 1, 0)) if len(hit) else len(self.parameter) - 1

    def first_lift_off(self, height: float | None = None) -> float | None:
        """First ramp parameter at which a node rises more than ``height`` (mm; default one
        filament diameter) above its printed height on the floor; None if it never does or
        there is no floor."""
        if self.floor_lift is None:
            return None
        h = 2.0 * self.lattice.radius if height is None else float(height)
        hit = np.flatnonzero(self.floor_lift > h)
        return None if not len(hit) else float(self.parameter[hit[0]])

    def first_overlap(self, threshold: float = 1.0) -> float | None:
        """First ramp parameter at which filaments come closer than ``threshold`` diameters."""
        hit = np.flatnonzero(self.min_clearance < threshold)
        return None if not len(hit) else float(self.parameter[hit[0]])


def _supports(lattice: Lattice, name: str) -> Supports:
    if name == "free":
        return Supports()
    if name == "pinned-centre":
        c = lattice.n // 2
        return Supports(pinned_nodes=(lattice.branch_index(c, c),))
    if name == "clamped-boundary":
        n = lattice.n
        i, j = np.divmod(lattice.branch_indices, n)
        rim = set(lattice.branch_indices[(i == 0) | (j == 0) | (i == n - 1) | (j == n - 1)])
        edges = lattice.network.edges
        clamped = np.flatnonzero(np.isin(edges[:, 0], list(rim)) | np.isin(edges[:, 1], list(rim)))
        return Supports(clamped_edges=tuple(int(k) for k in clamped))
    raise InvalidParameterError(
        "supports", f"must be 'free', 'clamped-boundary' or 'pinned-centre'; got {name!r}"
    )


def lattice_gravity(
    lattice: Lattice, *, fluid_density: float | None = None, density: float | None = None
) -> Gravity:
    """Self-weight of a lattice's filaments with buoyancy, all layers lumped: the effective
    line weight is (ρ_filament − ρ_bath) g A with A the lumped section.

    Parameters
    ----------
    fluid_density
        Density of the bath (g/cm³); default the silicone oil of the bath-fluid table at
        25 °C (:func:`rotomorph.materials.bath.bath_density`: 0.97, PDMS fluid data sheets;
        ``bath_density(temperature=175)`` ≈ 0.85 for the hot bath).
    density
        Filament density (g/cm³); default the mean of the lattice's two inks (materials table).
    """
    from rotomorph.materials.bath import bath_density

    if fluid_density is None:
        fluid_density = bath_density("silicone_oil")
    from rotomorph.materials.material import get_material

    if density is None:
        density = 0.5 * (
            float(get_material(lattice.active_material).density or 1.1)
            + float(get_material(lattice.passive_material).density or 1.1)
        )
    area = lattice.layers * np.pi * lattice.radius**2
    return Gravity(density=density, area=area, fluid_density=fluid_density)


def lattice_buoyancy(
    lattice: Lattice, *, bath: str = "silicone_oil", density: float | None = None
) -> Callable[[float], Gravity]:
    """The lattice's buoyant self-weight as a function of the bath temperature (°C).

    Returns ``T ↦`` :func:`lattice_gravity` with the bath's density at ``T``
    (:func:`rotomorph.materials.bath.bath_density`: silicone oil expands on heating, 0.97 g/cm³
    at 25 °C and about 0.85 at 175 °C, so a lattice weighs about twice as much in the hot
    bath). Pass it as ``heat_lattice(..., gravity=...)`` for ramps in temperature. The
    filament density is the inks' at room temperature (their thermal expansion is not in the
    weight).
    """
    from rotomorph.materials.bath import bath_density

    bath_density(bath)  # an unknown fluid fails here, not inside the ramp

    def at(temperature: float) -> Gravity:
        return lattice_gravity(
            lattice, fluid_density=bath_density(bath, temperature), density=density
        )

    return at


def _measure(
    lattice: Lattice, pos: FloatArray, ref: FloatArray, loop: IntArray, fused: IntArray
) -> tuple:
    # the branch nodes (paper); a 2 x 2 lattice has too few, so all its nodes
    pts = pos[lattice.branch_indices] if lattice.n >= 3 else pos
    fit = fit_quadratic_surface(pts, flat_tolerance=1e-6)
    return (
        normalized_area(pos, ref, loop),
        fit.gaussian_sign,
        fit.characteristic_curvature,
        edge_end_to_end_ratios(pos, ref, lattice.edge_chains),
        segment_clearance(pos, lattice.network.edges, 2.0 * lattice.radius, ignore=fused),
    )


def heat_lattice(
    lattice: Lattice,
    *,
    actuation: str | Actuation = DEFAULT_ACTUATION,
    steps: int = 16,
    stiffness: Stiffness | None = None,
    supports: SupportsName = "free",
    gravity: Gravity | Callable[[float], Gravity] | None = None,
    seed: int = 0,
    perturbation: float = 1e-3,
    options: NewtonOptions | None = None,
    max_halvings: int = 6,
    contact: bool | Contact = False,
    floor: bool | Floor = False,
    friction: float = 0.0,
    branch: Literal["lowest", "continuous"] = "lowest",
    lift_off_tolerance: float | None = None,
    path_check: int = 1,
    youngs_modulus: float | None = None,
    progress: Callable[[int], None] | None = None,
    on_step: Callable[[int, float, State, StaticResult | None], None] | None = None,
) -> HeatingResult:
    """Ramp ``actuation`` over ``steps`` equal steps from the flat printed lattice.

    Parameters
    ----------
    lattice
        The printed design (:func:`rotomorph.design.lattices.sinusoidal_lattice`).
    actuation
        A name of :data:`rotomorph.lattice.actuation.ACTUATIONS` (default ``"program"``: every
        line's natural field from its print program at the ramp temperature) or an actuation
        object; its ``start``/``end`` set the ramp.
    steps
        Equal ramp steps (>= 1).
    stiffness
        ``"paper"`` or ``"janus"`` (:func:`rotomorph.lattice.model.lattice_model`); default
        :func:`~rotomorph.lattice.actuation.default_stiffness` (the Janus section of the
        actuation's own materials model for ``program``/``thermal``, ``"paper"`` otherwise).
    supports
        ``"free"`` (default; the paper's free lattice), ``"clamped-boundary"`` (every segment
        touching a perimeter branch node clamped: position and frame fixed) or
        ``"pinned-centre"`` (the central branch node pinned, e.g. to carry gravity).
    gravity
        Optional self-weight: a :class:`~rotomorph.solve.loads.Gravity`
        (:func:`lattice_gravity`) or a function of the ramp parameter returning one
        (:func:`lattice_buoyancy`: the bath's density at each ramp temperature). A free
        lattice needs a ``floor`` to rest on, otherwise supports other than ``"free"``.
    seed
        Seed of the symmetry-breaking noise.
    perturbation
        Height of the symmetry-breaking perturbation relative to the spacing l (>= 0).
    options
        Newton settings of every solve; default :data:`RAMP_OPTIONS`.
    max_halvings
        Step halvings allowed per ramp step.
    contact
        ``True``: filaments touch instead of passing through each other (radius
        ``lattice.radius``; :class:`rotomorph.contact.Contact` with defaults), or a ``Contact``
        to set radius, activation distance, obstacles or friction yourself.
    floor
        ``True``: a frictionless floor just below the printed lattice (the bath bottom:
        centre lines at ``1.005 r`` above it), or a :class:`rotomorph.contact.Floor`. Turns
        contact on. On a floor, a free lattice keeps only its in-plane rigid motions free
        (they are removed from every Newton step).
    friction
        Coulomb coefficient of every contact (default 0). Lagged as in IPC: within each
        ramp step the normal forces, closest points and tangent bases are re-evaluated at the
        last solution and the step solved again from its own start until they no longer
        change (:func:`relag_friction`).
    branch
        Which equilibrium a lattice resting on a floor under its weight follows.
        ``"continuous"``: the one reached continuously from the previous step. On a rigid
        floor under any weight a perfectly flat lattice whose weightless flat state is an
        equilibrium never loses stability (lifting costs weight × height to first order, the
        bending energy it releases is of second order), so
        the resting state is left only where the barrier's finite stiffness gives way, late and
        with a snap. ``"lowest"`` (default): at every step where the lattice still rests on the
        floor and the unsupported lattice's lowest mode is unstable, also solve from lifted
        starts along that mode and keep the equilibrium of lower total energy — the state an
        imperfect real lattice, disturbed as it is moved into the hot bath, can settle in
        (:func:`_lift_probe`; ``lift_energy_gap`` records the comparison). The probe runs only
        for free lattices (it moves the lattice rigidly; with supports the ramp is
        continuous); with friction it compares potential energies, friction's lagged
        dissipation left out of both.
    lift_off_tolerance
        With ``branch="lowest"``: where the lattice leaves the floor, bisect the ramp
        parameter to this width for the lift-off (the first lifted equilibrium lower in
        energy) and for the buckling of the weightless flat lattice (its lowest mode turning
        unstable), so the weight's delay of lift-off is resolved below the step size
        (``HeatingResult.lift_off_bracket``, ``buckling_bracket``; the extra solves are not
        in ``iterations``). Default None: not refined.
    path_check
        ``k > 1``: ramp the lattice a second time with every step split into ``k`` sub-steps
        and, where the two ramps end in different stable states (a multistable lattice whose
        end state depends on the path), keep the one lower in total energy
        (:mod:`rotomorph.lattice.paths`; ``HeatingResult.path_check`` records it). A kept
        sub-stepped ramp is sampled at the requested steps (its sub-steps' iterations count
        toward them). Default 1: no check.
    youngs_modulus
        E (MPa) of the ``"paper"`` stiffness (:func:`~rotomorph.lattice.model.lattice_model`;
        default :func:`~rotomorph.lattice.model.paper_modulus`). Unloaded shapes do not depend
        on it; under a weight or in contact it sets the bending scale the weight is measured
        against.
    progress
        Called with 1 after every solved step of the ramp and of the path check's
        sub-stepped ramp: ``steps * (1 + path_check)`` calls with a path check, ``steps``
        without (halvings and the lift-off bisection are not counted). Each solve is also
        announced on the ``rotomorph.progress`` logger ("ramp step 3 of 8 at 131.2 °C").
    on_step
        ``on_step(k, parameter, state, result)`` as each step of the first ramp is reached,
        the printed state first (``k = 0``, row 0 of the result; ``result`` None): to show
        converged states while the ramp runs. With ``path_check > 1`` the kept end state may
        come from the second ramp, which is not reported step by step.

    Returns
    -------
    HeatingResult

    Raises
    ------
    InvalidParameterError
        Bad steps, perturbation, supports, stiffness or branch option; gravity on a free
        lattice.
    ConvergenceError
        A ramp step failed after ``max_halvings`` halvings (``error.result`` holds the steps
        reached).
    """
    act = get_actuation(actuation)
    if int(steps) != steps or steps < 1:
        raise InvalidParameterError("steps", f"must be an integer >= 1; got {steps}")
    if not (np.isfinite(perturbation) and perturbation >= 0):
        raise InvalidParameterError(
            "perturbation", f"must be >= 0 (relative to l); got {perturbation}"
        )
    options = RAMP_OPTIONS if options is None else options
    sup = _supports(lattice, supports)
    stiffness, fm = default_stiffness(act, stiffness)
    phase_log.info(
        "set-up: rod model of %s nodes (stencils, %s stiffness)",
        f"{lattice.network.n_nodes:,}",
        stiffness,
    )
    lm = lattice_model(
        lattice, stiffness=stiffness, filament_model=fm, youngs_modulus=youngs_modulus
    )

    def loads_at(p: float) -> Loads:
        return Loads(gravity=gravity(p) if callable(gravity) else gravity)

    phase_log.info("set-up: perturbed flat start")
    dz = symmetry_breaking(lattice, perturbation * lattice.spacing, seed)
    initial = perturbed_state(lm.model, dz)
    settings = contact_settings(lattice, initial.positions, contact, floor, friction)
    if gravity is not None and sup.is_free and (settings is None or settings.floor is None):
        raise InvalidParameterError(
            "supports",
            "gravity on a free lattice needs a floor to rest on (floor=True) or a support "
            "('pinned-centre' or 'clamped-boundary')",
        )
    if lift_off_tolerance is not None and not (
        np.isfinite(lift_off_tolerance) and lift_off_tolerance > 0
    ):
        raise InvalidParameterError(
            "lift_off_tolerance", f"must be > 0 (ramp units) or None; got {lift_off_tolerance}"
        )
    if branch not in ("lowest", "continuous"):
        raise InvalidParameterError("branch", f"must be 'lowest' or 'continuous'; got {branch!r}")
    # the probe moves the lattice rigidly (supports would move with it): free lattices only;
    # with friction it compares potential energies (_lift_probe)
    probe_floor = (
        settings.floor
        if branch == "lowest" and settings is not None and gravity is not None and sup.is_free
        else None
    )
    factor = check_factor(path_check)
    if factor > 1 and settings is not None and settings.friction:
        raise InvalidParameterError(
            "path_check",
            "cannot compare paths with friction (lagged friction is dissipation, not an "
            "energy): use path_check=1 with friction > 0",
        )
    values = np.linspace(act.start, act.end, int(steps) + 1)

    events: list[tuple[float, int, bool]] = []  # every solve: parameter, iterations, success

    probes: dict[float, float] = {}  # parameter -> energy of the lifted branch minus resting
    # the ramp being followed: its name and the step number of each requested value
    ramp: dict[str, Any] = {
        "name": "ramp",
        "steps": dict(zip(values[1:].tolist(), range(1, steps + 1), strict=True)),
    }

    def solve(p: float, state: State) -> StaticResult:
        k = ramp["steps"].get(p)
        where = "(a halved step)" if k is None else f"{k} of {len(ramp['steps'])}"
        phase_log.info("%s step %s at %s", ramp["name"], where, ramp_value_text(act, p))
        model = act.natural(lm, p)
        try:
            loads = loads_at(p)
            res = solve_static(model, sup, loads, initial=state, options=options, contact=settings)
            if settings is not None and settings.friction:
                res, its = relag_friction(model, sup, loads, state, res, settings, options)
                events.append((p, its, False))  # the earlier lags' solves count toward it
        except ConvergenceError as err:
            events.append((p, int(getattr(err.result, "iterations", 0)), False))
            raise
        if probe_floor is not None:
            assert settings is not None  # a floor implies contact settings
            lifted, gap, its = _lift_probe(
                model, sup, loads, settings, res, options, probe_floor, lattice
            )
            if its:
                events.append((p, its, False))  # probe solves count toward this step
        events.append((p, res.iterations, True))
        if probe_floor is not None:
            if gap is not None:
                probes[p] = gap
            if lifted is not None and gap is not None:
                phase_log.info(
                    "lifted branch at %s is lower by %.3g N mm", ramp_value_text(act, p), -gap
                )
                res = lifted
        if progress is not None and k is not None:
            progress(1)
        return res

    phase_log.info("set-up: Hessian sparsity pattern and ordering with the first solve")

    def reached(step: ContinuationStep) -> None:
        if on_step is not None:
            k = int(np.argmin(np.abs(values - step.parameter)))
            on_step(k, float(step.parameter), step.result.state, step.result)

    if on_step is not None:
        on_step(0, float(values[0]), lm.model.reference_state(), None)
    path = continuation(
        solve, values[1:], initial, start=values[0], max_halvings=max_halvings, on_step=reached
    )
    finals = path.results
    checked: PathCheck | None = None
    if factor > 1:
        phase_log.info("path check: the ramp again with %d sub-steps per step", factor)
        fine_values = sub_stepped(values, factor)[1:]
        ramp["name"] = "path check ramp"
        ramp["steps"] = dict(zip(fine_values.tolist(), range(1, len(fine_values) + 1), strict=True))
        # the solve closure appends to these: keep the first ramp's, collect the second's
        first_events, first_probes = list(events), dict(probes)
        events.clear()
        probes.clear()
        fine: ContinuationResult | None
        started = time.perf_counter()
        try:
            fine = continuation(
                solve,
                fine_values,
                initial,
                start=values[0],
                max_halvings=max_halvings,
            )
        except (ConvergenceError, InfeasibleContactError):
            fine = None
        fine_wall = time.perf_counter() - started  # also what a failed ramp cost
        same = fine is not None and shape_distance(
            path.final.positions, fine.final.positions
        ) <= SAME_SHAPE_TOL * float(lattice.radius)
        checked = choose_end(
            (path.final.energy, np.nan if fine is None else fine.final.energy),
            (
                _stable_flag(path.final) is True,
                fine is not None and _stable_flag(fine.final) is True,
            ),
            same,
            factor,
            admissible=(
                admissibility(lattice, path.final.state, contact=settings).admissible,
                fine is not None
                and admissibility(lattice, fine.final.state, contact=settings).admissible,
            ),
        )
        if checked.kept == "sub-steps":
            assert fine is not None
            dropped_events, dropped_wall = first_events, sum(st.wall_time for st in path.steps)
            finals, path = fine.results[factor - 1 :: factor], fine
        else:
            dropped_events, dropped_wall = list(events), fine_wall
            events[:] = first_events
            probes.clear()
            probes.update(first_probes)
        checked = replace(
            checked,
            discarded_iterations=sum(e[1] for e in dropped_events),
            discarded_wall_time=dropped_wall,
        )
    per_step = factor if len(path.steps) > len(finals) else 1  # sub-steps per kept row
    brackets: tuple[tuple[float, float] | None, tuple[float, float] | None] = (None, None)
    if probe_floor is not None and lift_off_tolerance is not None:
        assert settings is not None  # a floor implies contact settings
        phase_log.info("lift-off: bisecting the ramp parameter")
        brackets = _refine_lift_off(
            lambda p: act.natural(lm, p),
            sup,
            loads_at,
            settings,
            options,
            probe_floor,
            lattice,
            values,
            [initial] + [r.state for r in finals],
            float(lift_off_tolerance),
        )
    phase_log.info("analysis: areas, surface fits, edge ratios, clearances")
    ref = lattice.network.nodes
    loop = lattice_boundary_loop(lattice.edge_chains, lattice.n)
    positions = np.stack([ref] + [r.positions for r in finals])
    energy = np.array([0.0] + [r.energy for r in finals])
    residual = np.array([0.0] + [r.residual for r in finals])
    iterations = np.zeros(len(values), dtype=np.int64)
    k = 1
    for p, its, ok in events:  # sub-steps and failed attempts count toward their step
        iterations[k] += its
        if ok and k < len(values) and p == values[k]:
            k += 1
    halvings, wall = per_row(path.steps, per_step)
    states = (lm.model.reference_state(), *(r.state for r in finals))
    overlaps = overlap_counts(lattice, states, contact=settings)
    fused = fused_pairs(ref, lattice.network.edges, 2.0 * lattice.radius)
    rows = [_measure(lattice, p, ref, loop, fused) for p in positions]
    ratios = np.stack([r[3] for r in rows])
    clearance = np.array([r[4] for r in rows])
    active = lift = None
    if settings is not None:
        pot = path.final.contact
        # allowed pairs only (graph neighbours and printed fusions excluded), in r_a + r_b;
        # a stacked contact measures its layers (it reads them off the states' frames)
        where = states if not settings.stack.is_single else positions
        clearance = np.array([pot.clearance(p) for p in where])
        active = np.array([pot.active_contacts(p) for p in where], dtype=np.int64)
        if settings.floor is not None:
            lift = np.array([_rise(settings.floor, lattice, p) for p in positions])
    return HeatingResult(
        parameter=values,
        positions=positions,
        energy=energy,
        iterations=iterations,
        halvings=halvings,
        residual=residual,
        area_ratio=np.array([r[0] for r in rows]),
        gaussian_sign=np.array([r[1] for r in rows], dtype=np.int64),
        characteristic_curvature=np.array([r[2] for r in rows]),
        mean_edge_strain=ratios.mean(axis=1) - 1.0,
        edge_ratios=ratios,
        min_clearance=clearance,
        wall_time=wall,
        lattice=lattice,
        model=lm,
        actuation=act.name,
        states=states,
        stable=(True, *(_stable_flag(r) for r in finals)),
        lowest_eigenvalue=np.r_[np.nan, path.lowest_eigenvalues[per_step - 1 :: per_step]],
        max_axial_strain=np.r_[0.0, [getattr(r, "max_axial_strain", np.nan) for r in finals]],
        contact=settings,
        contacts_active=active,
        floor_lift=lift,
        lift_energy_gap=None if probe_floor is None else _gaps_per_step(probes, values),
        lift_off_bracket=brackets[0],
        buckling_bracket=brackets[1],
        path_check=checked,
        stack_overlaps=overlaps,
    )


def _gaps_per_step(probes: dict[float, float], values: FloatArray) -> FloatArray:
    """Row ``k`` (``k >= 1``): the lowest lift-probe gap at parameters in
    ``(values[k-1], values[k]]`` (ramps may run either way); NaN where none was probed."""
    out = np.full(len(values), np.nan)
    for p, gap in probes.items():
        for k in range(1, len(values)):
            lo, hi = sorted((values[k - 1], values[k]))
            inside = lo < p <= hi if values[k] >= values[k - 1] else lo <= p < hi
            if inside:
                out[k] = gap if np.isnan(out[k]) else min(out[k], gap)
                break
    return out


#: Height of the lifted start of :func:`_lift_probe`, in lattice spacings l (0.5 mm for the
#: paper's 5 mm cells, about a filament diameter): a start for the weightless buckling solve,
#: whose flat state is unstable there, so any height leaves it. Which buckled state it reaches
#: can depend on the height: on the 16-step contracting ramp 0.1 l and 0.2 l end in the same
#: state, 0.3 l and 0.5 l in another one (A/A0 0.2796 against 0.2778).
LIFT_PROBE_HEIGHT = 0.1

#: Barrier stiffness of the weightless buckling solve of :func:`_lift_probe`, as a fraction
#: of the ramp's: that solve only finds a start for the solves on the floor (which use the
#: ramp's contact model), and in a weightless crumpling the contact forces are far below the
#: force scale the default stiffness is sized by, so a full-stiffness barrier holds the pairs
#: at the edge of the activation distance, where it has almost no curvature: Newton steps run
#: into them and are cut to a few per cent (measured on the paper's contracting 5 x 5 ramp:
#: 146 iterations; 62 at this softening, and the same lifted state).
SEARCH_SOFTENING = 0.01

#: Newton solves (each up to the ramp's iteration limit) the weightless buckling solve of
#: :func:`_lift_probe` may take: one that runs out of iterations is continued from its last
#: iterate, since it only looks for a shape. Buckling a very slender lattice from its flat
#: state is a long Newton path: the authors' Fig. 4 lattice (r/l = 0.001,
#: :mod:`rotomorph.lattice.published`) takes about 430 iterations to its saddle at stretch
#: -0.17, beyond the ramp's 300, and a probe that gave up there kept it flat.
SEARCH_SOLVES = 4

#: Search settings of the lift probe, OFF by default (0.0, True, None: the ramp's tolerance,
#: certified, no softened settling). Measured on the contact model before the printed stack
#: was presented to contact they cut the 11 x 11 ramps' iterations by a third with the same
#: end states; with the printed stack the dome 11 x 11 then leaves another path (the search at
#: 1e-4 kept it flat, 5 840 iterations, a state 20 % higher in energy; with the softened
#: settling too a ramp step failed), so they stay off until that is understood
#: (``docs/contact.md``, *Lattices of 11 x 11 and 21 x 21 cells*).
#:
#: Residual tolerance (relative to the force scale, as ``NewtonOptions.rtol``) of the
#: weightless buckling solve of :func:`_lift_probe`, or the ramp's when that is looser, with
#: no stability certificate at its end (:data:`SEARCH_CERTIFY`): it only finds a shape to lay
#: on the floor, and the solves there converge to the ramp's tolerance and the last one is
#: certified. Converged to the ramp's 1e-7 and certified, the weightless lattice slid along its
#: soft modes and off saddles for most of its iterations (measured on the contracting 11 x 11
#: ramp: 188 iterations, the residual between 1e-5 and 1e-6 from the 60th on; 9 at 1e-4).
SEARCH_RTOL = 0.0

#: Whether the weightless buckling solve certifies its end point (see :data:`SEARCH_RTOL`).
SEARCH_CERTIFY = True

#: Barrier stiffness, as a fraction of the ramp's, of a first settling solve of each lifted
#: candidate laid on the floor, to the ramp's tolerance but not certified (None: settle with
#: the ramp's barrier alone). Laid on the floor from its weightless shape, a jammed lattice's
#: pairs enter contact one by one at the edge of the activation distance, where the ramp's
#: barrier has no curvature: Newton steps run into them, the line search cuts them to a few
#: per cent of the collision-free bound, the next whole step cleans up. The softer barrier
#: lets those steps close most of each gap; the certified solve with the ramp's barrier then
#: starts with the pairs inside its activation distance, where its Hessian sees them. With
#: :data:`SEARCH_RTOL`: the contracting 11 x 11 ramp (8 steps) 534 -> 339 iterations, the dome
#: 600 -> 387, the 5 x 5 saddle (16 steps) 536 -> 355, the 5 x 5 dome 214 -> 217; the same end
#: states but the contracting 11 x 11's, a neighbouring jam 3.4e-6 lower in energy
#: (``docs/contact.md``, *Lattices of 11 x 11 and 21 x 21 cells*; 1/10 instead of 1/100 saved
#: less).
SETTLE_SOFTENING: float | None = None


def _settle_softened(
    model: Model,
    supports: Supports,
    loads: Loads,
    start: State,
    options: NewtonOptions,
    contact: Contact,
) -> tuple[State, int]:
    """The first, softened settling of a lifted candidate on the floor
    (:data:`SETTLE_SOFTENING`): the state it reaches and the Newton iterations spent. It is
    only a search: where it runs out of iterations its last iterate is kept, where it fails
    otherwise the candidate settles from ``start`` with the ramp's barrier alone."""
    try:
        soft = solve_static(
            model, supports, loads, initial=start,
            options=replace(options, check_stability=False),
            contact=_softened(contact, SETTLE_SOFTENING),  # type: ignore[arg-type]
        )  # fmt: skip
    except (ConvergenceError, InfeasibleContactError) as err:
        result = getattr(err, "result", None)
        spent = int(getattr(result, "iterations", 0))
        last = getattr(err, "state", None)
        if getattr(result, "status", None) is Status.MAX_ITERATIONS and last is not None:
            return last, spent
        return start, spent
    return soft.state, soft.iterations


def _softened(settings: Contact, factor: float) -> Contact:
    """``settings`` with the barrier stiffness scaled by ``factor``."""
    return replace(
        settings,
        stiffness=None if settings.stiffness is None else factor * settings.stiffness,
        stiffness_scale=factor * settings.stiffness_scale,
    )


def _lift_probe(
    model: Model,
    supports: Supports,
    loads: Loads,
    settings: Contact,
    resting: StaticResult,
    options: NewtonOptions,
    floor: Floor,
    lattice: Lattice,
) -> tuple[StaticResult | None, float | None, int]:
    """Look for a lifted equilibrium of lower total energy than ``resting``.

    On a rigid floor under a positive weight, a flat lattice whose weightless flat state is an
    equilibrium (natural curvatures in the plane, no eigen-twist: e.g. lines whose nozzle only
    tracks the heading) and stable against in-plane and twist motions is a strict local
    minimum at any actuation: lifting any part by h costs weight × h, while the bending energy
    an incompatible flat lattice releases by rising is of second order in h. (A natural field
    that pushes the flat state out of the plane, such as an eigen-twist, lifts it by itself.)
    So the resting state does not lose stability (with the barrier floor it does, late, where
    the barrier's finite stiffness gives way), and following it continuously (what Newton
    from the previous step does) keeps a lattice flat that a real one — never perfectly flat,
    disturbed when moved into the hot bath — can leave once a lifted shape is lower in energy
    (the lowest-energy choice). This probe runs where the lattice still rests (every node
    within a filament diameter of its printed height) and the unsupported lattice's lowest
    mode is unstable: it solves from the resting state lifted along that mode (highest point
    :data:`LIFT_PROBE_HEIGHT` · l): first weightless and away from the floor, where the
    lattice buckles freely (with a softer barrier, :data:`SEARCH_SOFTENING`: this solve only
    finds a shape); then laid on the floor either way up (one buckled shape, two
    orientations), toppled as a rigid body into the pose it rests in under its weight
    (:func:`~rotomorph.lattice.resting.resting_rotation`; a saddle laid on its two low corners
    rocks over), where its elastic equilibrium under its weight is solved with the ramp's
    contact model (where :data:`SETTLE_SOFTENING` is set, after a softer first settling).
    It returns ``(best lifted result or None, its energy minus the resting one or None,
    Newton iterations spent)``. A lifted result is returned only if it is certified stable,
    admissible (no two layers of the printed stack interpenetrate:
    :mod:`rotomorph.lattice.admissibility`), lower in total energy (elastic + weight +
    barrier) and actually off the floor. A lift found inside a halved or path-check sub-step
    is recorded in the row of the step it leads to (``_gaps_per_step``).

    With friction the comparison is between potential energies (elastic + weight + barrier):
    lagged friction is dissipation, not a potential, so it is left out of both. The lifted
    candidates settle on a frictionless floor (whether a lifted state lower in potential
    energy exists does not depend on friction; an equilibrium of the frictionless problem is
    one of the frictional problem lagged at itself, where friction carries no force), the
    resting state's potential energy is evaluated without its friction term, and the lifted
    state taken is solved once more with the ramp's friction, lagged at itself, so that the
    ramp goes on from an equilibrium of its own problem.
    """
    diameter = 2.0 * lattice.radius
    if _rise(floor, lattice, resting.positions) > diameter:
        return None, None, 0
    modes = _unsupported_instability(model, resting.state, supports)
    if modes is None:
        return None, None, 0
    v = modes.modes.displacements[0][:, 2]
    if float(np.ptp(v)) == 0.0:
        return None, None, 0
    # the candidates settle on a frictionless floor; with friction the resting state is
    # compared by its potential energy (docstring)
    frictional = bool(settings.friction)
    on_floor = replace(settings, friction=0.0) if frictional else settings
    rest_energy = (
        _potential_energy(model, supports, loads, on_floor, resting.state)
        if frictional
        else resting.energy
    )
    # 1. the weightless lattice away from the floor buckles from the flat state along the mode
    afloat = replace(
        settings,
        obstacles=tuple(o for o in settings.obstacles if o is not floor),
        stiffness=None if settings.stiffness is None else SEARCH_SOFTENING * settings.stiffness,
        stiffness_scale=SEARCH_SOFTENING * settings.stiffness_scale,
        friction=0.0,
    )
    dz = v * (LIFT_PROBE_HEIGHT * lattice.spacing / float(np.abs(v).max()))
    free, spent = _settle_weightless(
        model, supports, _untouched_lift(model, resting.state, dz, afloat), options, afloat
    )
    if free is None:
        return None, None, spent
    # 2. laid on the floor either way up, it settles under its weight
    best: StaticResult | None = None
    gap_floor = float(floor.height_of(resting.positions).min())
    # each edge weighs its printed mass: half of its printed length to each end node
    net = lattice.network
    half = 0.5 * np.linalg.norm(net.nodes[net.edges[:, 1]] - net.nodes[net.edges[:, 0]], axis=1)
    weight = np.asarray(np.bincount(net.edges.ravel(), np.repeat(half, 2), net.n_nodes), float)
    for flip in (False, True):
        start = _laid_on(free.state, floor, gap_floor, flip, weight)
        try:
            if SETTLE_SOFTENING is not None:
                start, its = _settle_softened(model, supports, loads, start, options, on_floor)
                spent += its
            trial = solve_static(
                model, supports, loads, initial=start, options=options, contact=on_floor
            )
        except (ConvergenceError, InfeasibleContactError) as err:
            spent += int(getattr(getattr(err, "result", None), "iterations", 0))
            phase_log.debug("lift probe (flip %s): did not settle", flip)
            continue
        spent += trial.iterations
        lift = _rise(floor, lattice, trial.positions)
        phase_log.debug(
            "lift probe (flip %s): rise %.3g mm, energy %.6g vs resting %.6g N mm",
            flip,
            lift,
            trial.energy,
            rest_energy,
        )
        if (
            lift > diameter
            and trial.stable
            and (best is None or trial.energy < best.energy)
            and admissibility(lattice, trial.state, contact=settings).admissible
        ):
            best = trial
    if best is None:
        return None, None, spent
    gap = best.energy - rest_energy
    tol = 1e-9 * max(abs(rest_energy), abs(best.energy), 1e-300)
    if gap >= -tol:
        return None, gap, spent
    if frictional:  # an equilibrium of the ramp's own (frictional) problem, lagged at itself
        try:
            held = solve_static(
                model, supports, loads, initial=best.state, options=options, contact=settings
            )
        except (ConvergenceError, InfeasibleContactError) as err:
            spent += int(getattr(getattr(err, "result", None), "iterations", 0))
            phase_log.debug("lift probe: the lifted state did not settle with friction")
            return None, gap, spent
        spent += held.iterations
        if not (held.stable and _rise(floor, lattice, held.positions) > diameter):
            return None, gap, spent
        best = held
    return best, gap, spent


def _settle_weightless(
    model: Model, supports: Supports, start: State, options: NewtonOptions, contact: Contact
) -> tuple[StaticResult | None, int]:
    """The weightless equilibrium reached from ``start`` (None where none was reached) and the
    Newton iterations spent: a solve that runs out of iterations is continued from its last
    iterate, up to :data:`SEARCH_SOLVES` solves."""
    spent = 0
    options = replace(
        options,
        rtol=max(options.rtol, SEARCH_RTOL),
        check_stability=options.check_stability and SEARCH_CERTIFY,
    )
    for _ in range(SEARCH_SOLVES):
        try:
            free = solve_static(
                model, supports, Loads(), initial=start, options=options, contact=contact
            )
        except (ConvergenceError, InfeasibleContactError) as err:
            result = getattr(err, "result", None)
            spent += int(getattr(result, "iterations", 0))
            last = getattr(err, "state", None)
            if getattr(result, "status", None) is not Status.MAX_ITERATIONS or last is None:
                phase_log.debug("lift probe: the weightless lattice did not settle (%d its)", spent)
                return None, spent
            phase_log.debug("lift probe: the weightless search continues (%d its)", spent)
            start = last
            continue
        return free, spent + free.iterations
    phase_log.debug("lift probe: the weightless lattice did not settle (%d its)", spent)
    return None, spent


def _potential_energy(
    model: Model, supports: Supports, loads: Loads, contact: Contact, state: State
) -> float:
    """Total potential energy of ``state`` (N mm): elastic, minus the work of the loads, plus
    the contact barrier of ``contact`` (a frictionless copy of the ramp's: no lagged friction).
    The barrier stiffness follows from the model and loads alone, so it is the ramp's."""
    obj = RodObjective(model, state, supports, loads, contact)
    return float(obj.evaluate(obj.vector(), False, 0)[0])


def _untouched_lift(model: Model, state: State, dz: FloatArray, contact: Contact) -> State:
    """``state`` lifted by ``dz`` (:func:`perturbed_state`), or by the largest of ``dz/2``,
    ``dz/4`` … (down to ``dz/256``) at which nothing it may touch touches: a jammed lattice
    lifted along a mode can push the layers of neighbouring stacks into each other (they
    rest within the activation distance), and a start that touches is refused. The last
    one tried is returned if none is free (the solve then refuses it)."""
    lifted = perturbed_state(model, dz, state)
    for _ in range(8):
        try:
            RodObjective(model, lifted, Supports(), Loads(), contact)  # checks the start
            return lifted
        except InfeasibleContactError:
            dz = 0.5 * dz
            lifted = perturbed_state(model, dz, state)
    return lifted


def _refine_lift_off(
    natural: Callable[[float], Model],
    supports: Supports,
    loads: Callable[[float], Loads],
    settings: Contact,
    options: NewtonOptions,
    floor: Floor,
    lattice: Lattice,
    values: FloatArray,
    states: list[State],
    tol: float,
) -> tuple[tuple[float, float] | None, tuple[float, float] | None]:
    """Bisect the lift-off and the weightless buckling of a ramp (see ``lift_off_tolerance``).

    ``states[k]`` is the ramp's equilibrium at ``values[k]`` (``states[0]`` the printed
    start). Both brackets start from the last resting step before the first lifted one; the
    buckling bracket steps back further while the weightless lattice is already unstable
    there. Every trial solves the resting equilibrium from the bracket's lower state. A
    failed solve stops that bisection at the bracket reached.
    """
    diameter = 2.0 * lattice.radius

    def lifted(state: State) -> bool:
        return _rise(floor, lattice, state.positions) > diameter

    first = next((k for k in range(1, len(states)) if lifted(states[k])), None)
    if first is None:
        return None, None

    def resting(p: float, start: State) -> tuple[Model, StaticResult]:
        model = natural(p)
        return model, solve_static(
            model, supports, loads(p), initial=start, options=options, contact=settings
        )

    def leaves(p: float, start: State) -> tuple[bool, State]:
        model, res = resting(p, start)
        if lifted(res.state):
            return True, res.state
        best, _, _ = _lift_probe(model, supports, loads(p), settings, res, options, floor, lattice)
        return best is not None, res.state

    def buckled(p: float, start: State) -> tuple[bool, State]:
        model, res = resting(p, start)
        return _unsupported_instability(model, res.state, supports) is not None, res.state

    def bisect(test, lo: float, lo_state: State, hi: float) -> tuple[float, float]:  # type: ignore[no-untyped-def]
        while hi - lo > tol:
            mid = 0.5 * (lo + hi)
            try:
                flag, state = test(mid, lo_state)
            except (ConvergenceError, InfeasibleContactError):
                break
            if flag:
                hi = mid
            else:
                lo, lo_state = mid, state
        return lo, hi

    k = first - 1
    lift = bisect(leaves, float(values[k]), states[k], float(values[first]))
    # the weightless lattice is unstable where the lift-off was found; step back to a stable one
    j = k
    while j > 0:
        if _unsupported_instability(natural(float(values[j])), states[j], supports) is None:
            break
        j -= 1
    buckle = bisect(buckled, float(values[j]), states[j], float(values[j + 1]))
    return lift, buckle


def _unsupported_instability(
    model: Model, state: State, supports: Supports
) -> StabilityResult | None:
    """The weightless lattice's lowest mode at ``state`` (a :class:`StabilityResult`) when
    its lowest eigenvalue is negative, else None. A successful unshifted Cholesky
    factorization of the reduced Hessian decides the stable case without an eigensolve."""
    res = stability(model, state, supports, Loads(), count=0)
    if len(res.eigenvalues):
        phase_log.debug("lift probe: lowest unsupported eigenvalue %.3g", res.eigenvalues[0])
    return res if len(res.eigenvalues) and res.eigenvalues[0] < 0 else None


def _rise(floor: Floor, lattice: Lattice, positions: FloatArray) -> float:
    """Largest rise of a node above its printed height over ``floor`` (mm)."""
    return float((floor.height_of(positions) - floor.height_of(lattice.network.nodes)).max())


def _laid_on(state: State, floor: Floor, height: float, flip: bool, weight: FloatArray) -> State:
    """``state`` moved rigidly (turned upside down about the lattice's x axis when ``flip``),
    toppled as a rigid body into the pose where it rests on ``floor`` under the nodal weights
    ``weight`` (:func:`resting_rotation`) with its centre of mass over the same point of the
    floor, and lowered so that its lowest node is ``height`` (mm) above ``floor``."""
    n = np.asarray(floor.normal, dtype=float)
    rot = np.eye(3)
    if flip:  # a half turn about an axis in the floor's plane
        a = unit(np.cross(n, [0.0, 1.0, 0.0] if abs(n[1]) < 0.9 else [1.0, 0.0, 0.0]))
        rot = 2.0 * np.outer(a, a) - np.eye(3)
    centre = state.positions.mean(axis=0)
    pos = (state.positions - centre) @ rot.T + centre
    turn, _ = resting_rotation(pos, weight, n)
    centre = weight @ pos / weight.sum()  # turned about its centre of mass, which stays put
    pos = (pos - centre) @ turn.T + centre
    rot = turn @ rot
    pos += (height - float(floor.height_of(pos).min())) * n
    return replace(
        state, positions=pos, tangents=state.tangents @ rot.T, directors=state.directors @ rot.T
    )


def _stable_flag(result: StaticResult) -> bool | None:
    """``True`` where the solver certified a minimum; ``None`` (unknown) otherwise: a solve
    that ends on an unstable point raises, so ``stable=False`` on a returned result means the
    check was switched off, not that the state is unstable."""
    return True if getattr(result, "stable", None) is True else None


#: Re-lagged solves of a ramp step with friction before it counts as not converged, and the
#: change of the lagged normal forces (``rotomorph.contact.friction.lag_change``) below which
#: the lag has converged
FRICTION_RELAGS = 30
FRICTION_LAG_TOL = 1e-3


def relag_friction(
    model: Model,
    supports: Supports,
    loads: Loads,
    start: State,
    res: StaticResult,
    settings: Contact,
    options: NewtonOptions | None,
) -> tuple[StaticResult, int]:
    """IPC's outer loop for lagged friction within one load step.

    ``res`` was solved from ``start`` with friction lagged there: the normal forces, closest
    points and tangent bases of the contacts at the step's start. A contact that closes or
    presses harder during the step (a lattice settling onto the floor, filaments jamming)
    then carries no friction, or too little. So the lag is re-evaluated at the solution, slips
    still measured from ``start``, and the step solved again from the solution, until the
    lagged normal forces and normals change by less than :data:`FRICTION_LAG_TOL` of their
    total (Li et al., "Incremental Potential Contact", ACM TOG 39(4) 49, 2020, § 5: the
    lagged friction converges to the frictional contact solution as these iterations do).
    Returns the last solve and the Newton iterations of those before it.

    Raises
    ------
    ConvergenceError
        If the lag has not converged after :data:`FRICTION_RELAGS` solves (the ramp's
        continuation then halves the step).
    """
    from dataclasses import replace

    from rotomorph.contact.friction import lag_change

    spent = 0
    for k in range(FRICTION_RELAGS):
        pot = res.contact
        assert pot is not None  # solved with contact settings
        used = pot.friction_lag
        new = (
            pot.lag(start, at=res.state)  # the layer points of the printed stack
            if isinstance(pot, StackedContact)
            else pot.lag(start.positions, at=res.positions)
        )
        change = 0.0 if used is None else lag_change(used, new)
        logger.debug("friction lag %d: change %.3g", k, change)
        if change <= FRICTION_LAG_TOL:
            return res, spent
        spent += res.iterations
        res = solve_static(
            model,
            supports,
            loads,
            initial=res.state,
            options=options,
            contact=replace(settings, friction_lag=new),
        )
    raise ConvergenceError(
        f"lagged friction did not converge within {FRICTION_RELAGS} solves of one ramp step "
        f"(normal forces still changing by {change:.3g} of their total); take smaller steps",
        result=None,
    )


def contact_settings(
    lattice: Lattice,
    printed: FloatArray,
    contact: bool | Contact,
    floor: bool | Floor,
    friction: float,
) -> Contact | None:
    """The ramp's contact settings from the ``contact``/``floor``/``friction`` arguments.

    ``contact=True`` (or a floor alone) gives the lattice's printed stack as the contact
    shape (:func:`rotomorph.lattice.admissibility.lattice_stack`: one capsule per layer), and
    ``floor=True`` a floor just below its bottom layer; a :class:`Contact` passed in is used as
    given (with another shape than the stack, a state whose layers interpenetrate is flagged
    as not admissible)."""
    stack = lattice_stack(lattice)
    if isinstance(floor, Floor):
        fl: Floor | None = floor
    elif floor:
        # under the bottom layer (printed material directors: the sheet normal +z)
        fl = Floor.under(np.asarray(printed) - [0.0, 0.0, stack.extent], lattice.radius)
    else:
        fl = None
    if isinstance(contact, Contact):
        settings: Contact | None = contact
        if contact.stack != stack:
            logger.warning(
                "contact: the segments present %d capsule(s), the printed stack has %d layers; "
                "states whose layers interpenetrate are flagged as not admissible",
                contact.stack.count,
                stack.count,
            )
    elif contact or fl is not None:
        settings = Contact(radius=lattice.radius, stack=stack)
    else:
        settings = None
    if settings is None:
        if friction:
            raise InvalidParameterError("friction", "needs contact=True or a floor")
        return None
    obstacles = settings.obstacles + ((fl,) if fl is not None else ())
    return replace(settings, obstacles=obstacles, friction=friction or settings.friction)


def free_edge_ratio(
    lattice: Lattice,
    *,
    actuation: str | Actuation = DEFAULT_ACTUATION,
    parameter: float | None = None,
    edge: int = 0,
    steps: int = 8,
    stiffness: Stiffness | None = None,
) -> float:
    """End-to-end ratio L/L0 of one lattice edge printed alone and actuated freely.

    The single sinusoid of paper Fig. 3C/D (1.37 ± 0.07 expanding, 0.64 ± 0.05 contracting);
    for a homogeneous lattice of independent edges the area ratio is about this ratio squared.

    Parameters
    ----------
    lattice
        Supplies the edge geometry, mode, active sides and printing parameters.
    actuation
        As :func:`heat_lattice`.
    parameter
        Ramp value to reach (default: the actuation's ``end``); reached by continuation in
        ``steps`` equal steps from its ``start``.
    edge
        Which lattice edge (its mode decides expanding/contracting).
    """
    act = get_actuation(actuation)
    stiffness, fm = default_stiffness(act, stiffness)
    lm = edge_model(lattice, edge, stiffness=stiffness, filament_model=fm)
    end = act.end if parameter is None else float(parameter)
    values = np.linspace(act.start, end, int(steps) + 1)[1:]
    path = continuation(
        lambda p, s: solve_static(act.natural(lm, p), initial=s),
        values,
        lm.model.reference_state(),
        start=act.start,
    )
    ref = lm.model.network.nodes
    return end_to_end_ratio(path.final.positions, ref)

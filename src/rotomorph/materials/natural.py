r"""Assembly: print program + materials + temperature → natural curvature, twist, stiffness.

Frame A (interface-attached): the material director of every edge is the interface normal
m1 = n (pointing into the active phase), n = cos α d1 + sin α d2 with d1 the space-parallel
reference director of :func:`rotomorph.geometry.space_parallel_directors`. The printed filament
is stress-free in its printed shape, so its printed curvatures and twist are measured on the
printed polyline with :func:`rotomorph.geometry.polyline_strains` (as disMech sets κ̄ = κ at
set-up), divided by the printed Voronoi lengths; actuation adds, scaled by the actuation
fraction x(T),

* κ̄1 += K_J (curvature toward m1 = n, i.e. toward the active side), κ̄2 += K_2 (zero for a
  symmetric Janus section), τ̄ += Δτ (eigen-twist of the helical director),
* rest length = printed length × exp(x ε_c) (Hencky) or (1 + x ε_c) (engineering),

with K_J, Δτ, ε_c from the section of each edge (print speed and rotation averaged over the two
end vertices) and averaged over the two edges of each interior vertex.

Handedness: the LCE director, the material lines and the interface form helices of the same
sense, so the director helix in the filament frame turns with the part of dα/ds that
the nozzle rotation causes. With the design layer's convention α = ψ − α_n (the theory page, planar
paths: dα/ds = κ_p − ω/v) that rate is −ω/v, i.e. the signed rotation rate of the director
field is ω*_dir = :data:`DIRECTOR_HELIX_SENSE` · Rω/v with sense −1. On straight stretches the
printed twist dα/ds then has the sign of ω*_dir and the eigen-twist Δτ the opposite sign
(untwisting); a warning is logged when a program contradicts this.

Moduli at the actuation temperature are not measured. The passive modulus is
taken at its 25 °C value and the active one as ``FilamentModel.modulus_ratio`` × E_p: the
room-temperature ratio 52 under-predicts the Janus curvature 2-4×, so the ratio is
calibrated (:mod:`rotomorph.materials.calibrate`); only the ratio matters for unloaded shapes.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any, Literal, cast

import numpy as np

from rotomorph import geometry
from rotomorph._display import compact_display
from rotomorph._typing import BoolArray, FloatArray
from rotomorph.errors import InvalidDesignError, InvalidParameterError, MaterialError
from rotomorph.materials.finite_section import SECTION_MODELS
from rotomorph.materials.janus import (
    DEFAULT_RESOLUTION,
    FilamentSection,
    filament_section,
    with_law,
)
from rotomorph.materials.material import Material, get_material
from rotomorph.materials.morphology import HelixShape, free_helix
from rotomorph.materials.parameter_set import default_materials
from rotomorph.materials.process import (
    ActuationStrainModel,
    WarnerTerentjev,
    actuation_fraction,
    dimensionless_rotation,
)
from rotomorph.materials.stack import stack_section
from rotomorph.materials.temperature import (
    active_modulus,
    passive_modulus,
    passive_strain_fraction,
)

if TYPE_CHECKING:
    from rotomorph.materials.parameter_set import MaterialSet

logger = logging.getLogger(__name__)

#: Sign relating the nozzle rotation ω to the director-helix rate in the filament frame
#: (α = ψ − α_n; rotomorph.design.program).
DIRECTOR_HELIX_SENSE = -1.0


#: Field values of the default model: the paper's pair in the default materials file.
_PAPER = default_materials().model_values("lce", "acrylate")

#: Parameters of the default :class:`FilamentModel`: the chosen branch of the joint calibration
#: on the paper's filament measurements (:func:`rotomorph.materials.calibrate.paper_calibration`),
#: stored in the default materials file (``data/paper_inks.toml``) so that ``simulate``,
#: ``paper``, the examples and the lattice use one model. A test keeps the stored values equal
#: to a fresh calibration.
CALIBRATED = {
    "modulus_ratio": _PAPER["modulus_ratio"],
    "strain_model.gain": _PAPER["strain_model"].gain,
    "strain_model.threshold": _PAPER["strain_model"].threshold,
    "passive_strain": _PAPER["passive_strain"],
}
CALIBRATED_MODULUS_RATIO = CALIBRATED["modulus_ratio"]


def _calibrated_strain_model() -> ActuationStrainModel:
    return _PAPER["strain_model"]  # type: ignore[no-any-return]


@dataclass(frozen=True)
class LayerStack:
    """Geometry of a printed stack: ``layers`` layers ``layer_height`` (mm) apart along
    ``direction`` in the layers' interface frame (:meth:`FilamentModel.section`), or, with
    ``direction=None``, along the printed sheet's normal +z, whatever the interface's
    orientation at a vertex (:func:`actuation_increments` then solves each vertex's stack)."""

    layers: int
    layer_height: float
    direction: tuple[float, float] | None = None


_GroupedSections = list[tuple[Any, FilamentSection]]


def _sections_by_stacking(
    model: FilamentModel,
    mats: tuple[Material, Material],
    radius: float,
    frac: float,
    temperature: float,
    stack: LayerStack | None,
    n: FloatArray,
    m2: FloatArray,
) -> _GroupedSections:
    """The sections of points with interface frames ``(n, m2)`` ``(K, 3)``: one section, or
    for a stack along +z one per distinct stacking direction (z in the frame; a stack and its
    mirror image are the same section), with the indices of the points it serves."""
    active, passive = mats
    if stack is None or stack.layers <= 1 or stack.direction is not None:
        return [(slice(None), model.section(active, passive, radius, frac, temperature,
                                            stack=stack))]  # fmt: skip
    s = np.column_stack([n[:, 2], m2[:, 2]])
    s /= np.maximum(np.linalg.norm(s, axis=1), 1e-300)[:, None]
    mirror = (s[:, 0] < -1e-12) | ((np.abs(s[:, 0]) <= 1e-12) & (s[:, 1] < 0.0))
    s[mirror] *= -1.0
    key = np.round(s, 9) + 0.0
    uniq, inverse = np.unique(key, axis=0, return_inverse=True)
    out: _GroupedSections = []
    for g, direction in enumerate(uniq):
        geo = LayerStack(
            stack.layers, stack.layer_height, (float(direction[0]), float(direction[1]))
        )
        sec = model.section(active, passive, radius, frac, temperature, stack=geo)
        out.append((np.flatnonzero(inverse.reshape(-1) == g), sec))
    return out


@dataclass(frozen=True)
class FilamentModel:
    """Modelling choices of the print-to-shape chain (all can be calibrated).

    ``FilamentModel()`` is the calibrated default (:data:`CALIBRATED`): the threshold strain
    law, the effective modulus ratio and the passive strain fitted jointly to the paper's
    filament measurements. :func:`named_model` gives the others by name.

    Parameters
    ----------
    strain_model
        Actuation strains of the LCE vs print speed (:mod:`rotomorph.materials.process`).
    modulus_ratio
        Effective E_a/E_p at the actuation temperature (dimensionless) or ``None`` for the
        materials' 25 °C ratio (52 for the paper's inks; known to under-predict curvature).
    passive_strain
        Free strain of the passive ink at full actuation (dimensionless, in the strain model's
        measure) or ``None`` to take it from the material's ``actuation_length``.
    transition_width
        Width of the actuation sigmoid through T_NI (°C).
    hysteresis
        Width of the heating/cooling hysteresis loop (°C).
    direction
        ``"heating"`` or ``"cooling"`` branch of the actuation curve.
    resolution
        Boundary vertices of the section mesh.
    temperature_dependent
        ``True`` (default): over a heating ramp the moduli and the passive strain follow the
        temperature laws of :mod:`rotomorph.materials.temperature` (what is measured and what
        is assumed is listed there) and the LCE eigenstrains scale with x(T). ``False``: the
        full-actuation moduli at every temperature and every eigenstrain scaled by x(T). The
        calibration works at full actuation, where both agree (free shapes at 175 °C to
        1e-4); they differ on the way (e.g. where a contracting lattice first touches
        itself).
    director_pitch
        Director helix per nozzle rotation: tan φ(R) = ``director_pitch`` · ω* at the surface
        (dimensionless; 1 is the kinematic helix of the material lines).
    print_temperature, actuation_temperature
        Temperatures (°C) of the stored values: moduli measured at the first, full-actuation
        values (strain law, modulus ratio, passive strain) reached at the second.
    materials
        The materials file whose inks the model looks names up in (:meth:`material`); ``None``:
        the registry (:func:`~rotomorph.materials.material.get_material`, the paper's inks).
        :meth:`MaterialSet.filament_model
        <rotomorph.materials.parameter_set.MaterialSet.filament_model>` builds the model of a
        set's ink pair.
    section_model
        ``"linear"`` (default): the small-strain section (:mod:`rotomorph.materials.section`);
        ``"neo-hookean"``: natural strain and curvature of the incompressible neo-Hookean
        section at finite fibre strain (:mod:`rotomorph.materials.finite_section`), same moduli,
        no new parameter. Stiffnesses and natural twist are the linear section's in both.
    """

    strain_model: ActuationStrainModel = field(default_factory=_calibrated_strain_model)
    modulus_ratio: float | None = CALIBRATED_MODULUS_RATIO
    passive_strain: float | None = CALIBRATED["passive_strain"]
    transition_width: float = _PAPER["transition_width"]
    hysteresis: float = _PAPER["hysteresis"]
    direction: Literal["heating", "cooling"] = "heating"
    resolution: int = DEFAULT_RESOLUTION
    temperature_dependent: bool = True
    director_pitch: float = _PAPER["director_pitch"]
    print_temperature: float = _PAPER["print_temperature"]
    actuation_temperature: float = _PAPER["actuation_temperature"]
    materials: MaterialSet | None = None
    section_model: Literal["linear", "neo-hookean"] = "linear"

    def __post_init__(self) -> None:
        if self.section_model not in SECTION_MODELS:
            raise InvalidParameterError(
                "FilamentModel.section_model",
                f"must be one of {SECTION_MODELS}; got {self.section_model!r}",
            )
        if not isinstance(self.strain_model, ActuationStrainModel):
            raise InvalidParameterError(
                "FilamentModel.strain_model", "must implement active_strains(speed) and measure"
            )
        if self.modulus_ratio is not None and not (
            np.isfinite(self.modulus_ratio) and self.modulus_ratio > 0.0
        ):
            raise InvalidParameterError(
                "FilamentModel.modulus_ratio", f"must be > 0 or None; got {self.modulus_ratio}"
            )
        if self.passive_strain is not None and not np.isfinite(self.passive_strain):
            raise InvalidParameterError("FilamentModel.passive_strain", "must be finite or None")
        if not (np.isfinite(self.director_pitch) and self.director_pitch > 0.0):
            raise InvalidParameterError(
                "FilamentModel.director_pitch", f"must be > 0; got {self.director_pitch}"
            )
        if not (
            np.isfinite(self.print_temperature)
            and np.isfinite(self.actuation_temperature)
            and self.print_temperature < self.actuation_temperature
        ):
            raise InvalidParameterError(
                "FilamentModel.actuation_temperature",
                "must be finite and above print_temperature (°C)",
            )

    def material(self, name: str) -> Material:
        """The ink ``name`` from the model's materials file, else from the registry."""
        if self.materials is not None:
            return self.materials.material(name)
        return get_material(name)

    def fraction(self, active: Material, temperature: float) -> float:
        """Actuation fraction x(T) ∈ [0, 1] of ``active`` at ``temperature`` (°C)."""
        return float(
            actuation_fraction(
                temperature,
                active.transition_temperature,  # type: ignore[arg-type]
                self.transition_width,
                direction=self.direction,
                hysteresis=self.hysteresis,
            )
        )

    def moduli(
        self, active: Material, passive: Material, temperature: float | None = None
    ) -> tuple[float, float]:
        """(E_a, E_p) in MPa: at full actuation, or at ``temperature`` (°C).

        At full actuation E_p is the passive ink's (25 °C) modulus and E_a = ratio × E_p (the
        ratio is what matters for free shapes). With a temperature and
        ``temperature_dependent``, the laws of :mod:`rotomorph.materials.temperature`: E_p
        entropic, E_a from its measured 25 °C value to ratio × E_p(T) as x(T) goes 0 → 1.
        """
        e_p = passive.youngs_modulus
        if self.modulus_ratio is None:
            return active.youngs_modulus, e_p
        if temperature is None or not self.temperature_dependent:
            return self.modulus_ratio * e_p, e_p
        e_p = passive_modulus(e_p, temperature, self.print_temperature)
        x = self.fraction(active, temperature)
        return active_modulus(active.youngs_modulus, self.modulus_ratio * e_p, x), e_p

    def strains_at(
        self, speed: float | FloatArray, active: Material, passive: Material, temperature: float
    ) -> tuple[FloatArray, FloatArray, float]:
        """Free strains (ε∥, ε⊥, ε_p) reached at ``temperature`` (°C) for print speed v (mm/s).

        LCE strains x(T) × full; passive strain linear in T from 25 °C (thermal expansion;
        the model's value at 175 °C) when ``temperature_dependent``, else x(T) × full.
        """
        e_par, e_perp, eps_p = self.strains(speed, passive)
        x = self.fraction(active, temperature)
        share = (
            passive_strain_fraction(temperature, self.print_temperature, self.actuation_temperature)
            if self.temperature_dependent
            else x
        )
        return x * np.asarray(e_par), x * np.asarray(e_perp), share * eps_p

    def section(
        self,
        active: Material,
        passive: Material,
        radius: float,
        active_fraction: float,
        temperature: float | None = None,
        *,
        stack: LayerStack | None = None,
    ) -> FilamentSection:
        """The (cached) meshed section for these materials and geometry (at ``temperature``);
        with ``stack``, the fused section of printed layers
        (:func:`rotomorph.materials.stack.stack_section`)."""
        e_a, e_p = self.moduli(active, passive, temperature)
        common = dict(
            poisson_active=active.poisson_ratio,
            poisson_passive=passive.poisson_ratio,
            active_fraction=active_fraction,
            resolution=self.resolution,
        )
        measure = self.strain_model.measure
        if stack is not None and stack.layers > 1:
            stacked = stack_section(
                radius,
                stack.layers,
                stack.layer_height,
                e_a,
                e_p,
                direction=stack.direction or (0.0, 1.0),
                **common,  # type: ignore[arg-type]
            )
            return with_law(stacked, self.section_model, measure)
        one = filament_section(radius, e_a, e_p, **common)  # type: ignore[arg-type]
        return with_law(one, self.section_model, measure)

    def strains(
        self, speed: float | FloatArray, passive: Material
    ) -> tuple[FloatArray, FloatArray, float]:
        """Full-actuation (ε∥, ε⊥, ε_p) (dimensionless) for print speed v (mm/s)."""
        e_par, e_perp = self.strain_model.active_strains(speed)
        eps_p = (
            passive.free_strain(self.strain_model.measure)
            if self.passive_strain is None
            else float(self.passive_strain)
        )
        return e_par, e_perp, eps_p


#: Names of :func:`named_model` (``rotomorph simulate --model``).
MODEL_NAMES = ("calibrated", "warner-terentjev", "room-temperature")


def named_model(name: str, base: FilamentModel | None = None) -> FilamentModel:
    """A filament model by name, built on ``base`` (default :class:`FilamentModel`, the paper's
    calibrated model; a lab's: :meth:`MaterialSet.filament_model
    <rotomorph.materials.parameter_set.MaterialSet.filament_model>`).

    ``calibrated``
        ``base`` itself: for the default, the joint fit to the paper's filament measurements
        (:data:`CALIBRATED`).
    ``warner-terentjev``
        Ideal-nematic-rubber strains with Q = S(v) (Warner & Terentjev, *Liquid Crystal
        Elastomers*, OUP 2007; the ink's measured order parameter) and the calibrated modulus
        ratio: a physical prior that does not capture the speed dependence of the Janus
        curvature.
    ``room-temperature``
        Warner-Terentjev strains with the inks' measured moduli at the print temperature
        (E_a/E_p = 52 for the paper's inks): known to under-predict the Janus curvature 2-4×;
        shows what the measured moduli alone give.

    Raises
    ------
    InvalidParameterError
        Unknown name (the message lists the known ones).
    """
    model = FilamentModel() if base is None else base
    points = getattr(model.strain_model, "order_points", None)
    wt = WarnerTerentjev() if points is None else WarnerTerentjev(order_points=points)
    if name == "calibrated":
        return model
    if name == "warner-terentjev":
        return replace(model, strain_model=wt, passive_strain=None)
    if name == "room-temperature":
        return replace(model, strain_model=wt, modulus_ratio=None, passive_strain=None)
    raise InvalidParameterError("model", f"must be one of {MODEL_NAMES}; got {name!r}")


@compact_display()
@dataclass(frozen=True, eq=False)
class NaturalField:
    """Natural (stress-free) state and stiffness of one filament in DER conventions (Frame A).

    Attributes
    ----------
    directors
        ``(N-1, 3)`` unit material directors m1 = ±n of the edges: the interface normal n (into
        the active phase) or its opposite, signed so that the directors have no π jumps where
        the active side flips (see :func:`continuous_sign`); the curvature increments carry the
        side.
    curvature1, curvature2, twist
        ``(N-2,)`` natural curvature toward m1, m2 and twist at interior vertices: turning and
        twist angle per unit *printed* length (1/mm). Times ``voronoi_length`` (printed) they
        are the integrated natural values the rod uses, whatever the rest lengths: natural
        angles are material quantities, so a uniform centre-line strain of any printed shape is
        a similarity. In linear section theory (plane sections) the angle between two cross
        sections a printed distance dS apart is κ dS, with κ from the section (fibre strains
        ε_c − κ·x are relative to printed length), so the actuation increments are per printed
        length too.
    voronoi_length
        ``(N-2,)`` printed Voronoi lengths (mm).
    rest_length
        ``(N-1,)`` natural edge lengths after actuation (mm).
    axial_strain
        ``(N-1,)`` applied natural centre-line strain x·ε_c (dimensionless, model's measure).
    bending_stiffness1, bending_stiffness2, twist_stiffness
        ``(N-1,)`` B1 (toward m1 = n), B2, C (N·mm²).
    axial_stiffness
        ``(N-1,)`` EA (N).
    actuation
        Actuation fraction x ∈ [0, 1] at the given temperature.
    measure
        Strain measure used for ``rest_length``.
    """

    directors: FloatArray
    curvature1: FloatArray
    curvature2: FloatArray
    twist: FloatArray
    voronoi_length: FloatArray
    rest_length: FloatArray
    axial_strain: FloatArray
    bending_stiffness1: FloatArray
    bending_stiffness2: FloatArray
    twist_stiffness: FloatArray
    axial_stiffness: FloatArray
    actuation: float
    measure: Literal["hencky", "engineering"] = "hencky"

    def morphology(self, *, rtol: float = 1e-6) -> HelixShape:
        """Closed-form free-filament helix for a uniform natural field.

        Raises
        ------
        InvalidDesignError
            The curvature, twist or axial strain vary along the filament by more than ``rtol``
            relative to the field's scale (use the rod solver for non-uniform fields).
        """
        k = np.hypot(self.curvature1, self.curvature2)
        scale = max(float(np.max(np.abs(k))), float(np.max(np.abs(self.twist))), 1e-12)
        for name, arr, s in (
            ("curvature", k, scale),
            ("twist", self.twist, scale),
            ("axial_strain", self.axial_strain, 1.0),
        ):
            if np.ptp(arr) > rtol * s:
                raise InvalidDesignError(
                    f"NaturalField.{name}",
                    "varies along the filament; the closed-form helix needs a uniform field",
                )
        return free_helix(
            float(np.mean(k)),
            float(np.mean(self.twist)),
            float(np.mean(self.axial_strain)),
            measure=self.measure,
        )


def _program_arrays(
    program: Any,
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray, float, float]:
    pts = np.asarray(program.points, dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 3 or len(pts) < 3 or not np.all(np.isfinite(pts)):
        raise InvalidDesignError("PrintProgram.points", "must be finite (N, 3) mm with N >= 3")
    n = len(pts)
    speed = np.asarray(program.speed, dtype=float).reshape(-1)
    rot = np.asarray(program.rotation, dtype=float).reshape(-1)
    alpha = np.asarray(program.interface_angle, dtype=float).reshape(-1)
    for name, arr, size in (
        ("speed", speed, n),
        ("rotation", rot, n),
        ("interface_angle", alpha, n - 1),
    ):
        if arr.shape != (size,) or not np.all(np.isfinite(arr)):
            raise InvalidDesignError(f"PrintProgram.{name}", f"must be {size} finite values")
    if np.any(speed <= 0.0):
        i = int(np.argmax(speed <= 0.0))
        raise InvalidDesignError(
            "PrintProgram.speed", f"must be > 0 mm/s; got {speed[i]} at vertex {i}"
        )
    radius = float(program.radius)
    if not np.isfinite(radius) or radius <= 0.0:
        raise InvalidDesignError("PrintProgram.radius", f"must be > 0 mm; got {radius}")
    frac = float(program.active_fraction)
    if not 0.0 < frac <= 1.0:
        raise InvalidDesignError("PrintProgram.active_fraction", f"must lie in (0, 1]; got {frac}")
    return pts, speed, rot, alpha, radius, frac


def _material(
    name: str, materials: Mapping[str, Material] | None, kind: str, model: FilamentModel
) -> Material:
    if materials is not None and name in materials:
        mat = materials[name]
    else:
        mat = model.material(name)
    if mat.kind != kind:
        raise MaterialError(f"PrintProgram.{kind}_material", f"{name!r} is {mat.kind}, not {kind}")
    return mat


def _check_handedness(k1: FloatArray, k2: FloatArray, tw: FloatArray, w: FloatArray) -> None:
    """Warn when, on straight stretches, the printed twist opposes the director helix.

    Vertices where the interface turns by more than π/4 (integrated) are flips of the active
    side, not a resolved helix, and are left out.
    """
    w_vertex = 0.5 * (w[:-1] + w[1:])
    straight = (np.hypot(k1, k2) < 1e-9) & (np.abs(w_vertex) > 1e-9) & (np.abs(tw) < np.pi / 4)
    if np.any(straight):
        agree = np.sign(tw[straight]) == np.sign(w_vertex[straight])
        if np.mean(agree) < 0.5:
            logger.warning(
                "printed interface twist opposes the director helix on %d straight vertices; "
                "check the sign convention of PrintProgram.rotation vs interface_angle "
                "(expected dα/ds = %+g·ω/v)",
                int(np.sum(~agree)),
                DIRECTOR_HELIX_SENSE,
            )


def continuous_sign(normals: FloatArray, tangents: FloatArray) -> FloatArray:
    """Signs ``(E,)`` making ``sign * normals`` continuous along a filament.

    An edge's sign flips when its normal points against the parallel transport of the previous
    edge's signed normal (an interface flip by about pi).
    """
    sign = np.ones(len(normals))
    if len(normals) > 1:
        prev = geometry.parallel_transport(normals[:-1], tangents[:-1], tangents[1:])
        flips = np.einsum("ij,ij->i", prev, normals[1:]) < 0.0
        sign[1:] = np.where(np.cumsum(flips) % 2 == 1, -1.0, 1.0)
    return sign


def _vertex_increments(
    program: Any,
    t: FloatArray,
    normals: FloatArray,
    speed: FloatArray,
    rot: FloatArray,
    radius: float,
    model: FilamentModel,
    sections: Callable[[FloatArray, FloatArray], _GroupedSections],
    state: tuple[Material, Material, float],
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Curvature vector ``(N-2, 3)``, eigen-twist ``(N-2,)`` and the printed curvature's change of
    the centre-line strain ``(N-2,)`` at the interior vertices at the temperature of ``state``,
    sampled at the vertex (midpoint rule on its Voronoi cell). The section is solved as a
    curved bar with the path's printed curvature (:func:`printed_curvature`).

    The active side is the program's vertex interface normal (``vertex_interface_normals``;
    the mean of the two edge normals for programs without it). Sampling at vertices makes a
    flip between two vertices a step at the edge midpoint, the boundary of the two Voronoi
    cells; sampling the edge's mean nozzle angle instead put the active side on top of the
    filament over the whole flip edge, an out-of-plane curvature K_J·h per flip that changed
    the shape with the vertex spacing h.

    ``sections(n, m2)`` gives the sections of vertices with these interface frames (one, or a
    printed stack's per stacking direction).
    """
    vn = getattr(program, "vertex_interface_normals", None)
    if vn is None:
        n_v = geometry.unit(normals[:-1] + normals[1:])
    else:
        n_v = np.asarray(vn, dtype=float)[1:-1]
    omega_v = DIRECTOR_HELIX_SENSE * dimensionless_rotation(rot[1:-1], speed[1:-1], radius)
    omega_v = model.director_pitch * omega_v  # the director helix (kinematic: pitch 1)
    active, passive, temperature = state
    e_par, e_perp, eps_p = model.strains_at(speed[1:-1], active, passive, temperature)
    tb = geometry.unit(t[:-1] + t[1:])
    m2 = np.cross(tb, n_v)
    k0 = printed_curvature(program, radius)
    k0_section = np.column_stack([np.einsum("ij,ij->i", k0, n_v), np.einsum("ij,ij->i", k0, m2)])
    cols = np.broadcast_arrays(
        *(np.atleast_1d(np.asarray(a, dtype=float)) for a in (omega_v, e_par, e_perp, eps_p)),
        np.zeros(len(n_v)),
    )[:4]
    eps_straight, dtau = np.empty(len(n_v)), np.empty(len(n_v))
    eps_curved, kappa = np.empty(len(n_v)), np.empty((len(n_v), 2))
    for rows, section in sections(n_v, m2):
        w, ep, et, eq = (c[rows] for c in cols)
        eps_straight[rows], _, dtau[rows] = section.natural_strains(w, ep, et, eq)
        eps_curved[rows], kappa[rows] = section.curved_strains(w, ep, et, eq, k0_section[rows])
    vec = kappa[:, :1] * n_v + kappa[:, 1:2] * m2
    if getattr(program, "step_flips", False) and vn is not None and len(vec) > 2:
        # a vertex in the middle of a split step flip (both its edges flip) is the step
        # itself: half of its cell on each side, so its increment is the mean of its
        # neighbours' (about zero), not K toward the mid-flip normal (out of plane)
        mid = _mid_flip(np.asarray(vn, dtype=float))[1:-1]
        mid[0] = mid[-1] = False
        vec[mid] = 0.5 * (vec[np.flatnonzero(mid) - 1] + vec[np.flatnonzero(mid) + 1])
    deps = np.asarray(eps_curved - eps_straight, dtype=float)
    return vec, np.asarray(dtau, dtype=float).reshape(-1), deps


#: Largest ``|k0| R`` the curved-section theory is applied with (a printed corner sharper than
#: the filament is a polyline artefact: no extruded filament bends tighter than its radius).
CURVATURE_LIMIT = 0.9


def printed_curvature(program: Any, radius: float | FilamentSection) -> FloatArray:
    """Printed pointwise curvature vectors ``(N-2, 3)`` (1/mm, toward the centre of curvature)
    at the interior vertices of ``program``'s path, for the curved-section correction.

    Vertices whose curvature radius is below the filament radius R (a sharp polyline corner)
    are limited to ``|k0| R =`` :data:`CURVATURE_LIMIT`, with a warning: there the correction
    depends on the vertex spacing (a corner's curvature is its turning angle over the
    spacing), so paths with corners should be rounded to at least the filament radius.
    """
    pts = np.asarray(program.points, dtype=float)
    e = np.diff(pts, axis=0)
    kb = geometry.curvature_binormal(e[:-1], e[1:])
    lengths = np.linalg.norm(e, axis=1)
    vor = 0.5 * (lengths[:-1] + lengths[1:])
    tb = geometry.unit(e[:-1] / lengths[:-1, None] + e[1:] / lengths[1:, None])
    k0 = np.cross(kb, tb) / vor[:, None]
    r = float(radius.radius if isinstance(radius, FilamentSection) else radius)
    size = np.linalg.norm(k0, axis=1) * r
    sharp = size > CURVATURE_LIMIT
    if np.any(sharp):
        logger.warning(
            "%d printed corner(s) turn more sharply than the filament's radius (largest "
            "|k0|·R = %.3g); the curved-section correction uses |k0|·R = %g there",
            int(sharp.sum()),
            float(size.max()),
            CURVATURE_LIMIT,
        )
        k0[sharp] *= (CURVATURE_LIMIT / size[sharp])[:, None]
    return k0


def _flip_edges(vertex_normals: FloatArray) -> BoolArray:
    """Edges whose two vertex normals are 90° or more apart (a flip of the active side)."""
    dots = np.einsum("ij,ij->i", vertex_normals[:-1], vertex_normals[1:])
    return cast(BoolArray, dots <= 1e-9)


def _mid_flip(vertex_normals: FloatArray) -> BoolArray:
    """Vertices ``(N,)`` whose edges on both sides are flip edges."""
    flip = _flip_edges(vertex_normals)
    mid = np.zeros(len(vertex_normals), dtype=bool)
    mid[1:-1] = flip[:-1] & flip[1:]
    return mid


def _step_flip_normals(
    normals: FloatArray, vertex_normals: FloatArray, t: FloatArray
) -> FloatArray:
    """Edge normals of a program whose flips are ideal steps.

    A flip edge lies on the side of its end that is not itself mid-flip (a split flip steps at
    that vertex); an edge holding a whole flip steps at its midpoint and its principal axis is
    that of either end (their sign-aligned mean). Other edges keep their normals.
    """
    flip = _flip_edges(vertex_normals)
    if not flip.any():
        return normals
    mid = _mid_flip(vertex_normals)
    a, b = vertex_normals[:-1], vertex_normals[1:]
    aligned = a + np.sign(np.einsum("ij,ij->i", a, b) + 1e-300)[:, None] * b
    axis = np.where(mid[:-1, None], b, np.where(mid[1:, None], a, aligned))
    axis = axis - np.einsum("ij,ij->i", axis, t)[:, None] * t
    out = normals.copy()
    out[flip] = geometry.unit(axis[flip])
    return out


def edge_shares(vertex_values: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Each edge's shares ``(N-1,)`` of interior-vertex values ``(N-2,)``, from its start and
    from its end vertex: their sum is the mean over the edge's interior end vertices (one for
    the first and last edge)."""
    v = np.asarray(vertex_values, dtype=float)
    count = np.full(len(v) + 1, 2.0)
    count[0] = count[-1] = 1.0
    start, end = np.zeros(len(v) + 1), np.zeros(len(v) + 1)
    start[1:] = v / count[1:]  # vertex j is edge j's start
    end[:-1] = v / count[:-1]  # and edge j-1's end
    return start, end


@dataclass(frozen=True, eq=False)
class ActuationIncrements:
    """What heating adds to the printed natural state of one filament (frame-free form).

    Every lattice edge and every single filament gets its actuation from here, so both go
    through the same chain: print program → section (materials, temperature) → increments.

    Attributes
    ----------
    curvature
        ``(N-2, 3)`` natural-curvature vectors added at the interior vertices (1/mm per printed
        length, toward the side the filament bends to) at the temperature asked for.
    twist
        ``(N-2,)`` eigen-twist added at the interior vertices (1/mm per printed length).
    axial_strain
        ``(N-1,)`` natural centre-line strain ε_c(T) of each edge (model's measure), the
        printed curvature's change included.
    curved_strain
        ``(N-2,)`` that change at the interior vertices (curved-bar section minus straight);
        an edge takes the mean of its interior end vertices'.
    stretch
        ``(N-1,)`` rest length / printed length of each edge.
    normals
        ``(N-1, 3)`` interface normals n of the edges (into the active phase).
    omega_star
        ``(N-1,)`` signed director-helix rotation number of the edges.
    actuation
        x(T) ∈ [0, 1].
    measure
        Strain measure of ``axial_strain``.
    section
        The meshed cross-section (stiffnesses).
    """

    curvature: FloatArray
    twist: FloatArray
    axial_strain: FloatArray
    curved_strain: FloatArray
    stretch: FloatArray
    normals: FloatArray
    omega_star: FloatArray
    actuation: float
    measure: Literal["hencky", "engineering"]
    section: FilamentSection


def actuation_increments(
    program: Any,
    materials: Mapping[str, Material] | None = None,
    temperature: float = 175.0,
    *,
    model: FilamentModel | None = None,
    stack: LayerStack | None = None,
) -> ActuationIncrements:
    """Actuation increments of a printed filament at ``temperature`` (°C).

    Parameters and errors as :func:`natural_field`. The section quantities (K_J, K_2, Δτ) are
    sampled at the vertices with the vertex's speed and rotation, toward the vertex interface
    normal (see ``_vertex_increments``); the centre-line strain per edge. ``stack``: the
    program is one of the identical layers of a printed stack, and the increments are the
    stack's (its fused section, :func:`rotomorph.materials.stack.stack_section`, with every
    layer's eigenstrain field from this program).
    """
    model = FilamentModel() if model is None else model
    pts, speed, rot, alpha, radius, frac = _program_arrays(program)
    # the rotation that winds the director helix (ideal step flips wind none)
    rot = np.asarray(getattr(program, "director_rotation", rot), dtype=float).reshape(-1)
    active = _material(program.active_material, materials, "active", model)
    passive = _material(program.passive_material, materials, "passive", model)
    x = model.fraction(active, temperature)
    edge_speed = 0.5 * (speed[:-1] + speed[1:])
    edge_rot = 0.5 * (rot[:-1] + rot[1:])
    omega_star = DIRECTOR_HELIX_SENSE * dimensionless_rotation(edge_rot, edge_speed, radius)
    d1 = geometry.space_parallel_directors(pts)
    t = geometry.unit(np.diff(pts, axis=0))
    normals = geometry.rotate_about_tangent(d1, t, alpha)
    vn = getattr(program, "vertex_interface_normals", None)
    if getattr(program, "step_flips", False) and vn is not None:
        normals = _step_flip_normals(normals, np.asarray(vn, dtype=float), t)

    # section(s) and free strains at this temperature (moduli and strains: temperature laws)
    def sections(n: FloatArray, m2: FloatArray) -> _GroupedSections:
        return _sections_by_stacking(
            model, (active, passive), radius, frac, temperature, stack, n, m2
        )

    e_par, e_perp, eps_p = model.strains_at(edge_speed, active, passive, temperature)
    edge_cols = np.broadcast_arrays(
        *(
            np.atleast_1d(np.asarray(a, dtype=float))
            for a in (model.director_pitch * omega_star, e_par, e_perp, eps_p)
        ),
        np.zeros(len(t)),
    )[:4]
    eps_c = np.empty(len(t))
    edge_sections = sections(normals, np.cross(t, normals))
    for rows, sec in edge_sections:
        eps_c[rows] = sec.natural_strains(*(c[rows] for c in edge_cols))[0]
    section = edge_sections[0][1]
    vec, dtw, deps = _vertex_increments(
        program, t, normals, speed, rot, radius, model, sections, (active, passive, temperature)
    )
    measure = model.strain_model.measure
    # the curved-section change of the centre-line strain, from the edge's interior end(s)
    from_start, from_end = edge_shares(deps)
    axial = np.asarray(eps_c, dtype=float).reshape(-1) * np.ones(len(t)) + from_start + from_end
    stretch = np.exp(axial) if measure == "hencky" else 1.0 + axial
    return ActuationIncrements(
        curvature=vec,
        twist=dtw,
        axial_strain=axial,
        curved_strain=deps,
        stretch=stretch,
        normals=normals,
        omega_star=np.asarray(omega_star, dtype=float),
        actuation=x,
        measure=measure,
        section=section,
    )


def natural_field(
    program: Any,
    materials: Mapping[str, Material] | None = None,
    temperature: float = 175.0,
    *,
    model: FilamentModel | None = None,
) -> NaturalField:
    """Natural curvature, twist, rest lengths and stiffnesses of one printed filament.

    Parameters
    ----------
    program
        Print program with ``points`` (N, 3) mm, ``speed`` (N,) mm/s, ``rotation`` (N,) rad/s,
        ``interface_angle`` (N-1,) rad (from d1 toward d2 = t × d1), ``radius`` mm,
        ``active_fraction`` in (0, 1], ``active_material`` and ``passive_material`` names.
    materials
        Name → :class:`Material` overrides; names not in it come from the model's materials
        file (``model.materials``), else from the registry.
    temperature
        Actuation temperature T (°C); the paper actuates at 150-175 °C (full actuation).
    model
        Modelling choices; default :class:`FilamentModel` (WT strains, calibrated ratio).

    Returns
    -------
    NaturalField

    Raises
    ------
    InvalidDesignError
        Malformed program (shapes, non-positive speed or radius, bad active fraction).
    MaterialError
        Unknown material names or an active/passive mix-up.
    """
    inc = actuation_increments(program, materials, temperature, model=model)
    pts = np.asarray(program.points, dtype=float)
    t = geometry.unit(np.diff(pts, axis=0))
    # m1 = sign * n: the same principal axis, but without the pi jumps of n where the active
    # side flips (a DER vertex averages its two edges' frames, which vanish across a pi jump
    # and would leave a stiffness-free hinge there); the side is carried by the sign
    sign = continuous_sign(inc.normals, t)
    directors = sign[:, None] * inc.normals
    k1, k2, tw, vor = geometry.polyline_strains(pts, directors)
    _check_handedness(k1, k2, tw, inc.omega_star)
    dk1, dk2 = geometry.curvature_increment(
        t[:-1], t[1:], directors[:-1], directors[1:], inc.curvature
    )
    lengths = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    section = inc.section
    ones = np.ones(len(lengths))
    return NaturalField(
        directors=directors,
        curvature1=k1 / vor + dk1,
        curvature2=k2 / vor + dk2,
        twist=tw / vor + inc.twist,
        voronoi_length=vor,
        rest_length=lengths * inc.stretch,
        axial_strain=inc.axial_strain,
        bending_stiffness1=section.bending_stiffness1 * ones,
        bending_stiffness2=section.bending_stiffness2 * ones,
        twist_stiffness=section.twist_stiffness * ones,
        axial_stiffness=section.axial_stiffness * ones,
        actuation=inc.actuation,
        measure=inc.measure,
    )

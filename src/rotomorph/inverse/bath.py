r"""A lattice design verified in the surroundings it declares: the very heating ramp that
``rotomorph simulate`` runs on its design file.

A printed lattice is heated on the floor of a bath of hot oil: its filaments touch one another
and the floor, and it weighs its buoyant weight. :func:`verify_in_bath` heats a printed design
with :func:`rotomorph.lattice.heat_lattice` and the keyword arguments
:func:`rotomorph.simulate.surroundings.lattice_surroundings` builds from the design file's
``[contact]`` table (self-contact, the floor just below the printed lattice, the buoyant weight
following the bath's density along the temperature ramp, friction and the lift probe and path
check where set), over the same temperature ramp and the same number of steps as
``simulate``'s default. The verified state is *reached* only when it is a certified stable
minimum, admissible (no two filaments, or layers of the printed stack where the admissibility
check knows them, interpenetrate) and its Gaussian curvature lies within the tolerance of the
target's; otherwise the check says which of these failed.

Where the target is not reached under the weight, the check measures why:

* the same design heated in the same ramp without the weight (contact and floor kept): if that
  reaches the target, the weight is what holds the lattice down;
* the weight-to-bending ratio :math:`\Gamma = w\,(L/2)^2 / (B\,k)`: the moment of the buoyant
  line weight :math:`w` (N/mm) of a rim of half-width :math:`L/2` per unit width, over the
  bending moment :math:`B k` that holds the target's curvature :math:`k = \sqrt{|K|}` in an
  edge of bending stiffness :math:`B` (N mm², the mean of the heated edges' two bending
  stiffnesses). The per-width factors cancel on a square grid (one edge per spacing in each
  direction carries both the weight and the stiffness), so :math:`\Gamma \gtrsim 1` means the
  weight outweighs the bending the target needs.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from rotomorph.analysis.curvature import fit_quadratic_surface
from rotomorph.design.lattices import Lattice
from rotomorph.lattice.actuation import ProgramActuation, default_stiffness, get_actuation
from rotomorph.lattice.heating import HeatingResult, heat_lattice
from rotomorph.lattice.model import lattice_model
from rotomorph.solve.loads import Gravity

__all__ = [
    "REACHED_TOLERANCE",
    "VERIFY_STEPS",
    "BathCheck",
    "bath_contact",
    "bath_kwargs",
    "verify_in_bath",
    "weight_to_bending",
]

#: Relative error of the Gaussian curvature within which a dome or saddle counts as reached.
REACHED_TOLERANCE = 0.10

#: Heating steps of the verification ramp: ``rotomorph simulate``'s default.
VERIFY_STEPS = 8

#: Centre-line clearance (filament diameters) below which two filaments interpenetrate, where
#: the printed stack's own admissibility check is not available.
CLEARANCE_FLOOR = 0.99


def bath_contact(**overrides: Any) -> Any:
    """The bath a lattice lives in, as a design file's ``[contact]`` table
    (:class:`rotomorph.io.designfile.ContactModel`): self-contact, the bath floor, the buoyant
    weight in silicone oil, the lowest-energy branch (the lift probe ``simulate`` runs); any
    field may be overridden."""
    from rotomorph.io.designfile import ContactModel

    base: dict[str, Any] = {"self_contact": True, "floor": True, "gravity": True}
    base.update(overrides)
    return ContactModel.model_validate(base)


@dataclass(frozen=True, eq=False)
class BathCheck:
    """A printed lattice heated in its declared surroundings (module docstring).

    Attributes
    ----------
    gaussian_curvature
        K of the quadric fit of the verified state's branch nodes (1/mm²).
    target_gaussian_curvature
        The target's K (1/mm²; None for targets without one).
    error_rel
        ``|K − K_target| / |K_target|`` (None without a target K).
    stable
        The verified state is a certified stable minimum (None: not checked).
    stack_overlaps
        Interpenetrating layer pairs of the printed stack in the verified state (None where
        the admissibility check of the printed stack is not available; then
        ``min_clearance`` decides).
    min_clearance
        Smallest centre-line clearance of non-adjacent segments (filament diameters).
    admissible
        No interpenetration in the verified state.
    floor_lift
        Largest rise of a node above its printed height (mm; None without a floor).
    lift_energy_gap
        Lowest energy of a lifted state minus the resting one over the ramp (N mm; NaN where no
        lifted state was probed or found; None without the probe).
    weight_to_bending
        Γ of the module docstring (None without weight or target curvature).
    weightless_gaussian_curvature
        K of the same ramp without the weight (1/mm²; None where not measured).
    reached
        Stable, admissible and within :data:`REACHED_TOLERANCE` of the target's K (targets
        without K: stable and admissible).
    reason
        Why not reached, with the measures (empty when reached).
    cpu_s
        Process CPU time of the checks (s).
    result
        The verifying :class:`~rotomorph.lattice.heating.HeatingResult`.
    """

    gaussian_curvature: float
    target_gaussian_curvature: float | None
    error_rel: float | None
    stable: bool | None
    stack_overlaps: int | None
    min_clearance: float
    admissible: bool
    floor_lift: float | None
    lift_energy_gap: float | None
    weight_to_bending: float | None
    weightless_gaussian_curvature: float | None
    reached: bool
    reason: str
    cpu_s: float
    result: HeatingResult

    @property
    def positions(self) -> Any:
        """Node positions of the verified state ``(N, 3)`` (mm)."""
        return self.result.positions[-1]

    def record(self) -> dict[str, Any]:
        """JSON-ready form (the heating result left out)."""

        def num(x: float | None) -> float | None:
            return None if x is None or not np.isfinite(x) else float(x)

        return {
            "verified_by": "heat_lattice: the ramp rotomorph simulate runs on the design file",
            "gaussian_curvature": num(self.gaussian_curvature),
            "target_gaussian_curvature": num(self.target_gaussian_curvature),
            "gaussian_curvature_error_rel": num(self.error_rel),
            "stable": self.stable,
            "stack_overlaps": self.stack_overlaps,
            "min_clearance_diameters": num(self.min_clearance),
            "admissible": self.admissible,
            "floor_lift_mm": num(self.floor_lift),
            "lift_energy_gap_Nmm": num(self.lift_energy_gap),
            "weight_to_bending": num(self.weight_to_bending),
            "weightless_gaussian_curvature": num(self.weightless_gaussian_curvature),
            "reached": self.reached,
            "reason": self.reason,
            "cpu_s": round(self.cpu_s, 3),
        }


def _actuation(temperature: float, model: Any = None) -> ProgramActuation:
    base = get_actuation("program")
    assert isinstance(base, ProgramActuation)
    return replace(base, end=float(temperature), filament_model=model)


def weight_to_bending(
    lattice: Lattice,
    characteristic_curvature: float,
    temperature: float,
    gravity: Gravity,
    model: Any = None,
) -> float:
    """Γ = w (L/2)² / (B k) of the module docstring (dimensionless): ``w`` the buoyant line
    weight of ``gravity`` (the weight in the bath at ``temperature``, °C), ``L`` the lattice
    size, ``B`` the mean bending stiffness of the edges heated with the materials ``model``
    (N mm²), ``k`` the target's ``sqrt(|K|)`` (1/mm)."""
    act = _actuation(temperature, model)
    stiffness, fm = default_stiffness(act)
    lm = lattice_model(lattice, stiffness=stiffness, filament_model=fm)
    hot = act.natural(lm, act.end)
    b = 0.5 * (
        np.mean(np.asarray(hot.bending_stiffness1, dtype=float))
        + np.mean(np.asarray(hot.bending_stiffness2, dtype=float))
    )
    w = float(gravity.line_weight(1)[0])
    half = 0.5 * lattice.spacing * (lattice.n - 1)
    return float(w * half * half / (b * characteristic_curvature))


def bath_kwargs(
    lattice: Lattice, contact: Any, temperature: float, materials: Any = None, *, ramp: bool
) -> dict[str, Any]:
    """:func:`~rotomorph.lattice.heat_lattice`'s surroundings as ``simulate`` builds them
    from the ``[contact]`` table (the weight along the temperature ramp with ``ramp``, else
    at ``temperature``; the inks of the design's ``materials`` file where it has one)."""
    from rotomorph.simulate.surroundings import lattice_surroundings

    return lattice_surroundings(
        contact, lattice, temperature, ramp_in_temperature=ramp, materials=materials
    )


def _heat(
    lattice: Lattice, contact: Any, temperature: float, steps: int, model: Any, materials: Any
) -> HeatingResult:
    kwargs = bath_kwargs(lattice, contact, temperature, materials, ramp=True)
    return heat_lattice(lattice, actuation=_actuation(temperature, model), steps=steps, **kwargs)


def _overlaps(res: HeatingResult) -> int | None:
    """Interpenetrating layer pairs of the printed stack in the ramp's end state (None: the
    result carries no admissibility check)."""
    counts = res.stack_overlaps
    return None if counts is None else int(np.asarray(counts)[-1])


def verify_in_bath(
    lattice: Lattice,
    target_gaussian_curvature: float | None,
    contact: Any = None,
    *,
    temperature: float = 175.0,
    steps: int = VERIFY_STEPS,
    tolerance: float = REACHED_TOLERANCE,
    diagnose: bool = True,
    filament_model: Any = None,
    materials: Any = None,
) -> BathCheck:
    """Heat the printed ``lattice`` as ``rotomorph simulate`` heats its design file with the
    ``[contact]`` table ``contact`` (default :func:`bath_contact`) and judge the end state.

    Parameters
    ----------
    lattice
        The printed design (modes and per-edge speeds set).
    target_gaussian_curvature
        The target's K (1/mm²), or None.
    contact
        A :class:`rotomorph.io.designfile.ContactModel` (default: the bath).
    temperature
        Bath temperature at the end of the ramp (°C), from 25 °C.
    steps
        Ramp steps (default ``simulate``'s).
    tolerance
        Relative error of K within which the target counts as reached.
    diagnose
        Where the target is not reached under a weight, also heat the design without it
        (``weightless_gaussian_curvature``) and compute Γ (module docstring).
    filament_model, materials
        The materials model of the actuation (default the package's calibrated one) and the
        design's materials file (its inks' densities set the weight), as ``simulate`` takes
        them from the design file.
    """
    contact = bath_contact() if contact is None else contact
    c0 = time.process_time()
    res = _heat(lattice, contact, temperature, steps, filament_model, materials)
    pos = np.asarray(res.positions[-1])
    fit = fit_quadratic_surface(pos[lattice.branch_indices], flat_tolerance=1e-6)
    k = float(fit.gaussian_curvature)
    k_t = target_gaussian_curvature
    err = None if k_t is None else abs(k - k_t) / abs(k_t)
    stable = res.stable[-1] if res.stable else None
    overlaps = _overlaps(res)
    clearance = float(res.min_clearance[-1])
    admissible = overlaps == 0 if overlaps is not None else clearance >= CLEARANCE_FLOOR
    lift = None if res.floor_lift is None else float(res.floor_lift[-1])
    gap = None
    if res.lift_energy_gap is not None:
        finite = np.asarray(res.lift_energy_gap)[np.isfinite(res.lift_energy_gap)]
        gap = float(finite.min()) if len(finite) else float("nan")
    reasons = []
    if stable is not True:
        reasons.append(
            "the verified state is not a certified stable minimum"
            if stable is False
            else "stability not checked"
        )
    if not admissible:
        reasons.append(
            f"the verified state interpenetrates ({overlaps} layer pairs of the printed stack)"
            if overlaps is not None
            else f"filaments interpenetrate (clearance {clearance:.2f} diameters)"
        )
    if err is not None and err > tolerance:
        reasons.append(
            f"K = {k:.3g} 1/mm² against the target's {k_t:.3g} ({100 * err:.0f} % off, "
            f"tolerance {100 * tolerance:.0f} %)"
        )
    gamma = weightless = None
    if reasons and diagnose and contact.gravity and k_t is not None:
        weight = bath_kwargs(lattice, contact, temperature, materials, ramp=False)["gravity"]
        gamma = weight_to_bending(
            lattice, float(np.sqrt(abs(k_t))), temperature, weight, filament_model
        )
        light = _heat(
            lattice,
            contact.model_copy(update={"gravity": False}),
            temperature,
            steps,
            filament_model,
            materials,
        )
        lpos = np.asarray(light.positions[-1])
        weightless = float(
            fit_quadratic_surface(
                lpos[lattice.branch_indices], flat_tolerance=1e-6
            ).gaussian_curvature
        )
        l_err = abs(weightless - k_t) / abs(k_t)
        flat = lift is not None and lift < 2.0 * lattice.radius
        cause = (
            "the weight holds it on the floor: without it the same ramp reaches"
            if flat and l_err <= tolerance
            else "measured: without the weight the same ramp reaches"
        )
        reasons.append(
            f"{cause} K = {weightless:.3g} 1/mm² ({100 * l_err:.0f} % off); weight-to-bending "
            f"ratio w(L/2)²/(B k) = {gamma:.3g}; largest rise off the floor "
            f"{lift if lift is not None else float('nan'):.3g} mm"
        )
    return BathCheck(
        gaussian_curvature=k,
        target_gaussian_curvature=k_t,
        error_rel=err,
        stable=stable,
        stack_overlaps=overlaps,
        min_clearance=clearance,
        admissible=bool(admissible),
        floor_lift=lift,
        lift_energy_gap=gap,
        weight_to_bending=gamma,
        weightless_gaussian_curvature=weightless,
        reached=not reasons,
        reason="; ".join(reasons),
        cpu_s=time.process_time() - c0,
        result=res,
    )

r"""Lattice designs made, verified and bounded in the surroundings the design declares.

:func:`design_in_bath` optimises a lattice design with the physics ``rotomorph simulate``
applies to its design file (:func:`rotomorph.inverse.lattice.design_lattice` with self-contact,
the bath floor and the buoyant weight in the hot bath, on the branch ``simulate``'s lift probe
takes) and has ``simulate``'s own ramp (:func:`rotomorph.inverse.bath.verify_in_bath`) judge
it: where that ramp's verified state is on another branch than the optimiser's, or off the
target, the optimiser starts again from the state the ramp verified (``design_lattice``'s
``judge``, up to :data:`~rotomorph.inverse.lattice.JUDGE_ROUNDS` judgements). Only a design
still not reached then has its overall bending strength scanned with that ramp as the judge
(:data:`BATH_SCALES`). Its shape is bounded by the calibration and the nuisance inputs
(:func:`design_band`).

The band
--------
The verified state is re-solved, warm-started, with the material model at the calibration's
sigma points: the joint fit's optimum moved by ± one posterior standard deviation along each
independent direction of its covariance (:meth:`rotomorph.materials.inference.Fit.directions`,
as :mod:`rotomorph.prediction.band` does for filaments). The band's standard deviation of any
output is that of the central secants, :math:`\sigma^2 = \sum_k ((y_k^+ - y_k^-)/2)^2`; the
nominal value is the verified one (the package's default materials model, which ``simulate``
uses). The nuisance inputs a printed design leaves open (:data:`DESIGN_NUISANCE`: the inks'
mean density and the bath oil's, which set the buoyant weight, and the active ink's T_NI,
with the priors of :mod:`rotomorph.simulate.nuisance`) add :data:`NUISANCE_SAMPLES`
Latin-hypercube samples, whose sample standard deviation is reported beside the calibration's;
the design's geometry (spacing, amplitude, filament width) and the printed stack are its own.
Every band solve follows the verified branch continuously (no lift probe) and is
frictionless.

Robust designs
--------------
With ``robust=True`` the design's overall bending strength (every edge's speed moved so that
its Janus mismatch scales by a common factor, as the nominal design's last phase does) is
chosen to minimise the *expected* squared relative error of K over the sigma points (equal
weights on the ± points) instead of the nominal error; the chosen design is verified in the
bath like the nominal one, and :class:`RobustChoice` records how much it gives up nominally.
Only this one direction is searched for the expected misfit (each point of it costs one solve
per sigma point); the per-edge pattern is the nominal optimum's.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from functools import partial
from typing import Any

import numpy as np

from rotomorph._typing import FloatArray
from rotomorph.analysis.curvature import fit_quadratic_surface
from rotomorph.contact import Contact
from rotomorph.design.lattices import Lattice
from rotomorph.errors import ConvergenceError
from rotomorph.inverse.bath import (
    REACHED_TOLERANCE,
    BathCheck,
    bath_contact,
    bath_kwargs,
    verify_in_bath,
)
from rotomorph.inverse.blend import lattice_blend, with_settings
from rotomorph.inverse.lattice import (
    MEASURED_SPEEDS,
    LatticeDesign,
    ShapeTarget,
    SurfaceTarget,
    _misfit,
    _printable_speeds,
    _same_strength,
    design_lattice,
)
from rotomorph.lattice.actuation import ProgramActuation, default_stiffness, get_actuation
from rotomorph.lattice.admissibility import lattice_stack
from rotomorph.lattice.heating import lattice_buoyancy
from rotomorph.lattice.model import lattice_model
from rotomorph.rod.state import State
from rotomorph.solve.loads import Loads
from rotomorph.solve.newton import NewtonOptions
from rotomorph.solve.static import solve_static

__all__ = [
    "BATH_SCALES",
    "DESIGN_NUISANCE",
    "NUISANCE_SAMPLES",
    "ROBUST_SCALES",
    "DesignBand",
    "RobustChoice",
    "design_band",
    "design_in_bath",
]

#: Overall strength factors a robust design is chosen among (1: the nominal design).
ROBUST_SCALES = (0.85, 0.92, 1.0, 1.08, 1.16)

_BAND_OPTIONS = NewtonOptions(rtol=1e-8, max_iterations=300)

#: Nuisance inputs (:data:`rotomorph.simulate.nuisance.NUISANCE_PRIORS`) a printed design
#: leaves open: its geometry (spacing, amplitude, filament width) is the design's own.
DESIGN_NUISANCE = ("filament_density", "bath_density", "transition")

#: Latin-hypercube samples of :data:`DESIGN_NUISANCE` in a design's band.
NUISANCE_SAMPLES = 3


@dataclass(frozen=True, eq=False)
class DesignBand:
    """The calibration band of a verified lattice design (module docstring).

    Attributes
    ----------
    gaussian_curvature
        Nominal K (the verified state's, 1/mm²).
    gaussian_curvature_sd
        Its calibration standard deviation (1/mm²); NaN where a sigma-point solve failed.
    sigma_points
        K at each sigma point ``(2 p,)`` (+ then − along each direction; NaN: failed).
    directions
        Independent directions of the calibration covariance used (p).
    failed
        Sigma-point and nuisance-sample solves that did not converge.
    cpu_s
        Process CPU time of the band (s).
    nuisance_samples
        K at each Latin-hypercube sample of the nuisance inputs (:data:`DESIGN_NUISANCE`;
        NaN: failed; empty: not sampled).
    gaussian_curvature_sd_nuisance
        Sample standard deviation of ``nuisance_samples`` (1/mm²; NaN with fewer than two).
    """

    gaussian_curvature: float
    gaussian_curvature_sd: float
    sigma_points: FloatArray
    directions: int
    failed: int
    cpu_s: float
    nuisance_samples: FloatArray = field(default_factory=lambda: np.zeros(0))
    gaussian_curvature_sd_nuisance: float = float("nan")

    def text(self) -> str:
        """``K = 4.9e-03 ± 3.1e-04 1/mm² (calibration band) ± 2e-04 (nuisance, 3 samples)``."""
        out = (
            f"K = {self.gaussian_curvature:.3g} ± {self.gaussian_curvature_sd:.2g} 1/mm² "
            "(calibration band)"
        )
        if len(self.nuisance_samples):
            out += (
                f" ± {self.gaussian_curvature_sd_nuisance:.2g} (nuisance: "
                f"{len(self.nuisance_samples)} Latin-hypercube samples of "
                f"{', '.join(DESIGN_NUISANCE)})"
            )
        return out

    def record(self) -> dict[str, Any]:
        """JSON-ready form."""

        def num(x: float) -> float | None:
            return float(x) if np.isfinite(x) else None

        return {
            "gaussian_curvature": num(self.gaussian_curvature),
            "gaussian_curvature_sd_calibration": num(self.gaussian_curvature_sd),
            "sigma_points": [num(float(k)) for k in self.sigma_points],
            "directions": self.directions,
            "nuisance_inputs": list(DESIGN_NUISANCE),
            "nuisance_samples": [num(float(k)) for k in self.nuisance_samples],
            "gaussian_curvature_sd_nuisance": num(self.gaussian_curvature_sd_nuisance),
            "failed_solves": self.failed,
            "band_of": "the calibration's posterior and the nuisance inputs' priors (the "
            "design's geometry and the printed stack as given); every solve continues the "
            "verified branch, frictionless",
            "cpu_s": round(self.cpu_s, 3),
        }


@dataclass(frozen=True, eq=False)
class RobustChoice:
    """What a robust design chose (module docstring).

    Attributes
    ----------
    scale
        Overall strength factor chosen (1: the nominal design).
    expected_error
        Root of the expected squared relative K error over the sigma points, per scale tried.
    nominal_error_robust, nominal_error_nominal
        Relative K error of the robust and the nominal design at the nominal calibration,
        both verified in the bath (``simulate``'s ramp).
    gives_up
        ``nominal_error_robust − nominal_error_nominal``: what the robust design gives up at
        the nominal calibration (negative: it is better there too).
    """

    scale: float
    expected_error: dict[float, float]
    nominal_error_robust: float | None
    nominal_error_nominal: float | None
    gives_up: float | None

    def record(self) -> dict[str, Any]:
        """JSON-ready form."""
        return {
            "strength_scale": self.scale,
            "expected_error_rel_by_scale": {
                f"{k:g}": (float(v) if np.isfinite(v) else None)
                for k, v in self.expected_error.items()
            },
            "nominal_error_rel_robust": self.nominal_error_robust,
            "nominal_error_rel_nominal_design": self.nominal_error_nominal,
            "gives_up_nominally": self.gives_up,
        }


def _calibration() -> tuple[Any, FloatArray]:
    from rotomorph.prediction.band import calibration_fit

    fit = calibration_fit()
    dirs = [d for d in fit.directions().T if np.any(d)]
    return fit, np.asarray(dirs)


def _sigma_models(temperature: float) -> list[Any]:
    fit, dirs = _calibration()
    return [fit.model_at(fit.theta + s * d) for d in dirs for s in (1.0, -1.0)]


def _heated_k(
    lattice: Lattice,
    model: Any,
    temperature: float,
    start: State,
    contact: Contact | None,
    loads: Loads | None,
) -> float:
    """K of ``lattice``'s equilibrium with the materials ``model``, from ``start``."""
    act = replace(_program(temperature), filament_model=model)
    stiffness, fm = default_stiffness(act)
    lm = lattice_model(lattice, stiffness=stiffness, filament_model=fm)
    rod = act.natural(lm, act.end)
    res = solve_static(rod, loads=loads, initial=start, options=_BAND_OPTIONS, contact=contact)
    pos = np.asarray(res.positions)
    return float(
        fit_quadratic_surface(pos[lattice.branch_indices], flat_tolerance=1e-6).gaussian_curvature
    )


def _program(temperature: float, model: Any = None) -> ProgramActuation:
    base = get_actuation("program")
    assert isinstance(base, ProgramActuation)
    return replace(base, end=float(temperature), filament_model=model)


def _sigma_values(
    lattice: Lattice, check: BathCheck, temperature: float, contact_model: Any
) -> tuple[FloatArray, int]:
    res = check.result
    contact = None if res.contact is None else replace(res.contact, friction=0.0)
    loads = None
    if contact_model.gravity:
        loads = Loads(gravity=lattice_buoyancy(lattice, bath=contact_model.bath)(temperature))
    return _solved_or_nan(
        lambda model: _heated_k(lattice, model, temperature, res.states[-1], contact, loads),
        _sigma_models(temperature),
    )


def _solved_or_nan(solve: Any, inputs: Any) -> tuple[FloatArray, int]:
    """``solve(x)`` for each input, NaN where it does not converge, and how many did not."""
    out = []
    failed = 0
    for x in inputs:
        try:
            out.append(solve(x))
        except ConvergenceError:
            out.append(float("nan"))
            failed += 1
    return np.asarray(out), failed


def _nuisance_values(
    lattice: Lattice, check: BathCheck, temperature: float, contact_model: Any, count: int
) -> tuple[FloatArray, int]:
    """K at ``count`` Latin-hypercube samples of :data:`DESIGN_NUISANCE` (the active ink's
    T_NI, the inks' and the bath's densities setting the weight), each solved warm-started
    from the verified state with the package's materials model."""
    from rotomorph.simulate.nuisance import latin_hypercube
    from rotomorph.simulate.nuisance_lattices import sample_buoyancy, transition_material

    res = check.result
    contact = None if res.contact is None else replace(res.contact, friction=0.0)

    def solve(sample: Any) -> float:
        lat = replace(lattice, active_material=transition_material(sample.transition))
        loads = None
        if contact_model.gravity:
            loads = Loads(gravity=sample_buoyancy(lat, sample)(temperature))
        return _heated_k(lat, None, temperature, res.states[-1], contact, loads)

    return _solved_or_nan(solve, latin_hypercube(count, seed=0))


def design_band(
    lattice: Lattice,
    check: BathCheck,
    contact: Any = None,
    *,
    temperature: float = 175.0,
    nuisance_samples: int = NUISANCE_SAMPLES,
) -> DesignBand:
    """The band of the printed ``lattice``'s verified state ``check`` (module docstring):
    the calibration's sigma points and ``nuisance_samples`` Latin-hypercube samples of
    :data:`DESIGN_NUISANCE` (0: none), in the surroundings ``contact`` (a design file's
    ``[contact]`` table; default the bath)."""
    contact = bath_contact() if contact is None else contact
    c0 = time.process_time()
    ks, failed = _sigma_values(lattice, check, temperature, contact)
    pairs = ks.reshape(-1, 2)
    sd = float(np.sqrt(np.sum((0.5 * (pairs[:, 0] - pairs[:, 1])) ** 2)))
    nk = np.zeros(0)
    sd_n = float("nan")
    if nuisance_samples:
        nk, n_failed = _nuisance_values(lattice, check, temperature, contact, nuisance_samples)
        failed += n_failed
        finite = nk[np.isfinite(nk)]
        sd_n = float(np.std(finite, ddof=1)) if len(finite) >= 2 else float("nan")
    return DesignBand(
        gaussian_curvature=check.gaussian_curvature,
        gaussian_curvature_sd=sd,
        sigma_points=ks,
        directions=len(pairs),
        failed=failed,
        cpu_s=time.process_time() - c0,
        nuisance_samples=nk,
        gaussian_curvature_sd_nuisance=sd_n,
    )


def _scaled(
    design: LatticeDesign,
    scale: float,
    speed_range: tuple[float, float],
    resolution: float,
    blend: Any = None,
) -> Lattice:
    """``design``'s printed lattice with every edge's Janus mismatch times ``scale``."""
    blend = lattice_blend(design.lattice) if blend is None else blend
    v = _same_strength(blend, scale * design.modes, design.speeds, speed_range)
    v = _printable_speeds(v, speed_range, resolution)
    return with_settings(design.lattice, design.modes, v)


def design_in_bath(
    lattice: Lattice,
    target: SurfaceTarget | ShapeTarget,
    *,
    contact: Any = None,
    temperature: float = 175.0,
    tolerance: float = REACHED_TOLERANCE,
    band: bool = True,
    robust: bool = False,
    speed_range: tuple[float, float] | None = MEASURED_SPEEDS,
    speed_resolution: float = 0.05,
    filament_model: Any = None,
    materials: Any = None,
    **options: Any,
) -> LatticeDesign:
    """Design ``lattice`` for ``target`` in the surroundings ``contact`` declares (a design
    file's ``[contact]`` table; default :func:`~rotomorph.inverse.bath.bath_contact`: contact,
    floor, buoyant weight, the lift probe), verify it by ``simulate``'s ramp and, with
    ``band``, bound its shape by the calibration (module docstring).

    ``filament_model`` and ``materials``: the materials model and the design's materials file
    (a lab's own inks; as :func:`~rotomorph.inverse.bath.verify_in_bath`); the calibration
    band is the package calibration's and is left out (None) with another model.
    ``options`` go to :func:`~rotomorph.inverse.lattice.design_lattice` (``max_iterations``,
    ``printability``, ``seed``, ``nodes``, ``callback``). The optimiser is frictionless (lagged
    friction has no adjoint); the verification applies the table's friction and path check.
    The returned design's ``bath`` says whether it reached the target and, if not, why, with
    the measures; a design whose verified state is unstable or interpenetrates is never
    reported as reached.
    """
    contact = bath_contact() if contact is None else contact
    gravity = bath_kwargs(lattice, contact, temperature, materials, ramp=False).get("gravity")
    floor = bool(contact.floor)
    touch: bool | Contact = False
    if contact.self_contact or floor:
        # the printed stack's layers touch, one capsule each, as in simulate's ramp
        touch = Contact(
            radius=lattice.radius,
            self_contact=bool(contact.self_contact),
            stack=lattice_stack(lattice),
        )
    k_t = target.gaussian_curvature
    scan = k_t is not None and speed_range is not None
    verify = partial(
        verify_in_bath,
        contact=contact,
        temperature=temperature,
        tolerance=tolerance,
        filament_model=filament_model,
        materials=materials,
    )
    des = design_lattice(
        lattice,
        target,
        actuation=_program(temperature, filament_model),
        contact=touch,
        floor=floor,
        gravity=gravity,
        branch=str(contact.branch) if gravity is not None else "continuous",  # type: ignore[arg-type]
        speed_range=speed_range,
        speed_resolution=speed_resolution,
        judge=partial(verify, target_gaussian_curvature=k_t, diagnose=False),
        **options,
    )
    des = replace(des, optimised_gaussian_curvature=des.achieved_gaussian_curvature)
    check = des.bath
    assert check is not None  # the judge ran
    if scan and not check.reached:
        assert speed_range is not None
        des, check = _bath_scan(des, check, verify, speed_range, speed_resolution)
    elif not check.reached:  # the measures of an unreached target
        check = verify(des.lattice, k_t)
    des = _verified(des, check, options.get("nodes", "branch"))
    calibrated = filament_model is None
    if band and calibrated:
        des = replace(des, band=design_band(des.lattice, check, contact, temperature=temperature))
    if robust and calibrated and k_t is not None and speed_range is not None:
        des = _robust(des, contact, temperature, verify, speed_range, speed_resolution)
    return des


#: Overall strength factors the bath-verified scan tries first (then steps of 4 % and 2 %).
BATH_SCALES = (0.84, 0.92, 1.08, 1.18)


def _bath_scan(
    des: LatticeDesign,
    check: BathCheck,
    verify: Callable[..., BathCheck],
    speed_range: tuple[float, float],
    resolution: float,
) -> tuple[LatticeDesign, BathCheck]:
    """The overall bending strength of ``des`` scanned with ``simulate``'s own ramp as the
    judge: the optimiser's equilibria continue one lifted state, ``simulate`` lifts each
    design afresh, and K is what the two disagree on most (the height misfit is nearly flat
    along this direction, K is not). Each scale's printable design (every edge's mismatch
    times the scale, speeds rounded again) is verified in the bath; the stable, admissible one
    closest to the target's K is kept, with its own verification (where the measures of an
    unreached target are then taken)."""
    k_t = des.target_gaussian_curvature
    assert k_t is not None
    blend = lattice_blend(des.lattice)
    tried: dict[float, tuple[Lattice, BathCheck]] = {1.0: (des.lattice, check)}

    def rank(c: BathCheck) -> tuple[bool, float]:
        good = bool(c.stable) and c.admissible
        return (not good, np.inf if c.error_rel is None else c.error_rel)

    def run(scale: float) -> None:
        if any(abs(scale - s) < 1e-9 for s in tried):
            return
        lat = _scaled(des, scale, speed_range, resolution, blend)
        tried[scale] = (lat, verify(lat, k_t, diagnose=False))

    for scale in BATH_SCALES:
        run(scale)
    step = 0.04
    for _ in range(2):
        best = min(tried, key=lambda k: rank(tried[k][1]))
        for scale in (best * (1 - step), best * (1 + step)):
            run(scale)
        step /= 2
    best = min(tried, key=lambda k: rank(tried[k][1]))
    lat, chosen = tried[best]
    if not chosen.reached:  # the measures of an unreached target, on the design returned
        chosen = verify(lat, k_t)
    return replace(des, lattice=lat, speeds=np.asarray(lat.edge_speeds, dtype=float)), chosen


def _robust(
    des: LatticeDesign,
    contact: Any,
    temperature: float,
    verify: Callable[..., BathCheck],
    speed_range: tuple[float, float],
    resolution: float,
) -> LatticeDesign:
    """The strength scale of ``des`` minimising the expected K error over the sigma points."""
    assert des.bath is not None and des.target_gaussian_curvature is not None
    k_t = des.target_gaussian_curvature
    base = des.bath
    expected: dict[float, float] = {}
    printed: dict[float, Lattice] = {}
    blend = lattice_blend(des.lattice)
    for scale in ROBUST_SCALES:
        lat = des.lattice if scale == 1.0 else _scaled(des, scale, speed_range, resolution, blend)
        printed[scale] = lat
        ks, _ = _sigma_values(lat, base, temperature, contact)
        rel = (ks - k_t) / k_t
        expected[scale] = float(np.sqrt(np.mean(rel * rel))) if np.all(np.isfinite(rel)) else np.inf
    best = min(expected, key=lambda s: expected[s])
    nominal_err = base.error_rel
    if best == 1.0:
        choice = RobustChoice(1.0, expected, nominal_err, nominal_err, 0.0)
        return replace(des, robust=choice)
    check = verify(printed[best], k_t)
    gives = (
        None
        if check.error_rel is None or nominal_err is None
        else float(check.error_rel - nominal_err)
    )
    choice = RobustChoice(best, expected, check.error_rel, nominal_err, gives)
    lat = printed[best]
    out = _verified(replace(des, lattice=lat, speeds=np.asarray(lat.edge_speeds)), check, "branch")
    return replace(
        out, band=design_band(lat, check, contact, temperature=temperature), robust=choice
    )


def _verified(des: LatticeDesign, check: BathCheck, nodes: str) -> LatticeDesign:
    """``des`` with the verified state, its misfit and K those of ``check``."""
    lat = des.lattice
    picked = np.asarray(lat.branch_indices) if nodes == "branch" else np.arange(lat.network.n_nodes)
    size = lat.spacing * (lat.n - 1)
    j, _ = _misfit(des.target, check.positions, picked, size)
    rms = float(np.sqrt(2.0 * j)) * size
    return replace(
        des,
        positions=check.positions,
        misfit_rms=rms,
        misfit_rel=rms / size,
        achieved_gaussian_curvature=check.gaussian_curvature,
        stable=bool(check.stable),
        bath=check,
    )

r"""Inverse design of a lattice: which edges expand or contract, and how fast each is printed,
so that it rises into a target surface.

Design variables
----------------
Per lattice edge a mode :math:`c_e \in [-1, 1]` (:math:`+1` expanding, active half on the
outer side of the wave; :math:`-1` contracting) and a print speed :math:`v_e` (mm/s) within
the allowed range. :mod:`rotomorph.inverse.blend` gives the natural values (integrated
curvatures and twist per stencil, rest lengths per segment) as smooth functions of both: the
linear blend of the two printable modes, and the speed through the calibrated speed law, equal
to the forward ``program`` actuation at printable modes. After the gradient phase the modes are
rounded to :math:`\pm 1`, the speeds re-optimised with the modes fixed and rounded to the
printable speed resolution, and the design is re-verified by a fresh forward solve.

Objective
---------
The equilibrium's nodes, after the best rigid alignment (rotation and translation found by an
inner least-squares fit, which makes the objective independent of how the lattice floats), are
compared with a target surface :math:`z = f(x, y)`:

.. math::

    J = \frac{1}{2 N L^2}\sum_i \big(z'_i - f(x'_i, y'_i)\big)^2
        + \beta \sum_e (1 - c_e^2),

with :math:`L` the lattice size and :math:`\beta` a small weight that favours printable values.
By the envelope theorem the gradient of the aligned misfit with respect to the node positions
is that of the residuals at the optimal alignment. A :class:`ShapeTarget` (node positions of
the same lattice) is compared node by node after the best rotation (Kabsch) instead. The
gradient with respect to all design variables comes from one adjoint solve
(:mod:`rotomorph.inverse.adjoint`), and SciPy's L-BFGS-B handles the bounds. Every
equilibrium is warm-started from the previous one; a design whose equilibrium is not a stable
minimum is rejected by the line search (its objective is infinite).
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
from scipy.interpolate import RectBivariateSpline
from scipy.optimize import least_squares, minimize

from rotomorph._typing import FloatArray, IntArray
from rotomorph.analysis.curvature import fit_quadratic_surface
from rotomorph.contact import Contact, Floor
from rotomorph.design.lattices import Lattice
from rotomorph.errors import ConvergenceError, InvalidDesignError, InvalidParameterError
from rotomorph.geometry import best_rotation
from rotomorph.inverse.adjoint import NotAMinimumError, adjoint
from rotomorph.inverse.bath import BathCheck
from rotomorph.inverse.blend import LatticeBlend, lattice_blend, with_settings
from rotomorph.lattice.actuation import Actuation
from rotomorph.lattice.heating import contact_settings, perturbed_state, symmetry_breaking
from rotomorph.rod.model import Model
from rotomorph.rod.state import State
from rotomorph.solve.continuation import continuation
from rotomorph.solve.loads import Gravity, Loads, Supports
from rotomorph.solve.newton import NewtonOptions
from rotomorph.solve.objective import RodObjective
from rotomorph.solve.static import StaticResult, solve_static

__all__ = [
    "MEASURED_SPEEDS",
    "LatticeBlend",
    "LatticeDesign",
    "ShapeTarget",
    "SurfaceTarget",
    "Surroundings",
    "design_lattice",
    "dome",
    "height_map",
    "lattice_blend",
    "misfit_and_gradient",
    "rigid_motion",
    "saddle",
    "shape",
    "shape_misfit",
    "split",
    "surface_misfit",
    "surroundings",
]

if TYPE_CHECKING:
    from rotomorph.inverse.environment import DesignBand, RobustChoice

logger = logging.getLogger(__name__)

SOLVE_OPTIONS = NewtonOptions(rtol=1e-10, max_iterations=300)

#: Out-of-plane perturbation of the design ramps' flat start, relative to the spacing.
DESIGN_PERTURBATION = 1e-2


# ---------------------------------------------------------------------------------- targets
@dataclass(frozen=True, eq=False)
class SurfaceTarget:
    """A target surface ``z = f(x, y)`` (mm) in coordinates centred on the lattice.

    Attributes
    ----------
    kind
        ``"dome"``, ``"saddle"`` or ``"height_map"``.
    height
        ``f(x, y) -> (z, dz/dx, dz/dy)`` on arrays (mm, mm, dimensionless).
    gaussian_curvature
        Target Gaussian curvature K (1/mm²) for domes and saddles (None for height maps).
    description
        Human-readable summary.
    """

    kind: Literal["dome", "saddle", "height_map"]
    height: Callable[[FloatArray, FloatArray], tuple[FloatArray, FloatArray, FloatArray]]
    gaussian_curvature: float | None
    description: str

    @property
    def characteristic_curvature(self) -> float | None:
        """sqrt(|K|) (1/mm), the paper's characteristic curvature, or None."""
        k = self.gaussian_curvature
        return None if k is None else float(np.sqrt(abs(k)))


def _quadric(k1: float, k2: float) -> Callable[[FloatArray, FloatArray], tuple[Any, Any, Any]]:
    def f(x: FloatArray, y: FloatArray) -> tuple[Any, Any, Any]:
        return 0.5 * (k1 * x * x + k2 * y * y), k1 * x, k2 * y

    return f


def _check_curvature(name: str, value: float) -> float:
    v = float(value)
    if not (np.isfinite(v) and v > 0.0):
        raise InvalidDesignError(name, f"must be a positive curvature (1/mm); got {value}")
    return v


def dome(curvature: float, curvature2: float | None = None) -> SurfaceTarget:
    """A dome with principal curvatures ``curvature`` and ``curvature2`` (1/mm, both > 0;
    default equal: a spherical cap ``z = k r²/2``)."""
    k1 = _check_curvature("target.curvature", curvature)
    k2 = k1 if curvature2 is None else _check_curvature("target.curvature2", curvature2)
    return SurfaceTarget("dome", _quadric(k1, k2), k1 * k2, f"dome k1={k1:g}, k2={k2:g} 1/mm")


def saddle(curvature: float, curvature2: float | None = None) -> SurfaceTarget:
    """A saddle ``z = (k1 x² − k2 y²)/2`` with ``k1 = curvature``, ``k2 = curvature2`` (1/mm,
    both given as positive magnitudes; default equal)."""
    k1 = _check_curvature("target.curvature", curvature)
    k2 = k1 if curvature2 is None else _check_curvature("target.curvature2", curvature2)
    return SurfaceTarget(
        "saddle", _quadric(k1, -k2), -k1 * k2, f"saddle k1={k1:g}, k2={-k2:g} 1/mm"
    )


def height_map(x: FloatArray, y: FloatArray, z: FloatArray) -> SurfaceTarget:
    """A height map ``z[i, j]`` at grid points ``(x[i], y[j])`` (mm), centred on the lattice,
    interpolated by a bicubic spline."""
    xa, ya, za = (np.asarray(a, dtype=float) for a in (x, y, z))
    if xa.ndim != 1 or ya.ndim != 1 or za.shape != (len(xa), len(ya)):
        raise InvalidDesignError(
            "target.z", f"must have shape (len(x), len(y)) = ({len(xa)}, {len(ya)}); got {za.shape}"
        )
    if len(xa) < 4 or len(ya) < 4:
        raise InvalidDesignError("target.x", "a height map needs at least 4 × 4 grid points")
    if not (np.all(np.isfinite(za)) and np.all(np.diff(xa) > 0) and np.all(np.diff(ya) > 0)):
        raise InvalidDesignError("target.x", "grid must be finite and strictly increasing")
    spline = RectBivariateSpline(xa, ya, za, kx=3, ky=3)

    def f(px: FloatArray, py: FloatArray) -> tuple[Any, Any, Any]:
        return (
            spline.ev(px, py),
            spline.ev(px, py, dx=1),
            spline.ev(px, py, dy=1),
        )

    target = SurfaceTarget("height_map", f, None, f"height map {len(xa)}×{len(ya)}")
    object.__setattr__(target, "extent", (xa[0], xa[-1], ya[0], ya[-1], float(np.ptp(za))))
    return target


@dataclass(frozen=True, eq=False)
class ShapeTarget:
    """A lattice shape given by the positions of all its nodes ``(N, 3)`` (mm), e.g. a measured
    or simulated lattice, compared node by node after the best rigid alignment.

    Attributes
    ----------
    positions
        Target node positions, in the lattice's node order (mm).
    description
        Human-readable summary.
    """

    positions: FloatArray
    description: str = "lattice shape"
    kind: Literal["shape"] = "shape"
    gaussian_curvature: float | None = None
    characteristic_curvature: float | None = None


def shape(positions: FloatArray) -> ShapeTarget:
    """A :class:`ShapeTarget` from node positions ``(N, 3)`` (mm)."""
    x = np.array(positions, dtype=float)
    if x.ndim != 2 or x.shape[1] != 3 or len(x) < 3 or not np.all(np.isfinite(x)):
        raise InvalidDesignError(
            "target.positions", f"must be finite node positions (N >= 3, 3); got {x.shape}"
        )
    x.setflags(write=False)
    return ShapeTarget(x, f"lattice shape of {len(x)} nodes")


# ---------------------------------------------------------------------------------- misfit
def rigid_motion(params: FloatArray, x: FloatArray) -> FloatArray:
    """``x`` ``(N, 3)`` (mm) turned by ``Rz(γ) · R(a, b, 0)`` and raised by ``dz``, with
    ``params = (a, b, γ, dz)``: a swing about a horizontal axis (rotation vector ``(a, b, 0)``,
    rad) then a twist about z (rad). Every rotation is such a product, and the twist stays a
    well-scaled coordinate however far it turns (a rotation vector does not)."""
    y = np.asarray(x, dtype=float) @ _alignment_rotation(params).T
    y[:, 2] += params[3]
    return y


def _alignment_rotation(params: FloatArray) -> FloatArray:
    """The rotation matrix ``Rz(γ) · R(a, b, 0)`` of :func:`rigid_motion` (Rodrigues' formula
    for the swing; written out because the misfit's alignment evaluates it hundreds of times
    per design, where building rotation objects dominated the cost)."""
    a, b, gamma = float(params[0]), float(params[1]), float(params[2])
    theta = math.hypot(a, b)
    if theta > 0.0:
        ka, kb = a / theta, b / theta
        sn, vc = math.sin(theta), 1.0 - math.cos(theta)
    else:
        ka = kb = sn = vc = 0.0
    # R = I + sin θ K + (1 − cos θ) K² for the unit axis (ka, kb, 0)
    swing = [
        [1.0 - vc * kb * kb, vc * ka * kb, sn * kb],
        [vc * ka * kb, 1.0 - vc * ka * ka, -sn * ka],
        [-sn * kb, sn * ka, 1.0 - vc],
    ]
    c, s = math.cos(gamma), math.sin(gamma)
    return np.array(
        [
            [c * swing[0][j] - s * swing[1][j] for j in range(3)],
            [s * swing[0][j] + c * swing[1][j] for j in range(3)],
            swing[2],
        ]
    )


def surface_misfit(
    positions: FloatArray, target: SurfaceTarget, size: float
) -> tuple[float, FloatArray, FloatArray]:
    """Aligned misfit ``J``, its gradient ``(N, 3)`` w.r.t. ``positions`` (1/mm) and the
    alignment ``(a, b, γ, dz)`` of :func:`rigid_motion` (applied to the centred nodes).

    The nodes are centred (their centroid goes to x = y = 0, where the target is centred),
    then rotated and moved vertically to minimise
    ``J = sum_i r_i² / (2 N)`` with ``r_i = (z'_i − f(x'_i, y'_i)) / size``; the alignment
    starts from the centred state and from its upside-down copy. J is exactly invariant under
    rigid motions of ``positions`` (no term anchors the alignment to the lab frame; for a
    target symmetric about z, such as an isotropic dome, the twist γ is left out), which the
    adjoint of a free lattice needs: its equilibrium is defined up to a rigid motion. The
    gradient is exact at the optimal alignment (envelope theorem), including the centroid's
    dependence on every node.
    """
    x = np.asarray(positions, dtype=float)
    n = len(x)
    xc = x - x.mean(axis=0)

    def residuals(p: FloatArray) -> FloatArray:
        y = rigid_motion(p, xc)
        z, _, _ = target.height(y[:, 0], y[:, 1])
        return (y[:, 2] - z) / size

    best: Any = None
    for flip in (0.0, np.pi):
        p0 = np.array([flip, 0.0, 0.0, 0.0])
        y0 = rigid_motion(p0, xc)
        z0, _, _ = target.height(y0[:, 0], y0[:, 1])
        p0[3] = float(np.mean(z0 - y0[:, 2]))
        r0 = residuals(p0)
        # a target symmetric about z (an isotropic dome): the twist is no coordinate at all
        turned = residuals(p0 + np.array([0.0, 0.0, 0.3, 0.0]))
        free = [0, 1, 3] if np.allclose(turned, r0, rtol=0, atol=1e-13) else [0, 1, 2, 3]

        def sub(q: FloatArray, p0: FloatArray = p0, free: list[int] = free) -> FloatArray:
            full = p0.copy()
            full[free] = q
            return residuals(full)

        sol = least_squares(sub, p0[free], xtol=1e-15, ftol=1e-15, gtol=1e-15, method="lm")
        full = p0.copy()
        full[free] = sol.x
        if best is None or sol.cost < best[0]:
            best = (sol.cost, full)
    p = best[1]
    y = rigid_motion(p, xc)
    z, zx, zy = target.height(y[:, 0], y[:, 1])
    r = (y[:, 2] - z) / size
    j = 0.5 * float(r @ r) / n
    dr_dy = np.stack([-zx, -zy, np.ones(n)], axis=1) / size
    rot = _alignment_rotation(p)
    per_node = (r[:, None] * dr_dy) @ rot / n
    grad = per_node - per_node.mean(axis=0)
    return j, grad, p


def shape_misfit(
    positions: FloatArray, target: FloatArray, size: float
) -> tuple[float, FloatArray]:
    """Misfit ``J = sum_i |R x'_i - y'_i|² / (2 N size²)`` of nodes ``positions`` to
    ``target`` (both ``(N, 3)``, mm; primes: centred) at the best rotation R (Kabsch), and its
    gradient ``(N, 3)`` w.r.t. ``positions`` (1/mm²·mm).

    J is exactly invariant under rigid motions of ``positions``; by the envelope theorem its
    gradient is ``R^T (R x'_i - y'_i) / (N size²)`` (the centring drops out: both residual
    sums vanish).
    """
    x = np.asarray(positions, dtype=float)
    y = np.asarray(target, dtype=float)
    xc, yc = x - x.mean(axis=0), y - y.mean(axis=0)
    rot = best_rotation(xc, yc)
    r = xc @ rot.T - yc
    n = len(x)
    j = 0.5 * float(np.sum(r * r)) / (n * size * size)
    return j, (r @ rot) / (n * size * size)


def _misfit(
    target: SurfaceTarget | ShapeTarget, positions: FloatArray, picked: IntArray, size: float
) -> tuple[float, FloatArray]:
    """Misfit and gradient ``(N, 3)`` (zero off ``picked``) of any lattice target."""
    x = np.asarray(positions)
    grad = np.zeros_like(x, dtype=float)
    if isinstance(target, ShapeTarget):
        j, g = shape_misfit(x[picked], target.positions[picked], size)
    else:
        j, g, _ = surface_misfit(x[picked], target, size)
    grad[picked] = g
    return j, grad


# ---------------------------------------------------------------------------------- solve
@dataclass(frozen=True, eq=False)
class Surroundings:
    """What the lattice rests in: frictionless contact (self-contact and/or a floor, with a
    fixed barrier stiffness) and dead loads (buoyant self-weight). Default: neither."""

    contact: Contact | None = None
    loads: Loads | None = None


def surroundings(
    blend: LatticeBlend,
    *,
    contact: bool | Contact = False,
    floor: bool | Floor = False,
    gravity: Gravity | None = None,
    seed: int = 0,
    perturbation: float | None = None,
) -> Surroundings:
    """The forward solves' contact and loads, as :func:`rotomorph.lattice.heat_lattice`
    builds them from the same arguments (a ``floor=True`` lies just below the perturbed
    printed state), with the barrier stiffness fixed at its default for the printed lattice:
    a default scaled from each design's natural values would make the barrier depend on the
    design, which the adjoint gradient leaves out. ``perturbation`` (relative to the spacing;
    default the design ramp's) sets the perturbed printed state the floor lies under:
    :func:`~rotomorph.lattice.heat_lattice`'s own (1e-3) puts it where that ramp puts it.

    Raises
    ------
    InvalidParameterError
        Contact with friction (not conservative: no adjoint gradient); gravity on a free
        lattice without a floor to rest on.
    """
    lattice = blend.lattice
    scale = DESIGN_PERTURBATION if perturbation is None else perturbation
    start = _Equilibria(blend, seed=seed, perturbation=scale)._flat(1.0)
    settings = contact_settings(lattice, start.positions, contact, floor, 0.0)
    if settings is not None and settings.friction > 0:
        raise InvalidParameterError(
            "contact.friction", "inverse design needs frictionless contact (friction=0)"
        )
    if gravity is not None and (settings is None or settings.floor is None):
        raise InvalidParameterError(
            "gravity", "gravity on a free lattice needs a floor to rest on (floor=True)"
        )
    loads = None if gravity is None else Loads(gravity=gravity)
    if settings is not None and settings.stiffness is None:
        obj = RodObjective(blend.model, start, Supports(), loads or Loads(), settings)
        settings = replace(settings, stiffness=float(obj.contact.kappa))
    return Surroundings(settings, loads)


def _is_minimum(model: Model, state: State, env: Surroundings | None = None) -> bool:
    """True when the equilibrium's Hessian (rigid modes aside) is positive semidefinite."""
    env = env or Surroundings()
    try:
        adjoint(model, state, np.zeros(model.layout.count), loads=env.loads, contact=env.contact)
    except NotAMinimumError:
        return False
    return True


class _Equilibria:
    """Forward solves of designs ``p = (c, v)`` with warm starts (continuation in the ramp
    from the flat state first).

    A ramp that ends on an unstable equilibrium (a flat state past its buckling point, kept
    by symmetry) is repeated from a larger out-of-plane perturbation, up to ``retries`` times.
    With ``heated`` (a function of the design returning a state, e.g. the end of
    :func:`~rotomorph.lattice.heat_lattice`'s lowest-energy ramp of its printable rounding),
    a fresh solve starts from that state instead, and falls back to the ramp where it is not
    a stable equilibrium of the design (from heat_lattice's own perturbed start, above which
    the floor lies).
    """

    def __init__(
        self,
        blend: LatticeBlend,
        seed: int = 0,
        perturbation: float | None = None,
        retries: int = 3,
        env: Surroundings | None = None,
        heated: Callable[[FloatArray], State] | None = None,
    ) -> None:
        self.blend = blend
        self.heated = heated
        if perturbation is None:  # on the lowest branch the floor lies under heat_lattice's start
            perturbation = DESIGN_PERTURBATION if heated is None else HEAT_PERTURBATION
        self.env = env or Surroundings()
        self.seed = seed
        self.perturbation = perturbation
        self.retries = retries
        self.last: tuple[FloatArray, State] | None = None
        self.solves = 0
        self.options = SOLVE_OPTIONS

    def rod(self, p: FloatArray, t: float = 1.0) -> Model:
        """The rod model of design ``p`` at ramp fraction ``t``."""
        c, v = split(self.blend, p)
        return self.blend.rod(c, v, t)

    def _solve(self, model: Model, state: State) -> StaticResult:
        self.solves += 1
        env = self.env
        return solve_static(
            model, loads=env.loads, initial=state, options=self.options, contact=env.contact
        )

    def _flat(self, scale: float) -> State:
        lat = self.blend.lattice
        dz = symmetry_breaking(lat, scale * self.perturbation * lat.spacing, self.seed)
        return perturbed_state(self.blend.model, dz)

    def _ramp(self, p: FloatArray) -> StaticResult:
        if self.heated is not None:
            try:
                res = self._solve(self.rod(p), self.heated(p))
                if _is_minimum(self.rod(p), res.state, self.env):
                    return res
            except ConvergenceError:
                pass

        def solve(t: float, state: State) -> StaticResult:
            return self._solve(self.rod(p, t), state)

        path = continuation(solve, np.linspace(0.1, 1.0, 10), self._flat(1.0), start=0.0)
        res = path.results[-1]
        model = self.rod(p)
        lat = self.blend.lattice
        for k in range(self.retries):
            if _is_minimum(model, res.state, self.env):
                break
            # a symmetric state past its buckling point: kick it out of plane and re-solve
            kick = symmetry_breaking(lat, 5.0**k * self.perturbation * lat.spacing, self.seed + k)
            if self.env.contact is not None:  # upwards only: never into the floor
                kick = np.abs(kick)
            start = perturbed_state(model, res.positions - lat.network.nodes)
            start = perturbed_state(
                model, start.positions - lat.network.nodes + kick[:, None] * [0.0, 0.0, 1.0]
            )
            res = self._solve(model, start)
        return res

    def __call__(self, p: FloatArray) -> StaticResult:
        p = np.asarray(p, dtype=float).copy()
        if self.last is not None:
            p_prev, state = self.last
            try:
                res = self._solve(self.rod(p), state)
            except ConvergenceError:
                res = self._between(p_prev, p, state)
        else:
            res = self._ramp(p)
        self.last = (p, res.state)
        return res

    def _between(self, p0: FloatArray, p1: FloatArray, state: State) -> StaticResult:
        def solve(u: float, st: State) -> StaticResult:
            return self._solve(self.rod((1 - u) * p0 + u * p1), st)

        path = continuation(solve, np.linspace(0.25, 1.0, 4), state, start=0.0)
        return path.results[-1]


def split(blend: LatticeBlend, p: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Modes ``c`` and speeds ``v`` (mm/s) of a design vector ``p = (c, v)`` ``(2 E,)``."""
    p = np.asarray(p, dtype=float)
    n = blend.n_edges
    return p[:n], p[n:]


@dataclass(frozen=True, eq=False)
class LatticeDesign:
    """Result of :func:`design_lattice`.

    Attributes
    ----------
    lattice
        The designed, printable lattice (each edge ``expanding`` or ``contracting``, printed
        at its own speed).
    relaxed
        Continuous design ``(2 E,)`` (modes, then speeds in mm/s) at the end of the gradient
        phase.
    modes
        Printable modes ``(E,)`` of ±1 after rounding.
    speeds
        Printable speeds ``(E,)`` (mm/s) after rounding to the speed resolution.
    positions
        Verified equilibrium of the rounded design ``(N, 3)`` (mm).
    target
        The target surface.
    objective_history
        Objective value per optimiser evaluation.
    misfit_rms
        RMS vertical distance of the verified equilibrium to the target after alignment (mm).
    misfit_rel
        ``misfit_rms`` divided by the lattice size.
    achieved_gaussian_curvature, target_gaussian_curvature
        K of the quadric fit of the verified branch nodes and the target's K (1/mm²).
    stable
        Whether the verified equilibrium's Hessian is positive semidefinite.
    iterations, solves
        Optimiser iterations and forward solves.
    bath
        The verification in the declared surroundings by the ramp ``simulate`` runs
        (:func:`rotomorph.inverse.bath.verify_in_bath`; None where not run).
    band
        The calibration band of the verified shape
        (:func:`rotomorph.inverse.environment.design_band`; None where not computed).
    robust
        With a robust design: what was chosen over the band and what it gives up nominally
        (:class:`~rotomorph.inverse.environment.RobustChoice`).
    optimised_gaussian_curvature
        With ``bath``: K of the optimiser's own verified equilibrium of the design it returned
        (1/mm²), before ``simulate``'s ramp judged it (the two differ where that ramp lifts the
        design onto another branch).
    judge_rounds
        Judgements made by :func:`design_lattice`'s ``judge`` (0: none).
    """

    lattice: Lattice
    relaxed: FloatArray
    modes: FloatArray
    speeds: FloatArray
    positions: FloatArray
    target: SurfaceTarget | ShapeTarget
    objective_history: FloatArray
    misfit_rms: float
    misfit_rel: float
    achieved_gaussian_curvature: float
    target_gaussian_curvature: float | None
    stable: bool
    iterations: int
    solves: int
    bath: BathCheck | None = None
    band: DesignBand | None = None
    robust: RobustChoice | None = None
    optimised_gaussian_curvature: float | None = None
    judge_rounds: int = 0

    @property
    def reached(self) -> bool | None:
        """Verified in the declared surroundings and reached (stable, admissible, K within
        the tolerance: :class:`~rotomorph.inverse.bath.BathCheck`); None where the design was
        not verified there."""
        return None if self.bath is None else self.bath.reached

    @property
    def pattern(self) -> dict[int, str]:
        """Edge index → ``"expanding"`` / ``"contracting"``."""
        return {int(e): ("expanding" if m > 0 else "contracting") for e, m in enumerate(self.modes)}


def misfit_and_gradient(
    blend: LatticeBlend,
    p: FloatArray,
    result: StaticResult,
    target: SurfaceTarget | ShapeTarget,
    size: float,
    nodes: IntArray | None = None,
    env: Surroundings | None = None,
) -> tuple[float, FloatArray]:
    """Aligned misfit ``J`` of the equilibrium ``result`` of design ``p = (c, v)`` and
    ``dJ/dp`` ``(2 E,)`` (per unit mode, then per mm/s).

    One adjoint solve at the equilibrium (:func:`rotomorph.inverse.adjoint.adjoint`), whatever
    the number of edges; ``nodes`` (default all) are the nodes compared with the target;
    ``env`` the contact and loads ``result`` was solved with (the barrier's Hessian is part of
    the adjoint system).

    Raises
    ------
    NotAMinimumError
        The equilibrium is not a stable minimum.
    """
    picked = np.arange(len(result.positions)) if nodes is None else np.asarray(nodes)
    j, gx = _misfit(target, result.positions, picked, size)
    c, v = split(blend, p)
    model = blend.rod(c, v)
    lay = model.layout
    dj_dx = np.zeros(lay.count)
    dj_dx[(lay.pos[:, None] + np.arange(3)).ravel()] = gx.ravel()
    env = env or Surroundings()
    s = adjoint(model, result.state, dj_dx, loads=env.loads, contact=env.contact).sensitivity
    prod = np.stack([s.curvature1, s.curvature2, s.twist], axis=1)
    gc, gv = blend.gradient(c, v, prod, s.rest_length)
    return j, -np.concatenate([gc, gv])


def _check_target(lattice: Lattice, target: SurfaceTarget | ShapeTarget) -> None:
    size = lattice.spacing * (lattice.n - 1)
    ext = getattr(target, "extent", None)
    if ext is not None:
        x0, x1, y0, y1, height = ext
        half = 0.5 * size
        if x0 > -half or x1 < half or y0 > -half or y1 < half:
            raise InvalidDesignError(
                "target",
                f"the height map covers x ∈ [{x0:g}, {x1:g}], y ∈ [{y0:g}, {y1:g}] mm but the "
                f"lattice spans ±{half:g} mm about its centre; extend the grid",
            )
        if height > size:
            raise InvalidDesignError(
                "target.z",
                f"heights span {height:g} mm, more than the lattice size {size:g} mm: no "
                "inextensible lattice reaches it",
            )
    k = target.characteristic_curvature
    if k is not None and k * size > np.pi:
        raise InvalidDesignError(
            "target.curvature",
            f"sqrt(|K|)·size = {k * size:.3g} > π: the lattice would have to close on itself; "
            "lower the curvature or use a smaller lattice",
        )


#: Speeds the calibrated speed law was measured over (mm/s): the default design range.
MEASURED_SPEEDS = (0.25, 3.0)


def _check_options(
    printability: float, speed_range: tuple[float, float] | None, speed_resolution: float
) -> None:
    if not (np.isfinite(printability) and printability >= 0):
        raise InvalidParameterError("printability", f"must be >= 0; got {printability}")
    if speed_range is not None:
        lo, hi = speed_range
        if not (np.isfinite(lo) and np.isfinite(hi) and 0 < lo <= hi):
            raise InvalidParameterError(
                "speed_range", f"must be 0 < low <= high mm/s; got {speed_range}"
            )
    if not (np.isfinite(speed_resolution) and speed_resolution > 0):
        raise InvalidParameterError("speed_resolution", f"must be > 0 mm/s; got {speed_resolution}")


def _speed_steps(speed_range: tuple[float, float], resolution: float) -> tuple[int, int]:
    """First and last multiple of ``resolution`` inside ``speed_range`` (in steps)."""
    lo = int(np.ceil(speed_range[0] / resolution - 1e-9))
    hi = int(np.floor(speed_range[1] / resolution + 1e-9))
    return lo, hi


def _printable_speeds(
    speeds: FloatArray, speed_range: tuple[float, float], resolution: float
) -> FloatArray:
    """``speeds`` rounded to the nearest multiple of ``resolution`` inside ``speed_range``."""
    lo, hi = _speed_steps(speed_range, resolution)
    return np.clip(np.round(np.asarray(speeds) / resolution), lo, hi) * resolution


def _same_strength(
    blend: LatticeBlend, c: FloatArray, v: FloatArray, speed_range: tuple[float, float]
) -> FloatArray:
    """Speeds ``(E,)`` (mm/s) at which a printable edge (mode ±1) bends as strongly as the
    relaxed edge ``(c, v)``.

    Without director rotation a Janus section bends in proportion to the mismatch
    ``ε_p − ε∥(v)`` of its two halves along the filament, and inside an edge the blend is
    ``c`` times the printable actuation; the speed whose mismatch is ``|c|`` times that at
    ``v`` keeps the edge's bending (clipped to the range; unchanged where the mismatch is not
    monotonic in the speed over the range).
    """
    grid = np.geomspace(speed_range[0], speed_range[1], 2001)
    passive = blend.chain.passive_strain

    def mismatch(speed: FloatArray) -> FloatArray:
        return np.abs(passive - blend.chain.strains(speed)[:, 0])

    strength = mismatch(grid)
    if not np.all(np.diff(strength) > 0):
        return np.asarray(v, dtype=float)
    wanted = np.abs(c) * mismatch(np.asarray(v, dtype=float))
    return np.interp(wanted, strength, grid)


def _lifted(check: _Check, lattice: Lattice) -> bool:
    """The verified state has risen off the printed plane by more than a filament diameter."""
    z = np.asarray(check.result.positions)[:, 2]
    return float(np.ptp(z)) > 2.0 * lattice.radius


#: Judgements of a design (its first and the restarts from the judge's verified branch).
JUDGE_ROUNDS = 3


def _verdict_rank(check: BathCheck) -> tuple[bool, bool, float]:
    """Reached first; then stable and admissible; then by the verified K's relative error."""
    good = bool(check.stable) and check.admissible
    err = np.inf if check.error_rel is None else float(check.error_rel)
    return (not check.reached, not good, err)


#: Uniform speeds (geometrically spaced over the range) the starting pattern is tried at.
INITIAL_SPEEDS = 5

#: Factors of the overall bending strength tried about the optimised speeds (phase 5).
STRENGTH_SCALES = (0.84, 0.92, 1.08, 1.18)


@dataclass(frozen=True, eq=False)
class _Check:
    """A printable design verified by a fresh ramp."""

    result: StaticResult
    misfit: float
    stable: bool
    fit: Any
    solves: int
    target_k: float | None

    @property
    def rank(self) -> tuple[bool, float]:
        """Unstable last; then by the relative error of the (signed) Gaussian curvature, or
        the misfit for targets without one."""
        if self.target_k is None:
            return (not self.stable, self.misfit)
        err = abs(self.fit.gaussian_curvature - self.target_k) / abs(self.target_k)
        return (not self.stable, err)


def _verify(
    blend: LatticeBlend,
    p: FloatArray,
    seed: int,
    target: SurfaceTarget | ShapeTarget,
    picked: IntArray,
    size: float,
    lattice: Lattice,
    eq: _Equilibria | None = None,
    env: Surroundings | None = None,
    heated: Callable[[FloatArray], State] | None = None,
) -> _Check:
    """``p`` solved by ``eq`` (default: a fresh ramp from the flat printed state, as the
    forward simulation runs it, in ``env``; else warm-started from ``eq``'s last state)."""
    fresh = _Equilibria(blend, seed=seed, env=env, heated=heated) if eq is None else eq
    before = fresh.solves
    try:
        res = fresh(p)
    except ConvergenceError:
        if eq is None:
            raise
        return _verify(
            blend, p, seed, target, picked, size, lattice, env=fresh.env, heated=fresh.heated
        )
    return _Check(
        result=res,
        misfit=_misfit(target, res.positions, picked, size)[0],
        stable=_is_minimum(fresh.rod(p), res.state, fresh.env),
        fit=fit_quadratic_surface(res.positions[lattice.branch_indices]),
        solves=fresh.solves - before,
        target_k=target.gaussian_curvature,
    )


#: heat_lattice's default symmetry-breaking perturbation (relative to the spacing): the floor of
#: a design on the lowest branch lies where that ramp puts it.
HEAT_PERTURBATION = 1e-3


def _heated_start(
    blend: LatticeBlend,
    actuation: str | Actuation | None,
    contact: bool | Contact,
    floor: bool | Floor,
    gravity: Gravity | None,
    seed: int,
) -> Callable[[FloatArray], State]:
    """``p ↦`` a start on the lowest branch: the end state of
    :func:`~rotomorph.lattice.heat_lattice`'s lowest-energy ramp (its lift probe) of the first
    design asked for, rounded to printable modes (±1, its speeds), in the same surroundings.
    That ramp costs as much as ``simulate``'s, so it runs once; every later fresh solve starts
    from its state (the design's final verification is ``simulate``'s ramp of its own)."""
    from rotomorph.inverse.bath import VERIFY_STEPS
    from rotomorph.lattice.heating import heat_lattice

    act = actuation if actuation is not None else "program"
    found: list[State] = []

    def start(p: FloatArray) -> State:
        if found:
            return found[0]
        c, v = split(blend, p)
        printed = with_settings(blend.lattice, np.where(c >= 0, 1.0, -1.0), v)
        res = heat_lattice(
            printed,
            actuation=act,
            steps=VERIFY_STEPS,
            contact=contact,
            floor=floor,
            gravity=gravity,
            seed=seed,
            perturbation=HEAT_PERTURBATION,
            branch="lowest",
        )
        found.append(res.states[-1])
        return found[0]

    return start


def design_lattice(
    lattice: Lattice,
    target: SurfaceTarget | ShapeTarget,
    *,
    actuation: str | Actuation | None = None,
    initial: FloatArray | None = None,
    printability: float = 1e-6,
    max_iterations: int = 30,
    seed: int = 0,
    nodes: Literal["branch", "all"] = "branch",
    speed_range: tuple[float, float] | None = MEASURED_SPEEDS,
    speed_resolution: float = 0.05,
    callback: Callable[[int, float], None] | None = None,
    contact: bool | Contact = False,
    floor: bool | Floor = False,
    gravity: Gravity | None = None,
    branch: Literal["continuous", "lowest"] = "continuous",
    judge: Callable[[Lattice], BathCheck] | None = None,
) -> LatticeDesign:
    """Choose per-edge modes and print speeds that make ``lattice`` rise into ``target``.

    Parameters
    ----------
    lattice
        The printed geometry (size, spacing, amplitude; its pattern and speeds are only a
        starting guess).
    target
        :func:`dome`, :func:`saddle`, :func:`height_map` or :func:`shape` (node positions of
        the same lattice).
    actuation
        Lattice actuation mode (only ``"program"``, the default, follows per-edge settings).
    initial
        Starting relaxed modes ``(E,)`` in [−1, 1]; default from ``lattice``'s own pattern.
    printability
        Weight β of the term favouring printable modes ±1 (dimensionless).
    max_iterations
        L-BFGS-B iterations of the first phase.
    seed
        Seed of the symmetry-breaking perturbation of the first solve.
    nodes
        Nodes compared with the target: ``"branch"`` (default: the junctions, which span the
        lattice's surface; the sinusoidal edges wiggle about it by design) or ``"all"``.
    speed_range
        Bounds of the per-edge print speeds (mm/s): the machine's feed limits intersected with
        the range the speed law was measured over (default). ``None`` keeps the lattice's
        speeds and designs the modes only.
    speed_resolution
        Printable speed step (mm/s): the designed speeds are rounded to the multiples of it
        that lie in ``speed_range``.
    callback
        ``callback(iteration, objective)`` after each optimiser iteration (progress bars).
    contact, floor, gravity
        As :func:`rotomorph.lattice.heat_lattice` (self-contact, a floor just below the printed
        lattice, buoyant self-weight :func:`rotomorph.lattice.heating.lattice_gravity`), in
        every equilibrium solve and in the adjoint (the barrier's Hessian is part of it), with
        the barrier stiffness fixed at its default for the printed lattice
        (:func:`surroundings`). Frictionless only.
    branch
        With a floor and a weight: ``"continuous"`` (default) follows the resting state from
        the flat print, which a rigid floor never lets go by itself; ``"lowest"`` starts every
        fresh solve of a design from the end of :func:`~rotomorph.lattice.heat_lattice`'s
        lowest-energy ramp (its lift probe) of the design's printable rounding (modes ±1, the
        same speeds) in the same surroundings, with its floor, so the optimiser works on the
        branch ``simulate`` takes; the adjoint then differentiates that equilibrium.
    judge
        ``judge(printed) -> BathCheck``: the verification the design must pass, e.g.
        :func:`rotomorph.inverse.bath.verify_in_bath` (``simulate``'s own ramp with its lift
        probe). With a speed range, the starting pattern (modes ±1, the lattice's own speeds
        rounded) is judged first: on the lowest branch every fresh solve then starts from the
        state the judge verified, and a start judged reached is returned as it is (no
        optimisation). After phase (5) the printable design is judged; where the verdict is
        not *reached* (its ramp ended on another branch than the optimiser's, or off the
        target), phases (3)-(5) run again from the state the judge verified, every fresh
        solve starting there, up to :data:`JUDGE_ROUNDS` judgements of optimised designs. The
        design returned is the best judged optimised one (reached first; then stable and
        admissible; then by the verified K's error) and ``bath`` is its verdict;
        ``judge_rounds`` counts every judgement.

    Notes
    -----
    Phases: (0) the starting pattern solved at its own speeds and at :data:`INITIAL_SPEEDS`
    uniform speeds (one ramp, then warm starts), the best misfit starting the descent; (1) L-BFGS-B
    on the relaxed modes and the speeds, the printability weight raised
    tenfold twice; (2) modes rounded to ±1 (an edge's relaxed strength kept by lowering its
    speed), the rounded optimum and the starting pattern verified by a fresh ramp; (3) with
    the best modes fixed, L-BFGS-B on the speeds alone; (4) speeds rounded to the resolution
    and the design verified by a fresh ramp from the flat printed state, as the forward
    simulation runs it; (5) for targets with a Gaussian curvature K (dome, saddle), the
    overall bending strength is also scaled by each of :data:`STRENGTH_SCALES`, then by steps
    of 4 % and 2 % about the best scale (every edge's speed moved so that its mismatch changes
    by that factor, rounded again; each solved warm-started from the base design), and the
    stable one whose K is closest to the target's is verified by a fresh ramp and kept if it
    still beats the base design: the height misfit is nearly flat along this direction at its
    optimum while K is not.

    Raises
    ------
    InvalidDesignError
        A target the lattice cannot reach (height map outside the lattice or too high,
        curvature that would close the lattice on itself).
    InvalidParameterError
        Bad options (negative printability, an empty speed range, a non-positive resolution,
        friction, gravity without a floor).
    """
    _check_target(lattice, target)
    if isinstance(target, ShapeTarget) and target.positions.shape != lattice.network.nodes.shape:
        raise InvalidDesignError(
            "target.positions",
            f"must have one row per lattice node {lattice.network.nodes.shape}; got "
            f"{target.positions.shape}",
        )
    _check_options(printability, speed_range, speed_resolution)
    blend = lattice_blend(lattice, actuation)
    size = lattice.spacing * (lattice.n - 1)
    if branch not in ("continuous", "lowest"):
        raise InvalidParameterError("branch", f"must be 'continuous' or 'lowest'; got {branch!r}")
    lifting = branch == "lowest" and gravity is not None
    env = surroundings(
        blend,
        contact=contact,
        floor=floor,
        gravity=gravity,
        seed=seed,
        perturbation=HEAT_PERTURBATION if lifting else None,
    )
    heated = _heated_start(blend, actuation, contact, floor, gravity, seed) if lifting else None
    eq = _Equilibria(blend, seed=seed, env=env, heated=heated)
    n_edges = blend.n_edges
    if initial is None:
        c0 = np.array([1.0 if m == "expanding" else -1.0 for m in lattice.edge_mode]) * 0.9
    else:
        c0 = np.clip(np.asarray(initial, dtype=float), -1, 1)
    v0 = lattice.speeds
    picked = (
        np.asarray(lattice.branch_indices)
        if nodes == "branch"
        else np.arange(lattice.network.n_nodes)
    )
    history: list[float] = []
    nit = 0
    counted = [0]  # solves of the equilibria objects no longer in use
    judgements = [0]
    judged: list[tuple[FloatArray, FloatArray, _Check, BathCheck]] = []

    def designed(
        modes: FloatArray,
        speeds: FloatArray,
        check: _Check,
        verdict: BathCheck | None,
        relaxed: FloatArray,
    ) -> LatticeDesign:
        final, j, stable, fit = check.result, check.misfit, check.stable, check.fit
        rms = float(np.sqrt(2.0 * j)) * size
        printed = with_settings(lattice, modes, speeds if speed_range is not None else None)
        return LatticeDesign(
            lattice=printed,
            relaxed=relaxed,
            modes=modes,
            speeds=speeds,
            positions=final.positions,
            target=target,
            objective_history=np.array(history),
            misfit_rms=rms,
            misfit_rel=rms / size,
            achieved_gaussian_curvature=float(fit.gaussian_curvature),
            target_gaussian_curvature=target.gaussian_curvature,
            stable=stable,
            iterations=nit,
            solves=counted[0] + eq.solves,
            bath=verdict,
            judge_rounds=judgements[0],
        )

    if judge is not None and speed_range is not None:
        # the starting pattern, printable, judged first: the judge's verified state is where
        # the optimiser's solves start (the branch the judge takes), and a start the judge
        # already finds reached is returned as it is (the simplest design: one speed per edge
        # as given, no optimisation)
        modes0 = np.where(c0 >= 0, 1.0, -1.0)
        speeds0 = _printable_speeds(np.clip(v0, *speed_range), speed_range, speed_resolution)
        verdict0 = judge(with_settings(lattice, modes0, speeds0))
        judgements[0] += 1
        state0 = verdict0.result.states[-1]

        def from_start(p: FloatArray, state: State = state0) -> State:
            return state

        if lifting:
            heated = from_start
            eq = _Equilibria(blend, seed=seed, env=env, heated=heated)
        if verdict0.reached:
            p_start = np.concatenate([modes0, speeds0])
            check0 = _verify(
                blend, p_start, seed, target, picked, size, lattice, env=env, heated=from_start
            )
            counted[0] += check0.solves
            return designed(modes0, speeds0, check0, verdict0, p_start)
    if speed_range is None:
        v_bounds = [(float(v), float(v)) for v in v0]
    else:
        v_bounds = [(float(speed_range[0]), float(speed_range[1]))] * n_edges
        # (0) the starting pattern at a few uniform speeds: the best one starts the descent
        # (K is far from monotonic in the speed, so the lattice's own speed may start far off)
        uniform = np.geomspace(*speed_range, INITIAL_SPEEDS)
        if heated is not None:
            # on the lift probe's branch: strongest bending first, so the warm starts follow
            # the lifted branch down from where it is lifted most (in rising order they start
            # flat, where the floor holds every weaker design)
            mismatch = np.abs(blend.chain.passive_strain - blend.chain.strains(uniform)[:, 0])
            uniform = uniform[np.argsort(-mismatch, kind="stable")]
        starts = [np.clip(v0, *speed_range)] + [np.full(n_edges, v) for v in uniform]
        signs0 = np.where(c0 >= 0, 1.0, -1.0)
        # one ramp, then warm starts along the speeds
        scan = _Equilibria(blend, seed=seed, env=env, heated=heated)
        tried0 = [
            _verify(blend, np.concatenate([signs0, v]), seed, target, picked, size, lattice, scan)
            for v in starts
        ]
        eq.solves += sum(t.solves for t in tried0)
        order: list[int] = list(range(len(starts)))
        if heated is not None and target.gaussian_curvature is not None:
            # a curved target is not reached from the flat resting state the floor holds a
            # weak design in (the descent on that branch is blind): start from the lifted
            # candidates where any is stable
            lifted = [i for i in order if tried0[i].stable and _lifted(tried0[i], lattice)]
            order = lifted or order
        k0 = min(order, key=lambda i: (not tried0[i].stable, tried0[i].misfit))
        v0 = starts[k0]
    weight = [printability]

    def fun(p: FloatArray) -> tuple[float, FloatArray]:
        try:
            res = eq(p)
            j, grad = misfit_and_gradient(blend, p, res, target, size, picked, env)
        except (ConvergenceError, NotAMinimumError):
            return np.inf, np.zeros_like(p)
        c = p[:n_edges]
        j += weight[0] * float(np.sum(1.0 - c * c))
        grad[:n_edges] += weight[0] * (-2.0 * c)
        history.append(j)
        return j, grad

    it = [0]

    def cb(xk: FloatArray) -> None:
        it[0] += 1
        if callback is not None:
            callback(it[0], history[-1] if history else float("nan"))

    def lbfgs(f: Callable[[FloatArray], tuple[float, FloatArray]], x0: FloatArray,
              bounds: list[tuple[float, float]], maxiter: int) -> Any:  # fmt: skip
        return minimize(
            f, x0, jac=True, method="L-BFGS-B", bounds=bounds, callback=cb,
            options={"maxiter": maxiter, "ftol": 1e-12, "gtol": 1e-10},
        )  # fmt: skip

    # (1) relaxed modes and speeds; the printability weight raised tenfold twice pushes the
    # modes to printable values before rounding
    p = np.concatenate([c0, v0])
    bounds = [(-1.0, 1.0)] * n_edges + v_bounds
    nit = 0
    for k, beta in enumerate((printability, 10.0 * printability, 100.0 * printability)):
        weight[0] = beta
        opt = lbfgs(fun, p, bounds, max_iterations if k == 0 else max(2, max_iterations // 3))
        p = opt.x
        nit += int(opt.nit)
    relaxed = p.copy()
    c_rel, v_rel = split(blend, relaxed)

    # (2) rounded modes: the rounded optimum (its strength kept by the speed where speeds are
    # free, else as is) and the starting pattern
    signs = np.where(c_rel >= 0, 1.0, -1.0)
    candidates = [
        np.concatenate([signs, v_rel]),
        np.concatenate([np.where(c0 >= 0, 1.0, -1.0), v0]),
    ]
    if speed_range is not None:
        candidates.insert(
            0, np.concatenate([signs, _same_strength(blend, c_rel, v_rel, speed_range)])
        )
    scored = [
        (_verify(blend, m, seed, target, picked, size, lattice, env=env, heated=heated), m)
        for m in candidates
    ]
    eq.solves += sum(check.solves for check, _ in scored)
    best_check, best = min(scored, key=lambda t: t[0].misfit if t[0].stable else np.inf)
    best_res = best_check.result
    modes = best[:n_edges].copy()
    speeds = best[n_edges:].copy()

    def refine(start_p: FloatArray, start_state: State) -> tuple[FloatArray, _Check, int]:
        """Phases (3)-(5) from the design ``start_p`` solved in ``start_state``, with the
        current ``eq`` and ``heated`` (the branch the solves start on)."""
        speeds = start_p[n_edges:].copy()
        its = 0
        # (3) the speeds alone with the modes fixed, warm-started from the verified state
        if speed_range is not None:
            eq.last = (start_p, start_state)
            weight[0] = 0.0

            def fun_v(v: FloatArray) -> tuple[float, FloatArray]:
                j, g = fun(np.concatenate([modes, v]))
                return j, g[n_edges:]

            opt = lbfgs(fun_v, speeds, v_bounds, max_iterations)
            its = int(opt.nit)
            # (4) printable speeds
            speeds = _printable_speeds(opt.x, speed_range, speed_resolution)
        base = speeds
        near = _Equilibria(blend, seed=seed, env=env, heated=heated)

        def check_scale(scale: float) -> tuple[FloatArray, _Check]:
            v = base
            if scale != 1.0:
                v = _same_strength(blend, scale * modes, base, speed_range or MEASURED_SPEEDS)
                v = _printable_speeds(v, speed_range or MEASURED_SPEEDS, speed_resolution)
            # scaled designs warm-started from the base design's fresh equilibrium
            near.last = None if scale == 1.0 else (base_p, tried[1.0][1].result.state)
            p_s = np.concatenate([modes, v])
            checked = _verify(blend, p_s, seed, target, picked, size, lattice, near)
            counted[0] += checked.solves
            return v, checked

        base_p = np.concatenate([modes, base])
        tried: dict[float, tuple[FloatArray, _Check]] = {}
        tried[1.0] = check_scale(1.0)
        if speed_range is not None and target.gaussian_curvature is not None:
            # (5) the overall bending strength scaled about the optimum (every edge's mismatch
            # times s): the misfit is flat in this direction near its optimum, the target's K
            # is not. A coarse grid, then two rounds of halved steps about the best scale.
            for scale in STRENGTH_SCALES:
                tried[scale] = check_scale(scale)
            step = 0.04
            for _ in range(2):
                best_s = min(tried, key=lambda k: tried[k][1].rank)
                for scale in (best_s * (1 - step), best_s * (1 + step)):
                    tried.setdefault(scale, check_scale(scale))
                step /= 2
        speeds, check = min(tried.values(), key=lambda t: t[1].rank)
        if check is not tried[1.0][1]:
            # the chosen scale verified by a fresh solve from the branch's start (kept only if
            # it is still better than the fresh base design)
            fresh = _verify(
                blend,
                np.concatenate([modes, speeds]),
                seed,
                target,
                picked,
                size,
                lattice,
                env=env,
                heated=heated,
            )
            counted[0] += fresh.solves
            speeds, check = min([(speeds, fresh), tried[1.0]], key=lambda t: t[1].rank)
        return speeds, check, its

    start_p, start_state = best, best_res.state
    while True:
        speeds, check, its = refine(start_p, start_state)
        nit += its
        if judge is None:
            break
        verdict = judge(with_settings(lattice, modes, speeds if speed_range is not None else None))
        judged.append((modes, speeds, check, verdict))
        judgements[0] += 1
        logger.info(
            "judgement %d: verified K = %.4g 1/mm² (error %s), optimiser's K = %.4g; %s",
            judgements[0],
            verdict.gaussian_curvature,
            "n/a" if verdict.error_rel is None else f"{100 * verdict.error_rel:.1f} %",
            float(check.fit.gaussian_curvature),
            "reached" if verdict.reached else verdict.reason,
        )
        if verdict.reached or len(judged) >= JUDGE_ROUNDS or speed_range is None:
            break
        # the judge's ramp ended on another branch, or off the target: the optimiser starts
        # again from the state that ramp verified, so it works on the branch the judge takes
        branch_state = verdict.result.states[-1]

        def on_branch(p: FloatArray, state: State = branch_state) -> State:
            return state

        heated = on_branch
        counted[0] += eq.solves
        eq = _Equilibria(blend, seed=seed, env=env, heated=heated)
        start_p, start_state = np.concatenate([modes, speeds]), branch_state
    verdict_kept: BathCheck | None = None
    if judged:
        modes, speeds, check, verdict_kept = min(judged, key=lambda t: _verdict_rank(t[3]))
    return designed(modes, speeds, check, verdict_kept, relaxed)

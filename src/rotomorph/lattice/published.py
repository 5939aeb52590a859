r"""The authors' own simulation of the paper's Fig. 4, rebuilt in rotomorph.

The paper's dome and saddle lattices (Fig. 4) were computed with disMech (Choi, Jing, Sabelhaus
& Jawed, *IEEE RA-L* 9, 3483, 2024); the authors published that set-up as a disMech example
(``github.com/yeonsu-jung/shape-morphing-network``, MIT licence: ``robotDescription.cpp``,
``snakeLatticeController.cpp``, ``snake_lattice_params.yml``, ``run.py``, and in its first
commit the output and error files of one cluster run). This module builds the same set-up
from those files; every number below was checked against them.

Their set-up
------------
* **Geometry** (``robotDescription.cpp``): ``num_side_vertices = 5`` branch nodes per side at
  ``(step·j, step·i)``, ``step = 1`` (m); 40 limbs of ``n = 10`` nodes (8 between the branch
  nodes), one sine period each: node ``k`` at ``start + (end − start) t + perp · A sin(2π t)``,
  ``t = k/(n − 1)``, ``A = 0.25`` (a quarter of the cell), ``perp = (0, −1, 0)`` on limbs along
  x and ``(1, 0, 0)`` on limbs along y: the right-hand normal of the limb's direction. (The
  generator :func:`~rotomorph.design.lattices.sinusoidal_lattice` offsets along the left-hand
  normal ẑ × T; :func:`published_lattice` mirrors every ghost node across its chord, so the
  nodes are theirs.)
* **Numbering**: limbs along x first, ``y·4 + x`` from ``(x, y)`` to ``(x + 1, y)``, then limbs
  along y, ``20 + y·5 + x`` from ``(x, y)`` to ``(x, y + 1)`` (:func:`limb_edge` maps them to
  this package's lattice edges).
* **Edge classes** (``robotDescription.cpp``, ``snakeLatticeController.cpp``): the 12 "expand"
  limbs :data:`EXPAND_LIMBS` (the edges between the 3 × 3 interior nodes) get
  ``κ̄ = (1 − stretch) κ̄0`` on every interior vertex, the 26 "shrink" limbs
  :data:`SHRINK_LIMBS` ``(1 + stretch) κ̄0``, both curvature components, at every time step;
  joint pairs keep their printed values. **Limbs 29 and 30** (:data:`UNLISTED_LIMBS`, the
  boundary limbs from (4, 1) to (4, 2) and from (0, 2) to (0, 3)) **are in neither list**, so
  they are never actuated and the lattice is not symmetric under its quarter turns. That is
  reproduced as written (:func:`published_actuation`), not corrected.
* **Stretch range** (``run.py``): ``np.arange(-0.75, +0.75, +0.01)``, one cluster job per
  value (1 core, up to 12 h). ``arange`` leaves out its end, so their sweep has 150 values,
  −0.75 … +0.74; :data:`STRETCHES` is the 151 values −0.75 … +0.75 of the comparison asked for.
* **The logged run** (first commit, ``output_9442163.out`` / ``errors_9442163.err``): stretch
  −0.17 (``arange``'s −0.16999999999999948), ``young_mod`` 2e11 Pa, ``density`` 1000 kg/m³,
  ``radius`` 1e-3 m, ``poisson`` 0.5, ``mu`` 0.4, ``nu`` 1e-3, ``gravity_magnitude`` 0.5 m/s²,
  ``viscosity`` 0.1, ``velocity_amplitude`` 10 m/s, ``dt`` 1e-5 s, ``sim_time`` 10 s; wall time
  ``real 11m46.448s`` (``user 11m34.611s``). The floor contact takes
  ``max(floor_mu, limb mu)`` as its friction coefficient (disMech's floor contact), so the
  floor friction of that run is 0.4 whichever of ``mu`` and ``nu`` the modified floor
  constructor reads as its own. Its last 60 log lines report all 345 nodes within the floor's
  contact distance: the logged saddle run ends flat on the floor.
* **The repository's current yml differs**: ``young_mod`` 1e6, ``mu`` 0.0, ``stretch`` 0.1
  (one commit after the first). With E = 1e6 Pa the weight per length over the bending
  stiffness is w l³/B ≈ 2000 (the weight dominates); with the logged 2e11 Pa it is 0.01. The
  logged run is what the authors ran and timed, so it is the one followed here
  (:data:`YOUNGS_MODULUS`, :data:`FRICTION`).

In rotomorph's units (mm, MPa, g/cm³, N): l = 1000 mm, A = 250 mm, r = 1 mm,
E = 2e5 MPa, ρ = 1 g/cm³, g = 0.5 m/s², floor friction 0.4.

What differs here
-----------------
Every stretch is a *static equilibrium* (Newton, certified stable), reached by continuation
from its neighbour nearer zero, where the authors integrate damped dynamics for 10 s from the
flat print with the full stretch applied at once and initial velocities of ±10 m/s on chosen
limbs to break the symmetry. Symmetry is broken here by a small deterministic bump (10⁻³ l) and
by the lift probe of :func:`~rotomorph.lattice.heating.heat_lattice`, which looks for a lifted
equilibrium of lower total energy wherever the lattice rests flat on the floor. The floor is a
barrier on the node heights with lagged Coulomb friction (theirs: a smooth penalty with a
regularised Coulomb law); filaments also touch each other here (their run has no
filament-filament contact). ``docs/published-simulation.md`` discusses what this changes.
"""

from __future__ import annotations

import time
from concurrent.futures import Executor
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from rotomorph._typing import FloatArray, IntArray
from rotomorph.analysis.curvature import fit_quadratic_surface
from rotomorph.design.lattices import Lattice, sinusoidal_lattice
from rotomorph.design.network import Network
from rotomorph.errors import InvalidParameterError
from rotomorph.lattice.actuation import CurvatureScaling
from rotomorph.lattice.heating import RAMP_OPTIONS, HeatingResult, heat_lattice
from rotomorph.solve.loads import Gravity
from rotomorph.solve.newton import NewtonOptions

__all__ = [
    "AMPLITUDE_RATIO",
    "DENSITY",
    "EXPAND_LIMBS",
    "FRICTION",
    "GRAVITY",
    "LOGGED_RUN_SECONDS",
    "LOGGED_STRETCH",
    "NODES_PER_LIMB",
    "RADIUS",
    "SHRINK_LIMBS",
    "SPACING",
    "STRETCHES",
    "UNLISTED_LIMBS",
    "YOUNGS_MODULUS",
    "PublishedSweep",
    "fit_residual",
    "limb_edge",
    "published_actuation",
    "published_gravity",
    "published_lattice",
    "published_sweep",
    "weight_ratio",
]

#: Branch nodes per side (``num_side_vertices``).
SIDE = 5
#: Cell size l (mm): their ``step = 1`` m.
SPACING = 1000.0
#: Sine amplitude over the cell (``amplitude = 0.25`` with ``step = 1``).
AMPLITUDE_RATIO = 0.25
#: Nodes per limb, branch nodes included (``n = 10``): 8 ghost nodes per edge.
NODES_PER_LIMB = 10
#: Filament radius (mm): their ``radius = 1e-3`` m.
RADIUS = 1.0
#: Young's modulus of the logged run (MPa): ``young_mod = 2e11`` Pa.
YOUNGS_MODULUS = 2.0e5
#: Filament density (g/cm³): ``density = 1000`` kg/m³.
DENSITY = 1.0
#: Gravitational acceleration (m/s²): ``gravity_magnitude = 0.5``.
GRAVITY = 0.5
#: Floor friction coefficient of the logged run (``mu = 0.4``; module docstring).
FRICTION = 0.4
#: The logged run's stretch and wall time (s): ``real 11m46.448s``.
LOGGED_STRETCH = -0.17
LOGGED_RUN_SECONDS = 11 * 60 + 46.448

#: Their "expand" limbs: κ̄ × (1 − stretch).
EXPAND_LIMBS = (5, 6, 9, 10, 13, 14, 26, 27, 28, 31, 32, 33)
#: Their "shrink" limbs: κ̄ × (1 + stretch).
SHRINK_LIMBS = (0, 1, 2, 3, 4, 7, 8, 11, 12, 15, 16, 17, 18, 19, 20, 21, 22, 23, 24, 25,
                34, 35, 36, 37, 38, 39)  # fmt: skip
#: Limbs in neither list: never actuated.
UNLISTED_LIMBS = (29, 30)

#: Newton settings of the sweep: the ramp's, with room for snaps. Where the lifted saddle's
#: branch ends at a fold (stretch -0.44 to -0.45 under the logged weight) the lattice jumps
#: to another branch in one step (about 320 Newton iterations); halving the step cannot cross
#: a fold, so the ramp's 300 would stop the sweep there.
SWEEP_OPTIONS: NewtonOptions = replace(RAMP_OPTIONS, max_iterations=3000)

#: The 151 stretch values −0.75 … +0.75 by 0.01 (rounded to the grid).
STRETCHES: FloatArray = np.round(np.arange(-75, 76) / 100.0, 2)


def limb_edge(limb: int) -> int:
    """This package's lattice edge index of the authors' limb ``limb`` (0-39).

    Their limbs along x, ``y·4 + x``, are edges ``y·4 + x`` here too; their limbs along y,
    ``20 + y·5 + x``, are edges ``20 + x·4 + y`` (:mod:`rotomorph.design.lattices` numbers
    the y-edges column by column).
    """
    n = SIDE
    m = n * (n - 1)
    if isinstance(limb, bool) or int(limb) != limb or not 0 <= limb < 2 * m:
        raise InvalidParameterError("limb", f"must be an integer in [0, {2 * m - 1}]; got {limb}")
    limb = int(limb)
    if limb < m:
        return limb
    y, x = divmod(limb - m, n)
    return m + x * (n - 1) + y


def published_lattice() -> Lattice:
    """The authors' 5 × 5 lattice (module docstring), in mm.

    Edge modes: their "expand" limbs ``'expanding'``, every other limb ``'contracting'``
    (limbs 29 and 30 too; :func:`published_actuation` leaves them unscaled). One layer,
    radius :data:`RADIUS`.
    """
    mode = ["contracting"] * (2 * SIDE * (SIDE - 1))
    for limb in EXPAND_LIMBS:
        mode[limb_edge(limb)] = "expanding"
    base = sinusoidal_lattice(
        SIDE,
        SPACING,
        AMPLITUDE_RATIO * SPACING,
        NODES_PER_LIMB - 2,
        mode,
        layers=1,
        radius=RADIUS,
    )
    # their offset is along the right-hand normal -(z x T): mirror the ghosts across the chords
    net = base.network
    nodes = net.nodes.copy()
    ends = base.edge_nodes
    t = (nodes[ends[:, 1]] - nodes[ends[:, 0]]) / SPACING
    normal = np.cross([0.0, 0.0, 1.0], t)
    for e, chain in enumerate(base.edge_chains):
        ghosts = chain[1:-1]
        offset = (nodes[ghosts] - nodes[chain[0]]) @ normal[e]
        nodes[ghosts] -= 2.0 * offset[:, None] * normal[e]
    return replace(
        base,
        network=Network(nodes, net.edges, net.branch),
        amplitude=-base.amplitude,
        _cache={},
    )


def published_actuation(start: float = 0.0, end: float = 0.75) -> CurvatureScaling:
    """Their controller as a ramp of x = stretch from ``start`` to ``end``: curvature scaled by
    (1 − x) on the expand limbs, (1 + x) on the shrink limbs (the ``"swapped"`` reading), limbs
    29 and 30 unscaled."""
    return CurvatureScaling(
        "swapped",
        start=float(start),
        end=float(end),
        fixed_edges=tuple(limb_edge(k) for k in UNLISTED_LIMBS),
    )


def published_gravity(acceleration: float = GRAVITY) -> Gravity:
    """Their self-weight: ρ = 1 g/cm³ on the section π r², ``acceleration`` (m/s²), no bath."""
    return Gravity(density=DENSITY, area=np.pi * RADIUS**2, acceleration=float(acceleration))


@dataclass(frozen=True, eq=False)
class PublishedSweep:
    """The stretch sweep of the authors' set-up (:func:`published_sweep`).

    Attributes
    ----------
    stretch
        Stretch values ``(K,)``, ascending (0 included once: the flat print).
    characteristic_curvature
        √|k1 k2| of the quadratic surface fitted to the branch nodes (1/mm).
    gaussian_sign
        Sign of its Gaussian curvature (+1 dome, −1 saddle, 0 flat).
    fit_residual
        RMS residual of that fit over the fitted surface's rise (the branch nodes' extent
        along its normal; 0 where flat): above about 0.1 the quadratic surface no longer
        describes the shape (edges folded or crumpled), and √|k1 k2| is a fit to a shape it
        does not describe.
    wall_time
        Seconds spent on each value (0 for the flat print).
    energy
        Total potential energy of each equilibrium (N mm; ``HeatingResult.energy``: elastic,
        weight, barrier and, with friction, the lagged friction term; 0 for the print).
    floor_lift
        Largest rise of a node above its printed height (mm); None without a floor.
    lift_energy_gap
        Per value, the lift probe's energy of the best lifted equilibrium minus the resting
        one (N mm; NaN where none was probed), None where no probe ran.
    stable
        Per value: True where certified a stable minimum.
    stack_overlaps
        Per value: pairs of filament segments (one layer: the centre lines' capsules) that
        interpenetrate (:func:`rotomorph.lattice.admissibility.admissibility`; 0: admissible);
        None where not checked.
    positions
        Node positions per value ``(K, N, 3)`` (mm).
    negative, positive
        The two continuation ramps, 0 → min(stretch) and 0 → max(stretch).
    cpu_time
        CPU seconds of the whole sweep: both ramps' together, wherever they ran.
    """

    stretch: FloatArray
    characteristic_curvature: FloatArray
    gaussian_sign: IntArray
    fit_residual: FloatArray
    wall_time: FloatArray
    energy: FloatArray
    floor_lift: FloatArray | None
    lift_energy_gap: FloatArray | None
    stable: tuple[bool | None, ...]
    positions: FloatArray
    negative: HeatingResult
    positive: HeatingResult
    cpu_time: float
    stack_overlaps: IntArray | None = None

    @property
    def physical(self) -> tuple[bool, ...]:
        """Per value: certified stable and admissible (no filaments interpenetrating); a value
        whose admissibility was not checked is not counted as physical."""
        overlaps = (
            (None,) * len(self.stretch) if self.stack_overlaps is None else self.stack_overlaps
        )
        return tuple(
            s is True and c is not None and int(c) == 0
            for s, c in zip(self.stable, overlaps, strict=True)
        )

    @property
    def lattice(self) -> Lattice:
        """The authors' lattice."""
        return self.positive.lattice

    def at(self, stretch: float) -> int:
        """Row of the value nearest ``stretch``."""
        return int(np.argmin(np.abs(self.stretch - float(stretch))))

    def first(self, sign: int) -> float | None:
        """Smallest stretch magnitude at which the Gaussian sign is ``sign`` (signed), or None."""
        hit = [s for s, g in zip(self.stretch, self.gaussian_sign, strict=True) if g == sign]
        return None if not hit else float(min(hit, key=abs))


def weight_ratio(acceleration: float = GRAVITY, youngs_modulus: float = YOUNGS_MODULUS) -> float:
    """Weight per length over the bending stiffness, w l³ / B (dimensionless): 0.01 for the
    logged run, 2000 for the current yml's E = 1e6 Pa."""
    w = published_gravity(acceleration).line_weight(1)[0]  # N/mm
    bending = youngs_modulus * np.pi * RADIUS**4 / 4.0  # N mm²
    return float(w * SPACING**3 / bending)


def fit_residual(lattice: Lattice, positions: FloatArray) -> float:
    """RMS residual of the quadratic surface fitted to the branch nodes over its rise
    (dimensionless; 0 for a flat lattice): how well √|k1 k2| describes the shape."""
    pts = positions[lattice.branch_indices]
    fit = fit_quadratic_surface(pts, flat_tolerance=1e-6)
    rise = float(np.ptp((pts - fit.center) @ fit.frame[2]))
    return 0.0 if fit.gaussian_sign == 0 or rise == 0.0 else float(fit.rms_residual / rise)


def published_sweep(
    step: float = 0.01,
    end: float = 0.75,
    *,
    floor: bool = True,
    friction: float = FRICTION,
    acceleration: float = GRAVITY,
    contact: bool = True,
    executor: Executor | None = None,
) -> PublishedSweep:
    """The authors' stretch sweep by continuation: 0 → −``end`` and 0 → +``end`` by ``step``.

    Each value starts from the equilibrium of its neighbour nearer zero (the first from the
    flat print), so the states are those reached by loading quasi-statically from the print;
    the authors start every value from the flat print instead (module docstring).

    Parameters
    ----------
    step, end
        Stretch spacing and largest stretch magnitude (``end / step`` must be a whole number).
    floor
        Rest on a floor just below the print (the authors' floor); False: a free lattice.
    friction
        Floor friction coefficient (default the logged run's 0.4).
    acceleration
        Gravitational acceleration (m/s²; default their 0.5); 0: weightless. Needs ``floor``.
    contact
        Filaments touch each other (rotomorph's physics; their run has no such contact).
    executor
        Where the two ramps run (e.g. a two-worker process pool: they are independent, so on
        two cores the sweep takes the time of the longer one); default: here, one after the
        other. The results are the same either way.

    Raises
    ------
    InvalidParameterError
        A non-positive step or end, an end that is not a whole number of steps, weight or
        friction without a floor.
    """
    if not (np.isfinite(step) and step > 0 and np.isfinite(end) and end > 0):
        raise InvalidParameterError("step", f"step and end must be > 0; got {step}, {end}")
    steps = round(end / step)
    if abs(steps * step - end) > 1e-9 * end:
        raise InvalidParameterError("end", f"must be a whole number of steps {step}; got {end}")
    if not floor and (acceleration or friction):
        raise InvalidParameterError(
            "floor", "weight and friction need the floor: use floor=True or set both to 0"
        )
    kw: dict[str, Any] = dict(
        stiffness="paper",
        youngs_modulus=YOUNGS_MODULUS,
        steps=steps,
        contact=contact,
        floor=floor,
        friction=friction,
        gravity=published_gravity(acceleration) if acceleration else None,
        options=SWEEP_OPTIONS,
    )
    ends = (-steps * step, steps * step)
    if executor is None:
        (neg, cpu_neg), (pos, cpu_pos) = (_ramp(end, kw) for end in ends)
    else:
        futures = [executor.submit(_ramp, end, kw) for end in ends]
        (neg, cpu_neg), (pos, cpu_pos) = (f.result() for f in futures)
    lattice = pos.lattice
    order = np.r_[np.arange(steps, 0, -1), 0]  # the negative ramp reversed, 0 last

    def join(a: np.ndarray | None, b: np.ndarray | None) -> np.ndarray | None:
        return None if a is None or b is None else np.concatenate([a[order], b[1:]])

    stretch = np.round(np.concatenate([neg.parameter[order], pos.parameter[1:]]), 12)
    positions = np.concatenate([neg.positions[order], pos.positions[1:]])
    gaps = join(neg.lift_energy_gap, pos.lift_energy_gap)
    lift = join(neg.floor_lift, pos.floor_lift)
    return PublishedSweep(
        stretch=stretch,
        characteristic_curvature=np.concatenate(
            [neg.characteristic_curvature[order], pos.characteristic_curvature[1:]]
        ),
        gaussian_sign=np.concatenate([neg.gaussian_sign[order], pos.gaussian_sign[1:]]),
        fit_residual=np.array([fit_residual(lattice, x) for x in positions]),
        wall_time=np.concatenate([neg.wall_time[order], pos.wall_time[1:]]),
        energy=np.concatenate([neg.energy[order], pos.energy[1:]]),
        floor_lift=lift,
        lift_energy_gap=gaps,
        stable=tuple(neg.stable[k] for k in order) + tuple(pos.stable[1:]),
        positions=positions,
        negative=neg,
        positive=pos,
        cpu_time=cpu_neg + cpu_pos,
        stack_overlaps=join(neg.stack_overlaps, pos.stack_overlaps),
    )


def _ramp(end: float, kw: dict[str, Any]) -> tuple[HeatingResult, float]:
    """One continuation ramp 0 -> ``end`` of the authors' set-up and its CPU seconds."""
    cpu = time.process_time()
    result = heat_lattice(published_lattice(), actuation=published_actuation(0.0, end), **kw)
    return result, time.process_time() - cpu

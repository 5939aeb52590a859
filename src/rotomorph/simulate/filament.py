"""Simulate one printed filament over a heating ramp with the rod solver.

Pipeline per actuation step::

    PrintProgram ──natural_field(T)──► NaturalField ──Model.chain──► Model ──solve_static──►
    equilibrium ──analysis──► L/L0, helix fit, morphology

The ramp is uniform in the actuation fraction x (not in temperature): x(T) is a steep sigmoid
around T_NI, so equal temperature steps would put the whole shape change into one or two steps.
Each step starts from the previous equilibrium (continuation); a step whose Newton solve fails
is split in halves (up to ``max_refinements`` times) before the error propagates.

Step 0 is the printed (stress-free) configuration at ``start_temperature``; the tiny actuation
there (x ≈ 1e-3 at 25 °C) is not solved for, its natural field only starts the ramp.
"""

from __future__ import annotations

import logging
import os
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path as FilePath
from typing import Any

import numpy as np

from rotomorph._display import compact_display
from rotomorph._typing import FloatArray
from rotomorph.analysis.curvature import discrete_curvature
from rotomorph.analysis.shape import (
    HelixFit,
    Morphology,
    end_to_end_ratio,
    fit_helix,
    polyline_morphology,
)
from rotomorph.contact import Contact
from rotomorph.errors import InvalidParameterError, RotomorphError
from rotomorph.materials.material import Material
from rotomorph.materials.natural import FilamentModel, NaturalField, natural_field
from rotomorph.materials.process import actuation_fraction
from rotomorph.rod.model import Model
from rotomorph.rod.state import State
from rotomorph.solve.continuation import continuation
from rotomorph.solve.loads import Loads
from rotomorph.solve.newton import NewtonOptions
from rotomorph.solve.static import StaticResult, solve_static

__all__ = [
    "FilamentSimulation",
    "heating_temperatures",
    "rod_model",
    "simulate_filament",
]

logger = logging.getLogger(__name__)
#: What the solver is doing, for the command line's progress display (``rotomorph._progress``).
phase_log = logging.getLogger("rotomorph.progress")

#: Room temperature at which filaments are printed (°C).
PRINT_TEMPERATURE = 25.0
#: Actuation temperature of the paper's filaments (°C).
ACTUATION_TEMPERATURE = 175.0

Progress = Callable[[int], None]
#: ``on_step(k, temperature, state, result)``: step ``k`` of the ramp reached at ``temperature``
#: (°C) in ``state``; ``result`` is the step's :class:`StaticResult` (None for the printed k = 0).
StepCallback = Callable[[int, float, State, "StaticResult | None"], None]


@compact_display("final_ratio")
@dataclass(frozen=True, eq=False)
class FilamentSimulation:
    """A filament's equilibrium shapes over a heating ramp.

    Attributes
    ----------
    name
        Label (the design's filament name).
    printed
        Printed vertices ``(N, 3)`` (mm).
    temperature
        ``(S,)`` temperatures (°C), step 0 the printed state.
    actuation
        ``(S,)`` actuation fraction x (dimensionless).
    positions
        ``(S, N, 3)`` equilibrium vertices (mm).
    end_to_end_ratio
        ``(S,)`` L/L0: end-to-end distance over the printed one.
    curvature
        ``(S, N)`` discrete curvature per vertex (1/mm; NaN at the two ends).
    energy, iterations, residual
        ``(S,)`` elastic energy (N mm), Newton iterations (all sub-steps), relative residual.
    helix
        Helix fitted to the final shape, or ``None`` (straight, or the fit failed).
    morphology
        Label of the final shape (from its median curvature and material twist).
    closed_form
        Closed-form free-helix prediction for a uniform natural field, else ``None``.
    wall_time
        Seconds spent.
    states
        Rod state per step ``(S,)`` (positions, frames): the material directors give the Janus
        sides; step 0 is the printed reference state.
    stable
        Per step: ``True`` where the solver certified a stable minimum, ``None`` where it did
        not check (step 0, the stress-free printed state, is ``True``).
    program
        The print program simulated.
    lowest_eigenvalue
        ``(S,)`` lowest Hessian eigenvalue of each equilibrium (N/mm²; NaN for step 0).
    max_axial_strain
        ``(S,)`` largest centre-line strain against the natural length per step
        (:attr:`rotomorph.solve.static.StaticResult.max_axial_strain`; 0 for step 0).
    """

    name: str
    printed: FloatArray
    temperature: FloatArray
    actuation: FloatArray
    positions: FloatArray
    end_to_end_ratio: FloatArray
    curvature: FloatArray
    energy: FloatArray
    iterations: FloatArray
    residual: FloatArray
    helix: HelixFit | None
    morphology: Morphology
    closed_form: Any
    wall_time: float
    states: tuple[State, ...] = ()
    stable: tuple[bool | None, ...] = ()
    program: Any = None
    lowest_eigenvalue: FloatArray = field(default_factory=lambda: np.zeros(0))
    max_axial_strain: FloatArray = field(default_factory=lambda: np.zeros(0))

    @property
    def final_ratio(self) -> float:
        """L/L0 at the last step."""
        return float(self.end_to_end_ratio[-1])

    def to_run(self) -> Any:
        """This filament as a one-chain :class:`~rotomorph.simulate.design.DesignSimulation`."""
        from rotomorph.simulate.design import filaments_simulation

        return filaments_simulation([self], {"name": self.name, "source": "print program"})

    def save(self, folder: str | os.PathLike[str], *, movie: bool = True) -> list[FilePath]:
        """Write results.h5, summary.json, figures, movie and ParaView files into ``folder``.

        The same run folder as ``rotomorph simulate`` (created if missing); returns the paths.
        """
        from rotomorph.simulate.outputs import write_run

        return write_run(self, folder, movie=movie)

    def plot(self, folder: str | os.PathLike[str], *, movie: bool = False) -> list[FilePath]:
        """Draw the run's figures (and, with ``movie``, the animation) into ``folder``."""
        from rotomorph.simulate.outputs import plot_run
        from rotomorph.simulate.run_data import describe_run

        return plot_run(describe_run(self.to_run()), folder, movie=movie)


def _active_material(
    program: Any, materials: Mapping[str, Material] | None, model: FilamentModel
) -> Material:
    name = program.active_material
    return materials[name] if materials and name in materials else model.material(name)


def heating_temperatures(
    program: Any,
    steps: int,
    *,
    start_temperature: float = PRINT_TEMPERATURE,
    temperature: float = ACTUATION_TEMPERATURE,
    materials: Mapping[str, Material] | None = None,
    model: FilamentModel | None = None,
) -> FloatArray:
    """``steps + 1`` temperatures (°C) from ``start_temperature`` whose actuation is uniform in x.

    Parameters
    ----------
    program
        Print program (its ``active_material`` sets T_NI).
    steps
        Number of heating steps (≥ 1).
    start_temperature, temperature
        First and last temperature (°C), ``start_temperature < temperature``.
    materials, model
        As for :func:`~rotomorph.materials.natural_field`.
    """
    if steps < 1:
        raise InvalidParameterError("steps", f"must be >= 1; got {steps}")
    if not (np.isfinite(start_temperature) and np.isfinite(temperature)):
        raise InvalidParameterError("temperature", "must be finite (°C)")
    if not start_temperature < temperature:
        raise InvalidParameterError(
            "temperature",
            f"must exceed the start temperature {start_temperature} °C; got {temperature} °C",
        )
    model = FilamentModel() if model is None else model
    active = _active_material(program, materials, model)
    grid = np.linspace(start_temperature, temperature, 2001)
    x = actuation_fraction(
        grid,
        active.transition_temperature,  # type: ignore[arg-type]
        model.transition_width,
        direction=model.direction,
        hysteresis=model.hysteresis,
    )
    targets = np.linspace(x[0], x[-1], steps + 1)
    temps = np.interp(targets, x, grid)
    temps[0], temps[-1] = start_temperature, temperature
    return temps


def rod_model(program: Any, field: NaturalField) -> Model:
    """The rod :class:`~rotomorph.rod.model.Model` of a printed filament with natural ``field``."""
    return Model.from_field(program.points, field)


def _blend(a: NaturalField, b: NaturalField, w: float) -> NaturalField:
    """Field between two temperatures' fields (used only for the halved sub-steps)."""

    def mix(name: str) -> FloatArray:
        return (1.0 - w) * getattr(a, name) + w * getattr(b, name)

    return NaturalField(
        directors=b.directors,
        curvature1=mix("curvature1"),
        curvature2=mix("curvature2"),
        twist=mix("twist"),
        voronoi_length=b.voronoi_length,
        rest_length=mix("rest_length"),
        axial_strain=mix("axial_strain"),
        bending_stiffness1=b.bending_stiffness1,
        bending_stiffness2=b.bending_stiffness2,
        twist_stiffness=b.twist_stiffness,
        axial_stiffness=b.axial_stiffness,
        actuation=(1.0 - w) * a.actuation + w * b.actuation,
        measure=b.measure,
    )


def _final_shape(points: FloatArray, state: State) -> tuple[HelixFit | None, Morphology]:
    m1, _ = state.material_directors()
    try:
        morph = polyline_morphology(points, m1)
    except RotomorphError:
        morph = Morphology.STRAIGHT
    helix = None
    if morph in (Morphology.HELIX, Morphology.COIL):
        try:
            helix = fit_helix(points)
        except (RotomorphError, ValueError, np.linalg.LinAlgError):
            helix = None
    return helix, morph


def simulate_filament(
    program: Any,
    *,
    name: str = "",
    steps: int = 8,
    start_temperature: float = PRINT_TEMPERATURE,
    temperature: float = ACTUATION_TEMPERATURE,
    materials: Mapping[str, Material] | None = None,
    model: FilamentModel | None = None,
    options: NewtonOptions | None = None,
    max_refinements: int = 4,
    progress: Progress | None = None,
    contact: Contact | None = None,
    loads: Loads | Callable[[float], Loads] | None = None,
    on_step: StepCallback | None = None,
) -> FilamentSimulation:
    """Equilibrium shapes of a free filament heated from ``start_temperature`` to ``temperature``.

    Parameters
    ----------
    program
        The filament's :class:`~rotomorph.design.program.PrintProgram`.
    name
        Label stored with the result.
    steps
        Heating steps (uniform in actuation x); the result has ``steps + 1`` states.
    start_temperature, temperature
        Printing and final temperature (°C).
    materials, model
        As for :func:`~rotomorph.materials.natural_field`.
    options
        Newton settings of each solve.
    max_refinements
        Times a failing step may be halved.
    progress
        Called with 1 after every step (for a progress bar).
    contact
        Self-contact (and obstacles) of the filament (:class:`rotomorph.contact.Contact`):
        tight coils touch instead of passing through themselves.
    loads
        Dead loads (:class:`rotomorph.solve.loads.Loads`), e.g. the buoyant weight of a
        filament resting on a floor obstacle; or a function of the temperature (°C) returning
        them, for loads that change along the ramp (the bath's density falls as it heats).
    on_step
        Called as each step is reached, the printed state first (:data:`StepCallback`): to
        show converged states while the ramp runs.

    Raises
    ------
    ConvergenceError
        A step failed even after ``max_refinements`` halvings.
    InvalidDesignError, MaterialError
        Malformed program or unknown materials.
    """
    t0 = time.perf_counter()
    temps = heating_temperatures(
        program,
        steps,
        start_temperature=start_temperature,
        temperature=temperature,
        materials=materials,
        model=model,
    )
    printed = np.asarray(program.points, dtype=float)
    fields = [natural_field(program, materials, float(t), model=model) for t in temps]
    state = rod_model(program, fields[0]).reference_state()
    s = len(temps)
    positions = np.empty((s, len(printed), 3))
    energy, iterations, residual = np.zeros(s), np.zeros(s), np.zeros(s)
    # step 0 is the printed shape: at x(T0) ~ 1e-3 the loads are so small that a solve only
    # chases round-off (the residual is relative to the force scale)
    positions[0] = printed
    if progress is not None:
        progress(1)
    if on_step is not None:
        on_step(0, float(temps[0]), state, None)
    iterations_at: dict[float, int] = {}

    def solve(w: float, initial: State) -> StaticResult:
        # w runs over the step index; a halved step blends its two end fields (linear in
        # the eigenstrains; the moduli's slow temperature dependence is taken from the end
        # field): only the halved sub-steps use a blend, every reported step is exact
        k = min(int(np.floor(w)), s - 2)
        field = fields[k] if w == k else _blend(fields[k], fields[k + 1], w - k)
        # loads of the step's temperature (a halved step's linear blend)
        t_w = float(temps[k] + (w - k) * (temps[k + 1] - temps[k]))
        if w == int(w):
            phase_log.info("heating step %d of %d at %.1f °C", int(w), s - 1, t_w)
        step_loads = loads(t_w) if callable(loads) else loads
        res = solve_static(
            rod_model(program, field),
            loads=step_loads,
            initial=initial,
            options=options,
            contact=contact,
        )
        iterations_at[w] = iterations_at.get(w, 0) + res.iterations
        if progress is not None and w == int(w):
            progress(1)
        return res

    def reached(step: Any) -> None:
        if on_step is not None:
            k = round(step.parameter)
            on_step(k, float(temps[k]), step.result.state, step.result)

    path = continuation(
        solve, np.arange(1.0, s), state, start=0.0, max_halvings=max_refinements, on_step=reached
    )
    for k, step in enumerate(path.steps, start=1):
        res = step.result
        positions[k], energy[k], residual[k] = res.positions, res.energy, res.residual
        iterations[k] = sum(n for w, n in iterations_at.items() if k - 1 < w <= k)
    states = (state, *(step.result.state for step in path.steps))
    stable = (True, *(_stable_flag(step.result) for step in path.steps))
    state = path.final.state
    ratio = np.array([end_to_end_ratio(p, printed) for p in positions])
    curvature = np.full((s, len(printed)), np.nan)
    for k in range(s):
        curvature[k, 1:-1] = discrete_curvature(positions[k])
    helix, morph = _final_shape(positions[-1], state)
    try:
        closed = fields[-1].morphology(rtol=1e-6)
    except RotomorphError:
        closed = None
    return FilamentSimulation(
        name=name,
        printed=printed,
        temperature=temps,
        actuation=np.array([f.actuation for f in fields]),
        positions=positions,
        end_to_end_ratio=ratio,
        curvature=curvature,
        energy=energy,
        iterations=iterations,
        residual=residual,
        helix=helix,
        morphology=morph,
        closed_form=closed,
        wall_time=time.perf_counter() - t0,
        states=states,
        stable=stable,
        program=program,
        lowest_eigenvalue=np.r_[np.nan, path.lowest_eigenvalues],
        max_axial_strain=np.r_[0.0, [step.result.max_axial_strain for step in path.steps]],
    )


def _stable_flag(result: Any) -> bool | None:
    """``True`` where the solver certified a minimum; ``None`` (unknown) otherwise: a solve
    that ends on an unstable point raises, so ``stable=False`` on a returned result means the
    check was switched off, not that the state is unstable."""
    return True if getattr(result, "stable", None) is True else None

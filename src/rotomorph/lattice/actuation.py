r"""How heating changes the natural state of lattice edges: pluggable, named actuation modes.

An actuation maps a ramp parameter (the paper's x, or a temperature) to a rod
:class:`~rotomorph.rod.model.Model` with new natural values. Only rod vertices are actuated;
junction pairs keep their printed values, and the natural twist always stays
printed. κ0 below is the printed pointwise curvature (both material components, so a stencil
that straddles a flip is scaled as a vector).

==============  =============================================================================
name            natural curvature at ramp parameter x (expanding = active outer = "straightening",
                contracting = active inner = "curling" edges)
==============  =============================================================================
``literal``     (a) the paper's words: κ̄ = (1 + x) κ0 on straightening, (1 − x) κ0 on curling
                edges. Inverts the paper (expanding lattices contract, dome patterns give
                saddles) — kept as a documented known fact.
``swapped``     (b) labels swapped (the reading that keeps the paper's signs): (1 − x) κ0 expanding,
                (1 + x) κ0 contracting.
``radius``      (c) c multiplies the radius of curvature: κ0/(1 + x) expanding, κ0/(1 − x)
                contracting (4 κ0 at x = 0.75; curling edges loop through themselves).
``additive``    (d) physical rule of the theory page: κ̄ = κ0 + x K_J toward the active side (K_J the
                Janus curvature from the materials layer at the lattice's print speed, or given).
``thermal``     temperature T (°C) → actuation fraction x(T) (materials layer); κ̄ = κ0 +
                x(T) K_J toward the active side and rest lengths × exp(x ε_c) (centre-line
                strain of the Janus section, one K_J for the whole lattice at ω* = 0); printed
                turning angles are kept, so a pure axial strain is a similarity.
``program``     **default.** Temperature T (°C); every printed line of the lattice goes
                through the same chain as a single filament
                (:func:`rotomorph.materials.natural.actuation_increments`): its print program
                (speed, the nozzle rotation that keeps the active side, the flips) and the
                materials at T give per-vertex curvature vectors, eigen-twists and per-edge
                centre-line strains, read in the lattice's frames. Pass-through pairs at branch
                nodes are vertices of their line and actuate; cross pairs (bonds between two
                lines) keep their printed values.
==============  =============================================================================

The readings (a)-(d) reproduce or compare with the paper's own phenomenological simulation
(c_s = 1 + x, c_t = 1 − x, Methods); their magnitude depends on the amplitude A and the cell
size l, which the paper does not give. Only ``program`` and ``thermal`` predict from print
parameters.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal, Protocol, runtime_checkable

import numpy as np

from rotomorph._typing import BoolArray, FloatArray, IntArray
from rotomorph.errors import InvalidParameterError
from rotomorph.geometry import curvature_increment, unit
from rotomorph.lattice.model import LatticeModel, Stiffness
from rotomorph.materials.natural import (
    FilamentModel,
    LayerStack,
    actuation_increments,
)
from rotomorph.rod.model import Model

__all__ = [
    "ACTUATIONS",
    "DEFAULT_ACTUATION",
    "Actuation",
    "AdditiveCurvature",
    "CurvatureScaling",
    "ProgramActuation",
    "ThermalActuation",
    "default_stiffness",
    "get_actuation",
    "ramp_value_text",
]

ACTUATIONS = ("literal", "swapped", "radius", "additive", "thermal", "program")

#: The actuation a lattice is heated with unless another is asked for.
DEFAULT_ACTUATION = "program"

#: Final ramp value of the paper's x (Methods: x from 0 to 0.75).
PAPER_FINAL_X = 0.75


@runtime_checkable
class Actuation(Protocol):
    """What :func:`rotomorph.lattice.heating.heat_lattice` needs from an actuation mode."""

    @property
    def name(self) -> str:
        """Name of the actuation mode."""
        ...

    @property
    def start(self) -> float:
        """First value of the ramp parameter (x, or temperature in °C for thermal modes)."""
        ...

    @property
    def end(self) -> float:
        """Last value of the ramp parameter."""
        ...

    def natural(self, lm: LatticeModel, parameter: float) -> Model:
        """The rod model at ramp ``parameter``."""


def _check_range(name: str, start: float, end: float) -> None:
    for field, v in (("start", start), ("end", end)):
        if not np.isfinite(v):
            raise InvalidParameterError(f"{name}.{field}", f"must be finite; got {v}")


@dataclass(frozen=True)
class CurvatureScaling:
    """Readings (a)-(c) of the paper's recipe: printed curvature times a factor c(x).

    Parameters
    ----------
    reading
        ``"literal"``, ``"swapped"`` or ``"radius"`` (module table).
    start, end
        Ramp of x (dimensionless); the paper ramps 0 → 0.75. ``radius`` needs x < 1.
    fixed_edges
        Lattice edges (indices into ``lattice.edge_nodes``) whose rod vertices keep their
        printed curvature at every x: edges in neither class. Default none. (The authors'
        published simulation of Fig. 4 leaves two boundary edges out of both of its edge
        lists: :mod:`rotomorph.lattice.published`.)
    """

    reading: Literal["literal", "swapped", "radius"] = "swapped"
    start: float = 0.0
    end: float = PAPER_FINAL_X
    fixed_edges: tuple[int, ...] = ()

    def __post_init__(self) -> None:
        if self.reading not in ("literal", "swapped", "radius"):
            raise InvalidParameterError(
                "CurvatureScaling.reading",
                f"must be 'literal', 'swapped' or 'radius'; got {self.reading!r}",
            )
        _check_range("CurvatureScaling", self.start, self.end)
        if self.reading == "radius" and max(abs(self.start), abs(self.end)) >= 1.0:
            raise InvalidParameterError(
                "CurvatureScaling.end", "must be < 1 for the 'radius' reading (κ0/(1 − x))"
            )
        fixed = tuple(self.fixed_edges)
        for k, e in enumerate(fixed):
            if isinstance(e, bool) or int(e) != e or e < 0:
                raise InvalidParameterError(
                    f"CurvatureScaling.fixed_edges[{k}]",
                    f"must be a lattice edge index (an integer >= 0); got {e!r}",
                )
        object.__setattr__(self, "fixed_edges", tuple(int(e) for e in fixed))

    @property
    def name(self) -> str:
        """The reading's name."""
        return self.reading

    def factors(self, x: float) -> tuple[float, float]:
        """(c on expanding, c on contracting) edges at ramp value x."""
        if self.reading == "literal":
            return 1.0 + x, 1.0 - x
        if self.reading == "swapped":
            return 1.0 - x, 1.0 + x
        return 1.0 / (1.0 + x), 1.0 / (1.0 - x)

    def natural(self, lm: LatticeModel, parameter: float) -> Model:
        """Scaled printed curvature on rod vertices, printed values on junction pairs."""
        c_exp, c_con = self.factors(float(parameter))
        c = np.where(lm.expanding, c_exp, np.where(lm.rod_vertex, c_con, 1.0))
        if self.fixed_edges:
            c = np.where(_on_edges(lm, self.fixed_edges), 1.0, c)
        k1, k2, _ = lm.printed
        return lm.model.with_natural(curvature1=c * k1, curvature2=c * k2)


def _on_edges(lm: LatticeModel, edges: tuple[int, ...]) -> BoolArray:
    """``(S,)`` True on the rod vertices of lattice edges ``edges`` (junction pairs never).

    A rod vertex joins two segments of one lattice edge; the network's segments run in chain
    order along each edge, in edge order, ``ghost_nodes + 1`` per edge.
    """
    n_edges = len(lm.lattice.edge_nodes)
    bad = [e for e in edges if e >= n_edges]
    if bad:
        raise InvalidParameterError(
            "CurvatureScaling.fixed_edges",
            f"must be lattice edges in [0, {n_edges - 1}]; got {bad}",
        )
    per = lm.lattice.ghost_nodes + 1
    segments = np.arange(lm.model.network.n_edges) if lm.segments is None else lm.segments
    edge_of = np.asarray(segments)[lm.model.stencils.edge_e] // per
    return np.asarray(lm.rod_vertex & np.isin(edge_of, edges))


def _janus_curvature(lm: LatticeModel, fm: FilamentModel) -> tuple[float, float]:
    """(K_J toward n (1/mm), centre-line strain ε_c) at full actuation, ω* = 0."""
    lat = lm.lattice
    if lat.edge_speeds is not None and len(set(lat.edge_speeds)) > 1:
        raise InvalidParameterError(
            "actuation",
            "'additive' and 'thermal' use one Janus curvature for the whole lattice; a lattice "
            "with per-edge speeds needs actuation 'program'",
        )
    sec = fm.section(
        fm.material(lat.active_material),
        fm.material(lat.passive_material),
        lat.radius,
        lat.active_fraction,
    )
    e_par, e_perp, eps_p = fm.strains(lat.speeds[:1], fm.material(lat.passive_material))
    eps_c, kappa, _ = sec.natural_strains(0.0, e_par, e_perp, eps_p)
    return float(kappa[0, 0]), float(np.asarray(eps_c).reshape(-1)[0])


def _additive(lm: LatticeModel, curvature: float, stretch: float = 1.0) -> Model:
    # natural curvatures are per printed length (Model): a stretch changes rest lengths only
    k1, k2, _ = lm.printed
    b1, b2 = lm.side_basis
    rest = None if stretch == 1.0 else lm.model.network.edge_lengths * stretch
    return lm.model.with_natural(
        curvature1=k1 + lm.vertical(curvature * b1),
        curvature2=k2 + curvature * b2,
        rest_length=rest,
    )


@dataclass(frozen=True)
class AdditiveCurvature:
    """Reading (d): κ̄ = κ0 + x K_J toward the active side.

    Parameters
    ----------
    janus_curvature
        K_J (1/mm); default: the materials layer's Janus curvature at the lattice's print speed
        (0.59 mm⁻¹ at 3 mm/s with the calibrated modulus ratio).
    start, end
        Ramp of x (dimensionless).
    filament_model
        Materials modelling choices for the default K_J.
    """

    janus_curvature: float | None = None
    start: float = 0.0
    end: float = PAPER_FINAL_X
    filament_model: FilamentModel | None = None
    name: str = "additive"

    def __post_init__(self) -> None:
        _check_range("AdditiveCurvature", self.start, self.end)
        if self.janus_curvature is not None and not np.isfinite(self.janus_curvature):
            raise InvalidParameterError("AdditiveCurvature.janus_curvature", "must be finite")

    def curvature(self, lm: LatticeModel) -> float:
        """K_J used (1/mm)."""
        if self.janus_curvature is not None:
            return float(self.janus_curvature)
        fm = FilamentModel() if self.filament_model is None else self.filament_model
        return _janus_curvature(lm, fm)[0]

    def natural(self, lm: LatticeModel, parameter: float) -> Model:
        """Printed curvature plus x K_J toward the active side on rod vertices."""
        return _additive(lm, float(parameter) * self.curvature(lm))


@dataclass(frozen=True)
class ThermalActuation:
    """Physical mode: temperature (°C) → natural field from the materials layer.

    Parameters
    ----------
    start, end
        Temperature ramp (°C); the paper heats 25 → 150-175 °C.
    filament_model
        Materials modelling choices (strain model, modulus ratio, transition width).
    """

    start: float = 25.0
    end: float = 175.0
    filament_model: FilamentModel | None = None
    name: str = "thermal"

    def __post_init__(self) -> None:
        _check_range("ThermalActuation", self.start, self.end)

    def _fm(self) -> FilamentModel:
        return FilamentModel() if self.filament_model is None else self.filament_model

    def fraction(self, lm: LatticeModel, temperature: float) -> float:
        """Actuation fraction x(T) ∈ [0, 1] (dimensionless)."""
        fm = self._fm()
        return fm.fraction(fm.material(lm.lattice.active_material), temperature)

    def natural(self, lm: LatticeModel, parameter: float) -> Model:
        """Printed curvature plus x(T) K_J toward the active side, rest lengths × exp(x ε_c)."""
        fm = self._fm()
        x = self.fraction(lm, float(parameter))
        k_j, eps_c = _janus_curvature(lm, fm)
        strain = x * eps_c
        stretch = float(np.exp(strain)) if fm.strain_model.measure == "hencky" else 1.0 + strain
        return _additive(lm, x * k_j, stretch)


def _line_stencils(lm: LatticeModel) -> list[tuple[int, IntArray, IntArray, IntArray, IntArray]]:
    """Where each printed line's increments go in ``lm``'s model.

    Per line that has model edges: (line index, increment rows, their stencils, line edges,
    their model edges). Interior line vertex i (increment row i - 1) lands on the stencil
    joining the model edges of line edges i - 1 and i, when the model has both.
    """
    key = ("line_stencils", id(lm.model))
    cache = lm.lattice._cache
    if key not in cache:
        st = lm.model.stencils
        n_model = lm.model.network.n_edges
        segments = np.arange(n_model) if lm.segments is None else np.asarray(lm.segments)
        # network segment -> model edge (-1: not in the model)
        model_edge = -np.ones(lm.lattice.network.n_edges, dtype=np.int64)
        model_edge[segments] = np.arange(len(segments))
        # stencil of an unordered pair of model edges, looked up by a sorted integer key
        pair = np.sort(np.column_stack([st.edge_e, st.edge_f]).astype(np.int64), axis=1)
        pair_key = pair[:, 0] * n_model + pair[:, 1]
        order = np.argsort(pair_key, kind="stable")
        sorted_key = pair_key[order]
        out = []
        for line, (_, segs) in enumerate(lm.lattice.line_programs()):
            edges = model_edge[segs]
            a, b = edges[:-1], edges[1:]
            both = (a >= 0) & (b >= 0)
            query = np.minimum(a, b) * n_model + np.maximum(a, b)
            pos = np.searchsorted(sorted_key, query)
            found = both & (pos < len(sorted_key))
            found[found] = sorted_key[pos[found]] == query[found]
            here = np.flatnonzero(edges >= 0)
            if len(here):
                rows = np.flatnonzero(found)
                out.append((line, rows, order[pos[rows]], here, edges[here]))
        cache[key] = out
    return cache[key]  # type: ignore[no-any-return]


def _program_turns(a: Any, b: Any) -> int | None:
    """Quarter turns ``k`` about +z with which print program ``b`` is program ``a`` turned by
    ``k π/2`` and moved (to round-off), or None.

    The actuation increments of :func:`~rotomorph.materials.natural.actuation_increments` then
    follow: they depend on the points only through their differences, the nozzle angle only
    relative to the path's heading (the lab nozzle angle turns with the path), the first
    reference director is +z for a path in the plane, and the speeds and scalar settings are
    equal; so ``b``'s curvature vectors are ``a``'s turned by ``k π/2`` (exact in floating
    point: coordinates swapped and negated) and its eigen-twists and stretches are ``a``'s.
    Round-off is the 1e-12 relative tolerance (lines laid out at different offsets differ by a
    few 1e-16 of their extent).
    """
    if any(getattr(a, f) != getattr(b, f) for f in _PROGRAM_SCALARS):
        return None
    pa, pb = np.asarray(a.points, dtype=float), np.asarray(b.points, dtype=float)
    sa = np.asarray(a.speed, dtype=float)
    sb = np.asarray(b.speed, dtype=float)
    na = np.asarray(a.nozzle_angle, dtype=float)
    nb = np.asarray(b.nozzle_angle, dtype=float)
    if pa.shape != pb.shape or sa.shape != sb.shape or na.shape != nb.shape:
        return None
    if not np.allclose(sa, sb, rtol=1e-12, atol=1e-12):
        return None
    da, db = pa - pa[0], pb - pb[0]
    scale = 1.0 + float(np.abs(da).max(initial=0.0))
    for k in range(4):
        if not np.allclose(_turn(da, k), db, rtol=0.0, atol=1e-12 * scale):
            continue
        angle = 1.0 + float(np.abs(na).max(initial=0.0))
        if np.allclose(na + k * 0.5 * np.pi, nb, rtol=0.0, atol=1e-12 * angle):
            return k
    return None


def _turn(v: FloatArray, k: int) -> FloatArray:
    """Vectors ``(..., 3)`` turned by ``k`` quarter turns about +z (exact)."""
    x, y, z = v[..., 0], v[..., 1], v[..., 2]
    k %= 4
    if k == 0:
        return v
    if k == 1:
        return np.stack([-y, x, z], axis=-1)
    if k == 2:
        return np.stack([-x, -y, z], axis=-1)
    return np.stack([y, -x, z], axis=-1)


#: scalar fields of a print program that must match exactly for two lines to share increments
_PROGRAM_SCALARS = (
    "radius",
    "active_fraction",
    "active_material",
    "passive_material",
    "step_flips",
)


def _program_groups(lm: LatticeModel) -> list[tuple[int, int]]:
    """Per printed line, ``(rep, k)``: the first line whose print program it equals turned by
    ``k`` quarter turns about +z and moved (:func:`_program_turns`). The lines of a lattice
    repeat their program at a pitch and, from x- to y-lines, turned by a quarter turn, so the
    actuation increments of one program per group are computed per temperature."""
    key = ("program_groups",)
    cache = lm.lattice._cache
    if key not in cache:
        programs = [p for p, _ in lm.lattice.line_programs()]
        reps: list[int] = []
        out: list[tuple[int, int]] = []
        for line, prog in enumerate(programs):
            for rep in reps:
                turns = _program_turns(programs[rep], prog)
                if turns is not None:
                    out.append((rep, turns))
                    break
            else:
                reps.append(line)
                out.append((line, 0))
        cache[key] = out
    return cache[key]  # type: ignore[no-any-return]


class _Derived:
    """A print program whose attributes are computed once.

    Several attributes of :class:`~rotomorph.design.program.PrintProgram` (``rotation``,
    ``interface_angle``, ``director_rotation``, ``vertex_interface_normals``) are recomputed
    from its arrays on every access, about 4 ms per evaluation of a lattice line, and a ramp
    asks for them at every temperature. The program is a value, so each attribute is taken
    from it once, on first access (an absent one raises ``AttributeError`` as on the program,
    so ``getattr`` defaults still apply), and arrays are handed out as copies: the increments
    are bit for bit those of the program itself.
    """

    __slots__ = ("_memo", "_program")

    def __init__(self, program: Any) -> None:
        self._program = program
        self._memo: dict[str, Any] = {}

    def __getstate__(self) -> Any:
        return self._program

    def __setstate__(self, program: Any) -> None:
        self._program = program
        self._memo = {}

    def __getattr__(self, name: str) -> Any:
        if name in ("_memo", "_program") or name.startswith("__"):
            # unset slots (an instance being unpickled or copied) and protocol lookups
            raise AttributeError(name)
        memo = self._memo
        if name not in memo:
            memo[name] = getattr(self._program, name)
        value = memo[name]
        return value.copy() if isinstance(value, np.ndarray) else value


def _derived_programs(lm: LatticeModel) -> list[_Derived]:
    """:class:`_Derived` of every printed line (remembered with the lattice)."""
    key = ("derived_programs",)
    cache = lm.lattice._cache
    if key not in cache:
        cache[key] = [_Derived(p) for p, _ in lm.lattice.line_programs()]
    return cache[key]  # type: ignore[no-any-return]


@dataclass(frozen=True)
class ProgramActuation:
    """Default mode: each printed line's natural field from its print program at T (°C).

    Parameters
    ----------
    start, end
        Temperature ramp (°C); the paper heats 25 → 150-175 °C.
    filament_model
        Materials modelling choices (strain model, modulus ratio, transition).

    Notes
    -----
    The lines are those of :meth:`rotomorph.design.lattices.Lattice.line_programs` (one layer;
    every layer of a stack prints the same program one layer height up). With a stacked model
    (:attr:`~rotomorph.lattice.model.LatticeModel.stacked`) the increments are those of the
    fused stack's section under every layer's eigenstrain field
    (:func:`~rotomorph.materials.stack.stack_section`): the section stacked across the
    interface normal where it lies in the sheet, along it where it is the sheet normal (flip
    segments and vertices; in general along the sheet normal as seen in each vertex's
    interface frame). Their increments are the frame-free output of
    :func:`~rotomorph.materials.natural.actuation_increments`, read in the lattice model's
    frames with :func:`rotomorph.geometry.curvature_increment`, exactly as a single filament
    reads them in its own. Lines whose programs differ only by a translation and a quarter
    turn about +z (:func:`_program_turns`) share one evaluation per temperature.
    """

    start: float = 25.0
    end: float = 175.0
    filament_model: FilamentModel | None = None
    name: str = "program"

    def __post_init__(self) -> None:
        _check_range("ProgramActuation", self.start, self.end)

    def natural(self, lm: LatticeModel, parameter: float) -> Model:
        """Printed values plus every line's actuation increments at T = ``parameter``."""
        fm = FilamentModel() if self.filament_model is None else self.filament_model
        model = lm.model
        st = model.stencils
        vec = np.zeros((st.count, 3))
        twist = np.zeros(st.count)
        stretch = np.ones(model.network.n_edges)
        programs = _derived_programs(lm)
        groups = _program_groups(lm)
        increments: dict[int, _Increments] = {}  # one per distinct program
        for line, rows, stencils, line_edges, model_edges in _line_stencils(lm):
            rep, turns = groups[line]
            if rep not in increments:
                increments[rep] = _increments(lm, programs[rep], float(parameter), fm)
            curvature, tw_inc, st_inc = increments[rep]
            vec[stencils] = _turn(curvature[rows], turns)
            twist[stencils] = tw_inc[rows]
            stretch[model_edges] = st_inc[line_edges]
        x = model.network.nodes
        te = unit(x[st.nodes[:, 1]] - x[st.nodes[:, 0]])
        tf = unit(x[st.nodes[:, 2]] - x[st.nodes[:, 1]])
        m1 = np.asarray(model.directors)
        dk1, dk2 = curvature_increment(te, tf, m1[st.edge_e], m1[st.edge_f], vec)
        k1, k2, tw = lm.printed
        return model.with_natural(
            # a stacked model's increments are already the stack's (its fused section)
            curvature1=k1 + (dk1 if lm.stacked else lm.vertical(dk1)),
            curvature2=k2 + dk2,
            twist=tw + twist,
            rest_length=model.network.edge_lengths * stretch,
        )


_Increments = tuple[FloatArray, FloatArray, FloatArray]


def _increments(
    lm: LatticeModel, program: Any, temperature: float, fm: FilamentModel
) -> _Increments:
    """(curvature vectors, eigen-twists, stretches) of one printed line at ``temperature``:
    its own section's, or with a stacked model the fused stack's, stacked along the sheet
    normal at every vertex (:meth:`ProgramActuation.natural`)."""
    stack = (
        LayerStack(int(lm.lattice.layers), float(lm.lattice.layer_height)) if lm.stacked else None
    )
    inc = actuation_increments(program, temperature=temperature, model=fm, stack=stack)
    return inc.curvature, inc.twist, inc.stretch


def default_stiffness(
    actuation: Actuation, stiffness: Stiffness | None = None
) -> tuple[Stiffness, FilamentModel | None]:
    """Stiffness option and materials model a lattice is built with for ``actuation``.

    The physical modes (``program``, ``thermal``) use the Janus section of their own
    :class:`FilamentModel`, so stiffness and natural field come from one materials model; the
    paper's readings use its isotropic section. An explicit ``stiffness`` is kept.
    """
    fm = getattr(actuation, "filament_model", None)
    physical = isinstance(actuation, (ProgramActuation, ThermalActuation))
    chosen: Stiffness = stiffness or ("janus" if physical else "paper")
    return chosen, fm if chosen == "janus" else None


#: Actuations whose ramp parameter is the temperature (°C); the others ramp a number x.
TEMPERATURE_ACTUATIONS = ("thermal", "program")


def ramp_value_text(actuation: Actuation, value: float) -> str:
    """A ramp parameter with its unit, for messages: ``"131.2 °C"`` for the temperature-driven
    actuations (:data:`TEMPERATURE_ACTUATIONS`), ``"x = 0.35"`` for the others."""
    if actuation.name in TEMPERATURE_ACTUATIONS:
        return f"{value:.1f} °C"
    return f"x = {value:.4g}"


def get_actuation(actuation: str | Actuation) -> Actuation:
    """An actuation by name (module table) or the object itself.

    Raises
    ------
    InvalidParameterError
        Unknown name or an object without ``natural``/``start``/``end``.
    """
    if isinstance(actuation, str):
        if actuation in ("literal", "swapped", "radius"):
            return CurvatureScaling(actuation)  # type: ignore[arg-type]
        if actuation == "additive":
            return AdditiveCurvature()
        if actuation == "thermal":
            return ThermalActuation()
        if actuation == "program":
            return ProgramActuation()
        raise InvalidParameterError(
            "actuation", f"must be one of {ACTUATIONS} or an Actuation object; got {actuation!r}"
        )
    if not isinstance(actuation, Actuation):
        raise InvalidParameterError(
            "actuation", "must have name, start, end and natural(lattice_model, parameter)"
        )
    return actuation

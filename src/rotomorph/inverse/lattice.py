r"""Inverse design of a lattice: which edges expand and which contract so that it rises into a
target surface.

Design variables
----------------
One continuous variable :math:`c_e \in [-1, 1]` per lattice edge: :math:`+1` is an expanding
edge (active half on the outer side of the wave), :math:`-1` a contracting one (active half
inner). In between, the edge's natural values (integrated curvatures and twist of its own
stencils, rest lengths of its segments) are the linear blend of the two printable ones, which
is the continuous relaxation the gradient phase needs; the result is rounded to the printable
values :math:`\pm 1` and re-verified by a fresh forward solve. Junction stencils keep their
printed values in both modes.

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
is that of the residuals at the optimal alignment. The gradient with respect to :math:`c` comes
from one adjoint solve (:mod:`rotomorph.inverse.adjoint`), and SciPy's L-BFGS-B handles the box
:math:`[-1, 1]`. Every equilibrium is warm-started from the previous one; a design whose
equilibrium is not a stable minimum is rejected by the line search (its objective is
infinite).
"""

from __future__ import annotations

import itertools
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from scipy.interpolate import RectBivariateSpline
from scipy.optimize import least_squares, minimize
from scipy.spatial.transform import Rotation

from rotomorph._typing import FloatArray, IntArray
from rotomorph.analysis.curvature import fit_quadratic_surface
from rotomorph.design.lattices import Lattice, sinusoidal_lattice
from rotomorph.errors import ConvergenceError, InvalidDesignError, InvalidParameterError
from rotomorph.inverse.adjoint import NotAMinimumError, adjoint
from rotomorph.lattice.actuation import Actuation, get_actuation
from rotomorph.lattice.heating import perturbed_state, symmetry_breaking
from rotomorph.lattice.model import lattice_model
from rotomorph.rod.model import Model
from rotomorph.rod.state import State
from rotomorph.solve.continuation import continuation
from rotomorph.solve.newton import NewtonOptions
from rotomorph.solve.static import StaticResult, solve_static

__all__ = [
    "LatticeBlend",
    "LatticeDesign",
    "SurfaceTarget",
    "design_lattice",
    "dome",
    "height_map",
    "misfit_and_gradient",
    "saddle",
    "surface_misfit",
]

SOLVE_OPTIONS = NewtonOptions(rtol=1e-10, max_iterations=300)


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


# ---------------------------------------------------------------------------------- misfit
def _rigid(params: FloatArray, x: FloatArray) -> FloatArray:
    y = Rotation.from_rotvec(params[:3]).apply(x)
    y[:, 2] += params[3]
    return y


def surface_misfit(
    positions: FloatArray, target: SurfaceTarget, size: float
) -> tuple[float, FloatArray, FloatArray]:
    """Aligned misfit ``J``, its gradient ``(N, 3)`` w.r.t. ``positions`` (1/mm) and the
    alignment (rotation vector, vertical offset).

    The nodes are centred (their centroid goes to x = y = 0, where the target is centred),
    then rotated and moved vertically to minimise
    ``J = (sum_i r_i² + |reg·rotvec|²) / (2 N)`` with ``r_i = (z'_i − f(x'_i, y'_i)) / size``;
    the alignment starts from the centred state and from its upside-down copy. A tiny penalty
    on the rotation vector keeps the alignment unique when the target has a continuous
    symmetry (a dome turns freely about z). The gradient is exact at the optimal alignment
    (envelope theorem), including the centroid's dependence on every node.
    """
    x = np.asarray(positions, dtype=float)
    n = len(x)
    xc = x - x.mean(axis=0)
    reg = 1e-3

    def residuals(p: FloatArray, p0: FloatArray) -> FloatArray:
        y = _rigid(p, xc)
        z, _, _ = target.height(y[:, 0], y[:, 1])
        return np.concatenate([(y[:, 2] - z) / size, reg * (p[:3] - p0[:3])])

    best: tuple[Any, FloatArray] | None = None
    for flip in (0.0, np.pi):
        p0 = np.array([flip, 0.0, 0.0, 0.0])
        y0 = _rigid(p0, xc)
        z0, _, _ = target.height(y0[:, 0], y0[:, 1])
        p0[3] = float(np.mean(z0 - y0[:, 2]))
        sol = least_squares(
            residuals, p0, args=(p0,), xtol=1e-15, ftol=1e-15, gtol=1e-15, method="lm"
        )
        if best is None or sol.cost < best[0].cost:
            best = (sol, p0)
    assert best is not None
    sol, p0 = best
    p = sol.x
    y = _rigid(p, xc)
    z, zx, zy = target.height(y[:, 0], y[:, 1])
    r = (y[:, 2] - z) / size
    j = 0.5 * (float(r @ r) + float(np.sum((reg * (p[:3] - p0[:3])) ** 2))) / n
    dr_dy = np.stack([-zx, -zy, np.ones(n)], axis=1) / size
    rot = Rotation.from_rotvec(p[:3]).as_matrix()
    per_node = (r[:, None] * dr_dy) @ rot / n
    grad = per_node - per_node.mean(axis=0)
    return j, grad, p


# ---------------------------------------------------------------------------------- blend
def _integrated_factor(model: Model) -> FloatArray:
    ones = np.ones(model.stencils.count)
    return np.asarray(model.with_natural(curvature1=ones).integrated_natural()[0])


@dataclass(frozen=True, eq=False)
class LatticeBlend:
    """Natural values of a lattice as a function of per-edge design variables ``c``.

    Stencils inside one lattice edge depend on that edge's mode only: their natural values are
    the linear blend ``w+(c) K[+] + w-(c) K[-]`` with ``w±(c) = (1 ± c)/2`` of the values of the
    printable modes. Junction stencils couple two edges ``e, f`` (a printed line passing through
    a node, or a crossing) and may depend on both modes: their values are the bilinear blend of
    the four printable combinations. Rest lengths belong to one edge each.

    Attributes
    ----------
    lattice
        The printed geometry (its own pattern is irrelevant).
    model
        The printed rod model (zero actuation).
    printed
        Integrated natural values ``(S, 3)`` and rest lengths ``(E,)`` of the printed state.
    combos
        ``(S, 2, 2, 3)``: fully actuated integrated naturals of every stencil for its two edges'
        modes ``[mode of edge_a, mode of edge_b]`` (index 0 expanding, 1 contracting).
    rest
        ``(2, E)``: fully actuated rest lengths for each mode.
    stencil_edges
        ``(S, 2)`` lattice edges ``(a, b)`` of each stencil's two segments (equal inside an edge).
    segment_edge
        Lattice edge of every network segment ``(E,)``.
    """

    lattice: Lattice
    model: Model
    printed: tuple[FloatArray, FloatArray]
    combos: FloatArray
    rest: FloatArray
    stencil_edges: IntArray
    segment_edge: IntArray
    factor: FloatArray = field(repr=False)

    @property
    def n_edges(self) -> int:
        """Number of lattice edges (design variables)."""
        return len(self.lattice.edge_chains)

    def _weights(self, c: FloatArray) -> tuple[FloatArray, FloatArray]:
        c = np.asarray(c, dtype=float)
        ca, cb = c[self.stencil_edges[:, 0]], c[self.stencil_edges[:, 1]]
        wa = np.stack([0.5 * (1 + ca), 0.5 * (1 - ca)], axis=1)
        wb = np.stack([0.5 * (1 + cb), 0.5 * (1 - cb)], axis=1)
        return wa, wb

    def natural(self, c: FloatArray, t: float = 1.0) -> tuple[FloatArray, FloatArray]:
        """Integrated naturals ``(S, 3)`` and rest lengths ``(E,)`` at design ``c`` and ramp
        fraction ``t`` (0 = printed, 1 = fully actuated)."""
        wa, wb = self._weights(c)
        full = np.einsum("si,sj,sijk->sk", wa, wb, self.combos)
        k0, l0 = self.printed
        cs = np.asarray(c, dtype=float)[self.segment_edge]
        rest_full = 0.5 * (1 + cs) * self.rest[0] + 0.5 * (1 - cs) * self.rest[1]
        return k0 + t * (full - k0), l0 + t * (rest_full - l0)

    def gradient(
        self, c: FloatArray, products: FloatArray, rest_products: FloatArray
    ) -> FloatArray:
        """``d/dc`` of ``sum(products * naturals) + sum(rest_products * rest)`` at t = 1.

        ``products`` ``(S, 3)`` and ``rest_products`` ``(E,)`` are e.g. the adjoint products
        ``lambda^T dg/d(natural)`` of :func:`rotomorph.rod.sensitivity.natural_sensitivity`.
        """
        wa, wb = self._weights(c)
        dw = np.array([0.5, -0.5])
        da = np.einsum("i,sj,sijk->sk", dw, wb, self.combos)  # d(naturals)/dc_a
        db = np.einsum("si,j,sijk->sk", wa, dw, self.combos)  # d(naturals)/dc_b
        g = np.zeros(self.n_edges)
        np.add.at(g, self.stencil_edges[:, 0], np.sum(products * da, axis=1))
        np.add.at(g, self.stencil_edges[:, 1], np.sum(products * db, axis=1))
        np.add.at(g, self.segment_edge, rest_products * 0.5 * (self.rest[0] - self.rest[1]))
        return g

    def rod(self, c: FloatArray, t: float = 1.0) -> Model:
        """The rod model at design ``c`` and ramp fraction ``t``."""
        k, rest = self.natural(c, t)
        trial = self.model.with_natural(rest_length=rest)
        return trial.with_natural(
            curvature1=k[:, 0] / self.factor,
            curvature2=k[:, 1] / self.factor,
            twist=k[:, 2] / self.factor,
        )


def _values(model: Model) -> tuple[FloatArray, FloatArray]:
    k1, k2, tw = model.integrated_natural()
    return np.stack([k1, k2, tw], axis=1), np.array(model.rest_length, dtype=float)


def lattice_blend(
    lattice: Lattice, actuation: str | Actuation | None = None, *, seed: int = 0
) -> LatticeBlend:
    """Build the :class:`LatticeBlend` of ``lattice`` for an actuation mode (default: the
    package's default lattice actuation) at its full actuation.

    The four mode combinations of every junction stencil are read off fully actuated lattices
    of a few patterns (uniform ones, then random ones until every combination is seen); a
    combination seen in two patterns must give the same values, else the actuation is not
    local to the two edges and the blend refuses it.
    """
    act = get_actuation(actuation) if actuation is not None else _default_actuation()
    net = lattice.network
    seg_lookup = {}
    for j, (a, b) in enumerate(net.edges):
        seg_lookup[(int(min(a, b)), int(max(a, b)))] = j
    segment_edge = np.full(net.n_edges, -1, dtype=np.int64)
    for e, chain in enumerate(lattice.edge_chains):
        for a, b in itertools.pairwise(chain):
            segment_edge[seg_lookup[(int(min(a, b)), int(max(a, b)))]] = e
    base = lattice_model(lattice).model
    st = base.stencils
    pairs = np.stack([segment_edge[st.edge_e], segment_edge[st.edge_f]], axis=1)
    n_edges = len(lattice.edge_chains)
    combos = np.full((st.count, 2, 2, 3), np.nan)
    rest = np.full((2, net.n_edges), np.nan)
    printed = None
    rng = np.random.default_rng(seed)
    same = pairs[:, 0] == pairs[:, 1]
    patterns = [np.zeros(n_edges, dtype=int), np.ones(n_edges, dtype=int)]
    for _ in range(24):
        if patterns:
            modes = patterns.pop(0)
        elif not (np.isnan(combos[~same]).any() or np.isnan(rest).any()):
            break
        else:
            modes = rng.integers(0, 2, n_edges)
        lat = _with_pattern(
            lattice, {e: ("expanding", "contracting")[int(m)] for e, m in enumerate(modes)}
        )
        lm = lattice_model(lat)
        if printed is None:
            printed = _values(act.natural(lm, act.start))
        k, r = _values(act.natural(lm, act.end))
        ia, ib = modes[pairs[:, 0]], modes[pairs[:, 1]]
        seen = combos[np.arange(st.count), ia, ib]
        known = ~np.isnan(seen[:, 0])
        if np.any(np.abs(seen[known] - k[known]) > 1e-9 * (1 + np.abs(k[known]))):
            raise InvalidParameterError(
                "actuation",
                f"{act.name!r} is not local to the two edges of a junction; inverse design "
                "needs an actuation whose natural values depend on each edge's own mode",
            )
        combos[np.arange(st.count), ia, ib] = k
        rest[modes[segment_edge], np.arange(net.n_edges)] = r
    # inside one edge both modes move together: the off-diagonal combinations are the mean of
    # the diagonal ones, which makes the bilinear blend linear there (w+ + w- = 1)
    mean = 0.5 * (combos[same, 0, 0] + combos[same, 1, 1])
    combos[same, 0, 1] = mean
    combos[same, 1, 0] = mean
    if np.isnan(combos).any() or np.isnan(rest).any() or printed is None:
        raise InvalidParameterError("lattice", "could not sample every mode combination")
    printed_model = act.natural(lattice_model(lattice), act.start)
    return LatticeBlend(
        lattice=lattice,
        model=printed_model,
        printed=printed,
        combos=combos,
        rest=rest,
        stencil_edges=pairs,
        segment_edge=segment_edge,
        factor=_integrated_factor(printed_model),
    )


def _default_actuation() -> Actuation:
    from rotomorph.lattice import actuation as mod

    default = getattr(mod, "DEFAULT_ACTUATION", None)
    return get_actuation(default if default is not None else "swapped")


def _with_pattern(lattice: Lattice, pattern: Any) -> Lattice:
    return sinusoidal_lattice(
        n=lattice.n,
        spacing=lattice.spacing,
        amplitude=lattice.amplitude,
        ghost_nodes=lattice.ghost_nodes,
        pattern=pattern,
        layers=lattice.layers,
        layer_height=lattice.layer_height,
        speed=lattice.speed,
        radius=lattice.radius,
        active_fraction=lattice.active_fraction,
        active_material=lattice.active_material,
        passive_material=lattice.passive_material,
    )


# ---------------------------------------------------------------------------------- solve
def _is_minimum(model: Model, state: State) -> bool:
    """True when the equilibrium's Hessian (rigid modes aside) is positive semidefinite."""
    try:
        adjoint(model, state, np.zeros(model.layout.count))
    except NotAMinimumError:
        return False
    return True


class _Equilibria:
    """Forward solves with warm starts (continuation in the ramp from the flat state first).

    A ramp that ends on an unstable equilibrium (a flat state past its buckling point, kept
    by symmetry) is repeated from a larger out-of-plane perturbation, up to ``retries`` times.
    """

    def __init__(
        self, blend: LatticeBlend, seed: int = 0, perturbation: float = 1e-2, retries: int = 3
    ) -> None:
        self.blend = blend
        self.seed = seed
        self.perturbation = perturbation
        self.retries = retries
        self.last: tuple[FloatArray, State] | None = None
        self.solves = 0

    def _flat(self, scale: float) -> State:
        lat = self.blend.lattice
        dz = symmetry_breaking(lat, scale * self.perturbation * lat.spacing, self.seed)
        return perturbed_state(self.blend.model, dz)

    def _ramp(self, c: FloatArray) -> StaticResult:
        def solve(t: float, state: State) -> StaticResult:
            self.solves += 1
            return solve_static(self.blend.rod(c, t), initial=state, options=SOLVE_OPTIONS)

        path = continuation(solve, np.linspace(0.1, 1.0, 10), self._flat(1.0), start=0.0)
        res = path.results[-1]
        model = self.blend.rod(c)
        lat = self.blend.lattice
        for k in range(self.retries):
            if _is_minimum(model, res.state):
                break
            # a symmetric state past its buckling point: kick it out of plane and re-solve
            kick = symmetry_breaking(lat, 5.0**k * self.perturbation * lat.spacing, self.seed + k)
            start = perturbed_state(model, res.positions - lat.network.nodes)
            start = perturbed_state(
                model, start.positions - lat.network.nodes + kick[:, None] * [0.0, 0.0, 1.0]
            )
            self.solves += 1
            res = solve_static(model, initial=start, options=SOLVE_OPTIONS)
        return res

    def __call__(self, c: FloatArray) -> StaticResult:
        c = np.asarray(c, dtype=float).copy()
        if self.last is not None:
            c_prev, state = self.last
            try:
                self.solves += 1
                res = solve_static(self.blend.rod(c), initial=state, options=SOLVE_OPTIONS)
            except ConvergenceError:
                res = self._between(c_prev, c, state)
        else:
            res = self._ramp(c)
        self.last = (c, res.state)
        return res

    def _between(self, c0: FloatArray, c1: FloatArray, state: State) -> StaticResult:
        def solve(u: float, st: State) -> StaticResult:
            self.solves += 1
            c = (1 - u) * c0 + u * c1
            return solve_static(self.blend.rod(c), initial=st, options=SOLVE_OPTIONS)

        path = continuation(solve, np.linspace(0.25, 1.0, 4), state, start=0.0)
        return path.results[-1]


@dataclass(frozen=True, eq=False)
class LatticeDesign:
    """Result of :func:`design_lattice`.

    Attributes
    ----------
    lattice
        The designed, printable lattice (each edge ``expanding`` or ``contracting``).
    relaxed
        Continuous design ``(E,)`` at the end of the gradient phase.
    modes
        Printable design ``(E,)`` of ±1 after rounding.
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
    """

    lattice: Lattice
    relaxed: FloatArray
    modes: FloatArray
    positions: FloatArray
    target: SurfaceTarget
    objective_history: FloatArray
    misfit_rms: float
    misfit_rel: float
    achieved_gaussian_curvature: float
    target_gaussian_curvature: float | None
    stable: bool
    iterations: int
    solves: int

    @property
    def pattern(self) -> dict[int, str]:
        """Edge index → ``"expanding"`` / ``"contracting"``."""
        return {int(e): ("expanding" if m > 0 else "contracting") for e, m in enumerate(self.modes)}


def misfit_and_gradient(
    blend: LatticeBlend,
    c: FloatArray,
    result: StaticResult,
    target: SurfaceTarget,
    size: float,
    nodes: IntArray | None = None,
) -> tuple[float, FloatArray]:
    """Aligned misfit ``J`` of the equilibrium ``result`` of design ``c`` and ``dJ/dc`` ``(E,)``.

    One adjoint solve at the equilibrium (:func:`rotomorph.inverse.adjoint.adjoint`), whatever
    the number of edges; ``nodes`` (default all) are the nodes compared with the target.

    Raises
    ------
    NotAMinimumError
        The equilibrium is not a stable minimum.
    """
    picked = np.arange(len(result.positions)) if nodes is None else np.asarray(nodes)
    j, gsel, _ = surface_misfit(result.positions[picked], target, size)
    gx = np.zeros_like(result.positions)
    gx[picked] = gsel
    model = blend.rod(c)
    lay = model.layout
    dj_dx = np.zeros(lay.count)
    dj_dx[(lay.pos[:, None] + np.arange(3)).ravel()] = gx.ravel()
    s = adjoint(model, result.state, dj_dx).sensitivity
    prod = np.stack([s.curvature1, s.curvature2, s.twist], axis=1)
    return j, -blend.gradient(c, prod, s.rest_length)


def _check_target(lattice: Lattice, target: SurfaceTarget) -> None:
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


def design_lattice(
    lattice: Lattice,
    target: SurfaceTarget,
    *,
    actuation: str | Actuation | None = None,
    initial: FloatArray | None = None,
    printability: float = 1e-6,
    max_iterations: int = 30,
    seed: int = 0,
    nodes: Literal["branch", "all"] = "branch",
    callback: Callable[[int, float], None] | None = None,
) -> LatticeDesign:
    """Choose per-edge expanding/contracting modes that make ``lattice`` rise into ``target``.

    Parameters
    ----------
    lattice
        The printed geometry (size, spacing, amplitude; its pattern is only a starting guess).
    target
        :func:`dome`, :func:`saddle` or :func:`height_map`.
    actuation
        Lattice actuation mode (default: the package's default).
    initial
        Starting relaxed design ``(E,)`` in [−1, 1]; default from ``lattice``'s own pattern.
    printability
        Weight β of the term favouring printable values ±1 (dimensionless).
    max_iterations
        L-BFGS-B iterations.
    seed
        Seed of the symmetry-breaking perturbation of the first solve.
    nodes
        Nodes compared with the target: ``"branch"`` (default: the junctions, which span the
        lattice's surface; the sinusoidal edges wiggle about it by design) or ``"all"``.
    callback
        ``callback(iteration, objective)`` after each optimiser iteration (progress bars).

    Raises
    ------
    InvalidDesignError
        A target the lattice cannot reach (height map outside the lattice or too high,
        curvature that would close the lattice on itself).
    """
    _check_target(lattice, target)
    if not (np.isfinite(printability) and printability >= 0):
        raise InvalidParameterError("printability", f"must be >= 0; got {printability}")
    blend = lattice_blend(lattice, actuation)
    size = lattice.spacing * (lattice.n - 1)
    eq = _Equilibria(blend, seed=seed)
    if initial is None:
        c0 = np.array([1.0 if m == "expanding" else -1.0 for m in lattice.edge_mode]) * 0.9
    else:
        c0 = np.clip(np.asarray(initial, dtype=float), -1, 1)
    history: list[float] = []
    n_edges = blend.n_edges
    picked = (
        np.asarray(lattice.branch_indices)
        if nodes == "branch"
        else np.arange(lattice.network.n_nodes)
    )
    weight = [printability]

    def fun(c: FloatArray) -> tuple[float, FloatArray]:
        try:
            res = eq(c)
        except ConvergenceError:
            return np.inf, np.zeros_like(c)
        try:
            j, grad = misfit_and_gradient(blend, c, res, target, size, picked)
        except NotAMinimumError:
            return np.inf, np.zeros_like(c)
        j += weight[0] * float(np.sum(1.0 - c * c))
        grad += weight[0] * (-2.0 * c)
        history.append(j)
        return j, grad

    it = [0]

    def cb(xk: FloatArray) -> None:
        it[0] += 1
        if callback is not None:
            callback(it[0], history[-1] if history else float("nan"))

    # continuation in the printability weight: a free relaxed optimum first, then the weight
    # raised tenfold twice so that the design is pushed to printable values before rounding
    c = c0
    nit = 0
    weights = (printability, 10.0 * printability, 100.0 * printability)
    for k, beta in enumerate(weights):
        weight[0] = beta
        opt = minimize(
            fun,
            c,
            jac=True,
            method="L-BFGS-B",
            bounds=[(-1.0, 1.0)] * n_edges,
            options={
                "maxiter": max_iterations if k == 0 else max(2, max_iterations // 3),
                "ftol": 1e-12,
                "gtol": 1e-10,
            },
            callback=cb,
        )
        c = opt.x
        nit += int(opt.nit)
    relaxed = np.clip(c, -1, 1)

    def verified(design: FloatArray) -> tuple[float, StaticResult]:
        """Misfit of a printable design after a fresh ramp, as the forward simulation runs it."""
        res = _Equilibria(blend, seed=seed)(design)
        stable_here = _is_minimum(blend.rod(design), res.state)
        value = surface_misfit(res.positions[picked], target, size)[0]
        return (value if stable_here else np.inf), res

    # rounding: the rounded optimum and the starting pattern, then single-edge flips while
    # they lower the warm-started misfit (a discrete refinement of the printable design)
    candidates = [np.where(relaxed >= 0, 1.0, -1.0), np.where(c0 >= 0, 1.0, -1.0)]
    scored = [(verified(m), m) for m in candidates]
    (best_j, best_res), modes = min(scored, key=lambda t: t[0][0])
    local = _Equilibria(blend, seed=seed)
    local.last = (modes, best_res.state)
    for e in np.argsort(np.abs(relaxed)):  # least decided edges first
        trial = modes.copy()
        trial[e] = -trial[e]
        try:
            res = local(trial)
        except ConvergenceError:
            local.last = (modes, best_res.state)
            continue
        value = surface_misfit(res.positions[picked], target, size)[0]
        if value < best_j and _is_minimum(blend.rod(trial), res.state):
            modes, best_j, best_res = trial, value, res
        else:
            local.last = (modes, best_res.state)
    printed = _with_pattern(
        lattice, {e: ("expanding" if m > 0 else "contracting") for e, m in enumerate(modes)}
    )
    # verification as the forward simulation does it: a fresh ramp from the flat printed state
    verify = _Equilibria(blend, seed=seed)
    final = verify(modes)
    j, _, _ = surface_misfit(final.positions[picked], target, size)
    rms = float(np.sqrt(2.0 * j)) * size
    stable = _is_minimum(blend.rod(modes), final.state)
    branch = final.positions[lattice.branch_indices]
    fit = fit_quadratic_surface(branch)
    return LatticeDesign(
        lattice=printed,
        relaxed=relaxed,
        modes=modes,
        positions=final.positions,
        target=target,
        objective_history=np.array(history),
        misfit_rms=rms,
        misfit_rel=rms / size,
        achieved_gaussian_curvature=float(fit.gaussian_curvature),
        target_gaussian_curvature=target.gaussian_curvature,
        stable=stable,
        iterations=nit,
        solves=eq.solves + verify.solves + local.solves,
    )

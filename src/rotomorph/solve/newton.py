"""A modified-Newton minimiser with an energy line search, written against an objective.

The solver knows nothing about rods: an :class:`Objective` supplies energy, gradient and
Hessian as functions of a flat vector, a way to solve with a shifted Hessian, a retraction
(how a step is applied) and an ``accept`` hook (rods re-base their frames there). The loop is
the classical one (Nocedal & Wright, *Numerical Optimization*, 2nd ed., Alg. 3.2 with the
"Cholesky with added multiple of the identity" of §3.4, here a diagonal metric ``M``):

1. factor ``H + tau M``, raising ``tau`` until positive definite (so the step is a descent
   direction and saddle points repel), lowering it again after good steps;
2. backtracking Armijo line search on the energy (the merit function); a whole step that
   creeps (see below) is extended along its own direction while the energy keeps falling;
3. stop when the weighted gradient norm is below ``rtol`` times the force scale (a pure Newton
   step whose decrement is below ``decrement_tol`` times the energy scale is taken whole, without
   a line search, but the residual test still decides);
4. certify the exit point (:mod:`rotomorph.solve.spectrum`): the Hessian on the free DOFs with
   rigid modes removed must be positive definite. At a saddle (e.g. a straight column above its
   Euler load, where the gradient vanishes by symmetry) the solver steps along the direction of
   negative curvature with a second-order Armijo test (Moré & Sorensen, *Math. Programming* 16,
   1979) and continues; the same happens when the iteration stalls (no decrease) on an
   indefinite Hessian. An equilibrium that stays unstable ends with ``Status.SADDLE``.

Creeping: near a bifurcation the shift (or the convex Hessian) that makes an indefinite
Hessian positive definite also masks its direction of negative curvature; whole steps then
slide off the saddle along it by a few per cent per iteration, the residual never falling
(hundreds of iterations). After ``creep_steps`` such steps each further whole step is tried
at 2, 4 and 8 times its length (:data:`MAX_EXTENSION`; within the objective's step bound)
while the energy keeps falling with the Armijo condition: the ray the creep follows, covered up
to 8 times faster. (Longer extensions, or leaving the saddle along its negative mode at the
first creep, can carry a nearly neutral body much further: a free filament across two rods
slid off them.)

"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from typing import Any, Literal, Protocol, overload

import numpy as np

from rotomorph._typing import FloatArray
from rotomorph.errors import InvalidParameterError
from rotomorph.solve.linalg import diagonal, factorize, matvec
from rotomorph.solve.result import NewtonResult, Status
from rotomorph.solve.spectrum import Spectrum, analyse_hessian

log = logging.getLogger(__name__)


class Objective(Protocol):
    """What :func:`minimize` needs from a problem."""

    # asked for (need_grad=True), the gradient is never None
    @overload
    def evaluate(
        self, x: FloatArray, need_grad: Literal[True], need_hess: int
    ) -> tuple[float, FloatArray, Any]: ...

    @overload
    def evaluate(
        self, x: FloatArray, need_grad: bool, need_hess: int
    ) -> tuple[float, FloatArray | None, Any]: ...

    def evaluate(
        self, x: FloatArray, need_grad: bool, need_hess: int
    ) -> tuple[float, FloatArray | None, Any]:
        """Energy, gradient (or None) and Hessian (or None) at ``x`` relative to the base.

        ``need_hess``: 0 none, 1 exact, 2 the convex approximation of ``convex_hessian`` (an
        objective without one returns the exact Hessian for any non-zero value).
        """

    def metric(self) -> FloatArray:
        """Positive diagonal metric ``M`` for the modified-Newton shift."""

    def weights(self) -> FloatArray:
        """Positive weights making the gradient norm dimensionally consistent."""

    def retract(self, x: FloatArray, d: FloatArray, alpha: float) -> FloatArray:
        """The point reached from ``x`` by the step ``alpha * d``."""

    def accept(self, x: FloatArray) -> None:
        """Called with every accepted iterate (re-base frames, etc.)."""

    def project(self, d: FloatArray) -> FloatArray:
        """Remove exact zero-energy directions (e.g. free rigid motions) from a step."""

    def max_step(self, x: FloatArray, d: FloatArray) -> float:
        """Largest step fraction worth trying along ``d`` (1 when unlimited)."""

    def shift_floor(self, g: FloatArray) -> float:
        """Smallest shift for the end-game definiteness test (0 when not needed)."""

    def convex_hessian(self, x: FloatArray) -> Any:
        """A positive semidefinite Hessian approximation at ``x``, or None if there is none."""

    def curvature_step_scale(self, x: FloatArray, v: FloatArray) -> float:
        """Physical length to give a unit negative-curvature direction (0: use the step's)."""

    force_scale: float
    energy_scale: float
    has_convex_hessian: bool


@dataclass(frozen=True)
class NewtonOptions:
    """Settings of :func:`minimize`.

    Parameters
    ----------
    max_iterations
        Newton iterations allowed; reaching it is reported, never called convergence.
    rtol
        Weighted gradient norm relative to the force scale at which to stop; never below the
        round-off floor the objective estimates (``residual_floor()``, e.g. a nearly
        inextensible rod far from the origin), which the result reports.
    decrement_tol
        Newton decrement ``-g.d / 2`` relative to the energy scale at which to stop.
    armijo
        Sufficient-decrease constant of the line search.
    max_backtracks
        Halvings allowed in one line search before the shift is raised.
    curvature_iterations
        Inverse iterations used to find a direction of negative curvature when the Hessian is
        indefinite (0 disables it).
    curvature_shift
        Relative shift above which the Hessian counts as indefinite for that search.
    endgame
        Residual below which free bodies get the rigid-rotation shift floor (see the loop).
    check_stability
        Certify every exit point a minimum and leave saddles (see the module docstring).
    eigenvalues
        Lowest Hessian eigenvalues to report at the exit point (0: the verdict only).
    keep_modes
        Keep the eigenvectors of those eigenvalues in the result.
    stability_tol
        Eigenvalues above ``-stability_tol`` times the Hessian's diagonal scale count as
        neutral (stable).
    saddle_escapes
        Steps along negative curvature allowed before an unstable exit is reported as
        ``Status.SADDLE``.
    creep_steps
        Consecutive whole steps on an indefinite Hessian, below the ``endgame`` residual, that
        do not lower the residual by a tenth, after which whole steps are extended along
        their direction (see the module docstring; 0 disables it).
    """

    max_iterations: int = 200
    rtol: float = 1e-9
    decrement_tol: float = 1e-16
    armijo: float = 1e-4
    max_backtracks: int = 40
    curvature_iterations: int = 6
    endgame: float = 1e-3
    curvature_shift: float = 1e-9
    check_stability: bool = True
    eigenvalues: int = 3
    keep_modes: bool = False
    stability_tol: float = 1e-12
    saddle_escapes: int = 10
    creep_steps: int = 5

    def __post_init__(self) -> None:
        if self.max_iterations < 1:
            raise InvalidParameterError("NewtonOptions.max_iterations", "must be >= 1")
        for name in ("rtol", "decrement_tol", "armijo"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v > 0):
                raise InvalidParameterError(f"NewtonOptions.{name}", f"must be > 0; got {v}")
        for name in ("eigenvalues", "saddle_escapes", "creep_steps"):
            v = getattr(self, name)
            if int(v) != v or v < 0:
                raise InvalidParameterError(
                    f"NewtonOptions.{name}", f"must be an integer >= 0; got {v}"
                )
        if not (np.isfinite(self.stability_tol) and self.stability_tol >= 0):
            raise InvalidParameterError(
                "NewtonOptions.stability_tol", f"must be >= 0; got {self.stability_tol}"
            )


def minimize(obj: Objective, x0: FloatArray, options: NewtonOptions | None = None) -> NewtonResult:
    """Minimise ``obj`` from ``x0`` by modified Newton with a line search.

    Returns a :class:`NewtonResult`; the caller decides whether a non-converged status is an
    error (the static rod solver raises :class:`rotomorph.errors.ConvergenceError`).
    """
    opt = options or NewtonOptions()
    x = np.array(x0, dtype=float)
    log.debug("newton: start, %d unknowns", len(x))
    f, g, H = obj.evaluate(x, True, True)
    M = obj.metric()
    w = obj.weights()
    fscale = max(float(_norm(w * g)), obj.force_scale, 1e-300)
    escale = max(obj.energy_scale, abs(f), 1e-300)
    diag = diagonal(H)
    tau_unit = max(float(np.max(np.abs(diag) / M)) if diag.size else 1.0, 1e-300)
    tau_min = 1e-14 * tau_unit
    tau = 0.0
    first_try_ok = True
    convex = obj.has_convex_hessian
    skip_exact = 0
    backoff = 0
    history: list[tuple[float, float, float, float]] = []
    n_fact = 0
    dec = np.inf
    status = Status.MAX_ITERATIONS
    it = 0
    exact = True  # H is the exact Hessian at x (not the convex approximation)
    spec: Spectrum | None = None
    escapes = 0
    stall = False  # a null step on an indefinite Hessian: check for a saddle at the top
    stall_checked = False  # ... once until the next escape
    floor_steps = 0  # whole Newton steps that did not lower the residual
    creep = 0  # whole steps on an indefinite Hessian that did not lower the residual
    while it < opt.max_iterations:
        res = float(_norm(w * g)) / fscale
        if not np.isfinite(f) or not np.isfinite(res):
            status = Status.NOT_FINITE
            break
        rtol = max(opt.rtol, _residual_floor(obj) / fscale)
        if res <= rtol and not opt.check_stability:
            status = Status.CONVERGED
            break
        if res <= rtol or stall:
            # 4) certify the exit point; leave a saddle along its negative curvature
            stall = False
            if not exact:
                f, g, H = obj.evaluate(x, True, 1)
                exact = True
            spec = _certify(obj, H, opt)
            n_fact += spec.factorizations
            if spec.stable:
                if res <= rtol:
                    status = Status.CONVERGED
                    break
                stall_checked = True
            else:
                mode = spec.negative_mode()
                moved = None
                if mode is not None and escapes < opt.saddle_escapes:
                    moved = _leave_saddle(obj, x, f, g, mode, spec.lowest, opt.armijo)
                if moved is None:
                    status = Status.SADDLE
                    break
                escapes += 1
                it += 1
                x = moved
                obj.accept(x)
                f, g, H = obj.evaluate(x, True, 1)
                exact, spec, stall_checked = True, None, False
                tau, skip_exact, backoff, first_try_ok = 0.0, 0, 0, True
                history.append((f, float(_norm(w * g)) / fscale, 1.0, 0.0))
                continue
        it += 1
        # 1) Newton with the exact Hessian (a tiny shift covers free rigid-body modes); after
        #    the exact Hessian was found indefinite, it is retried only after 1, 2, 4, ...
        #    iterations (backoff), so an indefinite phase costs no failed factorizations
        pure = skip_exact == 0
        # rotating an unbalanced free body costs work of order |g|: in the end-game a shift of
        # that order (Levenberg–Marquardt with mu ~ |g|, which keeps quadratic convergence)
        # stops those rigid directions from failing the definiteness test (they are projected
        # out anyway); far from equilibrium the Gauss–Newton path is the better one
        floor = tau_min
        if res < opt.endgame:
            floor = max(floor, obj.shift_floor(g))
        shift = floor
        if pure:
            n_fact += 1
            fac = factorize(H, floor * M)
            d = None if fac is None else fac.solve(-g)
            if d is None or not np.all(np.isfinite(d)):
                pure, d = False, None
                backoff = min(2 * backoff, 8) if backoff else 1
                skip_exact = backoff
            else:
                backoff = 0
            Hc = obj.convex_hessian(x) if (d is None and convex) else H
        else:
            d = None
            skip_exact -= 1
            Hc = H  # evaluated in convex mode (see the end of the loop)
        if d is None:
            # 2) indefinite: the objective's convex (Gauss–Newton) Hessian if it has one,
            #    else the exact one; then the smallest uniform shift that makes it positive
            #    definite, warm-started and relaxed only after a first try succeeded
            if first_try_ok:
                tau = tau_min if tau <= 1e3 * tau_min else tau / 10.0
            tau = max(tau, floor)
            first_try_ok = True
            while True:
                n_fact += 1
                fac = factorize(Hc, tau * M)
                d = None if fac is None else fac.solve(-g)
                if d is not None and np.all(np.isfinite(d)):
                    break
                first_try_ok = False
                tau = max(10.0 * tau, 1e-8 * tau_unit)
                if tau > 1e12 * tau_unit:
                    status = Status.NOT_FINITE
                    return _result(x, status, it, n_fact, f, res, dec, history)
            shift = tau
            if not convex and tau > opt.curvature_shift * tau_unit:
                v = _negative_curvature_direction(fac, H, M, g, tau, opt.curvature_iterations)
                if v is not None:
                    d = d + _scale_curvature_step(obj, x, v, d, M)
        d = obj.project(d)
        slope = _dot(g, d)
        dec = -0.5 * slope / escale
        if dec <= opt.decrement_tol and res <= 1e3 * rtol:
            if pure:
                # the energy is flat to round-off: take the whole step without a line search;
                # only the residual test at the top may accept the point
                x = obj.retract(x, d, min(1.0, obj.max_step(x, d)))
                obj.accept(x)
                f, g, H = obj.evaluate(x, True, 1)
                exact = True
                new = float(_norm(w * g)) / fscale
                history.append((f, new, 1.0, shift))
                floor_steps = floor_steps + 1 if new >= 0.5 * res else 0
                if floor_steps >= 3 and new > rtol:
                    status, res = Status.STALLED, new
                    break
                continue
            if opt.check_stability and not stall_checked:
                stall = True  # no decrease left on an indefinite Hessian: a saddle?
                continue
        alpha = min(1.0, obj.max_step(x, d))
        accepted = False
        # largest change of an unknown along the step (mm or rad): a nearly singular direction
        # (a free body's fall onto a floor it does not touch yet) makes the shifted step huge,
        # and the step bound's fraction of it tiny although it moves the body by a gap
        reach = float(np.max(np.abs(d), initial=0.0))
        for _ in range(opt.max_backtracks):
            if alpha < 1e-10 and alpha * reach < 1e-8:  # a step this short changes nothing
                break
            xt = obj.retract(x, d, alpha)
            ft = obj.evaluate(xt, False, False)[0]
            if np.isfinite(ft) and ft <= f + opt.armijo * alpha * slope:
                accepted = True
                break
            # halve (as IPC's line search does): a quadratic fitted through a trial that a
            # contact barrier has made steep predicts a minimum far too short (it cut steps
            # to a tenth, so a pair closing in closed only a tenth of its gap per iteration)
            alpha *= 0.5
        if not accepted:
            if tau < 1e10 * tau_unit:
                # retry through the shifted path with a larger shift (on the convex Hessian
                # where the objective has one)
                tau = max(100.0 * tau, 1e-6 * tau_unit)
                first_try_ok = False
                if skip_exact == 0:
                    skip_exact = 1
                    if convex:
                        H = obj.convex_hessian(x)
                        exact = False
                history.append((f, res, 0.0, tau))
                continue
            status = Status.LINE_SEARCH_FAILED
            break
        if opt.creep_steps and creep >= opt.creep_steps and alpha == 1.0 and not pure:
            alpha, xt = _extend(obj, x, d, f, slope, xt, ft, opt.armijo)
        x = xt
        floor_steps = 0
        obj.accept(x)
        # exact Hessian (mode 1) unless the backoff asks for the convex one next (mode 2)
        exact = skip_exact == 0 or not convex
        f, g, H = obj.evaluate(x, True, 1 if exact else 2)
        new = float(_norm(w * g)) / fscale
        history.append((f, new, alpha, shift))
        slid = not pure and alpha >= 1.0 and res < opt.endgame and new >= 0.9 * res
        creep = creep + 1 if slid else 0
        log.debug(
            "newton %d: E=%.6e res=%.3e alpha=%.3g shift=%.3g", it, f, history[-1][1], alpha, shift
        )
    res = float(_norm(w * g)) / fscale
    floor = _residual_floor(obj) / fscale
    return _result(x, status, it, n_fact, f, res, dec, history, spec, escapes, floor)


#: Longest extension of a creeping whole step (a factor of 2 per energy evaluation)
MAX_EXTENSION = 8.0


def _extend(obj, x, d, f, slope, xt, ft, armijo):  # type: ignore[no-untyped-def]
    """The whole step ``d`` (point ``xt``, energy ``ft``) doubled while the doubled step stays
    within the objective's step bound, keeps the Armijo condition and lowers the energy
    further; returns the step fraction reached and its point."""
    alpha = 1.0
    while 2.0 * alpha <= MAX_EXTENSION:
        a = 2.0 * alpha
        if obj.max_step(x, a * d) < 1.0:
            break
        xa = obj.retract(x, d, a)
        fa = obj.evaluate(xa, False, False)[0]
        if not (np.isfinite(fa) and fa < ft and fa <= f + armijo * a * slope):
            break
        alpha, xt, ft = a, xa, fa
    return alpha, xt


def _residual_floor(obj: Objective) -> float:
    """The objective's estimate of the gradient's round-off floor (0 when it has none)."""
    floor = getattr(obj, "residual_floor", None)
    return 0.0 if floor is None else float(floor())


def _certify(obj: Objective, H: Any, opt: NewtonOptions) -> Spectrum:
    """Stability of the current iterate (the objective's base) from its exact Hessian ``H``."""
    rigid = getattr(obj, "rigid_modes", None)
    return analyse_hessian(
        H,
        obj.metric(),
        None if rigid is None else rigid(),
        count=opt.eigenvalues,
        modes=opt.keep_modes,
        tol=opt.stability_tol,
    )


def _leave_saddle(obj, x, f, g, v, lam, armijo):  # type: ignore[no-untyped-def]
    """A point of lower energy along ``+-v`` (unit M-norm, curvature ``lam < 0``), or None.

    The step starts at the objective's physical curvature step (a rod turns its most-turned
    edge by 0.2 rad) and is halved until the second-order Armijo condition
    ``f(x + a v) <= f + armijo (a g.v + a^2 lam / 2)`` holds. Both signs are tried; the lower
    energy wins, ``+v`` on a tie (the sign of ``v`` is normalised, so this is reproducible).
    """
    a = obj.curvature_step_scale(x, v)
    a = a if a > 0 else 1.0
    gv = _dot(g, v)
    for _ in range(30):
        best = None
        for sgn in (1.0, -1.0):
            # never beyond the objective's step bound (e.g. contact's collision-free step)
            d = sgn * a * v
            xt = obj.retract(x, d, min(1.0, obj.max_step(x, d)))
            ft = obj.evaluate(xt, False, False)[0]
            bound = f + armijo * (sgn * a * gv + 0.5 * a * a * lam)
            if np.isfinite(ft) and ft <= bound and (best is None or ft < best[1]):
                best = (xt, ft)
        if best is not None:
            return best[0]
        a *= 0.5
    return None


def _dot(a: FloatArray, b: FloatArray) -> float:
    """Inner product without BLAS (whose thread start-up dominates at these sizes)."""
    return float(np.einsum("i,i->", a, b))


def _norm(a: FloatArray) -> float:
    return float(np.sqrt(_dot(a, a)))


def _negative_curvature_direction(fac, H, M, g, tau, iterations):  # type: ignore[no-untyped-def]
    """A unit (M-norm) direction of negative curvature pointing downhill, or None.

    Inverse iteration with the shifted factor ``(H + tau M)^-1 M`` converges to the
    eigenvector of ``H v = lambda M v`` with the most negative ``lambda`` (the factor is
    positive definite, so ``lambda + tau > 0``). Adding it to the modified-Newton step moves
    off saddle points (e.g. a straight, twisted rod that should coil) instead of creeping
    along them (Moré & Sorensen, Math. Programming 16, 1979). The start vector is fixed, so
    the result is reproducible.
    """
    if iterations <= 0:
        return None
    n = len(g)
    v = np.cos(np.arange(n) * 2.399963229728653)  # deterministic, broadband start
    for _ in range(iterations):
        v = fac.solve(M * v)
        nv = np.sqrt(_dot(v, M * v))
        if not np.isfinite(nv) or nv == 0:
            return None
        v /= nv
    lam = _dot(v, matvec(H, v))
    if not lam < -0.1 * tau:
        return None
    return -v if _dot(g, v) > 0 else v


def _scale_curvature_step(obj, x, v, d, M):  # type: ignore[no-untyped-def]
    """Scale ``v`` to the larger of the step's M-norm and a physical move (objective-defined)."""
    scale = max(np.sqrt(_dot(d, M * d)), obj.curvature_step_scale(x, v))
    return scale * v


def _result(
    x, status, it, n_fact, f, res, dec, history, spec=None, escapes=0, floor=0.0
) -> NewtonResult:  # type: ignore[no-untyped-def]
    certified = spec is not None and status is Status.CONVERGED
    return NewtonResult(
        residual_floor=float(floor),
        stable=spec.stable if certified else None,  # type: ignore[union-attr]
        eigenvalues=spec.eigenvalues if certified else np.zeros(0),  # type: ignore[union-attr]
        modes=spec.modes if certified else None,  # type: ignore[union-attr]
        escapes=escapes,
        x=x,
        status=status,
        iterations=it,
        factorizations=n_fact,
        energy=float(f),
        residual=float(res),
        decrement=float(dec),
        history=np.array(history, dtype=float).reshape(-1, 4),
    )


class FunctionObjective:
    """Adapter for plain callables ``fun(x)``, ``jac(x)``, ``hess(x)`` (dense), e.g. SciPy's
    ``rosen``, ``rosen_der``, ``rosen_hess``; chord retraction, identity metric."""

    def __init__(self, fun, jac, hess, force_scale: float = 1.0, energy_scale: float = 1.0):  # type: ignore[no-untyped-def]
        self.fun, self.jac, self.hess = fun, jac, hess
        self.force_scale = force_scale
        self.energy_scale = energy_scale
        self.has_convex_hessian = False
        self._n: int | None = None

    def evaluate(self, x, need_grad, need_hess):  # type: ignore[no-untyped-def]
        self._n = len(x)
        return (
            float(self.fun(x)),
            np.asarray(self.jac(x), dtype=float) if need_grad else None,
            np.asarray(self.hess(x), dtype=float) if need_hess else None,
        )

    def metric(self) -> FloatArray:
        return np.ones(self._n or 0)

    def weights(self) -> FloatArray:
        return np.ones(self._n or 0)

    def retract(self, x: FloatArray, d: FloatArray, alpha: float) -> FloatArray:
        return x + alpha * d

    def accept(self, x: FloatArray) -> None:
        return None

    def project(self, d: FloatArray) -> FloatArray:
        return d

    def max_step(self, x: FloatArray, d: FloatArray) -> float:
        return 1.0

    def shift_floor(self, g: FloatArray) -> float:
        return 0.0

    def convex_hessian(self, x: FloatArray) -> None:
        return None

    def curvature_step_scale(self, x: FloatArray, v: FloatArray) -> float:
        return 0.0

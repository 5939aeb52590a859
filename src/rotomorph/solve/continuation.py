"""Quasi-static continuation: follow equilibria through a list of parameter values.

Each requested value is solved starting from the previous equilibrium. When a solve raises a
:class:`~rotomorph.errors.ConvergenceError`, the step from the last equilibrium is halved
(the midpoint is solved first, then the target again), up to ``max_halvings`` levels deep.
The solver is any callable ``solve(parameter, state) -> result``; nothing here knows about
rods, so the loop is testable on a scalar problem.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from rotomorph._typing import BoolArray, FloatArray
from rotomorph.errors import ConvergenceError, InvalidParameterError

__all__ = ["ContinuationResult", "ContinuationStep", "continuation"]


@dataclass(frozen=True, eq=False)
class ContinuationStep:
    """One requested parameter value and the equilibrium reached there.

    Attributes
    ----------
    parameter
        The requested value.
    result
        The solver's result at ``parameter``.
    solves
        Successful solves spent reaching it (1 without halving; intermediate points count).
    failures
        Solves that raised and caused a halving.
    halvings
        Deepest halving level used on the way (0: the step was taken whole).
    wall_time
        Seconds spent on this step, failures included.
    """

    parameter: float
    result: Any
    solves: int
    failures: int
    halvings: int
    wall_time: float


@dataclass(frozen=True, eq=False)
class ContinuationResult:
    """The path of equilibria; ``steps[k]`` belongs to ``parameters[k]``."""

    steps: tuple[ContinuationStep, ...]

    @property
    def parameters(self) -> FloatArray:
        """Requested parameter values reached ``(K,)``."""
        return np.array([s.parameter for s in self.steps], dtype=float)

    @property
    def results(self) -> list[Any]:
        """Solver results, one per step."""
        return [s.result for s in self.steps]

    @property
    def final(self) -> Any:
        """Result at the last parameter value."""
        return self.steps[-1].result

    @property
    def stable(self) -> BoolArray:
        """Per step: the equilibrium was certified stable (False where the solver's result
        carries no ``stable`` verdict)."""
        return np.array([bool(getattr(s.result, "stable", False)) for s in self.steps])

    @property
    def lowest_eigenvalues(self) -> FloatArray:
        """Per step: the lowest Hessian eigenvalue the solver reported (NaN where none)."""
        out = []
        for s in self.steps:
            ev = getattr(s.result, "eigenvalues", None)
            out.append(float(ev[0]) if ev is not None and len(ev) else np.nan)
        return np.array(out, dtype=float)


def _default_state(result: Any) -> Any:
    return result.state


def continuation(
    solve: Callable[[float, Any], Any],
    parameters: Sequence[float] | FloatArray,
    initial: Any,
    *,
    start: float | None = None,
    max_halvings: int = 6,
    state_of: Callable[[Any], Any] = _default_state,
    retry_on: tuple[type[BaseException], ...] = (ConvergenceError,),
    on_step: Callable[[ContinuationStep], None] | None = None,
) -> ContinuationResult:
    """Solve ``solve(p, state)`` for every ``p`` in ``parameters``, each from the last result.

    Parameters
    ----------
    solve
        ``solve(parameter, initial_state) -> result``; raises one of ``retry_on`` on failure.
    parameters
        Parameter values in the order to follow them (any unit; at least one).
    initial
        Starting state for the first solve (e.g. the printed configuration).
    start
        Parameter value at which ``initial`` is an equilibrium; needed to halve the first step
        (without it a failure of the first solve is final).
    max_halvings
        Deepest halving of a step (the smallest step is ``2**-max_halvings`` of a requested one).
    state_of
        Extracts the next starting state from a result (default ``result.state``).
    retry_on
        Exception types that trigger a halving; anything else propagates.
    on_step
        Called with each :class:`ContinuationStep` as soon as its requested value is reached
        (to show results while the path is followed); an exception it raises propagates.

    Returns
    -------
    ContinuationResult

    Raises
    ------
    ConvergenceError
        A step still fails after ``max_halvings`` halvings; ``error.result`` is the
        :class:`ContinuationResult` of the steps reached so far and ``error.parameter`` the
        value that failed.
    """
    values = np.asarray(parameters, dtype=float).reshape(-1)
    if values.size == 0 or not np.all(np.isfinite(values)):
        raise InvalidParameterError("parameters", "needs at least one value, all finite")
    if int(max_halvings) != max_halvings or max_halvings < 0:
        raise InvalidParameterError("max_halvings", f"must be an integer >= 0; got {max_halvings}")
    state = initial
    last = None if start is None else float(start)
    steps: list[ContinuationStep] = []
    for target in values:
        t0 = time.perf_counter()
        pending = [float(target)]
        solves = failures = deepest = 0
        result = None
        while pending:
            q = pending[-1]
            try:
                result = solve(q, state)
            except retry_on as exc:
                failures += 1
                level = len(pending)
                if last is None or level > max_halvings:
                    err = ConvergenceError(
                        f"continuation failed at parameter {q:.6g} (target {target:.6g}) after "
                        f"{level - 1} halvings from {last}; raise max_halvings, take smaller "
                        f"steps or pass start= so the first step can be halved ({exc})",
                        result=ContinuationResult(tuple(steps)),
                    )
                    err.parameter = q  # type: ignore[attr-defined]
                    raise err from exc
                pending.append(last + 0.5 * (q - last))
                deepest = max(deepest, level)
                continue
            solves += 1
            state = state_of(result)
            last = q
            pending.pop()
        steps.append(
            ContinuationStep(
                parameter=float(target),
                result=result,
                solves=solves,
                failures=failures,
                halvings=deepest,
                wall_time=time.perf_counter() - t0,
            )
        )
        if on_step is not None:
            on_step(steps[-1])
    return ContinuationResult(tuple(steps))

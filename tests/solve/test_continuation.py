"""Quasi-static continuation: order, warm starts and step halving on failure."""

from __future__ import annotations

import numpy as np
import pytest

from rotomorph.errors import ConvergenceError, InvalidParameterError
from rotomorph.solve.continuation import continuation


class _Result:
    def __init__(self, state: float) -> None:
        self.state = state


def _solver(max_jump: float, calls: list):
    """Converges only when the parameter moved by at most ``max_jump`` from the last state."""

    def solve(p: float, state: float) -> _Result:
        calls.append((p, state))
        if abs(p - state) > max_jump:
            raise ConvergenceError(f"jump {abs(p - state)} too large")
        return _Result(p)

    return solve


def test_each_step_starts_from_the_previous_equilibrium():
    calls: list = []
    res = continuation(_solver(1.0, calls), [0.5, 1.0, 1.5], 0.0, start=0.0)
    assert [c[1] for c in calls] == [0.0, 0.5, 1.0]
    assert np.allclose(res.parameters, [0.5, 1.0, 1.5])
    assert res.final.state == 1.5
    assert all(s.halvings == 0 and s.solves == 1 and s.failures == 0 for s in res.steps)


def test_failed_steps_are_halved():
    calls: list = []
    res = continuation(_solver(0.3, calls), [1.0], 0.0, start=0.0)
    # 1.0 fails, 0.5 fails, 0.25 ok, then 0.625 ... until 1.0 is reached in steps <= 0.3
    assert res.final.state == 1.0
    step = res.steps[0]
    assert step.halvings == 2
    assert step.failures >= 2
    reached = [p for p, s in calls if abs(p - s) <= 0.3]
    assert reached[0] == pytest.approx(0.25)
    assert all(b - a <= 0.3 + 1e-12 for a, b in zip([0.0, *reached[:-1]], reached, strict=True))


def test_gives_up_after_max_halvings_with_the_partial_path():
    calls: list = []
    with pytest.raises(ConvergenceError, match="halvings") as info:
        continuation(_solver(0.01, calls), [0.001, 1.0], 0.0, start=0.0, max_halvings=3)
    partial = info.value.result
    assert len(partial.steps) == 1
    assert partial.final.state == 0.001
    assert info.value.parameter == pytest.approx(0.001 + (1.0 - 0.001) / 8)


def test_first_step_cannot_be_halved_without_start():
    with pytest.raises(ConvergenceError, match="start="):
        continuation(_solver(0.1, []), [1.0], 0.0)


def test_other_errors_propagate_and_arguments_are_checked():
    def broken(p, s):
        raise KeyError("bug")

    with pytest.raises(KeyError):
        continuation(broken, [1.0], 0.0, start=0.0)
    with pytest.raises(InvalidParameterError, match="parameters"):
        continuation(_solver(1, []), [], 0.0)
    with pytest.raises(InvalidParameterError, match="max_halvings"):
        continuation(_solver(1, []), [1.0], 0.0, max_halvings=-1)


def test_on_step_reports_each_requested_value_once_in_order_as_it_is_reached():
    calls: list = []
    seen: list = []

    def on_step(step) -> None:
        seen.append((step.parameter, step.result.state, len(calls)))

    res = continuation(_solver(0.3, calls), [0.5, 1.0], 0.0, start=0.0, on_step=on_step)
    # halved sub-steps are not reported; each value as soon as it is reached (not at the end)
    assert [s[0] for s in seen] == [0.5, 1.0]
    assert [s[1] for s in seen] == [0.5, 1.0]
    assert seen[0][2] < len(calls)  # the first report came before the second step's solves
    assert [s.parameter for s in res.steps] == [0.5, 1.0]


def test_an_exception_in_on_step_propagates():
    def on_step(step) -> None:
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        continuation(_solver(1.0, []), [0.5, 1.0], 0.0, start=0.0, on_step=on_step)

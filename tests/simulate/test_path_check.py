"""The report counts the end state lower in total energy when a lattice's ramp is path
dependent (two stable end states reached with different step counts)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from rotomorph.simulate.report import lower_energy_end


def _ramp(steps: int, energy: float, *, stable: bool = True, clearance: float = 1.01):
    return SimpleNamespace(
        parameter=np.linspace(25.0, 175.0, steps + 1),
        energy=np.r_[np.zeros(steps), energy],
        gaussian_sign=np.r_[np.zeros(steps), 1.0],
        final_area_ratio=0.4,
        stable=np.r_[np.ones(steps, bool), stable],
        min_clearance=np.full(steps + 1, clearance),
    )


def test_same_state_keeps_the_first_ramp():
    pick, note = lower_energy_end(_ramp(8, 0.2), _ramp(16, 0.2 * (1 + 1e-8)))
    assert pick == 0 and "same state" in note


def test_lower_energy_end_is_counted():
    pick, note = lower_energy_end(_ramp(8, 0.222), _ramp(16, 0.214))
    assert pick == 1
    assert "different stable states" in note and "(16 steps)" in note
    pick, _ = lower_energy_end(_ramp(8, 0.214), _ramp(16, 0.222))
    assert pick == 0


def test_inadmissible_second_end_is_never_counted():
    assert lower_energy_end(_ramp(8, 0.3), _ramp(16, 0.1, stable=False))[0] == 0
    assert lower_energy_end(_ramp(8, 0.3), _ramp(16, 0.1, clearance=0.9))[0] == 0
    assert lower_energy_end(_ramp(8, 0.3), None)[0] == 0
    assert lower_energy_end(None, _ramp(16, 0.1))[0] == 1

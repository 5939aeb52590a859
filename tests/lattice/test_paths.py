"""Path check of a heating ramp: a multistable lattice keeps the end state lower in energy."""

from __future__ import annotations

import numpy as np
import pytest

import rotomorph.lattice.heating as heating
from rotomorph.design.lattices import sinusoidal_lattice
from rotomorph.errors import InvalidParameterError
from rotomorph.lattice import heat_lattice
from rotomorph.lattice.paths import PathCheck, check_factor, choose_end, sub_stepped


def test_sub_stepped_keeps_the_requested_values_exactly():
    values = np.linspace(25.0, 175.0, 9)
    fine = sub_stepped(values, 3)
    assert len(fine) == 25 and np.array_equal(fine[::3], values)
    assert np.all(np.diff(fine) > 0)
    np.testing.assert_allclose(fine, np.linspace(25.0, 175.0, 25), rtol=1e-15, atol=1e-12)


def test_choose_end():
    assert choose_end(0.2, 0.2 * (1 + 1e-8), True, 2).kept == "steps"
    assert choose_end(0.2, 0.2 * (1 + 1e-8), True, 2).same_state
    lower = choose_end(0.222, 0.214, True, 2)
    assert lower.kept == "sub-steps" and not lower.same_state
    assert "different stable states" in lower.note and "sub-steps" in lower.note
    assert choose_end(0.214, 0.222, True, 2).kept == "steps"
    assert choose_end(0.3, 0.1, False, 2).kept == "steps"  # not certified stable
    failed = choose_end(0.3, np.nan, False, 2)
    assert failed.kept == "steps" and "failed" in failed.note
    with pytest.raises(InvalidParameterError, match="path_check"):
        check_factor(0)
    with pytest.raises(InvalidParameterError, match="path_check"):
        check_factor(1.5)  # type: ignore[arg-type]


def _small():
    return sinusoidal_lattice(3, 5.0, 1.25, 6, "dome")


def test_path_check_records_and_keeps_the_lower_end():
    direct = [heat_lattice(_small(), steps=n) for n in (2, 4)]
    res = heat_lattice(_small(), steps=2, path_check=2)
    assert len(res.parameter) == 3 and res.path_check is not None
    e2, e4 = (float(d.energy[-1]) for d in direct)
    assert res.path_check.energy == pytest.approx((e2, e4), rel=1e-12)
    assert float(res.energy[-1]) == pytest.approx(min(e2, e4) if not res.path_check.same_state
                                                  else e2, rel=1e-12)  # fmt: skip
    assert heat_lattice(_small(), steps=2).path_check is None


def test_kept_sub_stepped_ramp_is_sampled_at_the_requested_steps(monkeypatch):
    def prefer_sub_steps(energy, other, ok, factor):  # type: ignore[no-untyped-def]
        return PathCheck(factor, (energy, other), "sub-steps", False)

    monkeypatch.setattr(heating, "choose_end", prefer_sub_steps)
    res = heat_lattice(_small(), steps=2, path_check=2)
    fine = heat_lattice(_small(), steps=4)
    np.testing.assert_array_equal(res.parameter, fine.parameter[::2])
    np.testing.assert_allclose(res.positions, fine.positions[::2], atol=1e-12)
    np.testing.assert_allclose(res.energy, fine.energy[::2], rtol=1e-12)
    assert res.total_iterations == fine.total_iterations
    assert res.iterations[1] == fine.iterations[1] + fine.iterations[2]

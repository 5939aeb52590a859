"""The zero-energy free shape is the rod solver's equilibrium, and the report's sinusoid is the
example design file's."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from rotomorph.errors import InvalidDesignError
from rotomorph.io.designfile import Filament, load_design
from rotomorph.materials.natural import natural_field
from rotomorph.rod.model import Model
from rotomorph.simulate.filament import simulate_filament
from rotomorph.simulate.free_shape import free_equilibrium, min_clearance
from rotomorph.simulate.validation import sinusoid_filament

DESIGNS = Path(__file__).resolve().parents[2] / "examples" / "designs"


def _ratio(x: np.ndarray, printed: np.ndarray) -> float:
    return float(np.linalg.norm(x[-1] - x[0]) / np.linalg.norm(printed[-1] - printed[0]))


@pytest.mark.parametrize("which", ["sinusoid", "composite"])
def test_free_shape_equals_rod_solver(which) -> None:
    if which == "sinusoid":
        fil = load_design(DESIGNS / "sinusoids.toml").filaments[0]
        prog = fil.model_copy(update={"spacing": 0.25}).to_program()
    else:
        line = [{"kind": "line", "length": 12.0}]
        prog = Filament(speed=3.0, rotation_number=0.25, radius=0.3, active_fraction=0.5,
                        spacing=0.25, segments=line).to_program()  # fmt: skip
    field = natural_field(prog, temperature=175.0)
    x = free_equilibrium(Model.from_field(prog.points, field))
    sim = simulate_filament(prog, steps=4)
    assert _ratio(x, prog.points) == pytest.approx(sim.final_ratio, abs=1e-6)
    # same shape up to a rigid motion: compare all pairwise distances
    y = sim.positions[-1]
    dx = np.linalg.norm(x[:, None] - x[None], axis=-1)
    dy = np.linalg.norm(y[:, None] - y[None], axis=-1)
    np.testing.assert_allclose(dx, dy, atol=1e-5)


def test_report_sinusoid_is_the_example_design() -> None:
    design = load_design(DESIGNS / "sinusoids.toml")
    for fil, side in zip(design.filaments, ("outer", "inner"), strict=True):
        ours = sinusoid_filament(side, fil.spacing).to_program()  # the printable variant
        theirs = fil.to_program()
        a, b = ours.points - ours.points[0], theirs.points - theirs.points[0]
        np.testing.assert_allclose(a, b, atol=1e-9)
        np.testing.assert_allclose(ours.interface_angle, theirs.interface_angle, atol=1e-9)
        np.testing.assert_allclose(ours.rotation, theirs.rotation, atol=1e-9)


def test_straight_chain_and_errors() -> None:
    pts = np.column_stack([np.linspace(0, 4, 9), np.zeros(9), np.zeros(9)])
    x = free_equilibrium(
        Model.chain(
            pts,
            bending_stiffness1=1.0,
            bending_stiffness2=1.0,
            twist_stiffness=1.0,
            axial_stiffness=1.0,
        )
    )
    np.testing.assert_allclose(x, pts, atol=1e-12)
    assert min_clearance(x, exclude_arc=1.2) == pytest.approx(1.5)

    class Loop:  # a closed ring is not an open chain
        network = type("Net", (), {"nodes": pts[:3], "edges": np.array([[0, 1], [1, 2], [2, 0]])})

    with pytest.raises(InvalidDesignError, match="open chain"):
        free_equilibrium(Loop())


def _clearance_by_every_pair(x: np.ndarray, exclude_arc: float) -> float:
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(x, axis=0), axis=1))])
    d = np.linalg.norm(x[:, None, :] - x[None, :, :], axis=-1)
    far = np.abs(s[:, None] - s[None, :]) > exclude_arc
    return float(d[far].min()) if np.any(far) else float("inf")


@pytest.mark.parametrize("n", [1, 2, 3, 40, 700])
def test_min_clearance_is_the_closest_far_pair_of_every_pair(n) -> None:
    # a noisy helix far from the origin (the squared-distance expansion is taken about the
    # centroid) against the distance matrix of every pair; rows in several blocks at n = 700
    rng = np.random.default_rng(n)
    t = np.linspace(0.0, 20.0, n)
    x = np.c_[3 * np.cos(t), 3 * np.sin(t), 0.3 * t] + 500.0 + 0.01 * rng.standard_normal((n, 3))
    for exclude in (0.0, 0.5, 2.0, 30.0, 1e3):
        assert min_clearance(x, exclude_arc=exclude) == _clearance_by_every_pair(x, exclude)

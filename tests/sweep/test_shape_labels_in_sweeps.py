"""A sweep labels a filament's shape as ``summary.json`` does: a gently bent arc (a Janus
filament bent through less than a radian) is no coil, a twisted rod keeps its label (it claims
no helix), and the phase diagram still shows unlabelled points."""

from __future__ import annotations

import pyarrow as pa
import pytest

from rotomorph.io.designfile import Filament
from rotomorph.simulate.design import HELIX_MIN_TURNS, shape_label
from rotomorph.simulate.filament import simulate_filament
from rotomorph.sweep.figures import plot_phase_diagram
from rotomorph.sweep.metrics import filament_metrics


def _janus(length: float):  # type: ignore[no-untyped-def]
    """A Janus filament (no rotation) ``length`` mm long: it bends into an arc of a ring."""
    f = Filament(
        speed=1.0,
        rotation_number=0.0,
        spacing=0.25,
        segments=[{"kind": "line", "length": length}],  # type: ignore[list-item]
    )
    return simulate_filament(f.to_program(), steps=2)


@pytest.mark.parametrize(("length", "label"), [(2.5, None), (10.0, "coil")])
def test_a_gently_bent_arc_is_not_called_a_coil(length, label) -> None:
    sim = _janus(length)
    assert sim.morphology.value == "coil"  # the curvature/twist rule alone: Λ = κ/|τ| large
    assert sim.helix is not None
    assert (sim.helix.turns < HELIX_MIN_TURNS) is (label is None)
    assert shape_label(sim) == label
    row = filament_metrics(sim, {})
    assert row["morphology"] == label
    assert row["helix_turns"] == pytest.approx(sim.helix.turns)  # the fit is still reported


def test_a_twisted_rod_keeps_its_label_without_a_helix() -> None:
    """A rotated pure-LCE-like filament printed slowly at high rotation barely bends: the
    material twist labels it a twisted rod, for which no helix is fitted."""
    f = Filament(
        speed=0.25,
        rotation_number=1.12,
        active_fraction=0.5,
        spacing=0.5,
        segments=[{"kind": "line", "length": 20.0}],  # type: ignore[list-item]
    )
    sim = simulate_filament(f.to_program(), steps=4)
    assert sim.morphology.value == "twisted rod" and sim.helix is None
    assert shape_label(sim) == "twisted rod"
    assert filament_metrics(sim, {})["morphology"] == "twisted rod"


def test_the_phase_diagram_shows_unlabelled_points() -> None:
    table = pa.table(
        {
            "x": [0.0, 1.0, 2.0],
            "y": [0.0, 0.0, 1.0],
            "morphology": ["coil", None, None],
            "physical": [True, True, None],
            "status": ["ok", "ok", "failed"],
        }
    )
    fig = plot_phase_diagram(table, "x", "y")
    labels = fig.axes[0].get_legend_handles_labels()[1]
    assert labels == ["coil", "no helix fits (a gently bent arc, other)", "invalid / failed"]

"""The default lattice actuation: every printed line's natural field from its print program,
through the same materials chain as a single filament."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest

from rotomorph.analysis.shape import end_to_end_ratio
from rotomorph.design.lattices import sinusoidal_lattice
from rotomorph.lattice.actuation import (
    DEFAULT_ACTUATION,
    ProgramActuation,
    default_stiffness,
    get_actuation,
)
from rotomorph.lattice.heating import free_edge_ratio, heat_lattice
from rotomorph.materials.natural import FilamentModel, natural_field
from rotomorph.rod.model import Model
from rotomorph.solve.static import solve_static

FM = FilamentModel(resolution=32)


@pytest.fixture(scope="module")
def isotropic():
    from tests.solve.test_similarity import ISOTROPIC

    return ISOTROPIC


def test_program_is_the_default_and_builds_on_the_janus_section():
    act = get_actuation(DEFAULT_ACTUATION)
    assert isinstance(act, ProgramActuation) and (act.start, act.end) == (25.0, 175.0)
    assert default_stiffness(act)[0] == "janus"
    assert default_stiffness(get_actuation("swapped"))[0] == "paper"
    assert default_stiffness(act, "paper") == ("paper", None)


def test_isotropic_strain_through_the_print_programs_is_a_similarity(isotropic):
    from tests.solve.test_similarity import STRAIN, _similarity_error

    lat = sinusoidal_lattice(3, 5.0, 1.25, 6, "dome")
    res = heat_lattice(
        lat, actuation=ProgramActuation(filament_model=isotropic), steps=2, perturbation=0.0
    )
    scale = float(np.exp(STRAIN))  # x(175 °C) = 1 to 1e-3
    assert _similarity_error(res.positions[-1], lat.network.nodes, scale) < 2e-3


@dataclass(frozen=True)
class _Cut:
    """A piece of a printed line with the rotation and normals it had in the line."""

    points: np.ndarray
    speed: np.ndarray
    rotation: np.ndarray
    interface_angle: np.ndarray
    vertex_interface_normals: np.ndarray
    step_flips: bool = True
    radius: float = 0.3
    active_fraction: float = 0.5
    active_material: str = "lce"
    passive_material: str = "acrylate"


def test_free_edge_equals_the_same_edge_simulated_as_a_filament():
    # one code path: the lattice edge printed alone, actuated by the lattice's program mode,
    # has the shape the single-filament chain (natural_field -> rod) gives its program
    lat = sinusoidal_lattice(3, 5.0, 1.25, 10, "expanding")
    ratio = free_edge_ratio(lat, actuation=ProgramActuation(filament_model=FM), steps=4)
    prog, _ = lat.line_programs()[0]
    cut = slice(0, lat.ghost_nodes + 2)  # the first edge of the first line, as printed there
    edge = _Cut(
        prog.points[cut],
        prog.speed[cut],
        prog.director_rotation[cut],
        prog.interface_angle[: lat.ghost_nodes + 1],
        prog.vertex_interface_normals[cut],
    )
    field = natural_field(edge, temperature=175.0, model=FM)
    x = solve_static(Model.from_field(edge.points, field)).positions
    # same increments; the frames differ (+z here, the interface normals there, which turn by
    # 45° on the cut's first edge, half of a flip split at the branch node), and DER reads
    # curvature in frames averaged over a twist: a frame-choice difference of order h²
    assert ratio == pytest.approx(end_to_end_ratio(x, edge.points), abs=2e-3)
    assert ratio > 1.1  # active outer: the edge straightens


def test_expanding_and_contracting_lattices_from_their_programs():
    grow = heat_lattice(sinusoidal_lattice(3, 5.0, 1.25, 6, "expanding"), steps=4)
    shrink = heat_lattice(sinusoidal_lattice(3, 5.0, 1.25, 6, "contracting"), steps=4)
    assert grow.actuation == "program"
    assert grow.area_ratio[-1] > 1.15
    assert shrink.area_ratio[-1] < 0.9


def test_per_edge_speeds_need_the_program_actuation():
    """'thermal' and 'additive' use one Janus curvature: mixed edge speeds are refused, and
    'program' gives a slower edge a weaker actuation."""
    from rotomorph.design.lattices import sinusoidal_lattice
    from rotomorph.errors import InvalidParameterError
    from rotomorph.lattice.actuation import ProgramActuation, ThermalActuation
    from rotomorph.lattice.model import lattice_model

    speeds = [3.0] * 11 + [0.5]
    lm = lattice_model(sinusoidal_lattice(n=3, ghost_nodes=4, edge_speeds=speeds))
    with pytest.raises(InvalidParameterError, match="per-edge speeds needs actuation 'program'"):
        ThermalActuation().natural(lm, 175.0)
    uniform = lattice_model(sinusoidal_lattice(n=3, ghost_nodes=4))
    act = ProgramActuation()

    def increment(m):
        nat = act.natural(m, 175.0)
        return np.hypot(
            nat.natural_curvature1 - m.printed[0], nat.natural_curvature2 - m.printed[1]
        )

    st = lm.model.stencils
    inner = (st.edge_e >= 55) & (st.edge_f >= 55)  # stencils inside edge 11 (segments 55-59)
    assert inner.sum() == 4
    assert np.all(increment(lm)[inner] < 0.5 * increment(uniform)[inner])
    assert np.allclose(
        increment(lm)[~inner & (st.edge_e < 50)], increment(uniform)[~inner & (st.edge_e < 50)]
    )

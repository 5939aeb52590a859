"""A design's [contact] table: validated like every field, and it makes a self-crossing run
physical (filaments touch instead of passing through; the floor carries the buoyant weight)."""

from __future__ import annotations

import numpy as np
import pytest

from rotomorph.contact.obstacles import RESTING_GAP
from rotomorph.errors import InvalidDesignError
from rotomorph.io.designfile import parse_design
from rotomorph.simulate.design import simulate_design
from rotomorph.simulate.run_data import describe_run

# a Janus filament curls to about 0.6 /mm when heated: 13 mm turn through more than a circle
RING = {
    "schema_version": 1,
    "filaments": [
        {
            "speed": 3.0,
            "rotation": 0.0,
            "spacing": 0.3,
            "segments": [{"kind": "line", "length": 13.0}],
        }
    ],
}


def _run(contact=None):
    data = dict(RING) if contact is None else {**RING, "contact": contact}
    sim = simulate_design(parse_design(data), steps=3)
    return sim, describe_run(sim)


def test_without_contact_the_ring_passes_through_itself_and_is_flagged():
    _, run = _run()
    assert run.metadata["physical"]["verdict"] == "no"
    assert "contact not modelled" in run.metadata["physical"]["reason"]


def test_self_contact_keeps_the_ring_apart():
    _, run = _run({"self_contact": True})
    assert run.metadata["physical"]["verdict"] == "yes", run.metadata["physical"]
    assert np.min(run.scalars["min_clearance"]) >= 0.999
    assert run.metadata["contact"] == {
        "self_contact": True,
        "floor": False,
        "gravity": False,
        "friction": 0.0,
    }  # no branch or path_check: lattice-only, not applied to a filament, so not recorded


def test_on_the_floor_under_buoyant_weight():
    sim, run = _run({"floor": True, "gravity": True})
    r = 0.3
    floor = -RESTING_GAP * r  # printed at z = 0
    lowest = sim.positions[:, :, 2].min()
    assert lowest >= floor + r * (1 - 1e-3)  # never through the floor
    assert sim.positions[-1, :, 2].max() < floor + 4 * r  # weighed down: stays near the floor
    record = run.metadata["contact"]
    assert record["gravity"] and 0.8 < record["bath_density_g_cm3"] < 0.97  # hot oil, lighter
    assert record["bath_density_along_ramp"] is True  # weighed in the bath of each step
    assert "PDMS" in record["bath_density_assumption"] or record["bath_density_source"]


def test_a_filament_is_weighed_in_the_bath_of_each_ramp_step():
    """The buoyant weight follows the bath's density over the ramp: every step is solved with
    the loads of its own temperature (the oil is lighter hot, the net weight larger)."""
    from rotomorph.materials.bath import bath_density
    from rotomorph.simulate.filament import simulate_filament
    from rotomorph.simulate.surroundings import filament_surroundings

    design = parse_design({**RING, "contact": {"floor": True, "gravity": True}})
    fil = design.filaments[0]
    program = fil.to_program()
    contact, loads = filament_surroundings(design.contact, program, fil)
    assert loads is not None
    cold, hot = loads(25.0).gravity, loads(175.0).gravity
    assert cold is not None and hot is not None
    assert cold.fluid_density == pytest.approx(bath_density("silicone_oil", 25.0))
    assert hot.line_weight(1)[0] > 1.5 * cold.line_weight(1)[0]
    asked: list[float] = []

    def recorded(temperature: float):  # type: ignore[no-untyped-def]
        asked.append(temperature)
        return loads(temperature)

    sim = simulate_filament(program, steps=3, contact=contact, loads=recorded)
    np.testing.assert_allclose(sorted(set(asked)), sim.temperature[1:], rtol=1e-12)


@pytest.mark.parametrize(
    ("contact", "message"),
    [
        ({"gravity": True}, "gravity = true needs floor = true"),
        ({"self_contact": False}, "nothing to touch"),
        ({"friction": -0.1}, "contact.friction"),
        ({"floor": "yes"}, "contact.floor"),
        ({"wall": True}, "contact.wall"),
    ],
)
def test_bad_contact_tables_are_refused(contact, message):
    with pytest.raises(InvalidDesignError, match=message.replace(".", r"\.")):
        parse_design({**RING, "contact": contact})


def test_the_floor_branch_reaches_the_lattice_ramp_and_a_bad_one_is_refused():
    from rotomorph.design.lattices import sinusoidal_lattice
    from rotomorph.simulate.surroundings import lattice_surroundings

    lattice = sinusoidal_lattice(n=2, ghost_nodes=2)
    for branch in ("lowest", "continuous"):
        design = parse_design(
            {
                "schema_version": 1,
                "lattice": {"n": 2},
                "contact": {"floor": True, "gravity": True, "branch": branch},
            }
        )
        assert lattice_surroundings(design.contact, lattice, 175.0)["branch"] == branch
    with pytest.raises(InvalidDesignError, match="branch"):
        parse_design({**RING, "contact": {"floor": True, "branch": "global"}})


def test_the_path_check_reaches_the_lattice_ramp_and_is_refused_for_filaments():
    from rotomorph.design.lattices import sinusoidal_lattice
    from rotomorph.simulate.surroundings import lattice_surroundings

    lattice = sinusoidal_lattice(n=2, ghost_nodes=2)
    design = parse_design(
        {"schema_version": 1, "lattice": {"n": 2}, "contact": {"floor": True, "path_check": 2}}
    )
    assert lattice_surroundings(design.contact, lattice, 175.0)["path_check"] == 2
    with pytest.raises(InvalidDesignError, match="applies to lattices"):
        parse_design({**RING, "contact": {"self_contact": True, "path_check": 2}})
    with pytest.raises(InvalidDesignError, match="friction"):
        parse_design(
            {"schema_version": 1, "lattice": {"n": 2},
             "contact": {"floor": True, "friction": 0.3, "path_check": 2}}
        )  # fmt: skip
    for bad in (0, 9, 1.5):
        with pytest.raises(InvalidDesignError, match="path_check"):
            parse_design({"schema_version": 1, "lattice": {"n": 2}, "contact": {"path_check": bad}})

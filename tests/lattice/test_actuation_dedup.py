"""The program actuation evaluates each distinct print state once, and exactly.

The lines of a lattice repeat a few thousand cross-section print states (rotation number,
LCE and passive strains) over all their vertices; the section solves each distinct one once and
remembers it (:meth:`rotomorph.materials.janus.FilamentSection.natural_strains`).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from rotomorph.design.lattices import sinusoidal_lattice
from rotomorph.lattice.actuation import ProgramActuation
from rotomorph.lattice.model import lattice_model
from rotomorph.materials.janus import FilamentSection, unique_rows
from rotomorph.materials.material import get_material
from rotomorph.materials.natural import FilamentModel, LayerStack


def _sections(lattice: Any) -> list[FilamentSection]:
    """The sections a lattice's program actuation solves: one layer's, or the stack's two
    (stacked across the interface normal where it lies in the sheet, along it at flips)."""
    fm = FilamentModel()
    mats = (get_material(lattice.active_material), get_material(lattice.passive_material))
    if lattice.layers == 1:
        return [fm.section(*mats, lattice.radius, lattice.active_fraction)]
    return [
        fm.section(
            *mats,
            lattice.radius,
            lattice.active_fraction,
            stack=LayerStack(lattice.layers, lattice.layer_height, d),
        )
        for d in ((0.0, 1.0), (1.0, 0.0))
    ]


def _natural(
    monkeypatch: pytest.MonkeyPatch,
    n: int,
    memo: bool,
    clear: bool = True,
    every_line: bool = False,
    layers: int = 3,
) -> tuple[Any, dict[int, list[np.ndarray]], dict[int, int]]:
    """Natural model of an n x n lattice at 150 °C, every state row asked for and rows solved,
    per section (``clear``: forget what the sections remember first; ``every_line``: evaluate
    every line's program, also those repeating another line's up to a translation)."""
    asked: dict[int, list[np.ndarray]] = {}
    solved: dict[int, int] = {}
    natural_strains = FilamentSection.natural_strains
    solve_states = FilamentSection._solve_states

    def record(self: FilamentSection, *args: Any) -> tuple[Any, Any, Any]:
        cols = np.broadcast_arrays(*(np.atleast_1d(np.asarray(a, dtype=float)) for a in args))
        asked.setdefault(id(self), []).append(np.column_stack(cols) + 0.0)
        if memo:
            return natural_strains(self, *args)
        rows = solve_states(self, asked[id(self)][-1])  # every row on its own: no deduplication
        return rows[:, 0], rows[:, 1:3], rows[:, 3]

    def count(self: FilamentSection, states: np.ndarray) -> np.ndarray:
        solved[id(self)] = solved.get(id(self), 0) + len(states)
        return solve_states(self, states)

    lattice = sinusoidal_lattice(n, layers=layers)
    if every_line:
        lattice._cache[("program_groups",)] = [(k, 0) for k in range(len(lattice.line_programs()))]
    if clear:
        for section in _sections(lattice):
            section._solved.clear()  # a section remembers states across calls: start empty
    monkeypatch.setattr(FilamentSection, "natural_strains", record)
    monkeypatch.setattr(FilamentSection, "_solve_states", count)
    lm = lattice_model(lattice, stiffness="janus")
    model = ProgramActuation().natural(lm, 150.0)
    return model, asked, solved


@pytest.mark.parametrize("layers", [1, 3])
def test_each_distinct_print_state_is_solved_once(
    monkeypatch: pytest.MonkeyPatch, layers: int
) -> None:
    _, asked, solved = _natural(monkeypatch, 6, memo=True, every_line=True, layers=layers)
    assert set(solved) <= set(asked)
    total = per_call = 0
    for key, rows in asked.items():
        # one solve per distinct state of each section over ALL lines and calls
        assert solved.get(key, 0) == len(unique_rows(np.concatenate(rows))[0])
        total += solved.get(key, 0)
        per_call += sum(len(unique_rows(r)[0]) for r in rows)
    assert total * 2 < per_call  # deduplicating within each line's call only solves more


@pytest.mark.parametrize("layers", [1, 3])
def test_remembered_states_give_the_same_field_bit_for_bit(
    monkeypatch: pytest.MonkeyPatch, layers: int
) -> None:
    cached, _, _ = _natural(monkeypatch, 5, memo=True, layers=layers)
    monkeypatch.undo()
    again, _, solved_again = _natural(monkeypatch, 5, memo=True, clear=False, layers=layers)
    assert sum(solved_again.values()) == 0  # every state remembered from the first call
    monkeypatch.undo()
    direct, _, _ = _natural(monkeypatch, 5, memo=False, layers=layers)
    for name in ("natural_curvature1", "natural_curvature2", "natural_twist", "rest_length"):
        assert np.array_equal(getattr(cached, name), getattr(direct, name)), name
        assert np.array_equal(getattr(again, name), getattr(direct, name)), name


def test_unique_rows_matches_numpy() -> None:
    rng = np.random.default_rng(3)
    table = rng.choice([-1.5, -0.0, 0.0, 0.25, 2.0], size=(400, 4))
    states, inverse = unique_rows(table)
    expected, expected_inverse = np.unique(table, axis=0, return_inverse=True)
    assert np.array_equal(states, expected)
    assert np.array_equal(inverse, expected_inverse.reshape(-1))
    assert np.array_equal(states[inverse], table)
    empty_states, empty_inverse = unique_rows(np.zeros((0, 4)))
    assert empty_states.shape == (0, 4) and empty_inverse.shape == (0,)


@pytest.mark.parametrize("pattern", ["contracting", "saddle"])
def test_repeated_lines_share_increments_and_give_the_uncached_field(pattern: str) -> None:
    """Lines whose print programs differ only by their offset and a quarter turn about +z
    (x- and y-lines) share one increment evaluation per temperature; the natural model equals
    the one computed line by line to 1e-12."""
    from rotomorph.lattice.actuation import _program_groups, _turn

    fm = FilamentModel(resolution=16)
    lat = sinusoidal_lattice(3, 5.0, 1.25, 6, pattern)
    lm = lattice_model(lat, stiffness="janus", filament_model=fm)
    groups = _program_groups(lm)
    programs = [p for p, _ in lat.line_programs()]
    assert len({rep for rep, _ in groups}) < len(groups) // 2  # x- and y-lines repeat
    assert {turns for _, turns in groups} == {0, 1}
    for line, (rep, turns) in enumerate(groups):
        a, b = programs[rep].points, programs[line].points
        assert np.allclose(_turn(a - a[0], turns), b - b[0], atol=1e-12)
    act = ProgramActuation(filament_model=fm)
    grouped = act.natural(lm, 140.0)
    lat._cache[("program_groups",)] = [(k, 0) for k in range(len(groups))]  # each on its own
    alone = act.natural(lm, 140.0)
    for f in ("natural_curvature1", "natural_curvature2", "natural_twist", "rest_length"):
        a, b = np.asarray(getattr(grouped, f)), np.asarray(getattr(alone, f))
        assert np.abs(a - b).max() <= 1e-12 * (1.0 + np.abs(b).max()), f


def test_a_changed_speed_shape_or_nozzle_is_not_the_same_program() -> None:
    from dataclasses import replace

    from rotomorph.lattice.actuation import _program_turns, _turn
    from rotomorph.materials.natural import actuation_increments

    lat = sinusoidal_lattice(3, 5.0, 1.25, 6, "contracting")
    p = lat.line_programs()[0][0]
    moved = replace(p, points=p.points + np.array([3.0, -2.0, 0.5]))
    assert _program_turns(p, moved) == 0
    assert _program_turns(p, replace(p, speed=p.speed * (1.0 + 1e-9))) is None
    bent = p.points.copy()
    bent[4, 1] += 1e-6
    assert _program_turns(p, replace(p, points=bent)) is None
    assert _program_turns(p, replace(p, active_fraction=0.4)) is None
    # turned by three quarter turns: the path and the lab nozzle angle together
    turned = replace(p, points=_turn(p.points, 3), nozzle_angle=p.nozzle_angle + 1.5 * np.pi)
    assert _program_turns(p, turned) == 3
    assert _program_turns(p, replace(turned, nozzle_angle=p.nozzle_angle)) is None
    # and the increments turn with it (what the shared evaluation relies on)
    fm = FilamentModel(resolution=16)
    a = actuation_increments(p, temperature=150.0, model=fm)
    b = actuation_increments(turned, temperature=150.0, model=fm)
    assert np.allclose(_turn(a.curvature, 3), b.curvature, rtol=0.0, atol=1e-12)
    assert np.allclose(a.twist, b.twist, rtol=0.0, atol=1e-12)
    assert np.allclose(a.stretch, b.stretch, rtol=0.0, atol=1e-12)


def test_programs_with_remembered_attributes_give_the_same_field_bit_for_bit() -> None:
    """The ramp reads each line program's derived attributes once (``_Derived``): the natural
    field is bit for bit the one from the programs themselves, handed-out arrays are copies,
    and an attribute the program lacks is still missing (``getattr`` defaults apply)."""
    from rotomorph.lattice.actuation import _Derived

    fm = FilamentModel(resolution=16)
    lat = sinusoidal_lattice(3, 5.0, 1.25, 6, "saddle")
    lm = lattice_model(lat, stiffness="janus", filament_model=fm)
    act = ProgramActuation(filament_model=fm)
    remembered = [act.natural(lm, t) for t in (120.0, 150.0)]
    lat._cache[("derived_programs",)] = [p for p, _ in lat.line_programs()]
    plain = [act.natural(lm, t) for t in (120.0, 150.0)]
    for a, b in zip(remembered, plain, strict=True):
        for name in ("natural_curvature1", "natural_curvature2", "natural_twist", "rest_length"):
            assert np.array_equal(getattr(a, name), getattr(b, name)), name
    program = lat.line_programs()[0][0]
    derived = _Derived(program)
    first = derived.interface_angle
    first[:] = 0.0
    assert np.array_equal(derived.interface_angle, program.interface_angle)
    assert getattr(derived, "no_such_attribute", "default") == "default"

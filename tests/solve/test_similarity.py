"""Kinematics of actuation: a uniform isotropic natural strain of any printed shape is a
similarity (natural turning and twist angles are per printed length, not per rest length)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest

from rotomorph.design.lattices import sinusoidal_lattice
from rotomorph.design.path import Arc, Line, Path, Sinusoid
from rotomorph.design.program import PrintProgram
from rotomorph.lattice.model import lattice_model
from rotomorph.materials.natural import FilamentModel, natural_field
from rotomorph.rod.model import Model
from rotomorph.solve.static import solve_static

STRAIN = -0.15  # Hencky: every fibre of both inks contracts by the same factor exp(-0.15)


@dataclass(frozen=True)
class IsotropicStrain:
    """An actuation-strain model whose LCE strain is isotropic (no director): ε∥ = ε⊥."""

    measure: str = "hencky"

    def active_strains(self, speed):
        e = np.full(np.shape(speed), STRAIN)
        return e, e


# every eigenstrain scaled by x(T) alike (the temperature laws would expand the passive ink
# linearly in T while the LCE follows x(T): no longer isotropic at intermediate T)
ISOTROPIC = FilamentModel(
    strain_model=IsotropicStrain(),
    passive_strain=STRAIN,
    resolution=48,
    temperature_dependent=False,
)


def _similarity_error(x: np.ndarray, ref: np.ndarray, scale: float) -> float:
    """Max distance (relative to the size) between x and the best rigid motion of scale * ref."""
    a = x - x.mean(0)
    b = scale * (ref - ref.mean(0))
    u, _, vt = np.linalg.svd(b.T @ a)
    d = np.sign(np.linalg.det(u @ vt))
    rot = u @ np.diag([1.0, 1.0, d]) @ vt
    return float(np.max(np.linalg.norm(b @ rot - a, axis=1)) / np.ptp(ref, axis=0).max())


def _programs() -> dict[str, PrintProgram]:
    arc = Path.from_segments([Line(2.0), Arc(3.0, 1.5), Line(1.0)], spacing=0.1)
    wave = Path.from_segments([Sinusoid(amplitude=1.0, wavelength=5.0, periods=2)], spacing=0.1)
    return {
        "curved": PrintProgram.sinusoid_with_active_side(arc, 3.0, "outer"),
        "twisted": PrintProgram.from_rotation(
            Path.from_segments([Line(3.0), Arc(4.0, 2.0)], spacing=0.1), 3.0, rotation=10.0
        ),
        "sinusoid_flips": PrintProgram.sinusoid_with_active_side(wave, 3.0, "inner"),
    }


@pytest.mark.parametrize("name", ["curved", "twisted", "sinusoid_flips"])
def test_uniform_contraction_of_a_printed_filament_is_a_similarity(name):
    program = _programs()[name]
    field = natural_field(program, temperature=175.0, model=ISOTROPIC)
    # isotropic eigenstrain: no Janus curvature, no eigen-twist, only a centre-line strain
    assert np.max(np.abs(field.axial_strain - field.actuation * STRAIN)) < 1e-9
    res = solve_static(Model.from_field(program.points, field))
    scale = float(np.exp(field.actuation * STRAIN))
    assert scale < 0.87
    assert _similarity_error(res.positions, program.points, scale) < 1e-6
    assert res.energy < 1e-12


def test_pure_lce_arc_keeps_its_turning_angle():
    # the regression that motivated the fix: a pure-LCE printed arc of 1.5 rad turned through
    # 1.197 rad once heated, because per-length curvature was multiplied by a shortened length
    path = Path.from_segments([Arc(4.0, 1.5)], spacing=0.05)
    # a nozzle that does not rotate: no director helix, hence no eigen-twist
    program = PrintProgram.from_rotation(path, 3.0, 0.0, active_fraction=1.0)
    field = natural_field(program, temperature=175.0)
    assert np.all(field.axial_strain < -0.1)  # the LCE contracts along its director

    def turning(x: np.ndarray) -> float:
        t0, t1 = x[1] - x[0], x[-1] - x[-2]
        return float(np.arctan2(np.cross(t0, t1)[2], np.dot(t0, t1)))

    x = solve_static(Model.from_field(program.points, field)).positions
    assert turning(program.points) == pytest.approx(1.5, rel=0.02)
    assert turning(x) == pytest.approx(turning(program.points), abs=1e-8)


def test_uniform_rest_length_change_of_a_lattice_is_a_similarity():
    # branched: junction pairs and rod vertices keep their natural angles
    lat = sinusoidal_lattice(3, 5.0, 1.25, 6, "expanding")
    model = lattice_model(lat).model
    scale = 0.8
    shrunk = model.with_natural(rest_length=scale * np.asarray(model.rest_length))
    res = solve_static(shrunk)
    assert _similarity_error(res.positions, lat.network.nodes, scale) < 1e-6

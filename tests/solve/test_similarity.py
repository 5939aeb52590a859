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
from rotomorph.materials.material import get_material
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


def test_pure_lce_arc_turns_by_its_metric_not_by_its_shrinkage():
    # a pure-LCE arc whose director follows the arc contracts along it (ε∥) and swells across
    # it (ε⊥): concentric fibres all shorten by the same factor while their spacing grows, so
    # the arc's turning angle becomes θ (1 + ε∥)/(1 + ε⊥) (the in-plane metric; the curved-bar
    # section gives it to first order, θ (1 + ε∥ − ε⊥)). An earlier bug multiplied the
    # per-length curvature by the shortened length instead, θ e^ε∥: 1.5 -> 1.197 rad.
    path = Path.from_segments([Arc(4.0, 1.5)], spacing=0.05)
    # a nozzle that turns with the heading (constant interface angle): no director helix,
    # hence no eigen-twist
    program = PrintProgram.from_interface_angle(path, 3.0, 0.0, active_fraction=1.0)
    assert np.allclose(program.director_rotation, 0.0)
    fm = FilamentModel()
    field = natural_field(program, temperature=175.0, model=fm)
    assert np.all(field.axial_strain < -0.1)  # the LCE contracts along its director
    lce, acrylate = get_material("lce"), get_material("acrylate")
    e_par, e_perp, _ = fm.strains_at(np.array([3.0]), lce, acrylate, 175.0)
    e_par, e_perp = float(e_par[0]), float(e_perp[0])
    assert e_perp > 0.0 > e_par

    def turning(x: np.ndarray) -> float:
        t0, t1 = x[1] - x[0], x[-1] - x[-2]
        return float(np.arctan2(np.cross(t0, t1)[2], np.dot(t0, t1)))

    x = solve_static(Model.from_field(program.points, field)).positions
    printed = turning(program.points)
    assert printed == pytest.approx(1.5, rel=0.02)
    # first order in the strains (the section theory's order; the exact metric factor
    # (1 + e_par)/(1 + e_perp) differs at second order, about 3 % here)
    assert turning(x) == pytest.approx(printed * (1.0 + e_par - e_perp), rel=1e-3)
    assert abs(turning(x) - printed * np.exp(e_par)) > 0.05  # not the shrinkage bug


def test_uniform_rest_length_change_of_a_lattice_is_a_similarity():
    # branched: junction pairs and rod vertices keep their natural angles
    lat = sinusoidal_lattice(3, 5.0, 1.25, 6, "expanding")
    model = lattice_model(lat).model
    scale = 0.8
    shrunk = model.with_natural(rest_length=scale * np.asarray(model.rest_length))
    res = solve_static(shrunk)
    assert _similarity_error(res.positions, lat.network.nodes, scale) < 1e-6

"""Saint-Venant torsion FEM and natural twist (reference values; benchmarks X6, X9, X10)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad

from rotomorph.materials.closed_form import full_disk_twist, twist_profile_factor
from rotomorph.materials.janus import filament_section
from rotomorph.materials.mesh import disk_mesh
from rotomorph.materials.section import phase_constant
from rotomorph.materials.torsion import torsion_section

R = 0.3
SEMICIRCLE = math.pi / 2 - 4 / math.pi  # 0.297557


def _semicircle_error(n: int) -> float:
    ts = torsion_section(disk_mesh(R, 0.5, n), phase_constant(1.0, 1e-9))
    return ts.torsion_constant / (SEMICIRCLE * R**4) - 1.0


def test_x6_semicircle_torsion_constant_converges() -> None:
    assert SEMICIRCLE == pytest.approx(0.297557, abs=1e-6)
    coarse, fine = _semicircle_error(48), _semicircle_error(96)
    assert abs(fine) < 0.01
    assert math.log2(abs(coarse) / abs(fine)) > 1.5  # O(h^2) convergence


def test_homogeneous_disk_has_no_warping() -> None:
    ts = torsion_section(disk_mesh(R, 0.5, 96), 2.0)
    assert ts.torsion_constant == pytest.approx(2.0 * math.pi * R**4 / 2, rel=2e-3)
    assert np.ptp(ts.warping) < 1e-10


def test_x9_linear_eigenshear_gives_exact_twist() -> None:
    ts = torsion_section(disk_mesh(R, 0.3, 64), 1.0)
    g0 = 1.7
    tau = ts.natural_twist(lambda xy, a: g0 * np.column_stack([-xy[:, 1], xy[:, 0]]))
    assert tau == pytest.approx(g0, rel=1e-6)


def test_x10_twist_profile_factor() -> None:
    assert twist_profile_factor(1.0) == pytest.approx(1 - math.log(2), abs=1e-12)
    assert twist_profile_factor(2.0) == pytest.approx(0.5 - math.log(5) / 8, abs=1e-12)
    assert twist_profile_factor(-2.0) == pytest.approx(-twist_profile_factor(2.0))
    assert twist_profile_factor(1e-4) == pytest.approx(0.5e-4, rel=1e-7)
    assert twist_profile_factor(0.9999e-3) == pytest.approx(
        twist_profile_factor(1.0001e-3), rel=1e-3
    )
    # independent quadrature of g(w) = int_0^1 u^2 sin(2 phi(u)) du, tan phi = w u
    for w in (0.25, 1.0, 2.0):
        exact = quad(lambda u, w=w: u * u * 2 * w * u / (1 + (w * u) ** 2), 0, 1)[0]
        assert twist_profile_factor(w) == pytest.approx(exact, rel=1e-12)
    # broad maximum g = 0.3190 at w = 1.348 (the notes' "~1.5" is slightly off)
    w = np.linspace(0.5, 3, 2501)
    assert w[np.argmax(twist_profile_factor(w))] == pytest.approx(1.348, abs=0.002)
    assert twist_profile_factor(1.348) == pytest.approx(0.3190, abs=1e-4)


@pytest.mark.parametrize("omega_star", [0.25, 1.0, 2.0, -1.0])
def test_pure_lce_twist_fem_vs_closed_form(omega_star: float) -> None:
    sec = filament_section(R, 1.0, 1.0, active_fraction=1.0, resolution=96)
    ep, et = -0.2131, 0.1065
    _, kappa, tau = sec.natural_strains(omega_star, ep, et, 0.0)
    assert tau[0] == pytest.approx(full_disk_twist(omega_star, ep - et, R), rel=2e-3)
    assert np.sign(tau[0]) == -np.sign(omega_star)  # untwisting sense
    np.testing.assert_allclose(kappa, 0.0, atol=1e-8)


# reference FEM table: m, C/[(Ga+Gp) pi R^4/4], C/(Gp R^4), twist factor f_tau
TORSION_TABLE = [
    (1, 1.000, 1.571, 0.500),
    (2, 0.931, 2.194, 0.568),
    (10, 0.585, 5.050, 0.766),
    (52.05, 0.425, 17.69, 0.929),
]


@pytest.mark.parametrize(("m", "c_norm", "c_gp", "f_tau"), TORSION_TABLE)
def test_janus_torsion_table(m: float, c_norm: float, c_gp: float, f_tau: float) -> None:
    ts = torsion_section(disk_mesh(R, 0.5, 96), phase_constant(m, 1.0))
    assert ts.torsion_constant / ((m + 1) * math.pi * R**4 / 4) == pytest.approx(c_norm, rel=3e-3)
    assert ts.torsion_constant / R**4 == pytest.approx(c_gp, rel=3e-3)
    g0 = 0.8
    tau = ts.natural_twist(
        lambda xy, a: np.where(a[:, None], g0 * np.column_stack([-xy[:, 1], xy[:, 0]]), 0.0)
    )
    assert tau / g0 == pytest.approx(f_tau, abs=2e-3)


def test_torsion_is_solved_only_for_states_with_eigen_shear() -> None:
    # print states without a director helix (omega* = 0) have no eigen-shear: no natural
    # twist, and the warping problem is not solved for them; a helix needs it and gets the
    # torsion FEM's twist
    section = filament_section(0.3, 7.3, 1.1)  # moduli of its own: a fresh cached section
    _, _, dtau = section.natural_strains(0.0, -0.2, 0.1, 0.01)
    assert dtau[0] == 0.0 and "torsion" not in section.__dict__
    _, _, dtau = section.natural_strains(0.7, -0.2, 0.1, 0.01)
    assert "torsion" in section.__dict__
    _, gamma = section.eigenfields(0.7, -0.2, 0.1, 0.01)
    np.testing.assert_allclose(dtau, section.torsion.natural_twist(gamma), rtol=1e-14)
    assert abs(dtau[0]) > 1e-3
    assert section.twist_stiffness == section.torsion.torsion_constant > 0

"""The curved-bar section against plane-stress elasticity of a curved bilayer strip.

An annular sector (inner radius ρ − h/2, outer ρ + h/2) of two layers with in-plane eigenstrains
(active: ε∥ along the strip, ε⊥ across it; passive: ε_p both ways) is solved as a plane-stress
elasticity problem, axisymmetric: radial displacement u(r) by linear finite elements and one
uniform opening strain δ of the sector angle (ε_θθ = u/r + δ), so the change of turning per
printed length of the centre line is δ/ρ. No plane sections and no transverse-dilation
assumption enter; the curved-bar formula of ``AxialSection.natural_curved`` must agree with it
to a few per cent of the straight bilayer's curvature, and dropping its transverse term must
not.
"""

from __future__ import annotations

import numpy as np
import pytest

from rotomorph.materials.mesh import SectionMesh, rectangle_mesh
from rotomorph.materials.section import axial_section, phase_constant

E_A, E_P, NU = 2.1, 1.0, 0.5
EPS_PAR, EPS_PERP, EPS_P = -0.173, 0.087, 0.031
H = 0.6  # strip thickness in the bending plane (mm), like a filament's diameter


def _elastic_turning_change(rho: float, active_inner: bool, n: int = 400) -> float:
    """δ/ρ of the plane-stress annular bilayer (1/mm; > 0: the sector turns more)."""
    r = np.linspace(rho - H / 2, rho + H / 2, n + 1)
    ndof = n + 2  # nodal u, then δ
    k = np.zeros((ndof, ndof))
    f = np.zeros(ndof)
    gauss = np.array([-1.0, 1.0]) / np.sqrt(3.0)
    for e in range(n):
        r0, r1 = r[e], r[e + 1]
        length = r1 - r0
        for g in gauss:
            rr = 0.5 * (r0 + r1) + 0.5 * length * g
            weight = 0.5 * length * rr  # area element r dr (per unit angle and width)
            active = rr < rho if active_inner else rr > rho
            modulus = E_A if active else E_P
            eig = np.array([EPS_PERP, EPS_PAR]) if active else np.array([EPS_P, EPS_P])
            b = np.zeros((2, ndof))
            b[0, e], b[0, e + 1] = -1.0 / length, 1.0 / length  # ε_rr = u'
            b[1, e], b[1, e + 1] = (r1 - rr) / (length * rr), (rr - r0) / (length * rr)
            b[1, -1] = 1.0  # ε_θθ = u/r + δ
            c = modulus / (1.0 - NU**2) * np.array([[1.0, NU], [NU, 1.0]])
            k += weight * b.T @ c @ b
            f += weight * b.T @ c @ eig
    d = np.linalg.solve(k, f)
    # the sector's angle becomes θ (1 + δ): the turning per printed length changes by δ/ρ
    return float(d[-1] / rho)


def _section(active_inner: bool):  # type: ignore[no-untyped-def]
    # layers along x1 from -H/2; the centre of curvature lies toward +x1 (k0 = (+k, 0)), so
    # the layer at x1 > 0 is the inner one
    raw = rectangle_mesh(0.6, (H / 2, H / 2), active_layer=1 if active_inner else 0, n=24)
    mesh = SectionMesh(raw.points - np.array([H / 2, 0.0]), raw.triangles, raw.active)
    ax = axial_section(mesh, phase_constant(E_A, E_P))
    eps = np.where(ax.active, EPS_PAR, EPS_P)[None, :]
    ew = ax.modulus * ax.weights
    turner = float(np.where(ax.active, EPS_PERP, EPS_P) @ ew / ew.sum())
    return ax, eps, turner


@pytest.mark.parametrize("k0r", [0.3, 0.5])
@pytest.mark.parametrize("active_inner", [True, False])
def test_curved_bar_matches_plane_stress_elasticity(k0r: float, active_inner: bool) -> None:
    ax, eps, turner = _section(active_inner)
    straight = float(np.linalg.norm(ax.natural_curvature(eps)[0]))
    k0 = k0r / (H / 2)
    exact = _elastic_turning_change(1.0 / k0, active_inner)
    _, dk = ax.natural_curved(eps, np.array([[k0, 0.0]]), np.array([turner]))
    assert abs(dk[0, 0] - exact) < 0.04 * straight
    # the asymmetry is real: inner curls less, outer straightens more than a straight bar
    if active_inner:
        assert 0.0 < exact < 0.8 * straight
    else:
        assert exact < -1.15 * straight
    # and the transverse dilation is needed to get it
    _, no_dilation = ax.natural_curved(eps, np.array([[k0, 0.0]]), np.zeros(1))
    assert abs(no_dilation[0, 0] - exact) > 0.1 * straight

"""Finite-strain (neo-Hookean) section: derivatives, small-strain limit, closed forms."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import root

from rotomorph.errors import InvalidParameterError
from rotomorph.materials import FilamentModel, filament_section
from rotomorph.materials.finite_section import (
    FibreQuadrature,
    fibre_energy,
    minimise,
    natural_state,
    tangent_bending_matrix,
)
from rotomorph.materials.janus import with_law
from rotomorph.materials.material import get_material
from rotomorph.materials.stack import stack_section

R = 0.3
EA, EP = 40.0, 1.0


def bilayer(h1: float, h2: float, e1: float, e2: float, n: int = 2000) -> FibreQuadrature:
    """Midpoint quadrature of a unit-width bilayer: layer 1 on x1 ∈ (0, h1), layer 2 on
    (−h2, 0), two columns x2 = ±1/4 (so that bending toward m2 is not singular)."""
    y1 = (np.arange(n) + 0.5) / n * h1
    y2 = -(np.arange(n) + 0.5) / n * h2
    x1 = np.concatenate([y1, y2])
    w = np.concatenate([np.full(n, h1 / n), np.full(n, h2 / n)]) / 2.0
    e = np.concatenate([np.full(n, e1), np.full(n, e2)])
    pts = np.vstack([np.column_stack([x1, np.full(2 * n, s)]) for s in (-0.25, 0.25)])
    w2, e2_ = np.concatenate([w, w]), np.concatenate([e, e])
    c = (e2_ * w2) @ pts / np.sum(e2_ * w2)
    return FibreQuadrature(pts, w2, e2_, c)


def timoshenko(h1: float, h2: float, e1: float, e2: float, d_eps: float) -> float:
    """Timoshenko (1925): κ = 6 Δε (1 + m)² / (h (3 (1 + m)² + (1 + m n)(m² + 1/(m n))))."""
    m, n, h = h1 / h2, e1 / e2, h1 + h2
    return 6 * d_eps * (1 + m) ** 2 / (h * (3 * (1 + m) ** 2 + (1 + m * n) * (m**2 + 1 / (m * n))))


def layer_values(q: FibreQuadrature, top: float, bottom: float) -> np.ndarray:
    return np.where(q.points[:, 0] > 0.0, top, bottom)[None, :]


def test_gradient_and_hessian_match_finite_differences() -> None:
    rng = np.random.default_rng(3)
    q = bilayer(0.4, 0.6, 30.0, 1.0, n=40)
    lam = rng.uniform(0.6, 1.2, (1, len(q.points)))
    vol = rng.uniform(0.8, 1.2, (1, len(q.points)))
    k0 = np.array([[0.3, -0.2]])
    y = np.array([[0.95, 0.4, -0.1]])
    _, g, h = fibre_energy(y, q, lam, vol, k0)
    step = 1e-6
    for i in range(3):
        d = np.zeros((1, 3))
        d[0, i] = step
        ep, gp, _ = fibre_energy(y + d, q, lam, vol, k0)
        em, gm, _ = fibre_energy(y - d, q, lam, vol, k0)
        assert (ep - em)[0] / (2 * step) == pytest.approx(g[0, i], rel=1e-7, abs=1e-10)
        np.testing.assert_allclose((gp - gm)[0] / (2 * step), h[0, i], rtol=1e-6, atol=1e-9)


def test_timoshenko_bimetal_in_the_small_strain_limit() -> None:
    h1, h2, e1, e2 = 0.4, 0.6, 5.0, 1.0
    q = bilayer(h1, h2, e1, e2)
    for d_eps in (1e-4, 1e-3):
        lam = layer_values(q, np.exp(-d_eps), 1.0)  # layer 1 shortens: bends toward +x1
        y = minimise(q, lam, np.ones_like(lam), np.zeros((1, 2)))
        _, k = natural_state(y, q, np.zeros((1, 2)), np.ones(1))
        exact = timoshenko(h1, h2, e1, e2, d_eps)
        assert k[0, 0] == pytest.approx(exact, rel=3 * d_eps)
        assert abs(k[0, 1]) < 1e-9 * exact


def _bilayer_exact(h1: float, h2: float, mu: tuple[float, float], lam: tuple[float, float]):
    """(a, G) of the neo-Hookean bilayer from the closed-form layer integrals of
    Φ'(s) = s − s⁻² with s = (a − G y)/λ linear in y (per unit width)."""

    def residual(v: np.ndarray) -> list[float]:
        a, g = v
        force = moment = 0.0
        for (y0, y1), m, lm in zip(((0.0, h1), (-h2, 0.0)), mu, lam, strict=True):
            s0, s1 = (a - g * y0) / lm, (a - g * y1) / lm
            p = (s0**2 / 2 + 1 / s0) - (s1**2 / 2 + 1 / s1)  # ∫Φ' dy = (λ/G)[..]_{s1}^{s0}
            r = a * p - lm * ((s0**3 / 3 - np.log(s0)) - (s1**3 / 3 - np.log(s1)))
            force += m / lm * (lm / g) * p
            moment += m / lm * (lm / g**2) * r  # ∫ y Φ'(s) dy
        return [force, moment]

    sol = root(residual, [0.5 * sum(lam), 0.5], tol=1e-15)
    assert sol.success
    return sol.x


def test_neo_hookean_bilayer_matches_its_semi_analytic_solution_at_finite_strain() -> None:
    h1, h2, e1, e2 = 0.5, 0.5, 20.0, 1.0
    lam1, lam2 = 0.6, 1.05  # 40 % contraction of the active layer
    q = bilayer(h1, h2, e1, e2, n=3000)
    lam = layer_values(q, lam1, lam2)
    y = minimise(q, lam, np.ones_like(lam), np.zeros((1, 2)))
    a, g = _bilayer_exact(h1, h2, (e1 / 3, e2 / 3), (lam1, lam2))
    assert y[0, 0] == pytest.approx(a, rel=1e-7)
    assert y[0, 1] == pytest.approx(g, rel=1e-6)
    # and this is far outside the linear section: Timoshenko with Hencky strains differs
    linear = timoshenko(h1, h2, e1, e2, float(np.log(lam2) - np.log(lam1)))
    assert abs(g / linear - 1.0) > 0.05


def test_reduces_to_the_linear_section_with_second_order_error() -> None:
    model = FilamentModel(resolution=48)
    e_par, e_perp, eps_p = model.strains(3.0, get_material("acrylate"))
    lin = filament_section(R, EA, EP, resolution=48)
    nh = with_law(lin, "neo-hookean", "hencky")
    errors, sizes = [], []
    for scale in (0.02, 0.01, 0.005):
        state = (0.0, scale * float(e_par), scale * float(e_perp), scale * eps_p)
        k_lin = lin.natural_strains(*state)[1][0, 0]
        k_nh = nh.natural_strains(*state)[1][0, 0]
        errors.append(abs(k_nh - k_lin))
        sizes.append(abs(k_lin))
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    np.testing.assert_allclose(orders, 2.0, atol=0.1)  # relative error of order 1 in ε
    assert errors[-1] / sizes[-1] < 0.01


def test_uniform_isotropic_eigenstretch_on_a_curved_bar_is_a_similarity() -> None:
    nh = with_law(filament_section(R, EA, EP, resolution=48), "neo-hookean", "hencky")
    k0 = np.array([[0.8, -0.5]])
    eps_c, dkappa = nh.curved_strains(0.4, 0.1, 0.1, 0.1, k0)
    assert eps_c[0] == pytest.approx(0.1, abs=1e-12)
    np.testing.assert_allclose(dkappa, 0.0, atol=1e-11)


def test_curved_section_at_zero_printed_curvature_is_the_straight_one() -> None:
    nh = with_law(filament_section(R, EA, EP, resolution=48), "neo-hookean", "hencky")
    state = (0.0, -0.35, 0.2, 0.05)
    straight = nh.natural_strains(*state)
    curved = nh.curved_strains(*state, np.array([[1e-9, 0.0]]))
    assert curved[0][0] == pytest.approx(straight[0][0], abs=1e-9)
    np.testing.assert_allclose(curved[1], straight[1], atol=1e-8)


def test_tangent_stiffness_at_zero_eigenstrain_is_the_linear_bending_matrix() -> None:
    lin = filament_section(R, EA, EP, resolution=48)
    q = with_law(lin, "neo-hookean", "hencky").fibre_quadrature()
    ones = np.ones((1, len(q.points)))
    y = minimise(q, ones, ones, np.zeros((1, 2)))
    b = tangent_bending_matrix(y, q, ones, ones, np.zeros((1, 2)))[0]
    np.testing.assert_allclose(b, lin.axial.bending_matrix, rtol=1e-10, atol=1e-12)


def test_finite_strain_softens_the_curl_of_a_strongly_contracting_janus_section() -> None:
    # a stiff active half contracting by a third: the passive half it compresses stiffens
    # (Φ'' = 1 + 2/s³ > 3 for s < 1) and the section's lateral dilation lengthens the lever
    lin = filament_section(R, EA, EP, resolution=48)
    nh = with_law(lin, "neo-hookean", "hencky")
    state = (0.0, -0.4, 0.2, 0.0)
    ratio = nh.natural_strains(*state)[1][0, 0] / lin.natural_strains(*state)[1][0, 0]
    assert 0.3 < ratio < 0.9


def test_model_option_selects_the_section_law() -> None:
    lce, acr = get_material("lce"), get_material("acrylate")
    linear = FilamentModel(resolution=48).section(lce, acr, R, 0.5)
    finite = FilamentModel(resolution=48, section_model="neo-hookean").section(lce, acr, R, 0.5)
    assert linear.law == "linear" and finite.law == "neo-hookean"
    assert finite.bending_stiffness1 == linear.bending_stiffness1
    with pytest.raises(InvalidParameterError, match="section_model"):
        FilamentModel(section_model="mooney")  # type: ignore[arg-type]


def test_stacked_section_uses_the_unfolded_quadrature() -> None:
    folded = stack_section(R, 3, 2 * R, EA, EP, resolution=32)
    nh = with_law(folded, "neo-hookean", "hencky")
    assert nh.axial.folded_moment is None
    state = (0.0, -0.004, 0.002, 0.0005)
    np.testing.assert_allclose(
        nh.natural_strains(*state)[1], folded.natural_strains(*state)[1], rtol=2e-2, atol=1e-8
    )


def test_the_strain_measure_only_relabels_the_same_stretches() -> None:
    sec = filament_section(R, EA, EP, resolution=48)
    hencky, engineering = (
        with_law(sec, "neo-hookean", "hencky"),
        with_law(sec, "neo-hookean", "engineering"),
    )
    stretches = np.array([0.7, 1.15, 1.04])  # λ∥, λ⊥, λ_p
    eps_h, k_h, _ = hencky.natural_strains(0.5, *np.log(stretches))
    eps_e, k_e, _ = engineering.natural_strains(0.5, *(stretches - 1.0))
    assert np.exp(eps_h[0]) == pytest.approx(1.0 + eps_e[0], rel=1e-12)
    np.testing.assert_allclose(k_h, k_e, rtol=1e-10, atol=1e-14)


def test_nearly_unactuated_states_converge_to_the_linear_values() -> None:
    # the start of a heating ramp: eigenstrains near round-off of the energy
    lin = filament_section(R, EA, EP, resolution=48)
    nh = with_law(lin, "neo-hookean", "hencky")
    for scale in (1e-5, 1e-8):
        state = (0.0, -0.4 * scale, 0.2 * scale, 0.03 * scale)
        eps_lin, k_lin, _ = lin.natural_strains(*state)
        eps_nh, k_nh, _ = nh.natural_strains(*state)
        assert eps_nh[0] == pytest.approx(eps_lin[0], rel=1e-3)
        assert k_nh[0, 0] == pytest.approx(k_lin[0, 0], rel=1e-3)

"""A section printed on a curved path: the curved-bar (Winkler) natural strains.

Checks the closed linear solve against a direct numerical minimisation of the same energy, the
straight limit, the similarity of a uniform isotropic eigenstrain and the asymmetry between an
active phase on the inner and on the outer side.
"""

from __future__ import annotations

import logging
from types import SimpleNamespace

import numpy as np
import pytest
from scipy.optimize import minimize

from rotomorph.errors import InvalidParameterError
from rotomorph.materials.janus import filament_section
from rotomorph.materials.natural import CURVATURE_LIMIT, printed_curvature

RADIUS = 0.3


@pytest.fixture(scope="module")
def section():  # type: ignore[no-untyped-def]
    return filament_section(RADIUS, 2.0, 1.0)


def _janus_eigenstrain(section, eps=-0.2):  # type: ignore[no-untyped-def]
    return np.where(section.axial.active, eps, 0.0)[None, :]


@pytest.mark.parametrize("k0", [(1.5, 0.0), (-2.0, 0.5), (0.7, -1.9)])
def test_linear_solve_minimises_the_curved_bar_energy(section, k0) -> None:  # type: ignore[no-untyped-def]
    ax = section.axial
    eps = _janus_eigenstrain(section)[0]
    k = np.asarray(k0)
    x = ax.points
    factor = 1.0 - x @ k
    ew = ax.modulus * ax.weights

    def energy(p: np.ndarray) -> float:
        strain = (p[0] - x @ p[1:]) / factor  # fibre strain, transverse dilation 0
        return float(0.5 * np.sum(ew * factor * (strain - eps) ** 2))

    best = minimize(energy, np.zeros(3), method="BFGS", options={"gtol": 1e-14}).x
    eps_c, dk = ax.natural_curved(eps[None, :], k[None, :], np.zeros(1))
    assert np.allclose(dk[0], best[1:], rtol=1e-6, atol=1e-7)
    # the returned strain is that of the fibre at the modulus-weighted centroid
    c = ax.centroid
    centroid_strain = (best[0] - best[1:] @ c) / (1.0 - k @ c)
    assert eps_c[0] == pytest.approx(centroid_strain, rel=1e-6, abs=1e-8)


def test_straight_limit_is_the_straight_section(section) -> None:  # type: ignore[no-untyped-def]
    ax = section.axial
    eps = _janus_eigenstrain(section)
    eps_c, dk = ax.natural_curved(eps, np.zeros((1, 2)), np.array([0.05]))
    assert eps_c[0] == pytest.approx(float(ax.natural_strain(eps)[0]), rel=1e-12)
    assert np.allclose(dk, ax.natural_curvature(eps), rtol=1e-10, atol=1e-14)
    # and the filament section returns the straight values bit for bit at k0 = 0
    straight = section.natural_strains(0.3, -0.25, 0.12, 0.02)
    curved = section.curved_strains(0.3, -0.25, 0.12, 0.02, np.zeros((1, 2)))
    assert np.array_equal(curved[0], straight[0]) and np.array_equal(curved[1], straight[1])


def test_anisotropic_uniform_eigenstrain_turns_by_the_metric(section) -> None:  # type: ignore[no-untyped-def]
    # fibres all shorten by 1 + e_par while the section widens by 1 + e_t: the bar turns
    # through (1 + e_par)/(1 + e_t) times its printed angle, 1 + e_par - e_t to first order
    ax = section.axial
    e_par, e_t = -0.2, 0.1
    k0 = np.array([[1.2, -0.5]])
    eps = np.full((1, len(ax.points)), e_par)
    _, dk = ax.natural_curved(eps, k0, np.array([e_t]))
    assert np.allclose(k0 + dk, k0 * (1 + e_par - e_t), rtol=1e-12)


@pytest.mark.parametrize("k0", [(2.0, 0.0), (-1.0, 2.2)])
def test_uniform_isotropic_eigenstrain_is_a_similarity(section, k0) -> None:  # type: ignore[no-untyped-def]
    ax = section.axial
    e = -0.15
    eps = np.full((1, len(ax.points)), e)
    eps_c, dk = ax.natural_curved(eps, np.asarray(k0, dtype=float)[None, :], np.array([e]))
    assert eps_c[0] == pytest.approx(e, rel=1e-12)
    assert np.allclose(dk, 0.0, atol=1e-12)  # turning per printed length unchanged


def test_inner_active_curls_less_and_outer_active_straightens_more(section) -> None:  # type: ignore[no-untyped-def]
    args = (0.0, -0.3, 0.15, 0.03)
    _, straight, _ = section.natural_strains(*args)
    k_straight = float(straight[0, 0])  # toward the active side (m1 = n), > 0
    assert k_straight > 0.0
    k0 = 0.5 / RADIUS
    _, inner = section.curved_strains(*args, np.array([[k0, 0.0]]))  # centre on active side
    _, outer = section.curved_strains(*args, np.array([[-k0, 0.0]]))
    assert 0.0 < inner[0, 0] < 0.8 * k_straight
    assert outer[0, 0] > 1.2 * k_straight
    # mirror symmetry of the half-and-half section: no curvature across the interface normal
    assert abs(inner[0, 1]) < 1e-9 and abs(outer[0, 1]) < 1e-9


def test_fibre_of_negative_length_is_refused(section) -> None:  # type: ignore[no-untyped-def]
    eps = _janus_eigenstrain(section)
    with pytest.raises(InvalidParameterError, match="curvature"):
        section.axial.natural_curved(eps, np.array([[1.5 / RADIUS, 0.0]]), np.zeros(1))


def test_printed_curvature_of_a_circle_and_a_sharp_corner(section, caplog) -> None:  # type: ignore[no-untyped-def]
    rho = 2.0
    s = np.linspace(0.0, 1.0, 41)
    circle = np.column_stack([rho * np.cos(s), rho * np.sin(s), np.zeros_like(s)])
    k0 = printed_curvature(SimpleNamespace(points=circle), section)
    assert np.allclose(np.linalg.norm(k0, axis=1), 1.0 / rho, rtol=1e-3)
    centre = -circle[1:-1] / rho  # toward the centre of curvature
    assert np.allclose(k0 * rho, centre, atol=1e-3)
    corner = np.array([[0.0, 0.0, 0.0], [0.1, 0.0, 0.0], [0.1, 0.1, 0.0]])
    with caplog.at_level(logging.WARNING, logger="rotomorph.materials.natural"):
        k = printed_curvature(SimpleNamespace(points=corner), section)
    assert np.linalg.norm(k[0]) * section.radius == pytest.approx(CURVATURE_LIMIT)
    assert "sharply" in caplog.text


def test_curved_states_survive_a_full_straight_memory(section, monkeypatch) -> None:  # type: ignore[no-untyped-def]
    # solving the straight rows of a batch may clear the straight states' memory; the curved
    # states are remembered apart, so a large mixed call still finds every one of its rows
    import rotomorph.materials.janus as janus

    monkeypatch.setattr(janus, "SOLVED_STATES_LIMIT", 700)
    n = 1200
    k0 = np.zeros((n, 2))
    k0[1::2, 0] = np.linspace(0.1, 2.0, n // 2)
    eps_par = np.linspace(-0.3, -0.1, n)
    eps_c, dk = section.curved_strains(0.0, eps_par, 0.1, 0.02, k0)
    assert eps_c.shape == (n,) and dk.shape == (n, 2) and np.all(np.isfinite(dk))


def test_a_rows_result_does_not_depend_on_its_batch(section) -> None:  # type: ignore[no-untyped-def]
    # a lattice's print states are solved in batches whose make-up depends on what was solved
    # before (the states are remembered): each row must come out bit for bit the same alone,
    # in any batch and at any position, or results depend on the order of earlier solves
    rng = np.random.default_rng(7)
    ax = section.axial
    n = 13
    eps = np.where(ax.active, rng.uniform(-0.3, 0.1, (n, 1)), rng.uniform(-0.05, 0.05, (n, 1)))
    k0 = rng.uniform(-1.5, 1.5, (n, 2))
    t = rng.uniform(-0.05, 0.1, n)
    whole = ax.natural_curved(eps, k0, t)
    order = rng.permutation(n)
    shuffled = ax.natural_curved(eps[order], k0[order], t[order])
    for i in range(n):
        alone = ax.natural_curved(eps[i : i + 1], k0[i : i + 1], t[i : i + 1])
        assert alone[0][0] == whole[0][i] and np.array_equal(alone[1][0], whole[1][i])
    assert np.array_equal(shuffled[0], whole[0][order])
    assert np.array_equal(shuffled[1], whole[1][order])
    # and the Janus section's curved states (Turner's transverse strain included), solved as
    # one batch and then one by one with its memory of solved states emptied in between
    states = (rng.uniform(0.0, 0.5, n), rng.uniform(-0.4, -0.1, n), rng.uniform(0.0, 0.2, n))
    janus = filament_section(RADIUS, 2.0, 1.5)
    janus._curved.clear()
    batch = janus.curved_strains(*states, np.zeros(n), k0)
    for i in range(n):
        janus._curved.clear()
        one = janus.curved_strains(*(s[i] for s in states), 0.0, k0[i : i + 1])
        assert one[0][0] == batch[0][i] and np.array_equal(one[1][0], batch[1][i])

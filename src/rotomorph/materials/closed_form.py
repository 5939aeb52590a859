r"""Closed-form Janus and pure-LCE section results, checked by quadrature/FEM.

Janus disk of radius R (mm): active half-disk ξ > 0 (ξ along the interface normal n), passive
half ξ < 0, moduli E_a, E_p (MPa), ratio m = E_a/E_p. Half-disk moments: ∫ξ dA = 2R³/3,
∫ξ² dA = ∫η² dA = πR⁴/8 (semicircle centroid 4R/(3π)). All results follow from the general
section formulas of :mod:`rotomorph.materials.section` (Timoshenko 1925 generalised):

* A_E = (E_a + E_p) πR²/2,   ξ_c = (4R/3π)(E_a − E_p)/(E_a + E_p)
* B_n = (E_a + E_p) πR⁴/8 − 8R⁴(E_a − E_p)²/[9π(E_a + E_p)],   B_η = (E_a + E_p) πR⁴/8
* uniform eigenstrains, Δε = ε_p − ε_a: K_J = (Δε/R) f(m), f(m) = 96πm/[9π²(1+m)² − 64(m−1)²]
  (f(1) = 8/(3π), f(m) = f(1/m))
* helical director tan φ = ω* r/R (ε*_zz = ε⊥ + Δ cos²φ, Δ = ε∥ − ε⊥):
  K_J = (2R³/3)[E_a²(ε̄_a − ε̃_a) + E_a E_p(2ε_p − ε̄_a − ε̃_a)]/[(E_a + E_p) B_n], with
  ε̄_a = ε⊥ + Δ h0(ω*²), ε̃_a = ε⊥ + Δ h1(ω*²), h0(a) = ln(1+a)/a, h1(a) = 3[1 − atan√a/√a]/a
* homogeneous full disk, γ* = Δ sin 2φ(r): τ̄ = (4/R⁴)∫r²γ* dr = (4Δ/R) g(ω*),
  g(w) = 1/w − ln(1+w²)/w³ (g(1) = 1 − ln 2, g(2) = 1/2 − ln 5/8)

Timoshenko, S., "Analysis of bi-metal thermostats", J. Opt. Soc. Am. 11, 233 (1925).
"""

from __future__ import annotations

import numpy as np

from rotomorph._typing import FloatArray
from rotomorph.errors import InvalidParameterError

_SMALL = 1e-3


def _pos(name: str, x: float | FloatArray) -> FloatArray:
    arr = np.asarray(x, dtype=float)
    if not np.all(np.isfinite(arr)) or np.any(arr <= 0.0):
        raise InvalidParameterError(name, f"must be finite and > 0; got {x!r}")
    return arr


def janus_axial_stiffness(e_active: float, e_passive: float, radius: float) -> FloatArray:
    """A_E = (E_a + E_p) π R²/2 (N) for moduli in MPa and radius in mm."""
    return (
        (_pos("e_active", e_active) + _pos("e_passive", e_passive))
        * np.pi
        * _pos("radius", radius) ** 2
        / 2
    )


def janus_centroid(e_active: float, e_passive: float, radius: float) -> FloatArray:
    """Modulus-weighted centroid offset ξ_c (mm) along n (toward the active half)."""
    ea, ep = _pos("e_active", e_active), _pos("e_passive", e_passive)
    return 4.0 * _pos("radius", radius) / (3.0 * np.pi) * (ea - ep) / (ea + ep)


def janus_bending_stiffness(
    e_active: float, e_passive: float, radius: float
) -> tuple[FloatArray, FloatArray]:
    """(B_n, B_η) (N·mm²): bending toward ±n (pairs with m1 = n) and toward ±(t × n)."""
    ea, ep, r = _pos("e_active", e_active), _pos("e_passive", e_passive), _pos("radius", radius)
    b_eta = (ea + ep) * np.pi * r**4 / 8.0
    return b_eta - 8.0 * r**4 * (ea - ep) ** 2 / (9.0 * np.pi * (ea + ep)), b_eta


def curvature_factor(modulus_ratio: float | FloatArray) -> FloatArray:
    """f(m) = K_J R/Δε = 96πm/[9π²(1+m)² − 64(m−1)²] (dimensionless; f(1) = 8/(3π))."""
    m = _pos("modulus_ratio", modulus_ratio)
    return 96.0 * np.pi * m / (9.0 * np.pi**2 * (1.0 + m) ** 2 - 64.0 * (m - 1.0) ** 2)


def janus_curvature(
    strain_difference: float | FloatArray, modulus_ratio: float | FloatArray, radius: float
) -> FloatArray:
    """K_J = (Δε/R) f(m) (1/mm) toward the active side for uniform eigenstrains, Δε = ε_p − ε_a."""
    return (
        np.asarray(strain_difference, dtype=float)
        / _pos("radius", radius)
        * curvature_factor(modulus_ratio)
    )


def h0(a: float | FloatArray) -> FloatArray:
    """h0(a) = ln(1+a)/a (a = ω*² ≥ 0; h0(0) = 1): mean of cos²φ over the active half-disk."""
    aa = np.asarray(a, dtype=float)
    small = np.abs(aa) < _SMALL
    safe = np.where(small, 1.0, aa)
    return np.where(small, 1.0 - aa / 2.0 + aa**2 / 3.0, np.log1p(safe) / safe)


def h1(a: float | FloatArray) -> FloatArray:
    """h1(a) = 3[1 − atan(√a)/√a]/a (a = ω*² ≥ 0; h1(0) = 1): ξ-weighted mean of cos²φ."""
    aa = np.asarray(a, dtype=float)
    small = np.abs(aa) < _SMALL
    safe = np.where(small, 1.0, aa)
    s = np.sqrt(safe)
    return np.where(
        small, 1.0 - 3.0 * aa / 5.0 + 3.0 * aa**2 / 7.0, 3.0 * (1.0 - np.arctan(s) / s) / safe
    )


def janus_curvature_helical(
    omega_star: float | FloatArray,
    eps_parallel: float | FloatArray,
    eps_perpendicular: float | FloatArray,
    eps_passive: float | FloatArray,
    e_active: float,
    e_passive: float,
    radius: float,
) -> FloatArray:
    """K_J (1/mm) of a Janus disk with the kinematic helical director tan φ = ω* r/R.

    Parameters
    ----------
    omega_star
        Dimensionless rotation rate (the sign does not matter).
    eps_parallel, eps_perpendicular
        LCE free strains along / across the director (dimensionless).
    eps_passive
        Passive isotropic free strain (dimensionless).
    e_active, e_passive
        Moduli (MPa).
    radius
        R (mm).
    """
    ea, ep = float(_pos("e_active", e_active)), float(_pos("e_passive", e_passive))
    r = float(_pos("radius", radius))
    a = np.asarray(omega_star, dtype=float) ** 2
    delta = np.asarray(eps_parallel, dtype=float) - np.asarray(eps_perpendicular, dtype=float)
    mean = eps_perpendicular + delta * h0(a)
    moment = eps_perpendicular + delta * h1(a)
    b_n, _ = janus_bending_stiffness(ea, ep, r)
    num = ea * ea * (mean - moment) + ea * ep * (2.0 * np.asarray(eps_passive) - mean - moment)
    return 2.0 * r**3 / 3.0 * num / ((ea + ep) * b_n)


def twist_profile_factor(omega_star: float | FloatArray) -> FloatArray:
    """g(w) = 1/w − ln(1+w²)/w³ (dimensionless, odd; g ≈ w/2 for small w).

    Broad maximum g = 0.3190 at w ≈ 1.348 (checked by quadrature in the tests).
    """
    w = np.asarray(omega_star, dtype=float)
    small = np.abs(w) < _SMALL
    safe = np.where(small, 1.0, w)
    series = w / 2.0 - w**3 / 3.0 + w**5 / 4.0
    return np.where(small, series, 1.0 / safe - np.log1p(safe**2) / safe**3)


def full_disk_twist(
    omega_star: float | FloatArray, strain_anisotropy: float | FloatArray, radius: float
) -> FloatArray:
    """Natural twist τ̄ = (4Δ/R) g(ω*) (1/mm) of a homogeneous LCE disk, Δ = ε∥ − ε⊥.

    Negative Δ (contraction along the director) twists against the printed helix (untwisting).
    """
    return (
        4.0
        * np.asarray(strain_anisotropy, dtype=float)
        / _pos("radius", radius)
        * (twist_profile_factor(omega_star))
    )


def pure_lce_axial_strain(
    omega_star: float | FloatArray,
    eps_parallel: float | FloatArray,
    eps_perpendicular: float | FloatArray,
) -> FloatArray:
    """Natural axial strain of a homogeneous LCE filament: ε⊥ + Δ ln(1+ω*²)/ω*²."""
    delta = np.asarray(eps_parallel, dtype=float) - np.asarray(eps_perpendicular, dtype=float)
    return eps_perpendicular + delta * h0(np.asarray(omega_star, dtype=float) ** 2)

r"""Finite-strain (incompressible neo-Hookean) plane-section mechanics of an active section.

The linear section (:mod:`rotomorph.materials.section`) minimises ½∫E(ε − ε*)² dA, valid for
small fibre strains; a Janus filament at its peak curvature (\|κ̄\|·R ≈ 0.6) strains its outer
fibres by tens of per cent. This module keeps the same kinematics (plane sections, each fibre
in uniaxial stress) and the same moduli (no new parameter), and replaces the quadratic energy
by the incompressible neo-Hookean one of each fibre's elastic stretch:

=========  ===============================================================  ==========
symbol     definition                                                       unit
=========  ===============================================================  ==========
λ*         axial eigen-stretch of a fibre (free, stress-free stretch)       1
J*         det F*, natural volume per reference volume                      1
f          1 − k0·x, reference fibre length per printed centre-line length  1
a, G       centre-line stretch and rotation rate: λ(x) = (a − G·x)/f        1, 1/mm
s          λ/λ*, elastic stretch                                            1
μ          E/3, shear modulus of the incompressible solid                   MPa
Φ(s)       (s² + 2/s − 3)/2, uniaxial neo-Hookean energy per μ              1
U(a, G)    Σ_q w_q f_q J*_q μ_q Φ(s_q), energy per printed length           N
=========  ===============================================================  ==========

A fibre at x of the section (x from the geometric centre, mm) on a bar printed with curvature
k0 has reference length ∝ f = 1 − k0·x (Winkler's curved bar) and, after actuation, length
∝ a − G·x (the centre line turns by G per printed length in the frame of the reference
section). The section dilates in its plane by its modulus-weighted mean transverse stretch
s_t (Turner's rule, as the linear curved section), so the natural turning per printed length
is K = G / s_t; the elastic transverse contraction of each fibre is not carried into the
lever arm (elementary beam theory's approximation, at finite strain). U is strictly convex in
(a, G) (Φ'' = 1 + 2/s³ > 0, s linear in (a, G)), so Newton's method with a backtracking line
search on U finds its unique minimum. At small eigenstrain Φ(s) ≈ (3/2)(s − 1)², 3μ = E, and
the minimiser reduces to the linear section's ε_c and κ̄ with an error of second order in
the strains (the tests measure the order).

The eigen-deformation of the LCE is F* = λ⊥ I + (λ∥ − λ⊥) p⊗p (director p), so its axial
stretch is λ*² = λ⊥² + (λ∥² − λ⊥²) cos²φ, J* = λ∥ λ⊥², and its in-plane stretches are λ⊥
(radial) and √(λ⊥² + (λ∥² − λ⊥²) sin²φ) (azimuthal); the passive phase has λ* = λ_p,
J* = λ_p³. The natural twist is the linear torsion solution's, and the rod keeps the
stress-free (small-strain) stiffnesses; :func:`tangent_bending_matrix` gives the tangent
bending stiffness of the natural state for comparison.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

from rotomorph._typing import FloatArray
from rotomorph.errors import ConvergenceError, InvalidParameterError

#: A section law's name.
SectionModel = Literal["linear", "neo-hookean"]

#: Names of the section laws (``FilamentModel.section_model``).
SECTION_MODELS: tuple[SectionModel, ...] = ("linear", "neo-hookean")

_MAX_ITERATIONS = 60
_TOLERANCE = 1e-13


@dataclass(frozen=True)
class FibreQuadrature:
    """Quadrature of a section for the fibre energy: ``points`` ``(Q, 2)`` (mm), ``weights``
    ``(Q,)`` (mm²), ``modulus`` E ``(Q,)`` (MPa) and the modulus-weighted ``centroid`` ``(2,)``
    (mm) at which the natural centre-line stretch is reported."""

    points: FloatArray
    weights: FloatArray
    modulus: FloatArray
    centroid: FloatArray


def fibre_energy(
    y: FloatArray,
    quadrature: FibreQuadrature,
    eigen_stretch: FloatArray,
    volume: FloatArray,
    curvature: FloatArray,
    *,
    derivatives: bool = True,
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Energy U (N), gradient ``(n, 3)`` and Hessian ``(n, 3, 3)`` in y = (a, G1, G2).

    Parameters
    ----------
    y
        ``(n, 3)`` centre-line stretch a (1) and rotation rate G (1/mm) per row.
    quadrature
        The section's :class:`FibreQuadrature`.
    eigen_stretch, volume
        λ* and J* at the quadrature points ``(n, Q)`` (dimensionless).
    curvature
        Printed curvature k0 ``(n, 2)`` (1/mm).
    derivatives
        ``False``: the energy only (empty gradient and Hessian).

    Returns
    -------
    energy, gradient, hessian
        ``(n,)``, ``(n, 3)``, ``(n, 3, 3)``; the energy is ``inf`` where a fibre's elastic
        stretch is not positive.
    """
    x = quadrature.points
    f = 1.0 - curvature @ x.T  # (n, Q)
    lever = np.concatenate([np.ones((1, len(x))), -x.T], axis=0)  # (3, Q): d(a - G.x)/dy
    s = (y[:, :1] - y[:, 1:] @ x.T) / (f * eigen_stretch)
    c = (quadrature.weights * quadrature.modulus / 3.0) * f * volume
    positive = np.all(s > 0.0, axis=1)
    ss = np.where(s > 0.0, s, 1.0)
    energy = np.where(positive, np.sum(c * 0.5 * (ss * ss + 2.0 / ss - 3.0), axis=1), np.inf)
    if not derivatives:
        return energy, np.empty((0, 3)), np.empty((0, 3, 3))
    v = lever[None, :, :] / (f * eigen_stretch)[:, None, :]  # (n, 3, Q) ds/dy
    d1 = c * (ss - 1.0 / ss**2)
    d2 = c * (1.0 + 2.0 / ss**3)
    gradient = (v @ d1[:, :, None])[:, :, 0]
    hessian = (v * d2[:, None, :]) @ v.transpose(0, 2, 1)
    return energy, gradient, hessian


def minimise(
    quadrature: FibreQuadrature,
    eigen_stretch: FloatArray,
    volume: FloatArray,
    curvature: FloatArray,
) -> FloatArray:
    """The minimiser y = (a, G1, G2) ``(n, 3)`` of :func:`fibre_energy` for each row.

    Raises
    ------
    InvalidParameterError
        A fibre of non-positive reference length (printed radius inside the section).
    ConvergenceError
        Newton's method did not reach a relative step of 1e-13 in 60 iterations.
    """
    k0 = np.asarray(curvature, dtype=float).reshape(-1, 2)
    lam = np.asarray(eigen_stretch, dtype=float)
    vol = np.asarray(volume, dtype=float)
    if np.any(1.0 - k0 @ quadrature.points.T <= 0.0):
        raise InvalidParameterError(
            "curvature", "printed radius of curvature is smaller than the section's extent"
        )
    # start: the stiffness-weighted mean stretch, no turning relative to the print
    ew = quadrature.weights * quadrature.modulus
    a0 = (lam * ew).sum(axis=1) / ew.sum()
    y = np.column_stack([a0, a0[:, None] * k0])
    energy, grad, hess = fibre_energy(y, quadrature, lam, vol, k0)
    if not np.all(np.isfinite(energy)):  # a uniform stretch is always admissible at k0
        y = np.column_stack([np.ones(len(k0)) * lam.min(axis=1), lam.min(axis=1)[:, None] * k0])
        energy, grad, hess = fibre_energy(y, quadrature, lam, vol, k0)
    scale = quadrature.points.std()  # mm: makes the step's parts comparable
    done = np.zeros(len(y), dtype=bool)
    for _ in range(_MAX_ITERATIONS):
        live = np.flatnonzero(~done)  # converged rows stay as they are
        step = -np.linalg.solve(hess[live], grad[live][..., None])[..., 0]
        size = np.abs(step[:, 0]) + scale * np.abs(step[:, 1:]).sum(axis=1)
        finished = size <= _TOLERANCE * np.abs(y[live, 0])
        done[live[finished]] = True
        if done.all():
            return y
        live, step = live[~finished], step[~finished]
        lam_l, vol_l, k0_l = lam[live], vol[live], k0[live]
        slope = np.einsum("ni,ni->n", grad[live], step)  # −(Newton decrement)²
        # below round-off of the energy the merit test says nothing, and a step this small
        # from a strictly convex energy is the exact quadratic model's: take the full step
        resolved = (-slope > 1e-10 * np.abs(energy[live])) & (
            size[~finished] > 1e-8 * np.abs(y[live, 0])
        )
        t = np.ones(len(live))
        for _ in range(40):  # backtracking on U (a true merit function)
            trial = y[live] + t[:, None] * step
            e_new = fibre_energy(trial, quadrature, lam_l, vol_l, k0_l, derivatives=False)[0]
            bad = ~(e_new <= energy[live] + 1e-4 * t * slope) & (resolved | ~np.isfinite(e_new))
            if not bad.any():
                break
            t = np.where(bad, 0.5 * t, t)
        y[live] = trial
        energy[live], grad[live], hess[live] = fibre_energy(trial, quadrature, lam_l, vol_l, k0_l)
    raise ConvergenceError(
        f"neo-Hookean section: Newton did not converge in {_MAX_ITERATIONS} iterations"
    )


def tangent_bending_matrix(
    y: FloatArray,
    quadrature: FibreQuadrature,
    eigen_stretch: FloatArray,
    volume: FloatArray,
    curvature: FloatArray,
) -> FloatArray:
    """Tangent bending stiffness ``(n, 2, 2)`` (N·mm²) at y: the Hessian of U in G with the
    centre-line stretch a relaxed (Schur complement); equal to the linear section's I_E at
    zero eigenstrain and zero printed curvature."""
    _, _, h = fibre_energy(y, quadrature, eigen_stretch, volume, curvature)
    return h[:, 1:, 1:] - h[:, 1:, :1] * h[:, :1, 1:] / h[:, :1, :1]


def natural_state(
    y: FloatArray, quadrature: FibreQuadrature, curvature: FloatArray, transverse: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """Natural centre-line stretch at the centroid ``(n,)`` and turning K per printed length
    ``(n, 2)`` (1/mm) of minimisers y, for mean transverse stretches s_t ``(n,)``."""
    k0 = np.asarray(curvature, dtype=float).reshape(-1, 2)
    c = quadrature.centroid
    stretch = (y[:, 0] - y[:, 1:] @ c) / (1.0 - k0 @ c)
    return stretch, y[:, 1:] / np.asarray(transverse, dtype=float)[:, None]

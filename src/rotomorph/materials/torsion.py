r"""Saint-Venant torsion with warping, and natural twist from an eigen-shear field (P1 FEM).

For a section with shear modulus G(x) (MPa) and an in-plane engineering eigen-shear field
γ*(x) = (2ε*_13, 2ε*_23) (dimensionless), the twist τ (1/mm) and warping w(x) (mm²·τ) minimise::

    ½ ∫ G |τ p + ∇w − γ*|² dA,        p(x) = (−x2, x1)

(Saint-Venant's torsion problem, e.g. Timoshenko & Goodier, *Theory of Elasticity*, ch. 10,
with an eigenstrain added as for thermal strains). Eliminating w (P1 elements, one vertex
pinned; the result does not depend on the origin of p):

* K z = b with K_ab = ∫G ∇φ_a·∇φ_b, b_a = ∫G p·∇φ_a,
* torsional stiffness C = ∫G ‖p − ∇z‖² dA (N·mm²),
* natural twist τ̄ = ∫G (p − ∇z)·γ* dA / C, a linear functional of γ* (``twist_weights``).

Checks (tests): homogeneous disk C = GπR⁴/2; semicircle C = (π/2 − 4/π) G R⁴ (Saint-Venant);
full disk with γ* = g0 r e_θ gives τ̄ = g0 with no warping.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.linalg import spsolve

from rotomorph._typing import BoolArray, FloatArray
from rotomorph.errors import InvalidParameterError
from rotomorph.materials.mesh import SectionMesh
from rotomorph.materials.section import Field, evaluate, row_contract


@dataclass(frozen=True, eq=False)
class TorsionSection:
    """Torsional stiffness C (N·mm²), unit-twist warping ``(P,)`` (mm²) and twist weights.

    ``twist_weights`` ``(Q, 2)`` (1/mm²) at the mesh's quadrature points ``points`` ``(Q, 2)``
    (mm): τ̄ = Σ_q weights[q]·γ*[q]. Build with :func:`torsion_section`.
    """

    torsion_constant: float
    warping: FloatArray
    twist_weights: FloatArray
    points: FloatArray
    active: BoolArray

    def natural_twist(self, eigenshear: Field | FloatArray) -> FloatArray:
        """Natural twist τ̄ (1/mm) of an eigen-shear field (values ``(..., Q, 2)`` or callable).

        A callable is called as ``eigenshear(xy, active)`` and must return ``(Q, 2)``.
        """
        if callable(eigenshear):
            g = np.asarray(eigenshear(self.points, self.active), dtype=float)
        else:
            g = np.asarray(eigenshear, dtype=float)
        if g.shape[-2:] != self.twist_weights.shape or not np.all(np.isfinite(g)):
            raise InvalidParameterError(
                "eigenshear", f"must be finite with trailing shape {self.twist_weights.shape}"
            )
        # (row by row in a fixed order beyond einsum's buffer: batch-independent values)
        q2 = g.shape[-2] * g.shape[-1]
        return row_contract(g.reshape((*g.shape[:-2], q2)), self.twist_weights.reshape(q2))


def _gradients(mesh: SectionMesh) -> FloatArray:
    """Gradients of the P1 basis functions ``(T, 3, 2)`` (1/mm)."""
    a = mesh.points[mesh.triangles]
    area2 = 2.0 * mesh.areas
    nxt, prv = a[:, [1, 2, 0]], a[:, [2, 0, 1]]
    gx = (nxt[:, :, 1] - prv[:, :, 1]) / area2[:, None]
    gy = (prv[:, :, 0] - nxt[:, :, 0]) / area2[:, None]
    return np.stack([gx, gy], axis=-1)


def torsion_section(mesh: SectionMesh, shear_modulus: Field | FloatArray | float) -> TorsionSection:
    """Solve the warping problem once for a meshed section (mesh must be conforming).

    Parameters
    ----------
    mesh
        Conforming triangle mesh (mm), e.g. :func:`rotomorph.materials.mesh.disk_mesh`.
    shear_modulus
        G at the quadrature points (MPa), > 0 (use a tiny value for a void phase).

    Returns
    -------
    TorsionSection
    """
    xy, w, act, owner = mesh.quadrature()
    g = evaluate(shear_modulus, xy, act)
    if np.any(g <= 0.0):
        raise InvalidParameterError("shear_modulus", "must be > 0 MPa everywhere")
    gw = g * w
    grad = _gradients(mesh)  # (T, 3, 2)
    n_tri = len(mesh.triangles)
    g_tri = np.bincount(owner, weights=gw, minlength=n_tri)
    p = np.column_stack([-xy[:, 1], xy[:, 0]])
    gp_tri = np.stack(
        [np.bincount(owner, weights=gw * p[:, k], minlength=n_tri) for k in range(2)], axis=-1
    )
    local_k = g_tri[:, None, None] * np.einsum("tai,tbi->tab", grad, grad)
    rows = np.repeat(mesh.triangles, 3, axis=1).ravel()
    cols = np.tile(mesh.triangles, (1, 3)).ravel()
    n_pts = len(mesh.points)
    stiff = coo_matrix((local_k.ravel(), (rows, cols)), shape=(n_pts, n_pts)).tocsr()
    load = np.bincount(
        mesh.triangles.ravel(),
        weights=np.einsum("tai,ti->ta", grad, gp_tri).ravel(),
        minlength=n_pts,
    )
    z = np.zeros(n_pts)
    z[1:] = spsolve(stiff[1:, 1:].tocsc(), load[1:])
    grad_z = np.einsum("ta,tai->ti", z[mesh.triangles], grad)  # (T, 2)
    q = p - grad_z[owner]
    c = float(np.sum(gw * np.einsum("qi,qi->q", q, q)))
    return TorsionSection(c, -z, gw[:, None] * q / c, xy, act)

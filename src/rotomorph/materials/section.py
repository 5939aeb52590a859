r"""General cross-section mechanics by quadrature: axial stretch and bending (plane sections).

For a section with Young's modulus field E(x) and axial eigenstrain field ε*_zz(x), minimising
½∫E(ε_zz − ε*_zz)² dA over ε_zz = ε_c − κ·(x − c) gives (the bimetal
set-up of Timoshenko, J. Opt. Soc. Am. 11, 233 (1925), generalised to any section):

=========  ==========================================================  ==========
symbol     definition                                                  unit
=========  ==========================================================  ==========
A_E        ∫E dA  (axial stiffness EA)                                 N
c          ∫E x dA / A_E  (modulus-weighted centroid)                  mm
I_E        ∫E (x − c)(x − c)ᵀ dA  (2×2 bending stiffness)              N·mm²
ε_c        ∫E ε*_zz dA / A_E  (natural centre-line strain)             1
κ̄          −I_E⁻¹ ∫E ε*_zz (x − c) dA  (natural curvature)             1/mm
=========  ==========================================================  ==========

κ̄_i is the curvature component toward m_i (fibres on that side are shortened), the DER
component convention of Bergou et al. (2008) used by :mod:`rotomorph.geometry`; with x1 along
the interface normal n (into the active phase) a contracting active phase gives κ̄_1 > 0.

Every field is given either as an array over the mesh's quadrature points or as a callable
``field(xy, active) -> values`` evaluated there (xy in mm, ``active`` a boolean mask);
:func:`phase_constant` builds the common piecewise-constant case. Because ε_c and κ̄ are linear in
ε*_zz, :class:`AxialSection` stores them as linear functionals on the quadrature values, so many
eigenstrain fields (one per rod edge) are evaluated with one matrix product.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import cast

import numpy as np
from numba import njit

from rotomorph._typing import BoolArray, FloatArray
from rotomorph.errors import InvalidParameterError
from rotomorph.materials.mesh import SectionMesh

Field = Callable[[FloatArray, BoolArray], FloatArray]


def phase_constant(active: float, passive: float) -> Field:
    """Piecewise-constant field: ``active`` on the active phase, ``passive`` elsewhere."""

    def field(xy: FloatArray, is_active: BoolArray) -> FloatArray:
        return np.where(is_active, float(active), float(passive))

    return field


def evaluate(field: Field | FloatArray | float, xy: FloatArray, active: BoolArray) -> FloatArray:
    """Values of ``field`` at quadrature points ``xy`` ``(Q, 2)`` (mm): ``(Q,)`` or ``(..., Q)``."""
    if callable(field):
        out = np.asarray(field(xy, active), dtype=float)
    else:
        out = np.asarray(field, dtype=float)
    out = np.broadcast_to(out, (*out.shape[:-1], len(xy))) if out.ndim else np.full(len(xy), out)
    if not np.all(np.isfinite(out)):
        raise InvalidParameterError("field", "must be finite at every quadrature point")
    return out


@dataclass(frozen=True, eq=False)
class AxialSection:
    """Stiffness of a section and the linear maps eigenstrain → natural strain and curvature.

    Build with :func:`axial_section`. Attributes: ``axial_stiffness`` A_E (N), ``centroid`` c
    ``(2,)`` (mm), ``bending_matrix`` I_E ``(2, 2)`` (N·mm²), quadrature ``points`` ``(Q, 2)``
    (mm), ``weights`` ``(Q,)`` (mm²), ``active`` ``(Q,)`` and ``modulus`` E at the points (MPa).
    ``folded_moment`` ``(2, 2)`` (mm², default none): the quadrature stands for several copies
    of itself shifted along directions that add ``Σ w · folded_moment`` to the second moment
    of every weight w (identical layers of a stack, :mod:`rotomorph.materials.stack`); the
    stiffnesses given are the whole section's.
    """

    axial_stiffness: float
    centroid: FloatArray
    bending_matrix: FloatArray
    points: FloatArray
    weights: FloatArray
    active: BoolArray
    modulus: FloatArray
    folded_moment: FloatArray | None = None

    @property
    def bending_stiffness1(self) -> float:
        """B1 = I_E[0, 0]: stiffness paired with curvature toward m1 = n (N·mm²)."""
        return float(self.bending_matrix[0, 0])

    @property
    def bending_stiffness2(self) -> float:
        """B2 = I_E[1, 1]: stiffness paired with curvature toward m2 = t × n (N·mm²)."""
        return float(self.bending_matrix[1, 1])

    def principal_stiffnesses(self) -> tuple[FloatArray, FloatArray]:
        """Eigenvalues (ascending, N·mm²) and unit eigenvectors (columns, (m1, m2) components)."""
        return np.linalg.eigh(self.bending_matrix)

    def natural_strain(self, eigenstrain: Field | FloatArray | float) -> FloatArray:
        """ε_c = ∫E ε*_zz dA / A_E (dimensionless); ``(...)`` for values ``(..., Q)``."""
        eps = evaluate(eigenstrain, self.points, self.active)
        # not a BLAS product: each field's value does not depend on the others in the batch
        # (bit for bit), so remembered print states equal freshly evaluated ones
        return row_contract(eps, self.modulus * self.weights) / self.axial_stiffness

    def natural_curvature(self, eigenstrain: Field | FloatArray | float) -> FloatArray:
        """κ̄ = −I_E⁻¹ ∫E ε*_zz (x − c) dA (1/mm), components toward (m1, m2): ``(..., 2)``."""
        eps = evaluate(eigenstrain, self.points, self.active)
        lever = (self.modulus * self.weights)[:, None] * (self.points - self.centroid)
        moment = row_contract(eps, lever)  # batch-independent (natural_strain)
        # float64 inputs give a float64 solution (the stubs only promise "floating")
        return cast(FloatArray, -np.linalg.solve(self.bending_matrix, moment[..., None])[..., 0])

    def natural_curved(
        self, eigenstrain: FloatArray, curvature: FloatArray, transverse: FloatArray
    ) -> tuple[FloatArray, FloatArray]:
        r"""Natural strain and curvature *change* of a section printed on a curved centre line.

        A bar printed with curvature k0 (1/mm, components toward m1, m2: the centre of curvature
        lies on that side) along its geometric centre line has fibres of reference length
        ∝ 1 − k0·x (x from the geometric centre, the nozzle's axis): fibres on the inner side
        are shorter (Winkler's curved bar; e.g. Boresi & Schmidt, *Advanced Mechanics of
        Materials*, 6th ed., Wiley 2003, ch. 9). The section itself dilates in its plane by its
        mean transverse eigenstrain ε̄_t, so a fibre at x ends at (1 + ε̄_t) x. With plane
        sections and natural turning K = k0 + Δκ per printed length, a fibre's strain is
        (ε_g − g·x)/(1 − k0·x) with g = Δκ + ε̄_t k0 and ε_g that of the geometric centre,
        to first order in the strains and exactly in k0·x (the product ε̄_t Δκ is dropped, as
        the straight bar drops ε̄_t κ). Minimising ½∫E(ε − ε*)²(1 − k0·x) dA gives, with
        w = E/(1 − k0·x),

        .. math::

            \begin{pmatrix}∫w & −∫w\,x^T \\ −∫w\,x & ∫w\,x x^T\end{pmatrix}
            \begin{pmatrix}ε_g \\ g\end{pmatrix}
            = \begin{pmatrix}∫E ε^* \\ −∫E ε^* x\end{pmatrix},

        and Δκ = g − ε̄_t k0. The natural strain returned is that of the fibre at the
        modulus-weighted centroid c, (ε_g − g·c)/(1 − k0·c), as :meth:`natural_strain` (to
        which, with :meth:`natural_curvature`, the result reduces for k0 = 0).

        Two effects make the change differ from the straight bar's. The larger is metric: a
        curved bar whose fibres shorten by ε along it while the section widens by ε̄_t turns
        through (1 + ε)/(1 + ε̄_t) times its printed angle, 1 + ε − ε̄_t here to first order
        (a uniform isotropic eigenstrain gives a similarity, Δκ = 0; an LCE contracting along
        the bar and swelling across it turns less). The smaller is Winkler's weighting of the
        shorter inner fibres. For a Janus section the two together make an active half on the
        inner side curl less, and one on the outer side straighten more, than on a straight
        bar.

        Parameters
        ----------
        eigenstrain
            ε*_zz at the quadrature points ``(n, Q)``.
        curvature
            Printed curvature k0 ``(n, 2)`` (1/mm); ``|k0|·|x| < 1`` at every point.
        transverse
            Mean transverse eigenstrain ε̄_t of the section ``(n,)`` (dimensionless).

        Returns
        -------
        eps_c, dkappa
            ``(n,)`` natural centre-line strain and ``(n, 2)`` change of the natural curvature
            (1/mm per printed length, toward m1, m2).

        Raises
        ------
        InvalidParameterError
            A fibre of non-positive reference length (``|k0|`` too large for the section).
        """
        eps = np.asarray(eigenstrain, dtype=float)
        k0 = np.asarray(curvature, dtype=float)
        x = self.points
        ew = self.modulus * self.weights
        # the quadrature sums, row by row in a fixed order: a row's result does not depend on
        # the other rows of the batch (the states of a lattice are solved in batches whose
        # make-up depends on what was solved before)
        m, rhs, shortest = _curved_sums(
            np.ascontiguousarray(eps.reshape(-1, len(ew))),
            np.ascontiguousarray(k0.reshape(-1, 2)),
            np.ascontiguousarray(x),
            np.ascontiguousarray(ew),
        )
        if np.any(shortest <= 0.0):
            raise InvalidParameterError(
                "curvature", "printed radius of curvature is smaller than the section's extent"
            )
        if self.folded_moment is not None:  # the copies' shifts (class docstring)
            m[:, 1:, 1:] += m[:, :1, :1] * self.folded_moment
        sol = np.linalg.solve(m, rhs[..., None])[..., 0]
        eps_g, g = sol[..., 0], sol[..., 1:]
        c = self.centroid  # (products written out: a matrix product rounds by batch size)
        eps_c = (eps_g - (g[..., 0] * c[0] + g[..., 1] * c[1])) / (
            1.0 - (k0[..., 0] * c[0] + k0[..., 1] * c[1])
        )
        t = np.asarray(transverse, dtype=float)[..., None]
        return eps_c, g - t * k0


def row_contract(values: FloatArray, weights: FloatArray) -> FloatArray:
    """``einsum("...q,q...->...", values, weights)``: each row of ``values`` ``(..., Q)``
    contracted with ``weights`` ``(Q,)`` or ``(Q, K)``, independent of the other rows.

    NumPy's einsum reduces a row to a scalar in buffers of ``np.getbufsize()`` elements whose
    split depends on the batch's shape, so beyond that many elements the row's value changes
    in its last bits with the rows evaluated beside it (measured; a reduction to a vector,
    ``(Q, K)`` weights, does not); such contractions are summed row by row in a fixed order
    (compiled). The others keep einsum (bit for bit what they gave before)."""
    v = np.asarray(values, dtype=float)
    w = np.asarray(weights, dtype=float)
    if w.ndim == 2:
        return np.einsum("...q,qk->...k", v, w)
    if w.size <= np.getbufsize():
        return np.einsum("...q,q->...", v, w)
    flat = np.ascontiguousarray(v.reshape(-1, v.shape[-1]))
    out = _row_sums(flat, np.ascontiguousarray(w.reshape(len(w), -1)))
    tail = () if w.ndim == 1 else (w.shape[1],)
    return out.reshape(v.shape[:-1] + tail)


@njit(cache=True)
def _row_sums(values, weights):  # pragma: no cover - compiled
    """``(n, K)``: row i is sum_q values[i, q] weights[q, :], summed in the order of q."""
    n, nq = values.shape
    k = weights.shape[1]
    out = np.zeros((n, k))
    for i in range(n):
        for q in range(nq):
            v = values[i, q]
            for c in range(k):
                out[i, c] += v * weights[q, c]
    return out


def axial_section(mesh: SectionMesh, modulus: Field | FloatArray | float) -> AxialSection:
    """Quadrature of A_E, c and I_E for a meshed section with Young's modulus field E (MPa).

    Parameters
    ----------
    mesh
        Triangulated section (mm); see :mod:`rotomorph.materials.mesh`.
    modulus
        E at the quadrature points (MPa), > 0, or a field callable.

    Returns
    -------
    AxialSection

    Examples
    --------
    A homogeneous disk of radius R gives I_E = E π R⁴/4 · identity (up to the polygon error of
    the mesh), a Janus half-and-half disk with E_a = E_p gives the same.
    """
    xy, w, act, _ = mesh.quadrature()
    e = evaluate(modulus, xy, act)
    if np.any(e <= 0.0):
        raise InvalidParameterError("modulus", "Young's modulus must be > 0 MPa everywhere")
    ew = e * w
    a_e = float(ew.sum())
    c = ew @ xy / a_e
    d = xy - c
    i_e = (ew[:, None, None] * d[:, :, None] * d[:, None, :]).sum(axis=0)
    return AxialSection(a_e, c, i_e, xy, w, act, e)


@njit(cache=True)
def _curved_sums(eps, k0, x, ew):  # pragma: no cover - compiled
    """The curved-bar system of :meth:`AxialSection.natural_curved` per row: ``(n, 3, 3)``
    matrices and ``(n, 3)`` right-hand sides, each summed over the quadrature points in
    their order (``w = E dA / (1 - k0.x)``), and the smallest relative fibre length
    ``1 - k0.x`` of each row ``(n,)`` (the system is meaningless where it is not positive)."""
    n, nq = eps.shape
    m = np.zeros((n, 3, 3))
    rhs = np.zeros((n, 3))
    shortest = np.empty(n)
    for i in range(n):
        s0 = s1 = s2 = s11 = s12 = s22 = r0 = r1 = r2 = 0.0
        low = np.inf
        for q in range(nq):
            x0 = x[q, 0]
            x1 = x[q, 1]
            f = 1.0 - (k0[i, 0] * x0 + k0[i, 1] * x1)
            low = min(low, f)
            if f <= 0.0:
                continue  # reported through ``shortest``
            w = ew[q] / f
            s0 += w
            s1 += w * x0
            s2 += w * x1
            s11 += w * x0 * x0
            s12 += w * x0 * x1
            s22 += w * x1 * x1
            e = eps[i, q] * ew[q]
            r0 += e
            r1 += e * x0
            r2 += e * x1
        m[i, 0, 0] = s0
        m[i, 0, 1] = m[i, 1, 0] = -s1
        m[i, 0, 2] = m[i, 2, 0] = -s2
        m[i, 1, 1] = s11
        m[i, 1, 2] = m[i, 2, 1] = s12
        m[i, 2, 2] = s22
        rhs[i, 0] = r0
        rhs[i, 1] = -r1
        rhs[i, 2] = -r2
        shortest[i] = low
    return m, rhs, shortest

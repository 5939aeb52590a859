r"""Is an equilibrium a minimum? Inertia and lowest eigenvalues of a Hessian on free DOFs.

An equilibrium ``x`` (zero gradient) of a smooth energy is a strict local minimum when the
Hessian ``H`` is positive definite on every direction that changes the energy. Directions that
never change it (rigid motions of an unsupported body) are removed first: their span ``R`` is
supplied by the objective, and only the part of it that ``H`` annihilates numerically (Rayleigh
quotient below a tolerance) is removed, so a floor or a support that stiffens a rigid motion keeps
it in the test.

Two certificates, cheapest first:

1. **Cholesky** (when no eigenvalues are asked for): the Hessian with the rigid directions
   removed (by eliminating ``k`` DOFs on which the rigid modes are independent, a complement of
   their span; with ``H R = 0`` this leaves the inertia unchanged) is factored *unshifted*.
   Success proves positive definiteness.
2. **Eigenvalues** (when asked for, or when the factorization fails): the lowest eigenvalues
   of the pencil ``H v = lambda M v`` restricted to the ``M``-orthogonal complement of the
   rigid span (``M`` the solver's diagonal metric: Voronoi length per position DOF, ``l^3`` per
   twist angle, so ``lambda`` has units of N/mm²). Small problems use a dense symmetric
   eigensolver; large ones shift-invert Lanczos (:mod:`rotomorph.solve.lanczos`, stopping as
   soon as the wanted Ritz values converge; ARPACK's implicitly restarted Lanczos, SciPy
   ``eigsh``, if they have not within its basis) with the shift below the lowest eigenvalue,
   found by trial factorizations (Ericsson & Ruhe, *Math. Comp.* 35, 1980; a trial that a
   rigid direction's negative Rayleigh quotient already rules out is skipped), and the rigid
   span projected out of every solve. An unstable point's eigenpairs come from ARPACK in every
   case: the solver leaves the saddle along its mode.

``stable`` is True when the Cholesky certificate succeeds or the lowest eigenvalue is above
``-tol * scale`` (``scale`` the largest diagonal ratio ``H_ii / M_ii``): an eigenvalue within
that band is *neutral* (a symmetry the objective did not declare, or a load at its critical
value) and is reported in ``eigenvalues``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from rotomorph._typing import FloatArray, IntArray
from rotomorph.solve.lanczos import shift_invert_lanczos
from rotomorph.solve.linalg import BandedMatrix, SparseMatrix, factorize, matvec

__all__ = ["DENSE_LIMIT", "Spectrum", "analyse_hessian", "to_csc"]

#: Problem size (free DOFs less rigid modes) up to which the dense eigensolver is used.
DENSE_LIMIT = 240


@dataclass(frozen=True, eq=False)
class Spectrum:
    """Stability verdict and lowest eigenvalues of a Hessian on the free DOFs.

    Attributes
    ----------
    stable
        True when the Hessian with rigid directions removed is positive definite, or its lowest
        eigenvalue is above ``-tol * scale`` (neutral within round-off).
    eigenvalues
        Lowest eigenvalues of ``H v = lambda M v`` on the complement of the rigid span,
        ascending ``(k,)`` (N/mm² for rod objectives); empty when none were asked for and the
        Cholesky certificate sufficed.
    modes
        The matching eigenvectors ``(n, k)``, ``M``-orthonormal, or None when not asked for.
    rigid
        Number of rigid (zero-energy) directions removed.
    certificate
        ``"cholesky"`` (an unshifted factorization succeeded) or ``"eigenvalues"``.
    scale
        ``max(H_ii / M_ii)`` (the units of ``eigenvalues``), the reference of ``tol``.
    factorizations
        Factorizations spent (for the solver's statistics).
    """

    stable: bool
    eigenvalues: FloatArray
    modes: FloatArray | None
    rigid: int
    certificate: str
    scale: float
    factorizations: int

    @property
    def lowest(self) -> float:
        """Lowest eigenvalue computed (NaN when none was)."""
        return float(self.eigenvalues[0]) if len(self.eigenvalues) else float("nan")

    def negative_mode(self) -> FloatArray | None:
        """The eigenvector of the lowest eigenvalue when the equilibrium is unstable."""
        if self.stable or self.modes is None or not len(self.eigenvalues):
            return None
        return self.modes[:, 0]


def to_csc(H: Any) -> sp.csc_matrix:
    """A banded, sparse or dense symmetric matrix as a full SciPy CSC matrix."""
    if isinstance(H, SparseMatrix):
        return H.csc
    if isinstance(H, BandedMatrix):
        n, u = H.n, H.u
        diags, offsets = [H.ab[u]], [0]
        for k in range(1, min(u, n - 1) + 1):
            d = H.ab[u - k, k:]
            diags += [d, d]
            offsets += [k, -k]
        return sp.diags(diags, offsets, shape=(n, n), format="csc")
    if sp.issparse(H):
        return sp.csc_matrix(H)
    return sp.csc_matrix(np.asarray(H, dtype=float))


def _dense(H: Any) -> FloatArray:
    if isinstance(H, (SparseMatrix, BandedMatrix)):
        return H.to_dense()
    if sp.issparse(H):
        return np.asarray(H.toarray())
    return np.array(H, dtype=float)


def _rigid_null_space(
    H: Any, M: FloatArray, rigid: FloatArray, tol: float
) -> tuple[FloatArray, float]:
    """``M``-orthonormal basis of the combinations of ``rigid`` that ``H`` annihilates, and the
    lowest Rayleigh quotient ``v^T H v / v^T M v`` over the span of ``rigid`` (an upper bound
    of the lowest eigenvalue of the pencil; ``inf`` without rigid directions)."""
    if rigid.size == 0:
        return np.zeros((len(M), 0)), np.inf
    # M-orthonormalise through the small Gram matrix (k <= 6 columns)
    G = np.einsum("ik,i,il->kl", rigid, M, rigid)
    w, V = np.linalg.eigh(G)
    ok = w > 1e-12 * max(float(w.max()), 1e-300)
    basis = rigid @ (V[:, ok] / np.sqrt(w[ok]))
    if basis.shape[1] == 0:
        return basis, np.inf
    cols = range(basis.shape[1])
    HB = np.column_stack([matvec(H, np.ascontiguousarray(basis[:, j])) for j in cols])
    C = basis.T @ HB
    mu, W = np.linalg.eigh(0.5 * (C + C.T))
    return basis @ W[:, np.abs(mu) <= tol], float(mu[0])


def _pivots(R: FloatArray) -> IntArray:
    """``k`` DOFs on which the ``k`` columns of ``R`` are independent (greedy pivoted
    Gram–Schmidt on the rows: each pick is the DOF where the remaining modes move most)."""
    A = np.array(R, dtype=float)
    picks = []
    for _ in range(R.shape[1]):
        i = int(np.argmax(np.einsum("ij,ij->i", A, A)))
        picks.append(i)
        r = A[i] / np.linalg.norm(A[i])
        A -= np.outer(A @ r, r)
    return np.array(picks, dtype=np.int64)


def _reduced_is_positive_definite(H: Any, R: FloatArray, scale: float) -> bool:
    """Unshifted Cholesky of ``H`` with the rigid span removed.

    Without rigid modes it is ``H`` itself. With ``k`` of them, ``k`` DOFs on which they are
    independent (a complement of their span) are eliminated by stiff springs of ``1e16`` times
    the diagonal scale on those DOFs only: by the Schur complement the result is positive
    definite exactly when ``H`` with those DOFs deleted is, up to ``1e-16`` of the scale, and
    the solver's cached symbolic factorization is reused (a diagonal change keeps the pattern).
    """
    shift = np.zeros(R.shape[0])
    if R.shape[1]:
        shift[_pivots(R)] = 1e16 * scale
    return factorize(H, shift) is not None


def analyse_hessian(
    H: Any,
    M: FloatArray,
    rigid: FloatArray | None = None,
    *,
    count: int = 3,
    modes: bool = False,
    tol: float = 1e-12,
    null_tol: float = 1e-6,
) -> Spectrum:
    """Stability verdict and lowest eigenvalues of ``H`` (see the module docstring).

    Parameters
    ----------
    H
        Symmetric Hessian of the free DOFs (banded, sparse, SciPy sparse or dense).
    M
        Positive diagonal metric ``(n,)``.
    rigid
        Candidate zero-energy directions ``(n, k)`` (e.g. rigid motions of a free body).
    count
        Lowest eigenvalues to compute. 0: the Cholesky verdict only (one eigenvalue is still
        computed when that factorization fails, to decide); otherwise the eigenvalues decide.
    modes
        Keep the eigenvectors (they are always kept when the point is unstable).
    tol
        Eigenvalues above ``-tol * scale`` count as non-negative (neutral).
    null_tol
        A rigid direction is removed when its Rayleigh quotient is within ``null_tol * scale``
        of zero.
    """
    M = np.asarray(M, dtype=float)
    n = len(M)
    d = np.asarray(H.diagonal if isinstance(H, BandedMatrix) else H.diagonal(), dtype=float)
    scale = max(float(np.max(np.abs(d) / M)) if n else 1.0, 1e-300)
    R, bound = _rigid_null_space(
        H, M, np.zeros((n, 0)) if rigid is None else rigid, null_tol * scale
    )
    k = R.shape[1]
    m = n - k
    if m <= 0:
        empty = np.zeros(0)
        return Spectrum(True, empty, np.zeros((n, 0)) if modes else None, k, "cholesky", scale, 0)
    nfact = 0
    if count <= 0:
        nfact += 1
        if _reduced_is_positive_definite(H, R, scale):
            return Spectrum(True, np.zeros(0), None, k, "cholesky", scale, nfact)
    want = min(max(int(count), 1), m)
    vec: FloatArray | None
    if m <= DENSE_LIMIT:
        lam, vec = _dense_eigen(H, M, R, want)
    else:
        lam, vec, extra = _sparse_eigen(H, M, R, want, scale, modes, tol, bound)
        nfact += extra
    stable = bool(lam[0] >= -tol * scale)
    return Spectrum(
        stable=stable,
        eigenvalues=lam,
        modes=_normalise_signs(vec) if (vec is not None and (modes or not stable)) else None,
        rigid=k,
        certificate="eigenvalues",
        scale=scale,
        factorizations=nfact,
    )


def _normalise_signs(vec: FloatArray) -> FloatArray:
    """Each mode with its largest-magnitude entry positive (reproducible signs)."""
    if vec.size == 0:
        return vec
    idx = np.argmax(np.abs(vec), axis=0)
    return vec * np.sign(vec[idx, np.arange(vec.shape[1])])


def _dense_eigen(H: Any, M: FloatArray, R: FloatArray, want: int) -> tuple[FloatArray, FloatArray]:
    s = np.sqrt(M)
    A = _dense(H) / s[:, None] / s[None, :]
    A = 0.5 * (A + A.T)
    k = R.shape[1]
    if k:
        Q = np.linalg.qr(s[:, None] * R, mode="complete")[0]
        Z = Q[:, k:]
        A = Z.T @ A @ Z
    lam, V = sla.eigh(A, subset_by_index=[0, want - 1])
    vec = (Z @ V if k else V) / s[:, None]
    return lam, vec


def _sparse_eigen(
    H: Any,
    M: FloatArray,
    R: FloatArray,
    want: int,
    scale: float,
    vectors: bool,
    tol: float,
    bound: float = np.inf,
) -> tuple[FloatArray, FloatArray | None, int]:
    """Shift-invert Lanczos with the shift below the lowest eigenvalue.

    The shift is the first of ``-1e-14 scale, -1e-13 scale, ...`` at which ``H - sigma M``
    factors; those not below ``bound`` (a Rayleigh quotient, so at least the lowest eigenvalue)
    cannot, and are skipped without a factorization.
    """
    n = len(M)
    extra = 0
    fac: Any = None
    sigma = 0.0
    delta = 1e-14 * scale
    while delta <= -bound:
        delta *= 10.0
    while fac is None:
        extra += 1
        fac = factorize(H, delta * M)
        sigma = -delta
        delta *= 10.0
        if delta > 1e3 * scale:  # pragma: no cover - a symmetric matrix always factors by then
            raise FloatingPointError("no shift below the lowest eigenvalue was found")
    RM = (M[:, None] * R).T  # R^T M

    def project(v: FloatArray) -> FloatArray:  # the M-orthogonal projector I - R R^T M
        return v - R @ (RM @ v) if R.shape[1] else v

    def op_inv(b: FloatArray) -> FloatArray:
        b = np.ravel(b)
        if R.shape[1]:
            b = b - RM.T @ (R.T @ b)  # the transposed projector removes rigid loads first
        return project(fac.solve(b))

    v0 = project(np.cos(np.arange(n) * 2.399963229728653) + 0.5)
    basis = 0 if want == 1 else max(2 * want + 1, 20)  # repeated eigenvalues: see min_steps
    found = shift_invert_lanczos(op_inv, M, v0, want, min_steps=basis)
    if found is not None:
        theta, vec = found
        lam = sigma + 1.0 / theta[::-1]  # the largest theta is the lowest eigenvalue
        if lam[0] >= -tol * scale:
            if not vectors:
                return lam, None, extra
            vec = vec[:, ::-1]
            norms = np.sqrt(np.einsum("ij,i,ij->j", vec, M, vec))
            return lam, vec / norms, extra
        # unstable: the solver leaves the saddle along these modes (the lift probe starts
        # along them), and a Ritz vector stopped when the eigenvalues converged is less
        # accurate than ARPACK's; an escape along it can reach another equilibrium
    # not converged within the Lanczos basis, or unstable: ARPACK's implicitly restarted
    # Lanczos, run to its own tolerance
    lin = spla.LinearOperator((n, n), matvec=lambda v: matvec(H, np.ravel(v)), dtype=float)
    opinv = spla.LinearOperator((n, n), matvec=op_inv, dtype=float)
    kwargs = dict(k=want, M=sp.diags(M), sigma=sigma, which="LM", OPinv=opinv, v0=v0, tol=1e-8)
    if not vectors:
        # Ritz vectors cost more than the eigenvalues (dseupd); get them only when needed
        lam = np.sort(spla.eigsh(lin, return_eigenvectors=False, **kwargs))
        if lam[0] >= -tol * scale:
            return lam, None, extra
    lam, vec = spla.eigsh(lin, **kwargs)
    order = np.argsort(lam)
    lam, vec = lam[order], vec[:, order]
    norms = np.sqrt(np.einsum("ij,i,ij->j", vec, M, vec))
    return lam, vec / norms, extra

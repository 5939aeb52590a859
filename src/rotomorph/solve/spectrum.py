r"""Is an equilibrium a minimum? Inertia and lowest eigenvalues of a Hessian on free DOFs.

An equilibrium ``x`` (zero gradient) of a smooth energy is a strict local minimum when the
Hessian ``H`` is positive definite on every direction that changes the energy. Directions that
never change it (rigid motions of an unsupported body) are removed first. Their candidate span
``R`` is supplied by the objective; a candidate is removed only where it is null *relative to
the rest of the spectrum*. In the eigenbasis of the span's own curvature, direction ``b_j`` has
the Rayleigh quotient ``mu_j`` and couples to the ``M``-orthogonal complement with a strength
``rho_j = |M^{-1/2}(H b_j - mu_j M b_j)|``; with ``lambda_1`` the lowest eigenvalue of the
complement, ``b_j`` can move the lowest eigenvalue of the whole by about
``|mu_j| + rho_j^2 / lambda_1``, and it is removed when that is at most ``NULL_TOL`` (1e-3) of
``lambda_1``. A rigid motion is an exact symmetry only when nothing acts on it: at an
equilibrium ``mu_j`` of a rigid rotation is the dead loads' second variation along it
(``-sum_i f_i . (w x (w x r_i))``: negative for a free rod under self-equilibrated
compression, which a half turn relieves) and ``rho_j`` follows from ``H (w x r) = w x f``. Such a
direction stays in the test and makes the point unstable; a floor or a tension that stiffens a
rigid motion keeps it in the test with a positive curvature. The reference is the spectrum's own
scale, not the largest diagonal ratio (on a 5 x 5 lattice seven orders of magnitude above
``lambda_1``), so a band of that ratio can no longer hide a rigid rotation that lowers the energy.

Two certificates, cheapest first:

1. **Cholesky** (when no eigenvalues are asked for): ``H - s M`` with every candidate direction
   removed (by eliminating ``k`` DOFs on which they are independent, a complement of their span)
   is factored, with the shift ``s`` just large enough that success proves ``lambda_1 >= s``
   for the smallest ``lambda_1`` at which every candidate is null (``_Rigid.shift``; ``s = 0``
   without candidates, and a few times the round-off of the rigid curvatures otherwise).
   Success proves positive definiteness with every candidate removed.
2. **Eigenvalues** (when asked for, or when the factorization fails): the lowest eigenvalues
   of the pencil ``H v = lambda M v`` restricted to the ``M``-orthogonal complement of the
   candidate span (``M`` the solver's diagonal metric: Voronoi length per position DOF, ``l^3``
   per twist angle, so ``lambda`` has units of N/mm²); when a candidate is not null, again on
   the complement of the null ones only. Small problems use a dense symmetric
   eigensolver; large ones shift-invert Lanczos (:mod:`rotomorph.solve.lanczos`, stopping as
   soon as the wanted Ritz values converge; ARPACK's implicitly restarted Lanczos, SciPy
   ``eigsh``, if they have not within its basis) with the shift below the lowest eigenvalue,
   found by trial factorizations (Ericsson & Ruhe, *Math. Comp.* 35, 1980; a trial that a
   kept rigid direction's negative Rayleigh quotient already rules out is skipped), and the
   removed span projected out of every solve. An unstable point's eigenpairs come from ARPACK
   in every case: the solver leaves the saddle along its mode.

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

from rotomorph._typing import BoolArray, FloatArray, IntArray
from rotomorph.solve.lanczos import (
    Steps,
    banded_steps,
    shift_invert_lanczos,
    supernodal_steps,
)
from rotomorph.solve.linalg import (
    BandedMatrix,
    Factor,
    SparseMatrix,
    factorize,
    matmat,
    matvec,
)

__all__ = ["DENSE_LIMIT", "Spectrum", "analyse_hessian", "to_csc"]

#: Problem size (free DOFs less rigid modes) up to which the dense eigensolver is used.
DENSE_LIMIT = 240
#: A candidate rigid direction is removed when its curvature and coupling can move the lowest
#: eigenvalue of the rest by at most this fraction of it (:meth:`_Rigid.null`)
NULL_TOL = 1e-3


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


@dataclass(frozen=True, eq=False)
class _Rigid:
    """The candidate rigid span in the eigenbasis of its own curvature.

    ``basis`` (n, k): ``M``-orthonormal, diagonalising ``B^T H B``; ``curvature`` (k,): those
    Rayleigh quotients ``mu_j = b_j^T H b_j`` (ascending, N/mm²); ``coupling`` (k,): how
    strongly each direction couples to the rest, ``rho_j = |M^{-1/2} (H b_j - mu_j M b_j)|``
    (the same units).
    """

    basis: FloatArray
    curvature: FloatArray
    coupling: FloatArray

    @property
    def count(self) -> int:
        return int(self.basis.shape[1])

    def shift(self, tol: float = NULL_TOL) -> float:
        """Shift ``s`` of the Cholesky certificate (N/mm²): if ``H - s M`` factors with the
        whole span eliminated, the lowest eigenvalue ``lambda_1`` of the complement is at least
        ``s0`` (the smallest reference at which :meth:`null` removes every direction), so every
        direction is null and the complement positive definite.

        Proof: success means ``H - s M`` is positive definite on a subspace of codimension
        ``k``, so the pencil's ``(k+1)``-th eigenvalue exceeds ``s`` (Courant–Fischer). In the
        basis of the span and its ``M``-orthogonal complement ``H`` is the block diagonal of
        ``diag(mu)`` and the complement's block plus a coupling of norm at most
        ``|rho|_2``, which moves every eigenvalue by at most that much (Weyl): the block
        diagonal's ``(k+1)``-th eigenvalue exceeds ``s - |rho|_2 = s0``, and since every
        ``mu_j < s0`` the complement's lowest eigenvalue does.
        """
        mu, rho = np.abs(self.curvature), self.coupling
        if not len(mu):
            return 0.0
        # |mu| + rho^2 / s0 <= tol s0 for every direction
        s0 = float(np.max((mu + np.sqrt(mu**2 + 4.0 * tol * rho**2)) / (2.0 * tol)))
        return s0 + float(np.linalg.norm(rho))

    def null(self, reference: float, tol: float = NULL_TOL) -> BoolArray:
        """Which directions are removed, given the lowest eigenvalue ``reference`` (> 0) of
        the complement: those whose own curvature and coupling can move it by at most ``tol``
        times itself, ``|mu_j| + rho_j^2 / reference <= tol * reference`` (a direction of
        curvature ``mu`` coupled by ``rho`` to a complement whose lowest eigenvalue is
        ``lambda`` turns the pair's lowest eigenvalue into ``mu - rho^2 / (lambda - mu)`` to
        leading order)."""
        mu, rho = np.abs(self.curvature), self.coupling
        return np.asarray(mu + rho**2 / reference <= tol * reference)


def _rigid_directions(
    H: Any, M: FloatArray, rigid: FloatArray, action: FloatArray | None = None
) -> _Rigid:
    """:class:`_Rigid` of the candidate directions ``rigid`` (n, k); ``action`` (n, k): the
    part of ``H`` times each candidate that the symmetry itself implies (see
    :func:`analyse_hessian`), taken off before the curvatures and couplings are measured."""
    n = len(M)
    if rigid.size == 0:
        return _Rigid(np.zeros((n, 0)), np.zeros(0), np.zeros(0))
    # M-orthonormalise through the small Gram matrix (k <= 6 columns)
    G = (M[:, None] * rigid).T @ rigid
    w, V = np.linalg.eigh(G)
    ok = w > 1e-12 * max(float(w.max()), 1e-300)
    to_basis = V[:, ok] / np.sqrt(w[ok])
    basis = rigid @ to_basis
    if basis.shape[1] == 0:
        return _Rigid(basis, np.zeros(0), np.zeros(0))
    HB = matmat(H, basis)
    if action is not None:
        HB = HB - action @ to_basis
    C = basis.T @ HB
    mu, W = np.linalg.eigh(0.5 * (C + C.T))
    basis, HB = basis @ W, HB @ W
    rest = (HB - (M[:, None] * basis) * mu) / np.sqrt(M)[:, None]
    return _Rigid(basis, mu, np.linalg.norm(rest, axis=0))


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


def _cholesky_verdict(H: Any, M: FloatArray, rigid: _Rigid, scale: float, tol: float) -> bool:
    """Whether one Cholesky factorization proves the point stable with every candidate rigid
    direction null (:meth:`_Rigid.shift`).

    ``H - s M`` is factored with ``k`` DOFs on which the rigid directions are independent (a
    complement of their span) eliminated by stiff springs of ``1e16`` times the diagonal scale
    on those DOFs only: by the Schur complement the result is positive definite exactly when
    ``H - s M`` with those DOFs deleted is, up to ``1e-16`` of the scale, and the solver's
    cached symbolic factorization is reused (a diagonal change keeps the pattern). Without
    rigid directions ``s = 0``: the unshifted factorization of ``H`` itself.
    """
    shift = -rigid.shift(tol) * M
    if rigid.count:
        shift[_pivots(rigid.basis)] = 1e16 * scale
    return factorize(H, shift) is not None


def analyse_hessian(
    H: Any,
    M: FloatArray,
    rigid: FloatArray | None = None,
    *,
    count: int = 3,
    modes: bool = False,
    tol: float = 1e-12,
    null_tol: float = NULL_TOL,
    rigid_action: FloatArray | None = None,
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
        A rigid direction of curvature ``mu`` and coupling ``rho`` to the rest is removed when
        ``|mu| + rho^2 / lambda_1 <= null_tol * lambda_1``, ``lambda_1`` the lowest eigenvalue
        of the complement of the rigid span (in magnitude, at least ``tol * scale``).
    rigid_action
        ``(n, k)``: the part of ``H rigid`` that the symmetry itself implies at a point that is
        not an equilibrium (for an energy invariant under a rotation ``w``, differentiating
        the invariance gives ``H (w x r) = w x grad E`` on the positions; 0 for a
        translation). Default 0: the point is an equilibrium, where the curvatures ``H``
        shows along the candidates are the loads' exact action on them.
    """
    M = np.asarray(M, dtype=float)
    n = len(M)
    d = np.asarray(H.diagonal if isinstance(H, BandedMatrix) else H.diagonal(), dtype=float)
    scale = max(float(np.max(np.abs(d) / M)) if n else 1.0, 1e-300)
    rig = _rigid_directions(H, M, np.zeros((n, 0)) if rigid is None else rigid, rigid_action)
    k = rig.count
    nfact = 0
    if count <= 0 and n > k:
        nfact += 1
        if _cholesky_verdict(H, M, rig, scale, null_tol):
            return Spectrum(True, np.zeros(0), None, k, "cholesky", scale, nfact)
    # the shifted factorizations are of the whole H: the lowest rigid curvature bounds its
    # lowest eigenvalue from above, and the shifts it rules out are skipped
    bound = float(rig.curvature[0]) if k else np.inf
    # 1. the complement of the whole candidate span: its lowest eigenvalue is the reference
    #    of which candidates are null
    lam, vec, extra = _eigen(H, M, rig.basis, count, scale, modes, tol, bound)
    nfact += extra
    reference = max(abs(float(lam[0])) if len(lam) else 0.0, tol * scale)
    null = rig.null(reference, null_tol)
    removed = int(np.count_nonzero(null))
    if removed < k:
        # 2. the candidates that are not null (a rigid rotation a dead load turns, a motion a
        #    support holds) stay in the test
        lam, vec, extra = _eigen(H, M, rig.basis[:, null], count, scale, modes, tol, bound)
        nfact += extra
    stable = bool(lam[0] >= -tol * scale) if len(lam) else True
    return Spectrum(
        stable=stable,
        eigenvalues=lam,
        modes=_normalise_signs(vec) if (vec is not None and (modes or not stable)) else None,
        rigid=removed,
        certificate="eigenvalues",
        scale=scale,
        factorizations=nfact,
    )


def _eigen(
    H: Any,
    M: FloatArray,
    R: FloatArray,
    count: int,
    scale: float,
    vectors: bool,
    tol: float,
    bound: float,
) -> tuple[FloatArray, FloatArray | None, int]:
    """Lowest eigenpairs on the ``M``-orthogonal complement of ``R`` (``M``-orthonormal),
    dense or sparse by size; none when the complement is empty. Returns them with the
    factorizations spent."""
    m = len(M) - R.shape[1]
    if m <= 0:
        return np.zeros(0), np.zeros((len(M), 0)), 0
    want = min(max(int(count), 1), m)
    if m <= DENSE_LIMIT:
        lam, vec = _dense_eigen(H, M, R, want)
        return lam, vec, 0
    return _sparse_eigen(H, M, R, want, scale, vectors, tol, bound)


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


def _compiled_steps(fac: Factor, M: FloatArray, R: FloatArray) -> Steps | None:
    """The Lanczos steps of ``op_inv`` compiled, for the compiled factors (None otherwise)."""
    if fac.kind == "banded":
        c, u = fac.data
        return banded_steps(c, u, M, R)
    if fac.kind == "cholesky":
        structure, lx, perm = fac.data.arrays
        return supernodal_steps(structure, lx, perm, M, R)
    return None


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
    found = shift_invert_lanczos(
        op_inv, M, v0, want, min_steps=basis, steps_kernel=_compiled_steps(fac, M, R)
    )
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

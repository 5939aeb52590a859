r"""Janus (and pure-LCE) filament sections: eigenstrain fields and their natural strains.

Combines the mesh (:mod:`~rotomorph.materials.mesh`), the axial quadrature
(:mod:`~rotomorph.materials.section`) and the torsion FEM (:mod:`~rotomorph.materials.torsion`)
for a disk of radius R whose segment x1 > d is active (LCE) and the rest passive.

Eigenstrain field (small-strain, the director of the LCE in the active phase
is p = cos φ t + sin φ e_θ with the kinematic profile tan φ(r) = ω* r/R, Δ = ε∥ − ε⊥):

* active:  ε*_zz = ε⊥ + Δ cos²φ(r),   γ* = Δ sin 2φ(r) e_θ  (engineering eigen-shear),
* passive: ε*_zz = ε_p (isotropic),   γ* = 0.

r is measured from the disk centre (the nozzle axis). The in-plane components ε*_rr, ε*_θθ only
distort the section and are ignored by rod theory.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace
from functools import cached_property, lru_cache
from typing import Literal

import numpy as np

from rotomorph._typing import FloatArray, IntArray
from rotomorph.errors import InvalidParameterError
from rotomorph.materials import finite_section as finite
from rotomorph.materials.mesh import SectionMesh, disk_mesh
from rotomorph.materials.section import AxialSection, axial_section, phase_constant
from rotomorph.materials.torsion import TorsionSection, torsion_section

DEFAULT_RESOLUTION = 96

#: Print states a section remembers (about 200 bytes each); the memory is emptied when full.
SOLVED_STATES_LIMIT = 1 << 16

#: Print states evaluated per batch of eigenfields (bounds the ``(batch, Q, 2)`` temporaries).
_BATCH = 512


def unique_rows(table: FloatArray) -> tuple[FloatArray, IntArray]:
    """Distinct rows of a float table ``(n, k)`` (exact comparison) and the inverse map ``(n,)``.

    Rows are equal when every entry compares equal (so −0.0 and +0.0 are one value); the first
    row of each group in sorted order represents it. Equivalent to
    ``np.unique(table, axis=0, return_inverse=True)``, with a lexicographic sort of the columns
    instead of a sort of opaque row records (which is many times slower).
    """
    table = np.asarray(table, dtype=float)
    if len(table) == 0:
        return table.reshape(0, table.shape[1]), np.zeros(0, dtype=np.int64)
    order = np.lexsort(table.T[::-1])
    ordered = table[order]
    new = np.ones(len(table), dtype=bool)
    new[1:] = np.any(ordered[1:] != ordered[:-1], axis=1)
    inverse = np.empty(len(table), dtype=np.int64)
    inverse[order] = np.cumsum(new) - 1
    return ordered[new], inverse


@dataclass(frozen=True, eq=False)
class FilamentSection:
    """Stiffnesses and eigenstrain → natural-strain maps of one filament cross-section.

    Build with :func:`filament_section` (cached). Stiffnesses: ``axial_stiffness`` EA (N),
    ``bending_stiffness1`` B1 toward m1 = n, ``bending_stiffness2`` B2 toward m2 = t × n,
    ``twist_stiffness`` C (N·mm²). ``law``: ``"linear"`` (the small-strain section,
    :mod:`~rotomorph.materials.section`) or ``"neo-hookean"`` (natural strain and curvature
    from :mod:`~rotomorph.materials.finite_section`, the eigenstrains read in ``measure``);
    :func:`with_law` gives a section's other law.
    """

    radius: float
    mesh: SectionMesh
    axial: AxialSection
    shear_moduli: tuple[float, float]  # G of the active and the passive phase (MPa)
    law: Literal["linear", "neo-hookean"] = field(default="linear", kw_only=True)
    measure: Literal["hencky", "engineering"] = field(default="hencky", kw_only=True)
    _solved: dict[bytes, FloatArray] = field(
        default_factory=dict, init=False, repr=False, compare=False
    )
    _curved: dict[bytes, FloatArray] = field(
        default_factory=dict, init=False, repr=False, compare=False
    )

    @cached_property
    def torsion(self) -> TorsionSection:
        """Saint-Venant torsion of the section (warping FEM), solved on first use: natural
        strains of print states without eigen-shear (no director helix) do not need it."""
        return torsion_section(self.mesh, phase_constant(*self.shear_moduli))

    @property
    def solved_states(self) -> int:
        """Distinct print states this section has evaluated and remembers (see
        :meth:`natural_strains`)."""
        return len(self._solved)

    @property
    def axial_stiffness(self) -> float:
        """EA = ∫E dA (N)."""
        return self.axial.axial_stiffness

    @property
    def bending_stiffness1(self) -> float:
        """B1 (N·mm²), paired with curvature toward m1 = n (= B_n for a Janus half disk)."""
        return self.axial.bending_stiffness1

    @property
    def bending_stiffness2(self) -> float:
        """B2 (N·mm²), paired with curvature toward m2 = t × n (= B_η)."""
        return self.axial.bending_stiffness2

    @property
    def twist_stiffness(self) -> float:
        """C (N·mm²), Saint-Venant torsion with warping."""
        return self.torsion.torsion_constant

    def eigenfields(
        self,
        omega_star: float | FloatArray,
        eps_parallel: float | FloatArray,
        eps_perpendicular: float | FloatArray,
        eps_passive: float | FloatArray,
    ) -> tuple[FloatArray, FloatArray]:
        """Eigenstrain ε*_zz ``(n, Q)`` and eigen-shear γ* ``(n, Q, 2)`` at the quadrature points.

        Parameters (each a scalar or ``(n,)``, dimensionless): ``omega_star`` ω* (signed),
        ``eps_parallel`` / ``eps_perpendicular`` LCE strains along / across the director,
        ``eps_passive`` isotropic passive strain.
        """
        w, ep, et, eq = (
            np.atleast_1d(np.asarray(a, dtype=float))[:, None]
            for a in (omega_star, eps_parallel, eps_perpendicular, eps_passive)
        )
        eps_zz, denom = self._axial_eigenstrain(w, ep, et, eq)
        xy, act = self.axial.points, self.axial.active
        factor = np.where(act, 2.0 * (ep - et) * w / (self.radius * denom), 0.0)  # Δ sin2φ / r
        rot = np.column_stack([-xy[:, 1], xy[:, 0]])  # r e_θ
        return eps_zz, factor[..., None] * rot

    def _axial_eigenstrain(
        self, w: FloatArray, ep: FloatArray, et: FloatArray, eq: FloatArray
    ) -> tuple[FloatArray, FloatArray]:
        """ε*_zz ``(n, Q)`` and 1 + tan²φ ``(n, Q)`` of columns ``(n, 1)`` (see
        :meth:`eigenfields`)."""
        xy, act = self.axial.points, self.axial.active
        u2 = np.sum(xy * xy, axis=1) / self.radius**2
        denom = 1.0 + w * w * u2  # 1 + tan²φ
        return np.where(act, et + (ep - et) / denom, eq), denom

    def natural_strains(
        self,
        omega_star: float | FloatArray,
        eps_parallel: float | FloatArray,
        eps_perpendicular: float | FloatArray,
        eps_passive: float | FloatArray,
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Natural axial strain ε_c ``(n,)``, curvature ``(n, 2)`` (1/mm, toward m1, m2) and twist
        increment Δτ ``(n,)`` (1/mm) for the given print/strain state (see :meth:`eigenfields`).
        """
        # the lines of a lattice and the cells of a filament repeat a few thousand print states
        # over hundreds of thousands of vertices: evaluate each distinct state (exact key: the
        # four floats, +0.0 for -0.0) once per section, and remember it for later calls
        cols = np.broadcast_arrays(
            *(np.atleast_1d(np.asarray(a, dtype=float)) for a in
              (omega_star, eps_parallel, eps_perpendicular, eps_passive))
        )  # fmt: skip
        table = _remembered(np.column_stack(cols), self._solved, self._solve_states)
        table = table.reshape(-1, 4)
        return table[:, 0], table[:, 1:3], table[:, 3]

    def curved_strains(
        self,
        omega_star: float | FloatArray,
        eps_parallel: float | FloatArray,
        eps_perpendicular: float | FloatArray,
        eps_passive: float | FloatArray,
        curvature: FloatArray,
    ) -> tuple[FloatArray, FloatArray]:
        """Natural axial strain ``(n,)`` and curvature increment ``(n, 2)`` (1/mm, toward m1, m2,
        per printed length) of a section printed with curvature ``curvature`` ``(n, 2)``
        (1/mm, toward m1, m2): the curved-bar theory of
        :meth:`rotomorph.materials.section.AxialSection.natural_curved`, with the section's
        mean transverse eigenstrain from Turner's rule (the modulus-weighted mean of the phases'
        in-plane eigenstrains; Turner, J. Res. NBS 37, 239 (1946)). Equal to
        :meth:`natural_strains`' (ε_c, κ̄) where the printed curvature is 0.
        """
        cols = np.broadcast_arrays(
            *(np.atleast_1d(np.asarray(a, dtype=float)) for a in
              (omega_star, eps_parallel, eps_perpendicular, eps_passive)),
        )  # fmt: skip
        k0 = np.asarray(curvature, dtype=float).reshape(-1, 2)
        cols = np.broadcast_arrays(*cols, k0[:, 0])[:4]
        # their own memory: solving straight rows may clear the straight states' one
        out = _remembered(np.column_stack([*cols, k0]), self._curved, self._solve_curved)
        out = out.reshape(-1, 3)
        return out[:, 0], out[:, 1:3]

    def _solve_curved(self, states: FloatArray) -> FloatArray:
        """``(m, 3)`` rows (ε_c, κ1, κ2) of distinct curved print states ``(m, 6)``."""
        w, ep, et, eq = (states[:, i : i + 1] for i in range(4))
        eps_zz, denom = self._axial_eigenstrain(w, ep, et, eq)
        act = self.axial.active
        sin2 = 1.0 - 1.0 / denom
        eps_t = np.where(act, et + 0.5 * (ep - et) * sin2, eq)  # mean in-plane eigenstrain
        ew = self.axial.modulus * self.axial.weights
        # (einsum, not a matrix product: a row's sum must not depend on the batch's other rows)
        transverse = np.einsum("iq,q->i", eps_t, ew) / self.axial.axial_stiffness
        k0 = states[:, 4:6]
        if self.law == "neo-hookean":
            eps_c, turning = self._finite(states[:, :4], k0)
            dkappa = turning - k0
        else:
            eps_c, dkappa = self.axial.natural_curved(eps_zz, k0, transverse)
        out = np.column_stack([eps_c, dkappa])
        straight = ~np.any(k0, axis=1)
        if straight.any():  # exactly the straight section's values (bit for bit)
            eps_c, kappa, _ = self.natural_strains(*states[straight, :4].T)
            out[straight] = np.column_stack([eps_c, kappa])
        return out

    def _solve_states(self, states: FloatArray) -> FloatArray:
        """``(m, 4)`` rows (ε_c, κ1, κ2, Δτ) of distinct print states ``(m, 4)``."""
        eps_zz, gamma = self.eigenfields(*states.T)
        # no eigen-shear (ω* = 0 everywhere): no natural twist, and no torsion solve for it
        twist = self.torsion.natural_twist(gamma) if np.any(gamma) else np.zeros(len(states))
        if self.law == "neo-hookean":
            eps_c, kappa = self._finite(states, np.zeros((len(states), 2)))
            return np.column_stack([eps_c, kappa, twist])
        return np.column_stack(
            [self.axial.natural_strain(eps_zz), self.axial.natural_curvature(eps_zz), twist]
        )

    def finite_fields(self, states: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Eigen-stretch λ* ``(n, Q)``, natural volume J* ``(n, Q)`` and mean transverse
        stretch s_t ``(n,)`` of print states ``(n, 4)`` (ω*, ε∥, ε⊥, ε_p in ``measure``), the
        eigen-deformation of :mod:`~rotomorph.materials.finite_section`."""
        from rotomorph.materials.process import strain_to_stretch

        w = states[:, :1]
        l_par, l_perp, l_p = (
            np.asarray(strain_to_stretch(states[:, i : i + 1], self.measure)) for i in (1, 2, 3)
        )
        lam2, denom = self._axial_eigenstrain(w, l_par**2, l_perp**2, l_p**2)
        act = self.axial.active
        volume = np.where(act, l_par * l_perp**2, l_p**3)
        sin2 = 1.0 - 1.0 / denom
        azimuthal = np.sqrt(l_perp**2 + (l_par**2 - l_perp**2) * sin2)
        lateral = np.where(act, 0.5 * (l_perp + azimuthal), l_p)
        ew = self.axial.modulus * self.axial.weights
        transverse = np.einsum("iq,q->i", lateral, ew) / self.axial.axial_stiffness
        return np.sqrt(lam2), volume, transverse

    def fibre_quadrature(self) -> finite.FibreQuadrature:
        """The section's quadrature for :mod:`~rotomorph.materials.finite_section`."""
        a = self.axial
        return finite.FibreQuadrature(a.points, a.weights, a.modulus, a.centroid)

    def _finite(self, states: FloatArray, k0: FloatArray) -> tuple[FloatArray, FloatArray]:
        """Neo-Hookean natural strain ``(n,)`` (``measure``) and turning per printed length
        ``(n, 2)`` (1/mm) of print states ``(n, 4)`` printed with curvature k0 ``(n, 2)``."""
        from rotomorph.materials.process import stretch_to_strain

        if self.axial.folded_moment is not None:
            raise InvalidParameterError(
                "FilamentSection.law", "solve a folded stack on its full section (with_law)"
            )
        lam, volume, transverse = self.finite_fields(states)
        quad = self.fibre_quadrature()
        y = finite.minimise(quad, lam, volume, k0)
        stretch, turning = finite.natural_state(y, quad, k0, transverse)
        return np.asarray(stretch_to_strain(stretch, self.measure)), turning


@lru_cache(maxsize=64)
def with_law(
    section: FilamentSection,
    law: Literal["linear", "neo-hookean"],
    measure: Literal["hencky", "engineering"],
) -> FilamentSection:
    """``section`` with natural strains from ``law`` (eigenstrains in ``measure``); the same
    object for the linear law. A folded stack is replaced by its full section (the same
    values, without the fold the fibre energy does not admit). Cached per section."""
    if law not in finite.SECTION_MODELS:
        raise InvalidParameterError(
            "section law", f"must be one of {finite.SECTION_MODELS}; got {law!r}"
        )
    if law == "linear":
        return section
    base = getattr(section, "full", section)
    return replace(base, law=law, measure=measure)


def _remembered(
    table: FloatArray, memory: dict[bytes, FloatArray], solve: Callable[[FloatArray], FloatArray]
) -> FloatArray:
    """``solve`` of every row of ``table``, each distinct row (exact key, +0.0 for -0.0) solved
    once and kept in ``memory`` (cleared when it would pass :data:`SOLVED_STATES_LIMIT`)."""
    states, inverse = unique_rows(table + 0.0)
    keys = [row.tobytes() for row in states]
    missing = [i for i, key in enumerate(keys) if key not in memory]
    if len(memory) + len(missing) > SOLVED_STATES_LIMIT:
        memory.clear()
        missing = list(range(len(keys)))
    for lo in range(0, len(missing), _BATCH):
        batch = missing[lo : lo + _BATCH]
        memory.update(zip((keys[i] for i in batch), solve(states[batch]), strict=True))
    return np.array([memory[key] for key in keys])[inverse]


@lru_cache(maxsize=16)
def _mesh(radius: float, active_fraction: float, resolution: int) -> SectionMesh:
    """The disk mesh, shared by every modulus pair (it depends on the geometry only)."""
    return disk_mesh(radius, active_fraction, resolution)


@lru_cache(maxsize=64)
def _cached(
    radius: float,
    e_active: float,
    e_passive: float,
    g_active: float,
    g_passive: float,
    active_fraction: float,
    resolution: int,
) -> FilamentSection:
    mesh = _mesh(radius, active_fraction, resolution)
    axial = axial_section(mesh, phase_constant(e_active, e_passive))
    return FilamentSection(radius, mesh, axial, (g_active, g_passive))


def filament_section(
    radius: float,
    e_active: float,
    e_passive: float,
    *,
    poisson_active: float = 0.5,
    poisson_passive: float = 0.5,
    active_fraction: float = 0.5,
    resolution: int = DEFAULT_RESOLUTION,
) -> FilamentSection:
    """Meshed Janus section with stiffness and torsion solved once (results are cached).

    Parameters
    ----------
    radius
        Filament radius R (mm).
    e_active, e_passive
        Young's moduli of the phases (MPa) at the temperature of interest; only their ratio
        matters for unloaded shapes.
    poisson_active, poisson_passive
        Poisson ratios (G = E / (2(1 + ν)); 0.5 for elastomers).
    active_fraction
        Area fraction of the active segment in (0, 1] (0.5 Janus, 1 pure LCE).
    resolution
        Boundary vertices of the disk mesh (accuracy ≈ 1e-3 relative at 96).

    Returns
    -------
    FilamentSection
    """
    for name, value in (("e_active", e_active), ("e_passive", e_passive), ("radius", radius)):
        if not np.isfinite(value) or value <= 0.0:
            raise InvalidParameterError(name, f"must be finite and > 0; got {value}")
    g_a = e_active / (2.0 * (1.0 + poisson_active))
    g_p = e_passive / (2.0 * (1.0 + poisson_passive))
    return _cached(
        float(radius),
        float(e_active),
        float(e_passive),
        float(g_a),
        float(g_p),
        float(active_fraction),
        int(resolution),
    )

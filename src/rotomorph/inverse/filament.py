r"""Inverse design of one free filament: target centre line → print program.

Method (geometry first, then verification):

1. :func:`rotomorph.inverse.curve.curve_geometry` gives, at every vertex of the target, the
   curvature toward a director that follows the curvature normal and that frame's twist — the
   natural field for which the target is a zero-energy shape of the rod model.
2. Each vertex needs a print setting (speed :math:`v`, signed director rotation rate
   :math:`\omega^*`) whose natural field per printed length, from the tabulated forward chain
   (:mod:`rotomorph.inverse.response`), matches the target per *actuated* length:
   :math:`K(v,\omega^*) = |\kappa|\,\lambda(v,\omega^*)` and
   :math:`\tau(v,\omega^*) = \tau_{\rm target}\,\lambda(v,\omega^*)`, where :math:`\lambda` is the
   natural stretch of the centre line. The two equations are solved per vertex by bounded least
   squares, started from the best grid point; where the curvature changes sign the active half
   changes side (the interface angle jumps by π, spread over the length the machine's rotation
   limit needs).
3. Printed arc length follows from the actuated one (:math:`ds_p = ds/\lambda`); the program is a
   straight line with per-vertex speed and interface angle.
4. The program is **verified** by the forward simulation (natural field → rod → static
   equilibrium of the free filament) and the achieved shape is compared with the target after a
   rigid alignment (Kabsch). What cannot be reached is reported per vertex with its residual.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from rotomorph._typing import BoolArray, FloatArray
from rotomorph.design.program import PrintProgram
from rotomorph.errors import InvalidDesignError
from rotomorph.geometry import best_rotation
from rotomorph.inverse.curve import CurveGeometry, curve_geometry, resample, self_intersection
from rotomorph.inverse.response import ResponseTable, cached_response_table
from rotomorph.materials.natural import FilamentModel, natural_field
from rotomorph.rod.model import Model
from rotomorph.solve.static import solve_static

__all__ = ["FilamentDesign", "aligned_rms", "design_filament", "kabsch"]


def kabsch(points: FloatArray, target: FloatArray) -> FloatArray:
    """``points`` moved by the rigid motion that best fits them onto ``target`` (least squares).

    Both are ``(N, 3)`` (mm) with corresponding rows (Kabsch, *Acta Cryst.* A32, 922, 1976).
    """
    p = np.asarray(points, float)
    q = np.asarray(target, float)
    pc, qc = p.mean(axis=0), q.mean(axis=0)
    return (p - pc) @ best_rotation(p - pc, q - qc).T + qc


def aligned_rms(points: FloatArray, target: FloatArray) -> float:
    """RMS distance (mm) between corresponding rows after the best rigid alignment."""
    moved = kabsch(points, target)
    return float(np.sqrt(np.mean(np.sum((moved - np.asarray(target)) ** 2, axis=1))))


@dataclass(frozen=True, eq=False)
class FilamentDesign:
    """A print program designed to take a target shape when heated, with its verification.

    Attributes
    ----------
    program
        The print program (straight path; speed and interface angle per vertex).
    target
        Target vertices ``(N, 3)`` (mm) the program's vertices map to after actuation.
    speed
        Print speed per vertex ``(N,)`` (mm/s).
    omega_star
        Signed rate at which the interface (and the director helix) turns in the filament's
        frame, R dα/ds per vertex ``(N,)``; the nozzle's rotation number of the design file is
        :attr:`rotation_number` = −``omega_star``.
    active_side
        +1 / −1 per vertex: which side of the curvature normal the active half sits on.
    reachable
        ``(N-2,)`` True where the material response reaches the required curvature and twist
        within the tolerance.
    residual
        ``(N-2, 2)`` remaining mismatch (curvature, twist) per interior vertex (1/mm).
    achieved
        Equilibrium shape of the designed program ``(N, 3)`` (mm), aligned onto the target.
    rms_error
        RMS distance between achieved and target (mm).
    rms_error_rel
        ``rms_error`` divided by the target's length.
    flips
        Number of active-side changes along the filament.
    notes
        Human-readable findings (unreachable stretches, flips spread by the rotation limit).
    stable
        Whether the verifying equilibrium is a certified stable minimum (``None`` without
        verification).
    """

    program: PrintProgram
    target: FloatArray
    speed: FloatArray
    omega_star: FloatArray
    active_side: FloatArray
    reachable: BoolArray
    residual: FloatArray
    achieved: FloatArray
    rms_error: float
    rms_error_rel: float
    flips: int
    notes: list[str] = field(default_factory=list)
    stable: bool | None = None

    @property
    def rotation_number(self) -> FloatArray:
        """The nozzle's rotation number per vertex ``(N,)``, as design files and G-code state it
        (:data:`rotomorph.inverse.simplify.CONVENTION`): on a straight print path the interface
        turns against the nozzle (α = ψ − α_n), so this is ``-omega_star``."""
        return -self.omega_star

    @property
    def fully_reachable(self) -> bool:
        """True when every vertex is reachable."""
        return bool(np.all(self.reachable))

    def unreachable_stretches(self) -> list[tuple[float, float, float]]:
        """``(s_start, s_end, max residual curvature)`` of each unreachable stretch (mm, 1/mm)."""
        s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(self.target, axis=0), axis=1))])
        s_v = s[1:-1]
        bad = ~self.reachable
        out = []
        i = 0
        while i < len(bad):
            if bad[i]:
                j = i
                while j + 1 < len(bad) and bad[j + 1]:
                    j += 1
                out.append(
                    (float(s_v[i]), float(s_v[j]), float(np.max(np.abs(self.residual[i : j + 1]))))
                )
                i = j + 1
            else:
                i += 1
        return out


def _solve_settings(
    geo: CurveGeometry, table: ResponseTable, tol: float
) -> tuple[FloatArray, FloatArray, FloatArray, BoolArray]:
    """Per interior vertex (v, ω*) matching |κ| and τ per printed length; residuals; mask.

    All vertices at once: the best grid point, then a box-projected Gauss–Newton iteration on
    the bicubic table with a backtracking line search per vertex.
    """
    need_k = np.abs(geo.curvature)
    need_t = geo.twist
    kscale = max(table.curvature_range[1], 1e-9)
    lo = np.array([table.speeds[0], table.omega_stars[0]])
    hi = np.array([table.speeds[-1], table.omega_stars[-1]])
    # best grid point per vertex
    err = (
        (table.curvature[None] - need_k[:, None, None] * table.stretch[None]) ** 2
        + (table.twist[None] - need_t[:, None, None] * table.stretch[None]) ** 2
    ).reshape(len(need_k), -1)
    j = np.argmin(err, axis=1)
    vv, ww = np.meshgrid(table.speeds, table.omega_stars, indexing="ij")
    x = np.stack([vv.ravel()[j], ww.ravel()[j]], axis=1)

    def residual(p: FloatArray) -> FloatArray:
        k, t, lam = table(p[:, 0], p[:, 1])
        return np.stack([k - need_k * lam, t - need_t * lam], axis=1) / kscale

    r = residual(x)
    for _ in range(40):
        kv, tv, lv = table(x[:, 0], x[:, 1], dv=1)
        kw, tw, lw = table(x[:, 0], x[:, 1], dw=1)
        jac = np.empty((len(x), 2, 2))
        jac[:, 0, 0] = kv - need_k * lv
        jac[:, 0, 1] = kw - need_k * lw
        jac[:, 1, 0] = tv - need_t * lv
        jac[:, 1, 1] = tw - need_t * lw
        jac /= kscale
        jt = np.transpose(jac, (0, 2, 1))
        a = jt @ jac + 1e-12 * np.eye(2)
        b = -(jt @ r[:, :, None])[:, :, 0]
        step = np.linalg.solve(a, b[:, :, None])[:, :, 0]
        f0 = np.sum(r**2, axis=1)
        alpha = np.ones(len(x))
        done = np.zeros(len(x), dtype=bool)
        for _ls in range(12):
            trial = np.clip(x + alpha[:, None] * step, lo, hi)
            rt = residual(trial)
            better = np.sum(rt**2, axis=1) <= f0
            accept = better & ~done
            x[accept] = trial[accept]
            r[accept] = rt[accept]
            done |= better
            alpha = np.where(done, alpha, 0.5 * alpha)
            if done.all():
                break
        if np.max(np.abs(step)) < 1e-12:
            break
    res = r * kscale
    reachable = np.all(np.abs(res) <= tol * np.maximum(need_k[:, None], 0.05 * kscale), axis=1)
    return x[:, 0].copy(), x[:, 1].copy(), res, reachable


def design_filament(
    target: FloatArray,
    *,
    spacing: float = 0.1,
    radius: float = 0.3,
    temperature: float = 175.0,
    speed_range: tuple[float, float] = (0.25, 3.0),
    max_rotation: float = 40.0,
    model: FilamentModel | None = None,
    table: ResponseTable | None = None,
    tolerance: float = 0.02,
    verify: bool = True,
    active_material: str = "lce",
    passive_material: str = "acrylate",
) -> FilamentDesign:
    """Design the print program of one free filament that heats into ``target``.

    Parameters
    ----------
    target
        Target centre line, points ``(M, 3)`` (mm) in order along the filament (resampled
        with a cubic spline to ``spacing``).
    spacing
        Vertex spacing of the design along the target (mm).
    radius
        Filament radius R (mm).
    temperature
        Heating temperature at which the shape is wanted (°C).
    speed_range
        Allowed print speeds (mm/s); the default is the measured range of the speed law.
    max_rotation
        Machine rotation-rate limit (rad/s); bounds |ω*| ≤ R ω_max / v and spreads active-side
        flips over the length the nozzle needs to turn by π.
    model
        Materials modelling choices (default: the package's calibrated model).
    table
        A precomputed :class:`~rotomorph.inverse.response.ResponseTable` (else built here).
    tolerance
        Relative mismatch in curvature and twist above which a vertex is unreachable.
    verify
        Run the forward simulation and measure the achieved shape (default True).
    active_material, passive_material
        The inks (names of ``model``'s materials file, or registered ones).

    Raises
    ------
    InvalidDesignError
        Empty, degenerate or self-intersecting target; a target whose curvature lies far
        outside what any print setting reaches (more than 3× the largest natural curvature).
    """
    pts = resample(target, spacing)
    hit = self_intersection(pts, 2.0 * radius)
    if hit is not None:
        i, j, d = hit
        raise InvalidDesignError(
            "target.points",
            f"the curve passes through itself (segments {i} and {j} are {d:.3g} mm apart, less "
            f"than the filament diameter {2 * radius:g} mm); a filament cannot take this shape",
        )
    geo = curve_geometry(pts)
    if table is None:
        omega_cap = radius * max_rotation / speed_range[0]
        table = cached_response_table(
            speed_range=speed_range,
            max_omega_star=min(omega_cap, 2.5),
            radius=radius,
            temperature=temperature,
            model=model,
            active_material=active_material,
            passive_material=passive_material,
        )
    kmax = table.curvature_range[1]
    if np.max(np.abs(geo.curvature)) > 3.0 * kmax:
        raise InvalidDesignError(
            "target",
            f"its curvature reaches {np.max(np.abs(geo.curvature)):.3g} 1/mm, more than 3× the "
            f"largest natural curvature any print setting gives ({kmax:.3g} 1/mm, radius "
            f"{1 / kmax:.3g} mm); scale the target up",
        )
    speed_v, omega_v, residual, reachable = _solve_settings(geo, table, tolerance)
    # the machine's rotation limit: |ω| = |ω*| v / R ≤ max_rotation
    over = np.abs(omega_v) * speed_v / radius > max_rotation * (1 + 1e-9)
    notes: list[str] = []
    if over.any():
        omega_v = np.clip(
            omega_v, -radius * max_rotation / speed_v, radius * max_rotation / speed_v
        )
        reachable = reachable & ~over
        notes.append(f"{int(over.sum())} vertices need a rotation above {max_rotation:g} rad/s")
    side_v = np.where(geo.curvature < 0.0, -1.0, 1.0)
    # per vertex values at the ends copy their neighbours
    speed = np.concatenate([[speed_v[0]], speed_v, [speed_v[-1]]])
    omega = np.concatenate([[omega_v[0]], omega_v, [omega_v[-1]]])
    side = np.concatenate([[side_v[0]], side_v, [side_v[-1]]])
    _, _, lam = table(speed, omega)
    # printed arc length: ds_p = ds / λ (edge mean of the vertex stretches)
    seg = np.diff(geo.arc_length)
    seg_p = seg / (0.5 * (lam[:-1] + lam[1:]))
    s_p = np.concatenate([[0.0], np.cumsum(seg_p)])
    # interface angle: α' = ω*/R on the printed length, plus π where the active side is flipped
    rate = omega / radius
    alpha = np.concatenate([[0.0], np.cumsum(0.5 * (rate[:-1] + rate[1:]) * seg_p)])
    flips_at = np.flatnonzero(np.diff(side) != 0)
    flip_len = np.pi * speed_range[1] / max_rotation
    phase = _flip_phase(s_p, side, flip_len)
    alpha = alpha + phase
    if len(flips_at):
        notes.append(
            f"{len(flips_at)} active-side flips, each spread over {flip_len:.3g} mm of printed "
            f"length (rotation limit {max_rotation:g} rad/s at up to {speed_range[1]:g} mm/s)"
        )
    printed = np.stack([s_p, np.zeros_like(s_p), np.zeros_like(s_p)], axis=1)
    program = PrintProgram.from_interface_angle(
        printed,
        speed,
        alpha,
        radius=radius,
        active_material=active_material,
        passive_material=passive_material,
    )
    if not reachable.all():
        notes.append(f"{int((~reachable).sum())} of {len(reachable)} vertices are not reachable")
    achieved = pts.copy()
    rms = float("nan")
    stable: bool | None = None
    if verify:
        nat = natural_field(program, temperature=temperature, model=model)
        rod = Model.from_field(printed, nat)
        eq = solve_static(rod)
        stable = eq.stable
        achieved = kabsch(eq.positions, pts)
        rms = float(np.sqrt(np.mean(np.sum((achieved - pts) ** 2, axis=1))))
    return FilamentDesign(
        program=program,
        target=pts,
        speed=speed,
        omega_star=omega,
        active_side=side,
        reachable=reachable,
        residual=residual,
        achieved=achieved,
        rms_error=rms,
        rms_error_rel=rms / geo.length,
        flips=len(flips_at),
        notes=notes,
        stable=stable,
    )


def _flip_phase(s: FloatArray, side: FloatArray, flip_length: float) -> FloatArray:
    """Extra interface angle (rad) per vertex: 0 on side +1, π on side −1, linear ramps of
    ``flip_length`` (mm of printed length) centred on each change of side."""
    target = np.where(side < 0, np.pi, 0.0)
    if flip_length <= 0 or len(s) < 2:
        return target
    out = target.copy()
    changes = np.flatnonzero(np.diff(side) != 0)
    for c in changes:
        mid = 0.5 * (s[c] + s[c + 1])
        a0, a1 = target[c], target[c + 1]
        near = np.abs(s - mid) < 0.5 * flip_length
        frac = np.clip((s[near] - (mid - 0.5 * flip_length)) / flip_length, 0.0, 1.0)
        out[near] = a0 + (a1 - a0) * frac
    return out

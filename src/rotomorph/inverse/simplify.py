r"""The program a person reads: the simplest printable filament design within the tolerance.

:func:`rotomorph.inverse.filament.design_filament` solves a print setting (speed, rotation
number) for every vertex of the target. A lab prints segments: this module turns that
solution into the fewest straight segments of constant, machine-realisable settings whose
heated shape still meets the target within ``tolerance`` (RMS distance after the best rigid
alignment, relative to the target's length).

1. The vertices are grouped into runs whose settings stay within a box of relative width
   :math:`\delta` (speed relative to the allowed speed span, rotation number to the tabulated
   span), never across a change of the active side; a range of :math:`\delta` from coarse to
   exact is tried.
2. Each run gets one setting, rounded to what the machine realises (:data:`SPEED_STEP`,
   :data:`ROTATION_STEP`): of the rounded settings around the run's mean, the one whose
   natural field per printed length best matches the run's required field (least squares over
   its vertices, as the per-vertex solve). Its printed length is the run's target length over
   the setting's natural stretch.
3. A change of the active side is a short flip segment at the start of the next run: the
   nozzle turns by π on top of the run's own rotation, at the machine's rotation limit.
4. Every candidate is the design file itself: its print program is built by the design file
   (:meth:`rotomorph.io.designfile.Design.to_programs`), heated free (the exact zero-energy
   state, :func:`rotomorph.simulate.free_shape.free_equilibrium`) and compared with the target
   at the same material points. The candidate with the fewest segments within the tolerance is
   returned, re-verified by the rod solver (a certified stable minimum).

Conventions (the design file's, used alike by the summary, the figure and the docs):
:data:`CONVENTION`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from rotomorph._typing import FloatArray
from rotomorph.inverse.curve import curve_geometry
from rotomorph.inverse.filament import FilamentDesign, kabsch
from rotomorph.inverse.response import ResponseTable
from rotomorph.io.design_limits import nozzle_table
from rotomorph.io.designfile import Design, parse_design
from rotomorph.materials.natural import FilamentModel, natural_field
from rotomorph.materials.parameter_set import MaterialSet
from rotomorph.rod.model import Model

__all__ = [
    "CONVENTION",
    "ROTATION_STEP",
    "SPEED_STEP",
    "Segment",
    "SimpleProgram",
    "handedness_of",
    "simplest_program",
]

#: Print speed resolution of a design (mm/s).
SPEED_STEP = 0.01
#: Rotation-number resolution of a design.
ROTATION_STEP = 1e-3
#: The sign convention every output of an inverse design uses.
CONVENTION = (
    "rotation_number is the nozzle's ω* = Rω/v as in design files (ω > 0: the nozzle turns "
    "counter-clockwise seen from above); with the calibrated inks ω* > 0 heats into a "
    "left-handed helix and ω* < 0 into a right-handed one (twist and pitch > 0: right-handed)"
)
_LEVELS = (0.5, 0.3, 0.2, 0.12, 0.08, 0.05, 0.03, 0.02, 0.012, 0.008, 0.005, 0.003, 0.002, 0.0)


def handedness_of(twist: float, tol: float = 1e-6) -> str:
    """``"right-handed"`` (twist > 0, 1/mm), ``"left-handed"`` or ``"planar"``."""
    if abs(twist) < tol:
        return "planar"
    return "right-handed" if twist > 0 else "left-handed"


@dataclass(frozen=True)
class Segment:
    """One straight segment of a designed filament.

    Attributes
    ----------
    target_start, target_length
        Where it lies along the target (heated arc length, mm).
    length
        Printed length (mm).
    speed
        Print speed (mm/s).
    rotation_number
        Nozzle rotation number ω* (design-file convention, :data:`CONVENTION`).
    flip
        True for a flip of the active side (the nozzle turns by π on top of the run's rate).
    handedness
        Of the heated segment: ``right-handed``, ``left-handed``, ``planar`` (``""`` for a flip).
    """

    target_start: float
    target_length: float
    length: float
    speed: float
    rotation_number: float
    flip: bool
    handedness: str

    def record(self) -> dict[str, Any]:
        """JSON-able form."""
        return {
            "target_start_mm": round(self.target_start, 4),
            "target_length_mm": round(self.target_length, 4),
            "printed_length_mm": self.length,
            "speed_mm_s": self.speed,
            "rotation_number": self.rotation_number,
            "role": "flip of the active side" if self.flip else "setting",
            "handedness": self.handedness,
        }

    def text(self) -> str:
        """``v = 2.40 mm/s, ω* = -0.090 (left-handed), 25.1 mm``."""
        what = "flip, " if self.flip else ""
        hand = f" ({self.handedness})" if self.handedness else ""
        return (
            f"{what}v = {self.speed:.2f} mm/s, ω* = {_signed(self.rotation_number)}{hand}, "
            f"{self.length:.3g} mm printed"
        )


@dataclass(frozen=True, eq=False)
class SimpleProgram:
    """The simplest printable design found (module docstring).

    Attributes
    ----------
    segments
        The segments in printing order.
    design
        The design file (one filament of line segments), exactly what was verified.
    program
        Its print program.
    target
        Target vertices ``(N, 3)`` (mm).
    achieved
        The heated shape at the target's material points, aligned onto the target ``(N, 3)``.
    rms_error, rms_error_rel
        RMS distance to the target (mm) and relative to its length.
    tolerance
        The tolerance it was simplified to (relative RMS).
    within_tolerance
        False when no candidate met the tolerance (the closest one is returned).
    stable
        Whether the rod solver certified the heated state a stable minimum.
    """

    segments: tuple[Segment, ...]
    design: Design
    program: Any
    target: FloatArray
    achieved: FloatArray
    rms_error: float
    rms_error_rel: float
    tolerance: float
    within_tolerance: bool
    stable: bool | None

    @property
    def settings(self) -> tuple[Segment, ...]:
        """The segments that are not flips."""
        return tuple(s for s in self.segments if not s.flip)

    def text(self) -> str:
        """One phrase stating the print settings."""
        runs = self.settings
        flips = len(self.segments) - len(runs)
        head = f"{len(runs)} segment{'s' if len(runs) != 1 else ''}"
        if flips:
            head += f" and {flips} flip{'s' if flips != 1 else ''}"
        if len(runs) <= 3:
            return head + ": " + "; ".join(s.text() for s in runs)
        v = [s.speed for s in runs]
        w = [s.rotation_number for s in runs]
        hands = sorted({s.handedness for s in runs})
        return (
            f"{head}: v = {min(v):.2f}-{max(v):.2f} mm/s, ω* = {_signed(min(w))} to "
            f"{_signed(max(w))} ({', '.join(hands)})"
        )


def _signed(x: float) -> str:
    """``+0.090``, ``-0.029`` or ``0`` (rotation numbers to the design's resolution)."""
    return "0" if abs(x) < 0.5 * ROTATION_STEP else f"{x:+.3f}"


def _round(x: float, step: float) -> float:
    return float(f"{round(x / step) * step:.10g}")


def _runs(settings: FloatArray, side: FloatArray, delta: float) -> list[tuple[int, int]]:
    """Runs ``[a, b)`` of vertices with one side whose settings fit in a box of width delta."""
    out = []
    a = 0
    n = len(side)
    while a < n:
        lo = settings[a].copy()
        hi = settings[a].copy()
        b = a + 1
        while b < n and side[b] == side[a]:
            lo2 = np.minimum(lo, settings[b])
            hi2 = np.maximum(hi, settings[b])
            if np.any(hi2 - lo2 > delta + 1e-15):
                break
            lo, hi = lo2, hi2
            b += 1
        out.append((a, b))
        a = b
    return out


def _merge_short(runs: list[tuple[int, int]], side: FloatArray, s: FloatArray, min_length: float):  # type: ignore[no-untyped-def]
    """Merge runs shorter than ``min_length`` (mm of target) into a neighbour of the same side."""
    runs = list(runs)
    changed = True
    while changed and len(runs) > 1:
        changed = False
        for k, (a, b) in enumerate(runs):
            end = s[b] if b < len(s) else s[-1]
            if end - s[a] >= min_length:
                continue
            left = k > 0 and side[runs[k - 1][0]] == side[a]
            right = k + 1 < len(runs) and side[runs[k + 1][0]] == side[a]
            if left:
                runs[k - 1] = (runs[k - 1][0], b)
            elif right:
                runs[k + 1] = (a, runs[k + 1][1])
            else:
                continue
            del runs[k]
            changed = True
            break
    return runs


def _best_setting(
    table: ResponseTable,
    need_k: FloatArray,
    need_t: FloatArray,
    weight: FloatArray,
    v_mean: float,
    w_mean: float,
    speed_range: tuple[float, float],
    max_rotation: float,
    radius: float,
) -> tuple[float, float]:
    """The rounded (speed, director rate) near the mean that best meets the run's field."""
    lo, hi = speed_range
    v0 = min(max(_round(v_mean, SPEED_STEP), _ceil(lo, SPEED_STEP)), _floor(hi, SPEED_STEP))
    w0 = _round(w_mean, ROTATION_STEP)
    vs = np.clip(v0 + SPEED_STEP * np.arange(-3, 4), _ceil(lo, SPEED_STEP), _floor(hi, SPEED_STEP))
    ws = w0 + ROTATION_STEP * np.arange(-3, 4)
    vv, ww = (a.ravel() for a in np.meshgrid(np.unique(vs), ws, indexing="ij"))
    ok = np.abs(ww) * vv / radius <= max_rotation * (1 + 1e-12)
    vv, ww = vv[ok], ww[ok]
    k, t, lam = table(vv, ww)
    err = (
        (
            (k[:, None] - need_k[None] * lam[:, None]) ** 2
            + (t[:, None] - need_t[None] * lam[:, None]) ** 2
        )
        * weight[None]
    ).sum(axis=1)
    j = int(np.argmin(err))
    return _round(float(vv[j]), SPEED_STEP), _round(float(ww[j]), ROTATION_STEP)


def _ceil(x: float, step: float) -> float:
    return _round(math.ceil(x / step - 1e-9) * step, step)


def _floor(x: float, step: float) -> float:
    return _round(math.floor(x / step + 1e-9) * step, step)


def _segments(
    runs: list[tuple[int, int]],
    design: FilamentDesign,
    table: ResponseTable,
    s: FloatArray,
    need: tuple[FloatArray, FloatArray, FloatArray],
    speed_range: tuple[float, float],
    max_rotation: float,
    radius: float,
) -> tuple[list[Segment], list[tuple[float, float, float, float]]]:
    """Segments of a grouping and, per run, (target start, printed start, stretch, length)."""
    need_k, need_t, weight = need
    segs: list[Segment] = []
    maps = []
    printed = 0.0
    side = design.active_side
    for k, (a, b) in enumerate(runs):
        start, end = s[a], (s[b] if b < len(s) else s[-1])
        if k + 1 == len(runs):
            end = s[-1]
        sl = slice(a, b)
        v, w = _best_setting(
            table, need_k[sl], need_t[sl], weight[sl],
            float(np.average(design.speed[sl], weights=weight[sl])),
            float(np.average(design.omega_star[sl], weights=weight[sl])),
            speed_range, max_rotation, radius,
        )  # fmt: skip
        _, t, lam = (float(x) for x in table(np.array(v), np.array(w)))
        length_p = (end - start) / lam
        rotation = _round(-w, ROTATION_STEP) + 0.0  # the nozzle's ω* (design files)
        flip_len = 0.0
        if k > 0 and side[a] != side[runs[k - 1][0]]:
            # at the rotation limit, but never more than half the run (a run shorter than the
            # limit needs can only come from a side that changes within a few vertices)
            flip_len = max(
                min(_ceil(1.05 * math.pi * v / max_rotation, 1e-3), _floor(0.5 * length_p, 1e-3)),
                1e-3,
            )
            turn = -1.0 if rotation > 0 else 1.0
            flip_rot = _round(rotation + turn * math.pi * radius / flip_len, ROTATION_STEP)
            segs.append(Segment(start, flip_len * lam, flip_len, v, flip_rot, True, ""))
        rest = max(_round(length_p - flip_len, 1e-3), 1e-3)
        segs.append(
            Segment(
                start + flip_len * lam, end - start - flip_len * lam, rest, v, rotation, False,
                handedness_of(t),
            )
        )  # fmt: skip
        maps.append((start, printed, lam, end))
        printed += flip_len + rest
    return segs, maps


def _design_file(
    segments: list[Segment],
    spacing: float,
    radius: float,
    fraction: float,
    name: str,
    inks: dict[str, Any] | None = None,
    materials: MaterialSet | None = None,
) -> Design:
    text = "; ".join(s.text() for s in segments if not s.flip)
    inks = dict(inks or {})
    names = inks.pop("filament", {})
    return parse_design(
        {
            "schema_version": 1,
            "name": name,
            "description": (
                "designed by rotomorph inverse (straight print path; heats into the target): "
                + text
                + ". "
                + CONVENTION
            )[:10_000],
            "filaments": [
                {
                    "name": name,
                    "speed": segments[0].speed,
                    "spacing": spacing,
                    "radius": radius,
                    "active_fraction": fraction,
                    **names,
                    "segments": [
                        {
                            "kind": "line",
                            "length": s.length,
                            "speed": s.speed,
                            "rotation_number": s.rotation_number,
                        }
                        for s in segments
                    ],
                }
            ],
            **nozzle_table(radius),  # when the default 1 mm nozzle cannot print the filament
            **inks,
        },
        materials=materials if inks else None,
    )


def _achieved(
    program: Any, shape: FloatArray, maps: list[tuple[float, float, float, float]], s: FloatArray
) -> FloatArray:
    """The heated shape at the target's material points (printed arc length of each)."""
    sp = np.empty_like(s)
    for start, printed, lam, end in maps:
        sel = (s >= start - 1e-12) & (s <= end + 1e-12)
        sp[sel] = printed + (s[sel] - start) / lam
    arc = program.arc_length
    sp = np.clip(sp, 0.0, arc[-1])
    return np.stack([np.interp(sp, arc, shape[:, i]) for i in range(3)], axis=1)


def simplest_program(
    design: FilamentDesign,
    table: ResponseTable,
    *,
    tolerance: float,
    speed_range: tuple[float, float],
    max_rotation: float,
    spacing: float,
    temperature: float = 175.0,
    model: FilamentModel | None = None,
    name: str = "inverse",
    inks: dict[str, Any] | None = None,
    materials: MaterialSet | None = None,
) -> SimpleProgram:
    """The fewest-segment printable design within ``tolerance`` (module docstring).

    Parameters
    ----------
    design
        The per-vertex design of :func:`~rotomorph.inverse.filament.design_filament`.
    table
        The response table it was designed with.
    tolerance
        Allowed RMS distance to the target after alignment, relative to its length.
    speed_range
        Allowed print speeds (mm/s).
    max_rotation
        The machine's rotation limit (rad/s).
    spacing
        Vertex spacing of the design file (mm).
    temperature
        Heating temperature (°C).
    model
        Materials model (default: the calibrated one).
    name
        Name of the design and its filament.
    inks, materials
        The design file's materials entry and ink names (``{"materials": path, "filament":
        {"active_material": …, "passive_material": …}}``) and the materials set they name;
        ``None``: the paper's inks.
    """
    from rotomorph.simulate.free_shape import free_equilibrium
    from rotomorph.solve.static import solve_static

    target = design.target
    geo = curve_geometry(target)
    s = geo.arc_length
    length = geo.length
    radius = float(table.radius)
    pad = lambda x: np.concatenate([[x[0]], x, [x[-1]]])  # noqa: E731
    need_k = pad(np.abs(geo.curvature))
    need_t = pad(geo.twist)
    weight = np.gradient(s)
    span = np.array(
        [max(speed_range[1] - speed_range[0], 1e-9), max(float(np.ptp(table.omega_stars)), 1e-9)]
    )
    settings = np.stack([design.speed, design.omega_star], axis=1) / span
    fraction = 0.5
    flip_min = 2.2 * math.pi * speed_range[1] / max_rotation
    best: SimpleProgram | None = None
    seen: set[tuple[tuple[int, int], ...]] = set()
    for delta in _LEVELS:  # coarse to exact: the first candidate within tolerance is simplest
        runs = _runs(settings, design.active_side, delta)
        runs = _merge_short(runs, design.active_side, s, flip_min)
        if tuple(runs) in seen:
            continue
        seen.add(tuple(runs))
        segs, maps = _segments(
            runs, design, table, s, (need_k, need_t, weight), speed_range, max_rotation, radius
        )
        file = _design_file(segs, spacing, radius, fraction, name, inks, materials)
        prog = file.to_programs()[0]
        nat = natural_field(prog, temperature=temperature, model=model)
        shape = free_equilibrium(Model.from_field(prog.points, nat))
        ach = kabsch(_achieved(prog, shape, maps, s), target)
        rms = float(np.sqrt(np.mean(np.sum((ach - target) ** 2, axis=1))))
        within = rms <= tolerance * length
        if best is None or within or rms < best.rms_error:
            best = SimpleProgram(
                tuple(segs), file, prog, target, ach, rms, rms / length, tolerance, within, None
            )
            best_maps = maps
        if within:
            break
    assert best is not None
    # the chosen design verified by the rod solver: a certified stable minimum
    nat = natural_field(best.program, temperature=temperature, model=model)
    eq = solve_static(Model.from_field(best.program.points, nat))
    ach = kabsch(_achieved(best.program, eq.positions, best_maps, s), target)
    rms = float(np.sqrt(np.mean(np.sum((ach - target) ** 2, axis=1))))
    return SimpleProgram(
        best.segments,
        best.design,
        best.program,
        target,
        ach,
        rms,
        rms / length,
        tolerance,
        rms <= tolerance * length,
        eq.stable,
    )

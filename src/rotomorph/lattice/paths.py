"""Path dependence of a heating ramp: which end state of a multistable lattice to keep.

A lattice can have several stable equilibria at the end of its ramp (e.g. a dome lattice that
either rises into a bowl or coils its rim edges and stays nearly flat). Quasi-static
continuation follows one of them, and which one can depend on the ramp's steps. The path check
ramps the lattice a second time with every step split into ``factor`` sub-steps; where the two
ramps end in different states, the one lower in total energy (elastic + weight + contact) is
kept — both end at the same parameter on the same model, so their energies compare. That is
the lowest-energy choice the floor's lift probe makes between resting and lifted states,
applied to the path.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from rotomorph._typing import FloatArray, IntArray
from rotomorph.errors import InvalidParameterError
from rotomorph.geometry import best_rotation

__all__ = [
    "ENERGY_TIE",
    "SAME_SHAPE_TOL",
    "PathCheck",
    "check_factor",
    "choose_end",
    "per_row",
    "shape_distance",
    "sub_stepped",
]

#: Largest node distance (in filament radii), after the best rigid alignment, below which two
#: end states count as the same state (free lattices drift rigidly by round-off).
SAME_SHAPE_TOL = 1e-3
#: Relative difference of total energy below which two end states of different shape are a
#: tie: one flat valley of the energy (a soft mode the solver's tolerance leaves undetermined)
#: or symmetric partners, never a reason to prefer one (round-off is ~1e-14 here).
ENERGY_TIE = 1e-9


@dataclass(frozen=True)
class PathCheck:
    """Outcome of a path check.

    Attributes
    ----------
    factor
        Sub-steps per ramp step of the second ramp.
    energy
        Final total energy of the ramp as requested and of the sub-stepped one (N mm); NaN
        where a ramp failed.
    stable
        Whether each ramp's end state was certified stable.
    kept
        ``"steps"`` (the ramp as requested) or ``"sub-steps"`` (the sub-stepped ramp, sampled
        at the requested parameters).
    same_state
        Both ramps ended in the same state (:data:`SAME_SHAPE_TOL`).
    tie
        The ends differ in shape but not in total energy (:data:`ENERGY_TIE`): the ramp as
        requested is kept.
    admissible
        Whether each ramp's end state is admissible (no two layers of the printed stack
        interpenetrate); an inadmissible end is never kept over an admissible one.
    discarded_iterations, discarded_wall_time
        Newton iterations and seconds of the ramp not kept (not in the result's
        ``iterations`` and ``wall_time``).
    """

    factor: int
    energy: tuple[float, float]
    stable: tuple[bool, bool]
    kept: str
    same_state: bool
    discarded_iterations: int = 0
    discarded_wall_time: float = 0.0
    tie: bool = False
    admissible: tuple[bool, bool] = (True, True)

    @property
    def note(self) -> str:
        """One sentence for reports."""
        e1, e2 = self.energy
        second = f"the ramp with {self.factor} sub-steps per step"
        if not np.isfinite(e2):
            return f"path check: {second} failed; the ramp as requested is kept"
        if self.same_state:
            return f"path check: {second} ends in the same state"
        if self.tie:
            return (
                f"path check: {second} ends in another shape of the same total energy "
                f"({e1:.9g} and {e2:.9g} N mm: one flat valley of the energy or a symmetric "
                "partner, not a lower state); the ramp as requested is kept"
            )
        ends = (
            f"path check: the ramp as requested and {second} end in different states "
            f"(total energy {e1:.6g} and {e2:.6g} N mm"
        )
        kept = "sub-stepped" if self.kept == "sub-steps" else "requested"
        if not all(self.admissible):
            which = "requested" if not self.admissible[0] else "sub-stepped"
            return (
                f"{ends}; the {which} one is not admissible: layers of the printed stack "
                f"interpenetrate); the {kept} one is kept"
            )
        if not all(self.stable):
            which = "requested" if not self.stable[0] else "sub-stepped"
            return f"{ends}; the {which} one is not certified stable); the {kept} one is kept"
        return (
            f"{ends}, both certified stable): the lattice is multistable and the one lower in "
            f"total energy is kept ({self.kept})"
        )


def check_factor(factor: object) -> int:
    """Validate a path-check factor (1: no check)."""
    ok = isinstance(factor, (int, np.integer)) and not isinstance(factor, bool)
    if not ok or not 1 <= int(factor) <= 8:  # type: ignore[call-overload]
        raise InvalidParameterError(
            "path_check", f"must be an integer from 1 (no check) to 8 sub-steps; got {factor!r}"
        )
    return int(factor)  # type: ignore[call-overload]


def sub_stepped(values: FloatArray, factor: int) -> FloatArray:
    """Ramp values with every step split into ``factor`` equal sub-steps; ``values`` are kept
    exactly (every ``factor``-th entry), so the requested states can be sampled from it."""
    v = np.asarray(values, dtype=float)
    out = np.empty((len(v) - 1) * factor + 1)
    out[::factor] = v
    for j in range(1, factor):
        out[j::factor] = v[:-1] + (v[1:] - v[:-1]) * (j / factor)
    return out


def shape_distance(a: FloatArray, b: FloatArray) -> float:
    """Largest node distance (mm) between two configurations ``(N, 3)`` after the best rigid
    alignment of ``b`` onto ``a`` (least squares; Kabsch, Acta Cryst. A32, 922 (1976))."""
    pa, pb = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    ca, cb = pa - pa.mean(axis=0), pb - pb.mean(axis=0)
    return float(np.linalg.norm(cb @ best_rotation(cb, ca).T - ca, axis=1).max())


def choose_end(
    energy: tuple[float, float],
    stable: tuple[bool, bool],
    same_shape: bool,
    factor: int,
    admissible: tuple[bool, bool] = (True, True),
) -> PathCheck:
    """Which ramp to keep: the requested one unless the sub-stepped one ends in a different
    state that is certified stable and admissible (no two layers of the printed stack
    interpenetrate) and either lower in total energy (by more than :data:`ENERGY_TIE`) or the
    only such one. ``energy`` holds both final total energies (NaN for a failed ramp);
    ``admissible`` both ends' admissibility (an inadmissible end counts as not stable: it is
    never chosen over an admissible one)."""
    e1, e2 = (float(e) for e in energy)
    s1 = bool(stable[0]) and bool(admissible[0])
    s2 = bool(stable[1]) and bool(admissible[1]) and np.isfinite(e2)
    same = bool(np.isfinite(e2) and same_shape)
    tie = bool(
        not same and s1 and s2 and abs(e1 - e2) <= ENERGY_TIE * max(abs(e1), abs(e2), 1e-300)
    )
    second = not same and not tie and s2 and (not s1 or e2 < e1)
    kept = "sub-steps" if second else "steps"
    return PathCheck(
        factor,
        (e1, e2),
        (bool(stable[0]), bool(stable[1]) and bool(np.isfinite(e2))),
        kept,
        same,
        tie=tie,
        admissible=(bool(admissible[0]), bool(admissible[1])),
    )


def per_row(steps: Sequence[Any], per_step: int) -> tuple[IntArray, FloatArray]:
    """Halvings and wall time (s) of each reported row from the continuation's ``steps``
    (each with ``halvings`` and ``wall_time``), ``per_step`` consecutive (sub-)steps per row:
    a row's halvings are the most any of its sub-steps needed, its time their sum. Row 0 (the
    printed state) is 0."""
    groups = [steps[i : i + per_step] for i in range(0, len(steps), per_step)]
    halvings = np.array([0] + [max(s.halvings for s in g) for g in groups], dtype=np.int64)
    wall = np.array([0.0] + [sum(s.wall_time for s in g) for g in groups])
    return halvings, wall

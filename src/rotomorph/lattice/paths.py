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

from dataclasses import dataclass

import numpy as np

from rotomorph._typing import FloatArray
from rotomorph.errors import InvalidParameterError

__all__ = ["SAME_STATE_RTOL", "PathCheck", "check_factor", "choose_end", "sub_stepped"]

#: Relative difference of total energy below which two ramps ended in the same state.
SAME_STATE_RTOL = 1e-6


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
    kept
        ``"steps"`` (the ramp as requested) or ``"sub-steps"`` (the sub-stepped ramp, sampled
        at the requested parameters).
    same_state
        Both ramps ended in the same state (energies within :data:`SAME_STATE_RTOL`).
    """

    factor: int
    energy: tuple[float, float]
    kept: str
    same_state: bool

    @property
    def note(self) -> str:
        """One sentence for reports."""
        e1, e2 = self.energy
        second = f"the ramp with {self.factor} sub-steps per step"
        if self.same_state:
            return f"path check: {second} ends in the same state"
        if not np.isfinite(e2):
            return f"path check: {second} failed"
        return (
            f"path check: the ramp as requested and the one with {self.factor} sub-steps per step "
            f"end in different stable states (total energy {e1:.6g} and {e2:.6g} N mm); the "
            f"lattice is multistable and the one lower in energy is kept ({self.kept})"
        )


def check_factor(factor: int) -> int:
    """Validate a path-check factor (1: no check)."""
    if int(factor) != factor or not 1 <= factor <= 8:
        raise InvalidParameterError(
            "path_check", f"must be an integer from 1 (no check) to 8 sub-steps; got {factor}"
        )
    return int(factor)


def sub_stepped(values: FloatArray, factor: int) -> FloatArray:
    """Ramp values with every step split into ``factor`` equal sub-steps; ``values`` are kept
    exactly (every ``factor``-th entry), so the requested states can be sampled from it."""
    v = np.asarray(values, dtype=float)
    out = np.empty((len(v) - 1) * factor + 1)
    out[::factor] = v
    for j in range(1, factor):
        out[j::factor] = v[:-1] + (v[1:] - v[:-1]) * (j / factor)
    return out


def choose_end(energy: float, other: float, other_admissible: bool, factor: int) -> PathCheck:
    """Keep the requested ramp (final total energy ``energy``) unless the sub-stepped one
    (``other``; NaN if it failed) ends in a different state that is ``other_admissible``
    (certified stable) and lower in total energy."""
    e1, e2 = float(energy), float(other)
    same = bool(
        np.isfinite(e1)
        and np.isfinite(e2)
        and abs(e2 - e1) <= SAME_STATE_RTOL * max(abs(e1), abs(e2), 1e-300)
    )
    lower = np.isfinite(e2) and (not np.isfinite(e1) or e2 < e1)
    kept = "sub-steps" if not same and other_admissible and lower else "steps"
    return PathCheck(factor, (e1, e2), kept, same)

"""Is a stored state physical? One verdict per step, from the flags a run stores.

A state is physical when the solve that produced it converged, the equilibrium is stable and
no two filaments pass through each other — for a lattice printed in layers, no two layers of its
printed stack either. Runs store what they checked as per-step scalars:

``converged``
    1 where the step's solve converged, 0 where not.
``stable``
    1 where the solver verified a stable minimum (positive definite Hessian up to rigid
    motions), 0 where it found an unstable equilibrium, NaN where it did not check.
``min_clearance``
    Smallest distance between segments that do not touch as printed, in filament diameters
    (< 1: filaments overlap; without a contact model that is not physical).
``max_axial_strain``
    Largest centre-line strain of any edge against its natural length (``|l/l̄ − 1|``). The
    rod model stretches by a linear, small-strain law; above :data:`MAX_AXIAL_STRAIN` the state
    is outside the model (a dead load that flipped a filament and pulls it to several times its
    length converges, and is nonsense). Runs that do not store it are not flagged for it.
``stack_overlaps``
    Lattices: layer pairs of the printed stack that interpenetrate
    (:mod:`rotomorph.lattice.admissibility`; > 0 is not physical, contact or not). Absent for
    filaments, whose section is one layer (the clearance check covers them).

A scalar that is missing, or NaN at a step, is **unknown** at that step — never counted as
fine. Whether contact was modelled is read from ``metadata["contact"]`` (absent: not
modelled). :func:`assess` returns one :class:`StepVerdict` per step; :func:`run_verdict`
summarises the end of the ramp for titles, the command line, ``summary.json`` and the HDF5
attributes.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, Final, Literal

import numpy as np

__all__ = [
    "MAX_AXIAL_STRAIN",
    "StepVerdict",
    "assess",
    "last_physical_step",
    "run_verdict",
    "verdict_record",
]

Verdict = Literal["yes", "no", "unknown"]

#: Largest centre-line strain against the natural length accepted as physical (20 %): the
#: stretching law is linear (small strain) and the printed inks are not that extensible.
MAX_AXIAL_STRAIN: Final = 0.2


@dataclass(frozen=True)
class StepVerdict:
    """Whether one stored state is physical.

    Attributes
    ----------
    verdict
        ``"yes"`` (every check passed), ``"no"`` (a check failed) or ``"unknown"`` (no check
        failed, but at least one was not made).
    reasons
        Short phrases: what failed (for ``"no"``) or what was not checked (for
        ``"unknown"``).
    """

    verdict: Verdict
    reasons: tuple[str, ...] = ()

    @property
    def is_physical(self) -> bool:
        """True only for a verdict of ``"yes"``."""
        return self.verdict == "yes"

    def text(self) -> str:
        """One line: ``"physical"``, ``"NOT PHYSICAL: …"`` or ``"unverified: …"``."""
        if self.verdict == "yes":
            return "physical"
        head = "NOT PHYSICAL" if self.verdict == "no" else "unverified"
        return f"{head}: {'; '.join(self.reasons)}"


def _flag(scalars: Mapping[str, Any], name: str, k: int) -> float:
    v = scalars.get(name)
    if v is None or k >= len(v):
        return float("nan")
    return float(v[k])


def assess(
    scalars: Mapping[str, Any], metadata: Mapping[str, Any], n_steps: int
) -> list[StepVerdict]:
    """One :class:`StepVerdict` per stored step.

    Parameters
    ----------
    scalars
        Per-step scalars of a run (``converged``, ``stable``, ``min_clearance`` and, where
        present, ``stack_overlaps`` are read).
    metadata
        Run metadata (``contact``: whether contact was modelled).
    n_steps
        Number of stored steps S.
    """
    contact = bool(metadata.get("contact", False))
    out = []
    for k in range(n_steps):
        failed, unknown = [], []
        conv = _flag(scalars, "converged", k)
        if np.isnan(conv):
            unknown.append("convergence not recorded")
        elif conv < 0.5:
            failed.append("solver did not converge")
        stab = _flag(scalars, "stable", k)
        if np.isnan(stab):
            unknown.append("stability not checked")
        elif stab < 0.5:
            failed.append("unstable equilibrium")
        clear = _flag(scalars, "min_clearance", k)
        if np.isnan(clear):
            if not contact:
                unknown.append("self-intersection not checked")
        elif clear < 1.0 and not contact:
            what = "pass through each other" if clear < 0.05 else "overlap"
            failed.append(
                f"filaments {what} (clearance {clear:.2f} diameters, contact not modelled)"
            )
        strain = _flag(scalars, "max_axial_strain", k)
        if strain > MAX_AXIAL_STRAIN:
            failed.append(
                f"edges strained {100 * strain:.0f} % against their natural length (the rod "
                f"model holds to {100 * MAX_AXIAL_STRAIN:.0f} %)"
            )
        stack = _flag(scalars, "stack_overlaps", k)
        if stack > 0:
            failed.append(f"{int(stack)} layer pairs of the printed stack interpenetrate")
        elif np.isnan(stack) and "stack_overlaps" in scalars:
            unknown.append("stack admissibility not checked")
        if failed:
            out.append(StepVerdict("no", tuple(failed)))
        elif unknown:
            out.append(StepVerdict("unknown", tuple(unknown)))
        else:
            out.append(StepVerdict("yes"))
    return out


def last_physical_step(verdicts: list[StepVerdict]) -> int | None:
    """Index of the last step before the first ``"no"`` (``None`` if step 0 already fails)."""
    for k, v in enumerate(verdicts):
        if v.verdict == "no":
            return k - 1 if k > 0 else None
    return len(verdicts) - 1


def run_verdict(verdicts: list[StepVerdict]) -> StepVerdict:
    """Verdict on the end of the ramp, naming the first failing step if any step fails."""
    end = verdicts[-1]
    first = next((k for k, v in enumerate(verdicts) if v.verdict == "no"), None)
    if first is not None and end.verdict != "no":
        return StepVerdict("no", (f"step {first}: {'; '.join(verdicts[first].reasons)}",))
    return end


def verdict_record(verdicts: list[StepVerdict]) -> dict[str, Any]:
    """JSON-compatible record: ``verdict``, ``reason``, ``last_physical_step`` and per-step
    verdicts (what ``metadata["physical"]`` and ``summary.json`` hold)."""
    end = run_verdict(verdicts)
    return {
        "verdict": end.verdict,
        "reason": "; ".join(end.reasons) if end.reasons else "all checks passed",
        "last_physical_step": last_physical_step(verdicts),
        "steps": [v.verdict for v in verdicts],
    }

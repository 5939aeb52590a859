r"""Print order for a machine: serpentine lines and the profile's z offset.

Reversing a filament prints the same filament backward. For a horizontal path with vertex
heading :math:`\psi_v` (the program's ``vertex_heading``: its curve's tangent), the interface
normal toward the active half keeps its lab direction when the nozzle angle becomes

.. math:: \alpha_n' = 2\psi_v + \pi - \alpha_n

at each vertex (then the interface angle, measured in the reversed path's own frame, is
:math:`\alpha' = -\alpha`): the active half stays on the same physical side, and on a straight
line :math:`d\alpha_n'/ds' = d\alpha_n/ds`, so ω is unchanged. On curved paths the rate changes
by :math:`2\kappa v`, so a reversal is used only where the machine's rotation limit allows it.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import numpy as np

from rotomorph.design.program import PrintProgram

__all__ = ["is_reversible", "machine_order", "reversed_program"]

_FLAT = 1e-9  # mm: a program is horizontal when its z spread is below this


def is_reversible(program: PrintProgram) -> bool:
    """True if ``program`` lies in a horizontal plane (reversal is defined there)."""
    return bool(np.ptp(program.points[:, 2]) < _FLAT)


def reversed_program(program: PrintProgram) -> PrintProgram:
    """The same horizontal filament printed from its end to its start (module docstring).

    Raises
    ------
    ValueError
        If the program is not horizontal.
    """
    if not is_reversible(program):
        raise ValueError("only horizontal programs can be reversed")
    psi_v = program.vertex_heading  # the curve's tangent where the program carries it
    angle = 2 * psi_v + np.pi - program.nozzle_angle
    speed = np.concatenate([program.speed[:-1][::-1], [program.speed[0]]])
    tangent = None if program.tangent_heading is None else (psi_v + np.pi)[::-1].copy()
    return dataclasses.replace(
        program,
        points=program.points[::-1].copy(),
        speed=speed,
        nozzle_angle=angle[::-1].copy(),
        tangent_heading=tangent,
    )


def _peak_rotation(program: PrintProgram) -> float:
    rate = np.abs(np.diff(program.nozzle_angle)) / program.path.edge_lengths
    return float(np.max(rate * program.speed[:-1]))


def machine_order(
    programs: Sequence[PrintProgram],
    *,
    serpentine: bool = True,
    max_rotation: float = np.inf,
    z_offset: float = 0.0,
) -> list[PrintProgram]:
    """Programs as a machine prints them: same order, some reversed, z shifted.

    Parameters
    ----------
    programs
        Print programs in the design's order (layers non-decreasing).
    serpentine
        Reverse a program when its end is closer than its start to where the previous one
        ended (no return travel between lattice lines), if the reversed program is horizontal
        and stays within ``max_rotation``.
    max_rotation
        Rotation limit (rad/s) a reversed program must respect.
    z_offset
        Added to every z (mm): the machine's program Z of design z = 0.
    """
    out: list[PrintProgram] = []
    for prog in programs:
        if serpentine and out and is_reversible(prog):
            here = out[-1].points[-1]
            if np.linalg.norm(prog.points[-1] - here) < np.linalg.norm(prog.points[0] - here):
                rev = reversed_program(prog)
                if _peak_rotation(rev) <= max(max_rotation, _peak_rotation(prog)):
                    prog = rev
        out.append(prog)
    if z_offset != 0.0:
        out = [p.translated((0.0, 0.0, z_offset)) for p in out]
    return out

"""Where a design sits on the machine: a refusal that names the design key to change.

The G-code writer (:mod:`rotomorph.io.gcode`) refuses any vertex outside the machine's
envelope, naming the machine profile's key. A design is placed by its own keys — each
filament's ``start``, the lattice's ``origin`` — so :func:`check_placement` checks the printed
vertices of each part of a design first and says which key to change, by how much, and a value
that fits.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from rotomorph.errors import MachineLimitError

__all__ = ["check_placement"]

_EPS = 1e-9  # mm, as the G-code writer's envelope check
_MARGIN = 5.0  # mm kept from the envelope's edge in a suggested placement


def _parts(design: Any) -> list[tuple[str, tuple[float, float, float], np.ndarray]]:
    """(key, its value, printed vertices) for every placed part of the design."""
    out = []
    for i, f in enumerate(design.filaments):
        out.append((f"filaments[{i}].start", tuple(f.start), f.to_program().points))
    if design.lattice is not None:
        lat = design.lattice
        pts = np.vstack([p.points for p in lat.to_lattice().print_programs()])
        out.append(("lattice.origin", tuple(lat.origin), pts + np.asarray(lat.origin)))
    return out


def _fmt(v: Any) -> str:
    return "[" + ", ".join(f"{float(x):.4g}" for x in v) + "]"


def check_placement(design: Any, machine: Any) -> None:
    """Raise unless every printed vertex of ``design`` lies in ``machine``'s envelope.

    Parameters
    ----------
    design
        A :class:`~rotomorph.io.designfile.Design`.
    machine
        A :class:`~rotomorph.io.machine.MachineProfile` (its ``z_offset`` included).

    Raises
    ------
    MachineLimitError
        Naming the design key (``filaments[i].start`` or ``lattice.origin``) whose part leaves
        the envelope, the shift it needs and a value that fits; or, for a part larger than the
        envelope, the machine profile keys.
    """
    lo = np.asarray(machine.envelope_min, dtype=float)
    hi = np.asarray(machine.envelope_max, dtype=float)
    for key, value, pts in _parts(design):
        pts = pts + np.array([0.0, 0.0, float(machine.z_offset)])
        p_lo, p_hi = pts.min(axis=0), pts.max(axis=0)
        if np.all(p_lo >= lo - _EPS) and np.all(p_hi <= hi + _EPS):
            continue
        where = (
            f"{key} = {_fmt(value)} mm: its printed path spans {_fmt(p_lo)}..{_fmt(p_hi)} mm "
            f"(z_offset {machine.z_offset:g} mm included), outside the envelope "
            f"{_fmt(lo)}..{_fmt(hi)} mm of machine {machine.name!r}"
        )
        size, room = p_hi - p_lo, hi - lo
        side = "envelope_max" if np.any(p_hi > hi + _EPS) else "envelope_min"
        if np.any(size > room + _EPS):
            axis = "xyz"[int(np.argmax(size - room))]
            raise MachineLimitError(
                f"{where}; it is {size[int(np.argmax(size - room))]:.4g} mm long in {axis}, more "
                f"than the envelope: it does not fit this machine (machine profile key '{side}')"
            )
        need = np.where(p_lo < lo - _EPS, lo - p_lo, 0.0) + np.where(
            p_hi > hi + _EPS, hi - p_hi, 0.0
        )
        margin = np.minimum(_MARGIN, 0.5 * (room - size))
        shift = need + np.sign(need) * margin
        fits = np.asarray(value, dtype=float) + shift
        raise MachineLimitError(
            f"{where}; move it by at least {_fmt(need)} mm: e.g. set {key} = {_fmt(fits)} "
            f"(or change the machine profile key '{side}')"
        )

"""Configuration of a rod network: node positions, twist angles and (time-parallel) frames."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rotomorph._display import compact_display
from rotomorph._typing import FloatArray
from rotomorph.rod.assembly import material_frames


@compact_display()
@dataclass(frozen=True, eq=False)
class State:
    """A configuration of a rod network.

    Attributes
    ----------
    positions
        Node positions ``(N, 3)`` (mm).
    theta
        Twist angle of each edge's material frame from its reference frame ``(E,)`` (rad).
    tangents
        Unit edge tangents ``(E, 3)``.
    directors
        Reference directors ``d1`` ``(E, 3)``, unit and perpendicular to the tangents, carried
        from configuration to configuration by parallel transport in time.
    reference_twist
        Reference twist of each stencil ``(S,)`` (rad), continuous over the history.
    """

    positions: FloatArray
    theta: FloatArray
    tangents: FloatArray
    directors: FloatArray
    reference_twist: FloatArray

    def material_directors(self) -> tuple[FloatArray, FloatArray]:
        """Material directors ``(m1, m2)`` of every edge, each ``(E, 3)``."""
        m1 = np.empty_like(self.directors)
        m2 = np.empty_like(self.directors)
        material_frames(self.tangents, self.directors, self.theta, m1, m2)
        return m1, m2

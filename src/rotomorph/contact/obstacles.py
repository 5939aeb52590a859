"""Rigid obstacles a filament network can touch: a floor, spheres and cylinders.

Obstacles are values (frozen dataclasses, mm). They are fixed during a solve; a study with
prescribed obstacle positions (a gripper closing, a sphere pushed into a filter) passes a moved
copy (:meth:`Sphere.moved`, :meth:`Cylinder.moved`, :meth:`Floor.moved`) to each solve of a
continuation. A filament of radius ``r`` touches an obstacle when its centre line comes within
``r`` of the obstacle's surface.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Union

import numpy as np

from rotomorph._typing import FloatArray
from rotomorph.errors import InvalidParameterError

__all__ = ["RESTING_GAP", "Cylinder", "Floor", "Obstacle", "Sphere"]


def _point(field: str, value: object) -> tuple[float, float, float]:
    v = np.asarray(value, dtype=float)
    if v.shape != (3,) or not np.isfinite(v).all():
        raise InvalidParameterError(field, f"must be a finite 3-vector (mm); got {value!r}")
    return (float(v[0]), float(v[1]), float(v[2]))


def _positive(field: str, value: float) -> float:
    v = float(value)
    if not (np.isfinite(v) and v > 0):
        raise InvalidParameterError(field, f"must be finite and > 0 mm; got {value}")
    return v


#: Height of the lowest centre line above a floor it rests on, in filament radii (just outside
#: contact, so the printed state is admissible).
RESTING_GAP = 1.005


@dataclass(frozen=True)
class Floor:
    """A rigid half-space below the plane ``normal·x = height`` (the bath bottom, a substrate).

    Parameters
    ----------
    height
        Offset of the plane along ``normal`` (mm); default 0 (the plane z = 0).
    normal
        Outward normal (pointing into the free side), normalised on construction; default +z.
    """

    height: float = 0.0
    normal: tuple[float, float, float] = (0.0, 0.0, 1.0)

    def __post_init__(self) -> None:
        if not np.isfinite(self.height):
            raise InvalidParameterError("Floor.height", f"must be finite (mm); got {self.height}")
        n = np.asarray(_point("Floor.normal", self.normal))
        if np.linalg.norm(n) == 0:
            raise InvalidParameterError("Floor.normal", "must be a non-zero 3-vector")
        n = n / np.linalg.norm(n)
        object.__setattr__(self, "normal", (float(n[0]), float(n[1]), float(n[2])))
        object.__setattr__(self, "height", float(self.height))

    def height_of(self, points: FloatArray) -> FloatArray:
        """Signed height of ``points`` (..., 3) above the plane (mm)."""
        return np.asarray(points, float) @ np.asarray(self.normal) - self.height

    def moved(self, offset: float) -> Floor:
        """The floor raised by ``offset`` (mm) along its normal."""
        return Floor(self.height + float(offset), self.normal)

    @classmethod
    def under(cls, points: FloatArray, radius: float) -> Floor:
        """The horizontal floor (normal +z) on which filaments of ``radius`` (mm) through
        ``points`` (..., 3) rest: the lowest centre line :data:`RESTING_GAP` radii above it."""
        lowest = float(np.asarray(points, float)[..., 2].min())
        return cls(height=lowest - RESTING_GAP * float(radius))


@dataclass(frozen=True)
class Sphere:
    """A rigid ball.

    Parameters
    ----------
    centre
        Centre (mm).
    radius
        Radius (mm), e.g. 2.5 for the paper's 5 mm spheres.
    """

    centre: tuple[float, float, float]
    radius: float

    def __post_init__(self) -> None:
        object.__setattr__(self, "centre", _point("Sphere.centre", self.centre))
        object.__setattr__(self, "radius", _positive("Sphere.radius", self.radius))

    def moved(self, offset: object) -> Sphere:
        """The sphere translated by ``offset`` (3-vector, mm)."""
        d = np.asarray(_point("offset", offset))
        return Sphere(tuple(np.asarray(self.centre) + d), self.radius)  # type: ignore[arg-type]


@dataclass(frozen=True)
class Cylinder:
    """A rigid rod: the points within ``radius`` of the axis segment ``start``–``end``.

    The ends are rounded (a capsule); make the axis longer than the region the filaments can
    reach for a cylinder that acts as infinite.

    Parameters
    ----------
    start, end
        Ends of the axis (mm).
    radius
        Radius (mm), e.g. 1.75 for the paper's 3.5 mm acrylic rods.
    """

    start: tuple[float, float, float]
    end: tuple[float, float, float]
    radius: float

    def __post_init__(self) -> None:
        a = _point("Cylinder.start", self.start)
        b = _point("Cylinder.end", self.end)
        if np.linalg.norm(np.subtract(b, a)) == 0:
            raise InvalidParameterError("Cylinder.end", "must differ from start (an axis, mm)")
        object.__setattr__(self, "start", a)
        object.__setattr__(self, "end", b)
        object.__setattr__(self, "radius", _positive("Cylinder.radius", self.radius))

    @classmethod
    def along(
        cls, point: object, direction: object, radius: float, length: float = 1e3
    ) -> Cylinder:
        """A cylinder of axis through ``point`` along ``direction``, ``length`` mm long
        (centred on ``point``; default 1 m, i.e. infinite for a lattice)."""
        p = np.asarray(_point("Cylinder.point", point))
        d = np.asarray(_point("Cylinder.direction", direction))
        if np.linalg.norm(d) == 0:
            raise InvalidParameterError("Cylinder.direction", "must be a non-zero 3-vector")
        d = d / np.linalg.norm(d) * 0.5 * _positive("Cylinder.length", length)
        return cls(tuple(p - d), tuple(p + d), radius)  # type: ignore[arg-type]

    def moved(self, offset: object) -> Cylinder:
        """The cylinder translated by ``offset`` (3-vector, mm)."""
        d = np.asarray(_point("offset", offset))
        return Cylinder(
            tuple(np.asarray(self.start) + d),  # type: ignore[arg-type]
            tuple(np.asarray(self.end) + d),  # type: ignore[arg-type]
            self.radius,
        )


Obstacle = Union[Floor, Sphere, Cylinder]  # noqa: UP007 - a runtime alias on Python 3.10

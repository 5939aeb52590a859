"""Exception hierarchy of rotomorph.

Every error raised on purpose by the library derives from :class:`RotomorphError`, so a
caller can catch them all at once, and every message names the offending field and the fix,
e.g. ``PrintProgram.speed must be > 0 mm/s; got -2.0 at vertex 14``.
"""

from __future__ import annotations

from typing import Any


class RotomorphError(Exception):
    """Base class of every error rotomorph raises on purpose."""


class InvalidParameterError(RotomorphError, ValueError):
    """A numerical argument is out of its valid range, NaN, or has the wrong shape.

    Parameters
    ----------
    field
        Dotted name of the offending argument (e.g. ``"Model.bending_stiffness"``).
    message
        What is wrong and how to fix it.
    """

    def __init__(self, field: str, message: str) -> None:
        self.field = field
        super().__init__(f"{field}: {message}")


class InvalidDesignError(InvalidParameterError):
    """A design (path, print program, lattice, design file) is invalid."""


class MaterialError(InvalidParameterError):
    """A material is unknown or its properties are inconsistent."""


class MachineLimitError(RotomorphError):
    """A toolpath would leave the machine's envelope or exceed one of its limits."""


class GcodeParseError(RotomorphError, ValueError):
    """A G-code file does not follow the dialect it claims (line number in the message)."""


class ConvergenceError(RotomorphError):
    """An iterative solver did not converge.

    Attributes
    ----------
    result
        The solver's result record at the point of failure (iterations, residual, energy),
        so that the caller can inspect the diagnostics.
    """

    def __init__(self, message: str, result: Any = None) -> None:
        self.result = result
        super().__init__(message)

"""Design layer: paths, print programs, networks and lattices (no mechanics)."""

from rotomorph.design.lattices import Lattice, sinusoidal_lattice
from rotomorph.design.path import Arc, Line, Path, Polyline, Sinusoid
from rotomorph.design.program import PrintProgram

__all__ = [
    "Arc",
    "Lattice",
    "Line",
    "Path",
    "Polyline",
    "PrintProgram",
    "Sinusoid",
    "sinusoidal_lattice",
]

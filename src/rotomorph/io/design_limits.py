"""Limits of a design file, and the size of a design estimated before anything is built.

Every number a design file holds has a physical range (:data:`LIMITS`): a filament is not 10 km
long, a nozzle does not turn at 10¹² rad/s. Values outside the range are refused by the schema
(:mod:`rotomorph.io.designfile`) with the field, the range and the fix. The size of a design
(rod nodes) is estimated from its parameters alone (:func:`segment_edges`,
:func:`lattice_nodes`), so that ``n = 100000`` is refused in microseconds with the numbers
(nodes, memory, set-up time) instead of filling memory.

The node limit :data:`MAX_NODES` bounds what ``validate``, ``simulate`` and ``gcode`` accept
(one validation path); the memory and time estimates use the per-node costs measured for a
lattice solve on a 2-core machine (:data:`BYTES_PER_NODE`, :data:`SETUP_S_PER_NODE`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Final

__all__ = [
    "BYTES_PER_NODE",
    "FILAMENT_PER_NOZZLE",
    "LIMITS",
    "MAX_LAYER_CURE_S",
    "MAX_NODES",
    "SETUP_S_PER_NODE",
    "TYPICAL_FILAMENT_PER_NOZZLE",
    "Limit",
    "SizeEstimate",
    "lattice_nodes",
    "nozzle_for",
    "nozzle_table",
    "segment_edges",
    "sinusoid_length",
]

#: Largest design accepted (rod nodes over all filaments, or of the lattice).
MAX_NODES: Final = 500_000
#: Memory of a lattice solve per rod node (bytes; Hessian, factor, states), measured.
BYTES_PER_NODE: Final = 20_000  # 19.8 kB/node at 18 300 nodes (30 x 30 lattice)
#: Set-up time (model, natural field, sparsity pattern, ordering) per rod node (s) on 2 cores:
#: 40 µs/node CPU measured for a 100 x 100 lattice (benchmarks/lattice_setup.py), with margin
#: for a busy machine.
SETUP_S_PER_NODE: Final = 6e-5


#: Longest UV-cure dwell per layer (s) that ``gcode --cure`` writes: an hour, as the design
#: file's dwells (``prime_dwell``, ``release_dwell``); 1e9 s would be 32 years of dwell.
MAX_LAYER_CURE_S: Final = 3600.0

#: Accepted printed filament diameter 2R per nozzle diameter: drawing (printing faster than the
#: ink leaves the nozzle) thins a filament, swelling thickens it; outside this band the pair
#: cannot be printed (a 10 mm filament from a 0.1 mm nozzle).
FILAMENT_PER_NOZZLE: Final = (0.2, 2.0)
#: What the paper prints: 0.6 mm filaments from its 1 mm nozzle, 0.3 mm from 0.5 mm.
TYPICAL_FILAMENT_PER_NOZZLE: Final = 0.6


def nozzle_for(radius: float) -> float:
    """A nozzle diameter (mm) that prints filaments of ``radius`` (mm) at the paper's ratio,
    within the nozzle's range."""
    lo, hi = 0.01, 10.0  # LIMITS["nozzle_diameter"]
    return float(min(max(round(2.0 * radius / TYPICAL_FILAMENT_PER_NOZZLE, 4), lo), hi))


def nozzle_table(radius: float) -> dict[str, dict[str, float]]:
    """``{"nozzle": {"diameter": …}}`` for a design file whose filaments of ``radius`` (mm) the
    default 1 mm nozzle cannot print, else ``{}`` (see :data:`FILAMENT_PER_NOZZLE`)."""
    lo, hi = FILAMENT_PER_NOZZLE
    return {} if lo <= 2 * radius <= hi else {"nozzle": {"diameter": nozzle_for(radius)}}


@dataclass(frozen=True)
class Limit:
    """Accepted range of one kind of design quantity (closed unless ``exclusive_min``)."""

    minimum: float
    maximum: float
    unit: str
    exclusive_min: bool = False

    def describe(self) -> str:
        """The range in words, e.g. ``"> 0 and <= 10000 mm"``."""
        lo = f"{'>' if self.exclusive_min else '>='} {self.minimum:g}"
        return f"{lo} and <= {self.maximum:g}{' ' + self.unit if self.unit else ''}"


#: Ranges by quantity; the schema attaches one to every numeric field (docs/design-files.md).
LIMITS: Final = {
    "extent": Limit(0.001, 10_000.0, "mm"),  # lengths, radii, wavelengths
    "coordinate": Limit(-10_000.0, 10_000.0, "mm"),  # start, origin, polyline points
    "speed": Limit(0.01, 500.0, "mm/s"),  # F0.0100 at 4 decimals: never a zero feed
    "rotation": Limit(-1_000.0, 1_000.0, "rad/s"),
    "rotation_number": Limit(-100.0, 100.0, ""),
    "angle_deg": Limit(-360.0, 360.0, "deg"),
    "arc_angle_deg": Limit(-36_000.0, 36_000.0, "deg"),
    "filament_radius": Limit(0.01, 10.0, "mm"),
    "vertex_spacing": Limit(0.001, 100.0, "mm"),
    "periods": Limit(0.0, 10_000.0, "", exclusive_min=True),
    "pressure": Limit(0.0, 1_000.0, "psi"),
    "nozzle_diameter": Limit(0.01, 10.0, "mm"),
    "layer_height": Limit(0.001, 10.0, "mm"),
    "lattice_n": Limit(2, 10_000, ""),
    "ghost_nodes": Limit(1, 1_000, ""),
    "layers": Limit(1, 1_000, ""),
    "layer": Limit(0, 10_000, ""),
}


@dataclass(frozen=True)
class SizeEstimate:
    """Size of a design before it is built."""

    nodes: int

    @property
    def memory_bytes(self) -> float:
        """Estimated peak memory of a solve (bytes)."""
        return self.nodes * BYTES_PER_NODE

    @property
    def setup_seconds(self) -> float:
        """Estimated set-up time before the first Newton step (s, 2 cores)."""
        return self.nodes * SETUP_S_PER_NODE

    def refusal(self) -> str | None:
        """None within :data:`MAX_NODES`, else the message with the numbers."""
        if self.nodes <= MAX_NODES:
            return None
        return (
            f"too large: about {self.nodes:,} rod nodes (~{self.memory_bytes / 1e9:.1f} GB of "
            f"memory, ~{self.setup_seconds / 60:.0f} min of set-up); the limit is {MAX_NODES:,} "
            "nodes"
        )


def sinusoid_length(amplitude: float, wavelength: float, periods: float) -> float:
    """Arc length (mm) of ``periods`` periods of ``A sin(2πx/λ)`` (periodic trapezoid rule)."""
    k = 2 * math.pi * amplitude / wavelength
    m = 64
    one = sum(math.sqrt(1 + (k * math.cos(2 * math.pi * i / m)) ** 2) for i in range(m)) / m
    return periods * wavelength * one


def segment_edges(length: float, spacing: float) -> int:
    """Edges of a segment of arc length ``length`` (mm) sampled at ``spacing`` (mm), >= 1.

    The count :func:`rotomorph.design.path.chain_segments` uses.
    """
    return max(1, math.ceil(length / spacing - 1e-9))


def lattice_nodes(n: int, ghost_nodes: int) -> int:
    """Rod nodes of an n × n lattice: branch nodes plus ghost nodes on its 2n(n−1) edges."""
    return n * n + 2 * n * (n - 1) * ghost_nodes

"""rotomorph: design, simulate and print shape-morphing active-passive filaments and lattices."""

from __future__ import annotations

__version__ = "0.1.0"

"""Simulation drivers: filaments over a heating ramp, lattice designs, and the paper report.

The package is also callable: ``rotomorph.simulate(design, steps=4)`` is
:func:`rotomorph.simulate.api.simulate` (a design, a design file path or a print program).
"""

from __future__ import annotations

import sys
import types
from typing import Any


class _CallableModule(types.ModuleType):
    """``rotomorph.simulate`` is both this subpackage and the function of the common path."""

    def __call__(self, design: Any, **options: Any) -> Any:
        from rotomorph.simulate.api import simulate

        return simulate(design, **options)


sys.modules[__name__].__class__ = _CallableModule

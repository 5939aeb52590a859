"""The compiled (numba) kernels: are they in the on-disk cache, and how many are compiled.

Every kernel is compiled with ``cache=True``, so only the first run on a machine (or after an
upgrade) compiles; later runs load machine code from ``__pycache__``. The command line uses
:func:`kernels_cached` to say "compiling kernels (first run only)" before that happens, and
:func:`compiled_count` to show how far the compilation has got.
"""

from __future__ import annotations

import importlib
import logging
from typing import Any, Final

__all__ = ["CORE_KERNELS", "KERNEL_MODULES", "compiled_count", "dispatchers", "kernels_cached"]

logger = logging.getLogger(__name__)

#: Modules holding compiled kernels.
KERNEL_MODULES: Final = (
    "rotomorph.geometry",
    "rotomorph.rod.kernels",
    "rotomorph.rod.assembly",
    "rotomorph.rod.sensitivity",
    "rotomorph.solve.banded",
    "rotomorph.solve.linalg",
    "rotomorph.solve.sparse_cholesky",
    "rotomorph.solve.retraction",
    "rotomorph.contact.barrier",
    "rotomorph.contact.broadphase",
    "rotomorph.contact.ccd",
    "rotomorph.contact.distance",
    "rotomorph.simulate.free_shape",
)

#: Module of :data:`CORE_KERNELS` (imported to read its cache index: numba and two modules).
_CORE_MODULES: Final = ("rotomorph.rod.assembly",)


def dispatchers(modules: tuple[str, ...] = KERNEL_MODULES) -> list[Any]:
    """The top-level numba dispatchers of ``modules`` (inlined helpers excluded)."""
    from numba.core.registry import CPUDispatcher

    out = []
    for name in modules:
        module = importlib.import_module(name)
        for value in vars(module).values():
            if (
                isinstance(value, CPUDispatcher)
                and value.__module__ == name
                and value.targetoptions.get("inline", "never") == "never"
            ):
                out.append(value)
    return out


#: The kernel every solve runs, half of all compile time: "cached" means it is. Its cached
#: machine code holds the stencil, stretching and assembly kernels it calls, so those need no
#: cache entry of their own (and have none when they were only ever compiled inside it).
CORE_KERNELS: Final = ("evaluate_network",)


def kernels_cached() -> bool:
    """True when the core kernels (:data:`CORE_KERNELS`) have machine code in the on-disk cache.

    Reads numba's cache index (the index is invalidated when a source file changes); any
    failure to read it counts as "not cached". Rarely used kernels are not required: they
    compile in a second or two when first needed.
    """
    try:
        for disp in dispatchers(_CORE_MODULES):
            if disp.py_func.__name__ not in CORE_KERNELS:
                continue
            cache = getattr(disp, "_cache", None)
            if cache is None or not cache._cache_file._load_index():
                return False
    except Exception as err:  # numba internals: report "unknown" as not cached
        logger.debug("could not read the numba cache index: %s", err)
        return False
    return True


def compiled_count() -> int:
    """Kernels compiled or loaded in this process so far (of ``len(dispatchers())``)."""
    return sum(1 for disp in dispatchers() if disp.overloads)

"""Imported by the local pool's fork server (and each worker): warms the solver's kernels.

Compiled (numba) kernels are loaded from their on-disk cache on first call, which costs about a
second per process; paying it here keeps it out of the first run's wall time. A failure only
costs the warm start.
"""

from __future__ import annotations

import logging

from rotomorph.sweep import run as _run  # noqa: F401  (workers unpickle execute_run from it)

try:
    from rotomorph.io.designfile import parse_design
    from rotomorph.simulate.design import simulate_design

    simulate_design(
        parse_design(
            {
                "schema_version": 1,
                "filaments": [
                    {
                        "speed": 1.0,
                        "rotation_number": 0.25,
                        "spacing": 1.0,
                        "segments": [{"kind": "line", "length": 6.0}],
                    }
                ],
            }
        ),
        steps=1,
    )
except Exception as err:  # pragma: no cover - warm-up is best effort
    logging.getLogger(__name__).info("sweep worker warm-up failed: %s", err)

"""``rotomorph serve``: a designer in the browser, a thin layer over the public API.

Start from an example design or an uploaded design file, edit a filament's print program or a
lattice (clicking its edges), read the closed-form prediction and its band as you type, simulate
the heating ramp in the background with live progress, cancel, and each converged step shown as
it arrives in the run viewer's 3-D view, preview the toolpath on a machine, download the design
file, the G-code with its controller configuration and the run's files (the CLI's own files,
written by the same functions), and run an inverse design whose result opens as the design.

Needs the ``app`` extra (``pip install "rotomorph[app]"``: Dash on plotly). Nothing below this
package imports it.
"""

from __future__ import annotations

__all__ = ["create_app"]


def __getattr__(name: str) -> object:
    if name == "create_app":
        from rotomorph.app.server import create_app

        return create_app
    raise AttributeError(f"module 'rotomorph.app' has no attribute {name!r}")

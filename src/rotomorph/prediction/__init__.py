"""Quick answers a lab can act on: closed-form predictions with the calibration band.

* :func:`predict_design` — what a design file's filaments heat into (curvature, twist, radius,
  pitch, L/L0, morphology) and, for a lattice, the independent-edge estimates (area ratio,
  Gaussian-curvature sign), each with the calibration's band and a flag where the settings lie
  outside the calibrated range (``rotomorph predict DESIGN``);
* :func:`settings_for` — which print settings (speed, ω*, active side) give a wanted shape
  (``rotomorph predict --for curvature=0.4``).

Both are evaluated on the paper report's calibrated curves, so they agree with the report.
"""

from __future__ import annotations

from importlib import import_module
from typing import Any

_WHERE = {
    "CalibratedRange": "band",
    "Estimate": "band",
    "calibrated_range": "band",
    "DesignPrediction": "design",
    "predict_design": "design",
    "FilamentPrediction": "filament",
    "predict_filament": "filament",
    "LatticePrediction": "lattice",
    "predict_lattice": "lattice",
    "SettingsAnswer": "settings",
    "parse_request": "settings",
    "settings_for": "settings",
}

__all__ = sorted(_WHERE)


def __getattr__(name: str) -> Any:
    """The public names, imported on first use (``rotomorph --help`` stays light)."""
    if name in _WHERE:
        return getattr(import_module(f"rotomorph.prediction.{_WHERE[name]}"), name)
    raise AttributeError(f"module 'rotomorph.prediction' has no attribute {name!r}")

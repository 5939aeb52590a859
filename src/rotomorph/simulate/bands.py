r"""A prediction's band in parts, and which comparisons are weak tests.

Every predicted row of the paper report carries its band in parts (standard deviations):

======================  =========================================================================
``sd_calibration``      the calibration's posterior uncertainty propagated to the number
                        (:meth:`rotomorph.materials.inference.Fit.propagate_parts`); of it,
                        ``sd_calibration_prior`` is the part the priors hold (the data left it open)
``sd_nuisance``         the spread of the number over the priors of the inputs the paper does not
                        give (:mod:`rotomorph.simulate.nuisance`), from a Latin hypercube of them
``sd_numerical``        the discretisation error (Richardson's estimate from two resolutions)
``sd_model_form``       where the model has two branches and the choice between them is not
                        measured (a lattice that leaves the floor or stays jammed on it): half their
                        difference, the standard deviation of an even choice between the two
======================  =========================================================================

The band is their root sum of squares, ``predicted_sd``, and ``z`` = (predicted − measured) /
√(spread² + predicted_sd²).

The weak-test rule (stated before it was applied; :data:`WEAK_SHARE`)
---------------------------------------------------------------------
A comparison is a **weak test** when more than half of its combined variance
(spread² + predicted_sd²) is width that no measurement constrains: the calibration's
prior-held part, the nuisance priors and the model-form choice,

.. math::  u^2 = \mathrm{sd}_{cal,prior}^2 + \mathrm{sd}_{nuis}^2 + \mathrm{sd}_{mf}^2
           > \tfrac12\,(s^2 + \mathrm{sd}^2).

Agreement within such a band holds largely by construction. The others are **discriminating**:
their combined spread is mostly the measurement's own and the data-constrained calibration, so
a hit or a miss says something about the model. The score reports the discriminating rows'
hit rate separately. A sign prediction (no spread) is weak when the nuisance samples do not
all give the predicted sign. A band whose nuisance part was not computed is not split: the
row is neither (``weak_test`` is ``None``) and the score line counts it apart.
Nothing here widens or narrows a band to move a score: the parts are computed, then the rule
is applied.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

__all__ = ["WEAK_RULE", "WEAK_SHARE", "Band", "finish_row", "is_weak_test", "plain_row"]

#: Share of the combined variance above which unconstrained width makes a comparison weak.
WEAK_SHARE = 0.5
#: The rule in words (every output that marks weak tests states it).
WEAK_RULE = (
    "A counted comparison is a weak test when more than half of its combined variance "
    "(spread^2 + sd^2) is width no measurement constrains: the calibration's prior-held part, "
    "the nuisance priors and the model-form choice; a sign prediction is weak when the "
    "nuisance samples do not all give the predicted sign. The rule was stated before it was "
    "applied; the score of the discriminating rows is reported separately."
)


def _sq(x: float | None) -> float:
    return 0.0 if x is None or not math.isfinite(x) else float(x) ** 2


@dataclass(frozen=True)
class Band:
    """The parts of a prediction's band (standard deviations, the prediction's unit).

    ``None`` marks a part that was not computed (e.g. in quick mode); it counts as 0 in the
    total and the row says which parts are missing.
    """

    calibration: float | None = None
    calibration_prior: float | None = None
    nuisance: float | None = None
    numerical: float | None = None
    model_form: float | None = None

    @property
    def total(self) -> float:
        """Root sum of squares of the parts."""
        return math.sqrt(
            _sq(self.calibration) + _sq(self.nuisance) + _sq(self.numerical) + _sq(self.model_form)
        )

    @property
    def unconstrained(self) -> float:
        """The part no measurement constrains: calibration prior, nuisance, model form."""
        return math.sqrt(_sq(self.calibration_prior) + _sq(self.nuisance) + _sq(self.model_form))

    def missing(self) -> list[str]:
        """Names of parts not computed."""
        return [
            name for name in ("calibration", "nuisance", "numerical") if getattr(self, name) is None
        ]


def is_weak_test(spread: float | None, band: Band) -> bool:
    """The weak-test rule of the module docstring for a comparison with ``spread``."""
    combined = _sq(spread) + band.total**2
    return combined > 0.0 and band.unconstrained**2 > WEAK_SHARE * combined


def _num(v: float | None, digits: int = 5) -> float | None:
    return None if v is None or not math.isfinite(v) else round(float(v), digits)


def finish_row(
    row: dict[str, Any],
    band: Band,
    *,
    extrapolated: list[str] | None = None,
    sign_agreement: float | None = None,
) -> dict[str, Any]:
    """``row`` with its band in parts, ``predicted_sd`` their total, ``z`` from it, the
    weak-test flag and the extrapolation flag (new dict).

    Parameters
    ----------
    row
        A summary row (:func:`rotomorph.simulate.validation.row`).
    band
        Its parts.
    extrapolated
        Why the row's settings lie outside the calibrated range (empty: inside).
    sign_agreement
        For a sign row: the fraction of nuisance samples giving the predicted sign.
    """
    out = dict(row)
    out["sd_calibration"] = _num(band.calibration)
    out["sd_calibration_prior"] = _num(band.calibration_prior)
    out["sd_nuisance"] = _num(band.nuisance)
    out["sd_numerical"] = _num(band.numerical, 6)
    out["sd_model_form"] = _num(band.model_form)
    out["band_missing"] = band.missing()
    reasons = list(extrapolated or [])
    out["extrapolated"] = bool(reasons)
    out["extrapolation"] = reasons
    if out["predicted"] is None:
        out["weak_test"] = None
        return out
    if sign_agreement is not None or out["spread"] == 0.0:
        # a sign (no spread, no z): weak when the priors leave it open
        out["weak_test"] = None if sign_agreement is None else bool(sign_agreement < 1.0)
        out["sign_agreement"] = _num(sign_agreement, 4)
        return out
    total = band.total
    out["predicted_sd"] = _num(total) if total > 0.0 else None
    if out["measured"] is not None and out["spread"] is not None and not out["calibration"]:
        comb = math.hypot(out["spread"], total)
        out["z"] = _num((out["predicted"] - out["measured"]) / comb, 3) if comb > 0 else None
    # a band without its nuisance part cannot say how much of it is prior width
    out["weak_test"] = (
        None
        if out["measured"] is None or band.nuisance is None
        else bool(is_weak_test(out["spread"], band))
    )
    return out


def plain_row(row: dict[str, Any], *, extrapolated: list[str] | None = None) -> dict[str, Any]:
    """``row`` with the band fields present but not computed (inputs, rows shown but not
    compared, rows without a measurement); ``predicted_sd`` and ``z`` kept as they are."""
    out = dict(row)
    for key in ("sd_calibration", "sd_calibration_prior", "sd_nuisance", "sd_numerical"):
        out.setdefault(key, None)
    out.setdefault("sd_model_form", None)
    out.setdefault("band_missing", [])
    if out.get("sd_calibration") is None and out.get("predicted_sd") is not None:
        out["sd_calibration"] = out["predicted_sd"]
    reasons = list(extrapolated or out.get("extrapolation") or [])
    out["extrapolated"] = bool(reasons)
    out["extrapolation"] = reasons
    out.setdefault("weak_test", None)
    return out

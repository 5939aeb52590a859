r"""Which parameters a set of measured tables determines, said plainly.

Linearised about a point θ (the prior mean, or the optimum of a fit), the data's weighted
residuals change as r(θ + δ) ≈ r(θ) + J δ. In the coordinates of the prior (each parameter in
units of its prior standard deviation s_k, A = J diag(s)), the Laplace posterior covariance is
(AᵀA + I)⁻¹, so

* the **width ratio** w_k = √((AᵀA + I)⁻¹)_kk ∈ (0, 1] is the posterior's width over the
  prior's: near 1, the tables add (almost) nothing and the parameter stays at its prior; small,
  the tables determine it;
* the singular values σ_i of A measure how many prior widths the data pin each independent
  combination of parameters to (σ ≫ 1 determined, σ ≪ 1 left to the prior); the right singular
  vectors name the combinations (e.g. only gain × (S(v) − S0) when a single speed is measured).

Parameters are classed **determined** (w < :data:`DETERMINED`), **weakly determined**
(w < :data:`AT_PRIOR`) or **at its prior** (w ≥ :data:`AT_PRIOR`: the data narrow the prior by
less than 10 %). Each parameter's entry names the tables that inform it (their share of its
information) and, from the caller's hints, the measurement that would pin it down.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Final

import numpy as np

from rotomorph._typing import FloatArray
from rotomorph.materials.inference import Group, Parameter, set_parameter

__all__ = ["AT_PRIOR", "DETERMINED", "Identifiability", "ParameterReport", "identifiability"]

#: Width ratio below which the tables determine a parameter.
DETERMINED: Final = 0.5
#: Width ratio at and above which a parameter stays at its prior.
AT_PRIOR: Final = 0.9


@dataclass(frozen=True)
class ParameterReport:
    """What the tables say about one parameter.

    Attributes
    ----------
    name
        Dotted parameter name.
    label
        The parameter in words.
    width_ratio
        Posterior width over prior width (linearised).
    status
        ``"determined"``, ``"weakly determined"`` or ``"at its prior"``.
    informed_by
        ``(table, share)`` of the tables that carry its information (shares sum to 1).
    pinned_by
        The measurement that would pin it down (the caller's hint).
    """

    name: str
    label: str
    width_ratio: float
    status: str
    informed_by: tuple[tuple[str, float], ...]
    pinned_by: str

    def sentence(self) -> str:
        """One line in words."""
        w = f"posterior/prior width {self.width_ratio:.2f}"
        if self.status == "at its prior":
            return (
                f"{self.label}: stays at its prior ({w}): no table determines it; "
                f"{self.pinned_by} would"
            )
        tables = ", ".join(f"{t} ({100 * s:.0f} %)" for t, s in self.informed_by if s >= 0.05)
        lead = "determined" if self.status == "determined" else "only weakly determined"
        more = "" if self.status == "determined" else f"; {self.pinned_by} would pin it down"
        return f"{self.label}: {lead} by {tables or 'the tables'} ({w}){more}"


@dataclass(frozen=True, eq=False)
class Identifiability:
    """Identifiability of every fitted parameter at one point (module docstring).

    Attributes
    ----------
    parameters
        One :class:`ParameterReport` per fitted parameter, in order.
    singular_values
        σ_i of the prior-scaled Jacobian, descending.
    combinations
        For each σ_i, the parameter combination in words (largest components).
    where
        At which point it was evaluated (words).
    """

    parameters: tuple[ParameterReport, ...]
    singular_values: FloatArray
    combinations: tuple[str, ...]
    where: str

    def names(self, status: str) -> tuple[str, ...]:
        """Names of the parameters of one status."""
        return tuple(p.name for p in self.parameters if p.status == status)

    @property
    def determined(self) -> tuple[str, ...]:
        """Parameters the tables determine (also weakly)."""
        return tuple(p.name for p in self.parameters if p.status != "at its prior")

    @property
    def at_prior(self) -> tuple[str, ...]:
        """Parameters the tables leave at their priors."""
        return self.names("at its prior")

    def lines(self) -> list[str]:
        """The report in words, one line per parameter, then the singular values."""
        out = [p.sentence() for p in self.parameters]
        sv = ", ".join(
            f"{s:.3g} ({c})" for s, c in zip(self.singular_values, self.combinations, strict=True)
        )
        out.append(
            f"singular values of the prior-scaled sensitivities ({self.where}): {sv}; "
            "above 1 the tables pin a combination to better than its prior width"
        )
        return out

    def record(self) -> dict[str, Any]:
        """JSON-able form."""
        return {
            "where": self.where,
            "parameters": [
                {
                    "name": p.name,
                    "label": p.label,
                    "width_ratio": round(p.width_ratio, 4),
                    "status": p.status,
                    "informed_by": {t: round(s, 3) for t, s in p.informed_by},
                    "pinned_by": p.pinned_by,
                }
                for p in self.parameters
            ],
            "singular_values": [round(float(s), 4) for s in self.singular_values],
            "combinations": list(self.combinations),
        }


def _model_at(base: Any, params: Sequence[Parameter], theta: FloatArray) -> Any:
    m = base
    for p, t in zip(params, theta, strict=True):
        m = set_parameter(m, p.name, p.value(float(t)))
    return m


def _residuals(groups: Sequence[Group], model: Any) -> list[FloatArray]:
    return [
        (np.asarray(g.predict(model), dtype=float) - g.table.value) / g.table.spread for g in groups
    ]


def identifiability(
    groups: Sequence[Group],
    parameters: Sequence[Parameter],
    base: Any,
    theta: FloatArray,
    *,
    labels: Mapping[str, str] | None = None,
    hints: Mapping[str, str] | None = None,
    where: str = "",
) -> Identifiability:
    """Identifiability of ``parameters`` by ``groups`` about fit coordinates ``theta``.

    Parameters
    ----------
    groups
        Measured groups with predictors (as :func:`~rotomorph.materials.inference.joint_calibrate`).
    parameters
        Fitted parameters with their priors.
    base
        Model the parameters are set on.
    theta
        Fit coordinates of the point (within the bounds).
    labels, hints
        Parameter name → words; → the measurement that would pin it down.
    where
        The point, in words (for the report).
    """
    params = list(parameters)
    labels = dict(labels or {})
    hints = dict(hints or {})
    theta = np.asarray(theta, dtype=float)
    sd = np.array([p.sd for p in params])
    sizes = [len(g.table) for g in groups]
    cols = []
    for k, p in enumerate(params):
        h = 1e-3 * sd[k]
        lo, hi = theta.copy(), theta.copy()
        lo[k] = max(theta[k] - h, p.lower)
        hi[k] = min(theta[k] + h, p.upper)
        r_hi = np.concatenate(_residuals(groups, _model_at(base, params, hi)) or [np.zeros(0)])
        r_lo = np.concatenate(_residuals(groups, _model_at(base, params, lo)) or [np.zeros(0)])
        cols.append((r_hi - r_lo) / (hi[k] - lo[k]) * sd[k])  # per prior width
    a = np.column_stack(cols) if cols else np.zeros((0, 0))
    cov = np.linalg.inv(a.T @ a + np.eye(len(params)))
    width = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    bounds = np.cumsum([0, *sizes])
    reports = []
    for k, p in enumerate(params):
        info = np.array([np.sum(a[bounds[g] : bounds[g + 1], k] ** 2) for g in range(len(groups))])
        total = float(info.sum())
        shares = tuple(
            (g.name, float(i / total))
            for g, i in zip(groups, info, strict=True)
            if total > 0 and i > 0
        )
        shares = tuple(sorted(shares, key=lambda t: -t[1]))
        w = float(width[k])
        status = (
            "determined"
            if w < DETERMINED
            else "weakly determined"
            if w < AT_PRIOR
            else "at its prior"
        )
        reports.append(
            ParameterReport(
                p.name,
                labels.get(p.name, p.name),
                w,
                status,
                shares,
                hints.get(p.name, "more data"),
            )
        )
    _, sv, vt = (
        np.linalg.svd(a, full_matrices=False) if a.size else (None, np.zeros(0), np.zeros((0, 0)))
    )
    combos = []
    for row in vt:
        order = np.argsort(-np.abs(row))
        parts = [
            f"{'+' if row[i] >= 0 else '-'}{abs(row[i]):.2f} "
            + labels.get(params[i].name, params[i].name)
            for i in order[:3]
            if abs(row[i]) >= 0.2
        ]
        combos.append(" ".join(parts).lstrip("+"))
    return Identifiability(tuple(reports), np.asarray(sv), tuple(combos), where)

r"""Joint calibration as inference: weighted least squares with priors, branches, uncertainty.

The unknown material parameters θ of a :class:`~rotomorph.materials.natural.FilamentModel`
(dotted float fields, e.g. ``"modulus_ratio"`` or ``"strain_model.gain"``) are fitted jointly to
several groups of measurements (:class:`Group`: a measured table and a predictor) by minimising

.. math::  χ²(θ) = Σ_groups Σ_i ((f_i(θ) − y_i)/σ_i)² + Σ_j ((θ_j − μ_j)/s_j)²

with σ_i the reported standard deviations (taken as known) and Gaussian priors
(:class:`Parameter`: mean μ_j, width s_j, in the fit coordinate: ln of the value for
``log = True``). The priors are weak and stated; they keep directions that the data do not
constrain finite (e.g. the threshold of the strain law when only one print speed is fitted),
so every prediction carries an honest, possibly wide, uncertainty. This is a maximum a
posteriori fit with the Laplace (linearised) posterior: cov(θ) = (JᵀJ)⁻¹ of the weighted
residuals and prior rows (Tarantola, *Inverse Problem Theory*, SIAM 2005, ch. 3).

Non-identifiable directions. A Janus bilayer's curvature is symmetric under E_a/E_p ↔ E_p/E_a
(Timoshenko, J. Opt. Soc. Am. 11, 233 (1925): for equal layers the curvature depends on the
ratio only through m + 1/m), so a fit of curvatures alone cannot tell m from 1/m. With
``branch`` the fit is run twice, restricted to ln m ≥ 0 and to ln m ≤ 0; both optima are
reported (:class:`Fit`), and one is chosen by the data when their χ² differ by at least
:data:`BRANCH_DCHI2`, otherwise by the stated preferred branch — the choice and its reason are
recorded in :attr:`JointCalibration.choice`.

Uncertainty propagation (:meth:`Fit.propagate`): a quantity q(θ) is evaluated at θ̂ and at
θ̂ ± L e_k (L the Cholesky factor of cov(θ), one standard deviation along each independent
direction); sd(q) = √Σ_k ((q(θ̂ + L e_k) − q(θ̂ − L e_k))/2)² — first-order propagation with
secants over one standard deviation (exact for q linear in θ).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.optimize import least_squares

from rotomorph._typing import FloatArray
from rotomorph.errors import InvalidParameterError
from rotomorph.materials.measurements import MeasuredTable

__all__ = [
    "BRANCH_DCHI2",
    "Fit",
    "Group",
    "JointCalibration",
    "Parameter",
    "joint_calibrate",
]

#: χ² difference (≈ a 2σ likelihood ratio for one parameter) at and above which the data, not
#: the stated physical preference, choose between the two modulus-ratio branches.
BRANCH_DCHI2 = 4.0

Predictor = Callable[[Any], FloatArray]


@dataclass(frozen=True)
class Parameter:
    """One fitted parameter with its Gaussian prior (in the fit coordinate).

    Parameters
    ----------
    name
        Dotted float field of the model (``"modulus_ratio"``, ``"strain_model.gain"``).
    mean, sd
        Prior mean and standard deviation in the fit coordinate (ln of the value if ``log``).
    log
        Fit ln(value) (for positive scale parameters such as modulus ratios).
    lower, upper
        Bounds in the fit coordinate.
    reason
        Why this prior (recorded in every output).
    """

    name: str
    mean: float
    sd: float
    log: bool = False
    lower: float = -np.inf
    upper: float = np.inf
    reason: str = ""

    def __post_init__(self) -> None:
        if not (np.isfinite(self.mean) and np.isfinite(self.sd) and self.sd > 0.0):
            raise InvalidParameterError(
                f"Parameter[{self.name}]", "prior mean must be finite and sd > 0"
            )
        if not self.lower < self.upper:
            raise InvalidParameterError(f"Parameter[{self.name}]", "needs lower < upper")

    def value(self, theta: float) -> float:
        """Model value of fit coordinate ``theta``."""
        return float(np.exp(theta)) if self.log else float(theta)

    def coordinate(self, value: float) -> float:
        """Fit coordinate of model value ``value``."""
        if self.log:
            if value <= 0.0:
                raise InvalidParameterError(self.name, f"must be > 0 for a log prior; got {value}")
            return float(np.log(value))
        return float(value)


@dataclass(frozen=True)
class Group:
    """One group of measurements and the model's predictor for it.

    Parameters
    ----------
    name
        Group label (e.g. ``"janus_curvature"``).
    table
        The measured rows (values and standard deviations).
    predict
        ``model -> (n,)`` predictions at the table's rows.
    """

    name: str
    table: MeasuredTable
    predict: Predictor


def get_parameter(model: object, name: str) -> float:
    """Value of a dotted float parameter, e.g. ``"strain_model.gain"``."""
    obj = model
    for part in name.split("."):
        if not hasattr(obj, part):
            raise InvalidParameterError("params", f"{type(obj).__name__} has no parameter {part!r}")
        obj = getattr(obj, part)
    if obj is None:
        raise InvalidParameterError("params", f"{name} is None; give it a starting value first")
    return float(obj)  # type: ignore[arg-type]


def set_parameter(model: object, name: str, value: float) -> object:
    """Copy of a (nested) frozen dataclass with the dotted parameter ``name`` set to ``value``."""
    head, _, rest = name.partition(".")
    if not dataclasses.is_dataclass(model) or not hasattr(model, head):
        raise InvalidParameterError("params", f"{type(model).__name__} has no parameter {head!r}")
    new = set_parameter(getattr(model, head), rest, value) if rest else float(value)
    return dataclasses.replace(model, **{head: new})  # type: ignore[type-var]


@dataclass(frozen=True, eq=False)
class Fit:
    """One optimum of the joint fit (one branch).

    Attributes
    ----------
    label
        Branch label (``"all"`` without branches).
    parameters
        The fitted :class:`Parameter` s, in order.
    theta, covariance
        Optimum and its covariance in the fit coordinates.
    model
        The model at the optimum.
    chi2_data, chi2_prior
        Data and prior parts of χ² at the optimum.
    n_data
        Number of fitted measurements.
    at_bound
        Names of parameters whose optimum lies on a bound (e.g. m = 1 between the branches:
        the branch has no interior optimum).
    success
        Optimiser convergence flag.
    """

    label: str
    parameters: tuple[Parameter, ...]
    theta: FloatArray
    covariance: FloatArray
    model: Any
    chi2_data: float
    chi2_prior: float
    n_data: int
    at_bound: tuple[str, ...]
    success: bool
    base: Any = None

    @property
    def values(self) -> dict[str, float]:
        """Fitted model values by parameter name."""
        return {p.name: p.value(t) for p, t in zip(self.parameters, self.theta, strict=True)}

    @property
    def sd_coordinate(self) -> dict[str, float]:
        """Standard deviations in the fit coordinates (relative sd for log parameters)."""
        sd = np.sqrt(np.clip(np.diag(self.covariance), 0.0, None))
        return {p.name: float(s) for p, s in zip(self.parameters, sd, strict=True)}

    @property
    def intervals(self) -> dict[str, tuple[float, float]]:
        """±1 sd intervals in model values (asymmetric for log parameters)."""
        out = {}
        for p, t, s in zip(self.parameters, self.theta, self.sd_coordinate.values(), strict=True):
            out[p.name] = (p.value(t - s), p.value(t + s))
        return out

    def model_at(self, theta: FloatArray) -> Any:
        """The model with fit coordinates ``theta``."""
        m: object = self.base if self.base is not None else self.model
        for p, t in zip(self.parameters, theta, strict=True):
            m = set_parameter(m, p.name, p.value(float(t)))
        return m

    def directions(self) -> FloatArray:
        """``(p, p)`` columns L e_k: one standard deviation along independent directions."""
        cov = 0.5 * (self.covariance + self.covariance.T)
        w, v = np.linalg.eigh(cov)
        return v * np.sqrt(np.clip(w, 0.0, None))

    def propagate(
        self, quantity: Predictor, *, central: bool = True
    ) -> tuple[FloatArray, FloatArray]:
        """Value at the optimum and propagated standard deviation of ``quantity(model)``.

        See the module docstring (secants over ± one standard deviation per direction).
        ``central = False`` uses one-sided secants θ̂ → θ̂ + L e_k (half the evaluations, for
        expensive quantities; first order like the central ones).
        """
        centre, sd, _ = self.propagate_parts(quantity, central=central)
        return centre, sd

    def propagate_parts(
        self, quantity: Predictor, *, central: bool = True
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        r"""Value, propagated sd and the part of that sd the priors hold.

        With the posterior precision H = JᵀJ = A + P (A from the data rows, P = diag(1/s_j²)
        from the prior rows) and Σ = H⁻¹, the posterior variance of a linear q = gᵀθ splits
        exactly into gᵀΣAΣg (carried by the data's noise) and gᵀΣPΣg (carried by the priors'
        width): the MAP estimate is Σ(Aθ_data + Pμ), so its spread comes from the two through
        those two terms. With the secants s = Lᵀg of :meth:`propagate` (Σ = LLᵀ) the prior
        part is sᵀ(LᵀPL)s. Where it is most of the variance the data left q open and a
        comparison within the band holds largely by construction (a weak test).

        Returns
        -------
        centre, sd, sd_prior
            Arrays of ``quantity``'s shape; ``sd_prior ≤ sd``.
        """
        centre = np.asarray(quantity(self.model), dtype=float)
        dirs = self.directions()
        secants = []
        for d in dirs.T:
            if not np.any(d):
                secants.append(np.zeros_like(centre))
                continue
            up = np.asarray(quantity(self.model_at(self.theta + d)), dtype=float)
            if central:
                down = np.asarray(quantity(self.model_at(self.theta - d)), dtype=float)
                secants.append(0.5 * (up - down))
            else:
                secants.append(up - centre)
        s = np.asarray(secants).reshape(len(secants), -1)  # (directions, outputs)
        precision = np.diag([1.0 / p.sd**2 for p in self.parameters])
        held = dirs.T @ precision @ dirs  # LᵀPL, eigenvalues in [0, 1]
        var = np.sum(s * s, axis=0)
        var_prior = np.clip(np.einsum("ki,kl,li->i", s, held, s), 0.0, var)
        return (
            centre,
            np.sqrt(var).reshape(centre.shape),
            np.sqrt(var_prior).reshape(centre.shape),
        )

    def record(self) -> dict[str, Any]:
        """JSON-able summary (values, ±1 sd intervals, χ², bounds hit)."""
        return {
            "branch": self.label,
            "values": {k: round(v, 6) for k, v in self.values.items()},
            "sd_fit_coordinate": {k: round(v, 6) for k, v in self.sd_coordinate.items()},
            "interval_1sd": {k: [round(a, 6), round(b, 6)] for k, (a, b) in self.intervals.items()},
            "chi2_data": round(self.chi2_data, 4),
            "chi2_prior": round(self.chi2_prior, 4),
            "n_data": self.n_data,
            "at_bound": list(self.at_bound),
            "success": self.success,
        }


@dataclass(frozen=True, eq=False)
class JointCalibration:
    """Outcome of :func:`joint_calibrate`: both branches, the chosen one and why.

    Attributes
    ----------
    groups
        Names of the fitted groups.
    branches
        One :class:`Fit` per branch (one without a branch parameter).
    chosen
        The fit used for predictions.
    choice
        Why it was chosen (data: Δχ²; or the stated preference when the data cannot tell).
    """

    groups: tuple[str, ...]
    branches: tuple[Fit, ...]
    chosen: Fit
    choice: str

    def record(self) -> dict[str, Any]:
        """JSON-able summary of the calibration (every choice included)."""
        p = self.chosen.parameters
        return {
            "fitted_groups": list(self.groups),
            "parameters": [
                {
                    "name": q.name,
                    "coordinate": "ln" if q.log else "linear",
                    "prior_mean": q.mean,
                    "prior_sd": q.sd,
                    "bounds": [q.lower, q.upper],
                    "reason": q.reason,
                }
                for q in p
            ],
            "branches": [b.record() for b in self.branches],
            "chosen": self.chosen.label,
            "choice": self.choice,
        }


def _solve(
    groups: Sequence[Group],
    params: Sequence[Parameter],
    base: Any,
    start: FloatArray,
    lower: FloatArray,
    upper: FloatArray,
    label: str,
) -> Fit:
    mean = np.array([p.mean for p in params])
    sd = np.array([p.sd for p in params])

    def model_at(theta: FloatArray) -> Any:
        m: object = base
        for p, t in zip(params, theta, strict=True):
            m = set_parameter(m, p.name, p.value(float(t)))
        return m

    def data_residual(theta: FloatArray) -> FloatArray:
        model = model_at(theta)
        parts = [
            (np.asarray(g.predict(model), dtype=float) - g.table.value) / g.table.spread
            for g in groups
        ]
        return np.concatenate(parts) if parts else np.zeros(0)

    def residual(theta: FloatArray) -> FloatArray:
        return np.concatenate([data_residual(theta), (theta - mean) / sd])

    x0 = np.clip(start, lower + 1e-9 * (1 + np.abs(lower)), upper - 1e-9 * (1 + np.abs(upper)))
    sol = least_squares(
        residual, x0, bounds=(lower, upper), x_scale="jac", xtol=1e-10, ftol=1e-10, gtol=1e-10
    )
    jac = sol.jac
    cov = np.linalg.pinv(jac.T @ jac)
    r = sol.fun
    n = len(r) - len(params)
    span = upper - lower
    hit = tuple(
        p.name
        for p, t, lo, hi, s in zip(params, sol.x, lower, upper, span, strict=True)
        if min(t - lo, hi - t) < 1e-6 * max(1.0, float(np.nan_to_num(s, posinf=1.0)))
    )
    return Fit(
        label=label,
        parameters=tuple(params),
        theta=np.asarray(sol.x, dtype=float),
        covariance=cov,
        model=model_at(sol.x),
        chi2_data=float(np.sum(r[:n] ** 2)),
        chi2_prior=float(np.sum(r[n:] ** 2)),
        n_data=n,
        at_bound=hit,
        success=bool(sol.success),
        base=base,
    )


def joint_calibrate(
    groups: Sequence[Group],
    parameters: Sequence[Parameter],
    model: Any,
    *,
    branch: str | None = None,
    preferred: str = "above",
    preference_reason: str = "",
) -> JointCalibration:
    """Fit ``parameters`` of ``model`` jointly to ``groups`` (see the module docstring).

    Parameters
    ----------
    groups
        Measured groups with predictors; every spread must be > 0.
    parameters
        Fitted parameters with priors; the starting point is the prior mean (per branch).
    model
        Base model (frozen dataclass); parameters not fitted keep its values.
    branch
        Name of a ``log`` parameter whose sign of ln(value) splits two symmetric branches
        (``"modulus_ratio"``: E_a > E_p or E_a < E_p), or ``None``.
    preferred
        ``"above"`` (value ≥ 1) or ``"below"``: the branch chosen when the data cannot tell.
    preference_reason
        Why that branch is preferred (recorded in :attr:`JointCalibration.choice`).

    Returns
    -------
    JointCalibration

    Raises
    ------
    InvalidParameterError
        No parameters, a non-positive spread, an unknown branch parameter or preference.
    """
    params = list(parameters)
    if not params:
        raise InvalidParameterError("joint_calibrate.parameters", "name at least one parameter")
    for g in groups:
        if np.any(g.table.spread <= 0.0):
            raise InvalidParameterError(
                f"joint_calibrate.groups[{g.name}]", "spreads must be > 0 to weight the fit"
            )
    if preferred not in ("above", "below"):
        raise InvalidParameterError("joint_calibrate.preferred", "must be 'above' or 'below'")
    for p in params:
        get_parameter(model, p.name)  # fail early on unknown names
    lower = np.array([p.lower for p in params], dtype=float)
    upper = np.array([p.upper for p in params], dtype=float)
    start = np.array([p.mean for p in params], dtype=float)
    names = tuple(g.name for g in groups)
    if branch is None:
        fit = _solve(groups, params, model, start, lower, upper, "all")
        return JointCalibration(names, (fit,), fit, "no branch parameter")
    k = next((i for i, p in enumerate(params) if p.name == branch), None)
    if k is None or not params[k].log:
        raise InvalidParameterError(
            "joint_calibrate.branch", f"{branch!r} must be one of the fitted log parameters"
        )
    fits = {}
    for side, lo, hi, s0 in (
        ("above", 0.0, upper[k], max(params[k].sd, 0.5)),
        ("below", lower[k], 0.0, -max(params[k].sd, 0.5)),
    ):
        lo_b, hi_b, st = lower.copy(), upper.copy(), start.copy()
        lo_b[k], hi_b[k] = lo, hi
        st[k] = float(np.clip(s0, lo + 1e-3, hi - 1e-3))
        label = f"{branch} {'>=' if side == 'above' else '<='} 1"
        fits[side] = _solve(groups, params, model, st, lo_b, hi_b, label)
    other = "below" if preferred == "above" else "above"
    total = {s: f.chi2_data + f.chi2_prior for s, f in fits.items()}
    delta = total[other] - total[preferred]
    if abs(delta) >= BRANCH_DCHI2:
        best = preferred if delta > 0 else other
        choice = (
            f"data: chi2 {total[best]:.3f} on branch {fits[best].label} vs "
            f"{total['above' if best == 'below' else 'below']:.3f} (difference "
            f"{abs(delta):.2f} >= {BRANCH_DCHI2:g})"
        )
    else:
        best = preferred
        choice = (
            f"not distinguished by the data (chi2 {total['above']:.3f} vs {total['below']:.3f}, "
            f"difference {abs(delta):.2f} < {BRANCH_DCHI2:g}); branch {fits[best].label} by "
            f"stated preference: {preference_reason or 'none given'}"
        )
    return JointCalibration(names, (fits["above"], fits["below"]), fits[best], choice)

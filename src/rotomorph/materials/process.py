r"""Process model: print parameters → director field → actuation strains of the LCE.

Symbols (units): print speed v (mm/s), nozzle rotation rate ω (rad/s), filament radius R (mm),
dimensionless rotation rate ω* = Rω/v, surface helix angle φ = atan ω*, nematic order S
(WAXS), backbone anisotropy r, actuation stretches λ∥, λ⊥ and strains ε∥, ε⊥ (dimensionless).

* Kinematics (paper, after Raney et al., PNAS 115, 1198 (2018)): φ = atan ω*. R is the
  *filament* radius: material lines at radius r are helices with
  tan φ(r) = rω/v = ω* r/R, so atan ω* is the exact surface value and the angle falls to zero on
  the axis.
* Order parameter: S(v) interpolates the two WAXS points of the paper (0.150 at 0.25 mm/s,
  0.230 at 3 mm/s) linearly in ln v. This is an *interpolation*, not a flow model (the paper
  attributes the trend to the Weissenberg number; Telles et al., PNAS 2025).
* Actuation strains, pluggable (:class:`ActuationStrainModel`):

  - :class:`WarnerTerentjev`: ideal nematic rubber (Warner & Terentjev, *Liquid Crystal
    Elastomers*, OUP 2007): r = (1 + 2Q)/(1 - Q), λ∥ = r^(-1/3), λ⊥ = r^(1/6) with Q ≈ S
    (assumption).
  - :class:`EmpiricalThreshold`: effective axial strain ε∥ = -gain (S(v) - S0), calibrated to
    the Janus curvature data; ε⊥ from volume conservation.

* Temperature → actuation fraction x(T) ∈ [0, 1]: logistic sigmoid through T_NI with a width;
  optional hysteresis shifts the midpoint to T_NI ± h/2 on heating / cooling. All eigenstrains
  scale linearly with x (the theory page, partial actuation).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from typing import Literal, Protocol, runtime_checkable

import numpy as np

from rotomorph._typing import FloatArray
from rotomorph.errors import InvalidParameterError

logger = logging.getLogger(__name__)

Measure = Literal["hencky", "engineering"]
ABSOLUTE_ZERO = -273.15  # °C

#: WAXS order parameter vs print speed (paper, Supp. Figs 8-9): (v in mm/s, S).
PAPER_ORDER_POINTS: tuple[tuple[float, float], ...] = ((0.25, 0.150), (3.0, 0.230))


def _as_array(name: str, value: float | FloatArray) -> FloatArray:
    arr = np.asarray(value, dtype=float)
    if not np.all(np.isfinite(arr)):
        raise InvalidParameterError(name, f"must be finite; got {value!r}")
    return arr


def _positive(name: str, value: float | FloatArray, unit: str) -> FloatArray:
    arr = _as_array(name, value)
    if np.any(arr <= 0.0):
        bad = float(arr.reshape(-1)[np.argmax(arr.reshape(-1) <= 0.0)])
        raise InvalidParameterError(name, f"must be > 0 {unit}; got {bad}")
    return arr


def _check_measure(measure: str) -> None:
    if measure not in ("hencky", "engineering"):
        raise InvalidParameterError(
            "measure", f"must be 'hencky' or 'engineering'; got {measure!r}"
        )


def dimensionless_rotation(
    rotation: float | FloatArray, speed: float | FloatArray, radius: float
) -> FloatArray:
    """Dimensionless rotation rate ω* = R ω / v (paper; R = filament radius).

    Parameters
    ----------
    rotation
        Nozzle rotation rate ω (rad/s, signed; convert rpm with 2π/60).
    speed
        Print speed v (mm/s), > 0.
    radius
        Filament radius R (mm), > 0.

    Examples
    --------
    ω = 10 rad/s at v = 3 mm/s and R = 0.3 mm gives ω* = 1 (φ = 45°).
    """
    v = _positive("speed", speed, "mm/s")
    r = _positive("radius", radius, "mm")
    return r * _as_array("rotation", rotation) / v


def helix_angle(omega_star: float | FloatArray) -> FloatArray:
    """Surface helix angle of the LCE director φ = atan ω* (rad; paper, Fig. 2E)."""
    return np.arctan(_as_array("omega_star", omega_star))


def helix_angle_profile(
    r: float | FloatArray, radius: float, omega_star: float | FloatArray
) -> FloatArray:
    """Radial director profile φ(r) = atan(ω* r / R) (rad; kinematic).

    Parameters
    ----------
    r
        Distance from the filament axis (mm), 0 ≤ r ≤ R.
    radius
        Filament radius R (mm).
    omega_star
        Dimensionless rotation rate (signed).
    """
    rr = _as_array("r", r)
    big_r = _positive("radius", radius, "mm")
    return np.arctan(_as_array("omega_star", omega_star) * rr / big_r)


def order_parameter(
    speed: float | FloatArray,
    points: tuple[tuple[float, float], ...] = PAPER_ORDER_POINTS,
) -> FloatArray:
    """Nematic order parameter S(v) by piecewise-linear interpolation in ln v.

    Between the measured points S is linear in ln v; outside them the first / last segment is
    extrapolated and the result clipped to [0, 0.99]. With the paper's two points this is
    S = 0.1946 + 0.0322 ln(v / 1 mm/s) (S(0.5) = 0.172, S(1.75) = 0.213).

    Parameters
    ----------
    speed
        Print speed v (mm/s), > 0.
    points
        Measured (v in mm/s, S) pairs, at least two, distinct speeds.

    Returns
    -------
    ndarray
        S (dimensionless), same shape as ``speed``.
    """
    v = _positive("speed", speed, "mm/s")
    pts = sorted(points)
    if len(pts) < 2 or len({p[0] for p in pts}) != len(pts):
        raise InvalidParameterError("order_parameter.points", "needs >= 2 distinct speeds")
    lv = np.log([p[0] for p in pts])
    s = np.array([p[1] for p in pts])
    x = np.log(v)
    if np.any((x < lv[0]) | (x > lv[-1])):
        logger.debug(
            "order_parameter: extrapolating S(v) outside %g..%g mm/s", pts[0][0], pts[-1][0]
        )
    seg = np.clip(np.searchsorted(lv, x) - 1, 0, len(lv) - 2)
    slope = (s[seg + 1] - s[seg]) / (lv[seg + 1] - lv[seg])
    return np.clip(s[seg] + slope * (x - lv[seg]), 0.0, 0.99)


def _check_points(name: str, points: tuple[tuple[float, float], ...]) -> None:
    """Refuse order-parameter points that :func:`order_parameter` cannot interpolate."""
    try:
        pts = [(float(v), float(s)) for v, s in points]
    except (TypeError, ValueError):
        raise InvalidParameterError(name, "must be (speed mm/s, S) pairs") from None
    if len(pts) < 2 or len({v for v, _ in pts}) != len(pts):
        raise InvalidParameterError(name, "needs >= 2 points at distinct speeds")
    if not all(np.isfinite(v) and v > 0 and np.isfinite(s) and 0 <= s < 1 for v, s in pts):
        raise InvalidParameterError(name, "needs speeds > 0 mm/s and S in [0, 1)")


def backbone_anisotropy(q: float | FloatArray) -> FloatArray:
    """Backbone anisotropy r = (1 + 2Q)/(1 - Q) of an ideal nematic network.

    Warner & Terentjev, *Liquid Crystal Elastomers* (OUP 2007).

    Parameters
    ----------
    q
        Backbone order parameter Q in [0, 1) (dimensionless).
    """
    qq = _as_array("q", q)
    if np.any((qq < 0.0) | (qq >= 1.0)):
        raise InvalidParameterError("q", "order parameter must lie in [0, 1)")
    return (1.0 + 2.0 * qq) / (1.0 - qq)


def stretch_to_strain(stretch: float | FloatArray, measure: Measure) -> FloatArray:
    """Strain of a stretch λ: ln λ (``"hencky"``) or λ - 1 (``"engineering"``) (dimensionless)."""
    _check_measure(measure)
    lam = _positive("stretch", stretch, "")
    return np.log(lam) if measure == "hencky" else lam - 1.0


def strain_to_stretch(strain: float | FloatArray, measure: Measure) -> FloatArray:
    """Inverse of :func:`stretch_to_strain`: exp ε or 1 + ε (dimensionless)."""
    _check_measure(measure)
    eps = _as_array("strain", strain)
    return np.exp(eps) if measure == "hencky" else 1.0 + eps


@runtime_checkable
class ActuationStrainModel(Protocol):
    """Principal free strains of the LCE at full actuation as a function of print speed.

    Implementations are frozen dataclasses with float fields (so :func:`calibrate` can vary them)
    and a ``measure`` field (``"hencky"`` or ``"engineering"``).
    """

    @property
    def measure(self) -> Measure:
        """``"hencky"`` or ``"engineering"``: the measure of the returned strains."""
        ...

    def active_strains(self, speed: float | FloatArray) -> tuple[FloatArray, FloatArray]:
        """(ε∥ along the director, ε⊥ across it) at full actuation, for print speed v (mm/s)."""
        ...


@dataclass(frozen=True)
class WarnerTerentjev:
    """Ideal-nematic-rubber strains with Q = order_scale · S(v) (Warner & Terentjev 2007).

    λ∥ = r^(-1/3), λ⊥ = r^(1/6), r = (1 + 2Q)/(1 - Q); volume preserving. With Q = S = 0.23
    (v = 3 mm/s): λ∥ = 0.808, matching the pure-LCE L/L0 = 0.80 ± 0.03 at ω* = 0.06 (Fig. 2F).

    Parameters
    ----------
    measure
        Strain measure of the returned strains.
    order_scale
        Q / S (dimensionless, default 1: the assumption Q ≈ S of the theory page).
    order_points
        Measured (v in mm/s, S) pairs of the ink's order parameter (:func:`order_parameter`).
    """

    measure: Measure = "hencky"
    order_scale: float = 1.0
    order_points: tuple[tuple[float, float], ...] = PAPER_ORDER_POINTS

    def __post_init__(self) -> None:
        _check_measure(self.measure)
        _positive("WarnerTerentjev.order_scale", self.order_scale, "")
        _check_points("WarnerTerentjev.order_points", self.order_points)

    def active_strains(self, speed: float | FloatArray) -> tuple[FloatArray, FloatArray]:
        """(ε∥, ε⊥) (dimensionless) for print speed v (mm/s)."""
        r = backbone_anisotropy(self.order_scale * order_parameter(speed, self.order_points))
        return (
            stretch_to_strain(r ** (-1.0 / 3.0), self.measure),
            stretch_to_strain(r ** (1.0 / 6.0), self.measure),
        )


@dataclass(frozen=True)
class EmpiricalThreshold:
    """Calibrated effective strain ε∥ = -gain · max(S(v) - threshold, 0).

    The Janus curvature rises ×4.5 between 0.25 and 3 mm/s while S rises ×1.53, which WT with
    Q = S cannot reproduce; the data suggest an effective strain linear in S above a threshold
    (two-point fit K_J ≈ 5.75 (S - 0.127) mm⁻¹). ε⊥ follows from volume conservation:
    ε⊥ = -ε∥/2 (Hencky) or (1 + ε∥)^(-1/2) - 1 (engineering). The parameters are meant to be
    fitted with :func:`rotomorph.materials.calibrate.calibrate`; defaults are the notes' two-point
    estimate for m_eff ≈ 4 (Hencky).

    Parameters
    ----------
    gain
        dε∥/dS above the threshold (dimensionless), > 0.
    threshold
        Order parameter S0 below which the LCE does not contract (dimensionless).
    measure
        Strain measure.
    order_points
        Measured (v in mm/s, S) pairs of the ink's order parameter (:func:`order_parameter`).
    """

    gain: float = 2.1
    threshold: float = 0.127
    measure: Measure = "hencky"
    order_points: tuple[tuple[float, float], ...] = PAPER_ORDER_POINTS

    def __post_init__(self) -> None:
        _check_measure(self.measure)
        _positive("EmpiricalThreshold.gain", self.gain, "")
        _as_array("EmpiricalThreshold.threshold", self.threshold)
        _check_points("EmpiricalThreshold.order_points", self.order_points)

    def active_strains(self, speed: float | FloatArray) -> tuple[FloatArray, FloatArray]:
        """(ε∥, ε⊥) (dimensionless) for print speed v (mm/s)."""
        s = order_parameter(speed, self.order_points)
        eps_par = -self.gain * np.maximum(s - self.threshold, 0.0)
        if self.measure == "hencky":
            return eps_par, -0.5 * eps_par
        return eps_par, (1.0 + eps_par) ** -0.5 - 1.0


def actuation_fraction(
    temperature: float | FloatArray,
    transition_temperature: float,
    width: float = 10.0,
    *,
    direction: Literal["heating", "cooling"] = "heating",
    hysteresis: float = 0.0,
) -> FloatArray:
    """Fraction x ∈ [0, 1] of the full actuation strain at temperature T.

    x(T) = 1 / (1 + exp(-(T - T_mid)/w)) with T_mid = T_NI + h/2 on heating and T_NI - h/2 on
    cooling (a smooth stand-in for the normalized-length-vs-T curve of the paper's Fig. 1D,
    which is not available numerically; an assumption). Eigenstrains scale by x.

    Parameters
    ----------
    temperature
        T (°C), ≥ -273.15.
    transition_temperature
        Nematic-to-isotropic temperature T_NI (°C).
    width
        Sigmoid width w (°C), > 0.
    direction
        ``"heating"`` or ``"cooling"`` branch.
    hysteresis
        Width h (°C) ≥ 0 of the hysteresis loop; 0 gives one curve for both directions.

    Returns
    -------
    ndarray
        x (dimensionless), same shape as ``temperature``.
    """
    t = _as_array("temperature", temperature)
    if np.any(t < ABSOLUTE_ZERO):
        raise InvalidParameterError("temperature", "must be >= -273.15 °C (absolute zero)")
    tni = float(_as_array("transition_temperature", transition_temperature))
    w = float(_positive("width", width, "°C"))
    h = float(_as_array("hysteresis", hysteresis))
    if h < 0.0:
        raise InvalidParameterError("hysteresis", f"must be >= 0 °C; got {h}")
    if direction not in ("heating", "cooling"):
        raise InvalidParameterError(
            "direction", f"must be 'heating' or 'cooling'; got {direction!r}"
        )
    mid = tni + 0.5 * h if direction == "heating" else tni - 0.5 * h
    return 0.5 * (1.0 + np.tanh(0.5 * (t - mid) / w))

r"""What a print setting gives: the natural field per unit printed length, tabulated.

For inverse design the forward chain (print program → natural field → rod model) is sampled on
a grid of print speed :math:`v` and signed director rotation rate :math:`\omega^*` (the
interface turns at :math:`d\alpha/ds = \omega^*/R` along the printed filament). The samples
are taken *through the same functions the forward simulation uses*
(:func:`rotomorph.materials.natural.natural_field` and
:meth:`rotomorph.rod.model.Model.from_field`), on one long straight probe program in which every
grid point occupies a block of vertices with constant settings, so the inverse is consistent
with the forward model by construction — whatever the model's conventions for rest lengths and
integrated curvatures are.

Per grid point the table holds, per unit *printed* length:

* ``curvature``: integrated natural curvature toward the interface normal (active side), 1/mm,
* ``twist``: integrated natural twist (printed interface twist plus the eigen-twist), 1/mm,
* ``stretch``: natural length / printed length (dimensionless).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.interpolate import RectBivariateSpline

from rotomorph._typing import FloatArray
from rotomorph.design.program import PrintProgram
from rotomorph.errors import InvalidParameterError
from rotomorph.materials.natural import FilamentModel, natural_field
from rotomorph.rod.model import Model

__all__ = ["ResponseTable", "cached_response_table", "response_table"]

_BLOCK = 5  # vertices per grid point in the probe program (vertices 1-3 are pure)


@dataclass(frozen=True, eq=False)
class ResponseTable:
    """Natural field per printed length on a (speed, ω*) grid, with smooth interpolation.

    Attributes
    ----------
    speeds
        Grid of print speeds ``(nv,)`` (mm/s).
    omega_stars
        Grid of signed director rotation rates ω* ``(nw,)`` (dimensionless).
    curvature, twist, stretch
        ``(nv, nw)`` tables (1/mm, 1/mm, dimensionless).
    radius
        Filament radius R (mm).
    temperature
        Actuation temperature (°C).
    """

    speeds: FloatArray
    omega_stars: FloatArray
    curvature: FloatArray
    twist: FloatArray
    stretch: FloatArray
    radius: float
    temperature: float

    def __post_init__(self) -> None:
        object.__setattr__(
            self,
            "_splines",
            tuple(
                RectBivariateSpline(self.speeds, self.omega_stars, tab, kx=3, ky=3)
                for tab in (self.curvature, self.twist, self.stretch)
            ),
        )

    def __call__(
        self, speed: FloatArray, omega_star: FloatArray, dv: int = 0, dw: int = 0
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Bicubic-spline ``(curvature, twist, stretch)`` (or their ``dv``/``dw`` derivatives)
        at the given settings, clipped to the grid."""
        v = np.clip(np.asarray(speed, float), self.speeds[0], self.speeds[-1])
        w = np.clip(np.asarray(omega_star, float), self.omega_stars[0], self.omega_stars[-1])
        k, t, s = (
            f.ev(v.ravel(), w.ravel(), dx=dv, dy=dw).reshape(v.shape)
            for f in self._splines  # type: ignore[attr-defined]
        )
        return k, t, s

    @property
    def curvature_range(self) -> tuple[float, float]:
        """Smallest and largest natural curvature magnitude in the table (1/mm)."""
        k = np.abs(self.curvature)
        return float(k.min()), float(k.max())


def response_table(
    *,
    speed_range: tuple[float, float] = (0.25, 3.0),
    max_omega_star: float = 2.0,
    radius: float = 0.3,
    active_fraction: float = 0.5,
    active_material: str = "lce",
    passive_material: str = "acrylate",
    temperature: float = 175.0,
    model: FilamentModel | None = None,
    n_speeds: int = 15,
    n_omega: int = 31,
) -> ResponseTable:
    """Tabulate the forward chain on a grid (module docstring).

    Parameters
    ----------
    speed_range
        Print speeds (mm/s) to cover; the default is the range over which the speed law was
        measured (extrapolating it is not a prediction).
    max_omega_star
        Largest |ω*| tabulated (dimensionless).
    radius, active_fraction, active_material, passive_material
        Filament section (mm, area fraction, material names).
    temperature
        Actuation temperature (°C).
    model
        Modelling choices of the chain (default: the package's calibrated model).
    n_speeds, n_omega
        Grid sizes (speeds are spaced geometrically).
    """
    lo, hi = speed_range
    if not (np.isfinite(lo) and np.isfinite(hi) and 0 < lo < hi):
        raise InvalidParameterError(
            "speed_range", f"must be 0 < low < high mm/s; got {speed_range}"
        )
    if not (np.isfinite(max_omega_star) and max_omega_star > 0):
        raise InvalidParameterError("max_omega_star", f"must be > 0; got {max_omega_star}")
    speeds = np.geomspace(lo, hi, n_speeds)
    omegas = np.linspace(-max_omega_star, max_omega_star, n_omega)
    vv, ww = np.meshgrid(speeds, omegas, indexing="ij")
    # one padding block after the last grid point keeps the last block away from the end
    v_flat = np.append(vv.ravel(), vv.ravel()[-1])
    w_flat = np.append(ww.ravel(), ww.ravel()[-1])
    h = 0.05 * radius  # probe spacing: small enough for the interface twist to be resolved
    n_blocks = len(v_flat)
    n = n_blocks * _BLOCK
    x = np.arange(n) * h
    pts = np.stack([x, np.zeros(n), np.zeros(n)], axis=1)
    v_vertex = np.repeat(v_flat, _BLOCK)
    rate = np.repeat(w_flat / radius, _BLOCK)  # dα/ds per vertex (1/mm)
    # interface angle per vertex: integrate the rate inside each block, restart at 0 per block
    alpha = np.zeros(n)
    for k in range(1, _BLOCK):
        alpha[k::_BLOCK] = alpha[k - 1 :: _BLOCK] + rate[k::_BLOCK] * h
    program = PrintProgram.from_interface_angle(
        pts,
        v_vertex,
        alpha,
        radius=radius,
        active_fraction=active_fraction,
        active_material=active_material,
        passive_material=passive_material,
    )
    field = natural_field(program, temperature=temperature, model=model)
    rod = Model.from_field(pts, field)
    k1, _, tw = rod.integrated_natural()
    printed = np.diff(x)
    vor_p = 0.5 * (printed[:-1] + printed[1:])
    rest = np.asarray(field.rest_length)
    # the programme's rotation rate is a central difference of the nozzle angle, so only
    # vertices 1-3 of a block see their block's setting alone; the stencil at vertex 2 uses
    # edges 1 and 2, both pure (stencil index = vertex - 1)
    centre = np.arange(vv.size) * _BLOCK + _BLOCK // 2
    st = centre - 1
    curvature = (k1[st] / vor_p[st]).reshape(vv.shape)
    twist = (tw[st] / vor_p[st]).reshape(vv.shape)
    stretch = (rest[centre] / printed[centre]).reshape(vv.shape)
    # the directors are signed without pi jumps; the block's sign is that of its centre edge
    sign = np.sign(
        np.einsum("ij,ij->i", field.directors[centre], program.interface_normals[centre])
    )
    curvature = curvature * sign.reshape(vv.shape)
    return ResponseTable(
        speeds=speeds,
        omega_stars=omegas,
        curvature=curvature,
        twist=twist,
        stretch=stretch,
        radius=float(radius),
        temperature=float(temperature),
    )


_CACHE: dict[tuple, ResponseTable] = {}


def cached_response_table(**kwargs: object) -> ResponseTable:
    """:func:`response_table` memoised per process on its (hashable) arguments.

    The table depends only on the material model and the grid, so repeated designs in one
    session (a sweep of targets, the test-suite) build it once.
    """
    try:
        key = tuple(sorted(kwargs.items()))
        hash(key)
    except TypeError:
        return response_table(**kwargs)  # type: ignore[arg-type]
    if key not in _CACHE:
        _CACHE[key] = response_table(**kwargs)  # type: ignore[arg-type]
    return _CACHE[key]

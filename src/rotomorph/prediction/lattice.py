r"""Independent-edge estimates for a sinusoidal lattice: area ratio and Gaussian-curvature sign.

An *estimate*, not the lattice's equilibrium (that is ``rotomorph simulate``): every lattice edge
is taken as a free filament of its own — one sine period of amplitude A and wavelength l,
printed at its speed with its active side (expanding: outer, contracting: inner), heated
free — and its end-to-end ratio :math:`\lambda_e` is the exact zero-energy shape of the discrete
rod (:func:`rotomorph.simulate.free_shape.free_equilibrium`). The junctions, the lattice's
bending out of plane, self-contact, the floor and the weight are all ignored, and so is the
printed stack (one filament per edge).

* Area ratio: each cell keeps its rectangle, with sides the mean ratios of its two x- and two
  y-edges, :math:`A/A_0 = \langle \bar\lambda_x \bar\lambda_y\rangle_{\rm cells}`.
* Gaussian-curvature sign: the edges prescribe a metric. Taken as conformal,
  :math:`g = \lambda^2 (dx^2 + dy^2)` with :math:`\lambda` at a node the geometric mean of its
  edges' ratios, its Gaussian curvature is :math:`K = -\Delta \ln\lambda/\lambda^2`
  (e.g. do Carmo, *Differential Geometry of Curves and Surfaces*, §4-3, ex. 1); summed over
  the interior nodes (5-point Laplacian) its sign is that of the flux of
  :math:`\nabla\ln\lambda` through the boundary: +1 when the centre grows relative to the rim
  (a dome), −1 when the rim does (a saddle), 0 for a uniform lattice. Only the sign is
  reported: the magnitude is set by bending, which the estimate ignores.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from rotomorph._typing import FloatArray
from rotomorph.errors import InvalidDesignError
from rotomorph.materials.natural import FilamentModel
from rotomorph.prediction.band import CALIBRATION_TEMPERATURE, Estimate, calibrated_range, with_band

__all__ = ["LABEL", "LatticePrediction", "predict_lattice"]

LABEL = (
    "independent-edge estimate: each edge a free heated filament (no junctions, bending, "
    "contact, floor or weight); not the lattice's equilibrium (rotomorph simulate)"
)


@dataclass(frozen=True)
class LatticePrediction:
    """Independent-edge estimate of a lattice (module docstring).

    Attributes
    ----------
    area_ratio
        Estimated A/A0 with its calibration band.
    gaussian_sign
        +1 (dome), −1 (saddle), 0 (flat) of the metric the edges prescribe.
    edge_ratios
        End-to-end ratio of each distinct edge kind: ``(mode, speed) -> Estimate``.
    extrapolated
        Why the settings lie outside the calibrated range (empty: inside).
    label
        What kind of estimate this is (:data:`LABEL`).
    """

    area_ratio: Estimate
    gaussian_sign: int
    edge_ratios: dict[tuple[str, float], Estimate]
    extrapolated: tuple[str, ...]
    label: str = LABEL

    def record(self) -> dict[str, Any]:
        """JSON-able form."""
        return {
            "kind": "lattice",
            "method": self.label,
            "area_ratio": self.area_ratio.record(),
            "gaussian_sign": self.gaussian_sign,
            "edge_end_to_end_ratio": [
                {"mode": m, "speed_mm_s": v, **e.record()} for (m, v), e in self.edge_ratios.items()
            ],
            "extrapolated": bool(self.extrapolated),
            "extrapolation": list(self.extrapolated),
        }

    def line(self) -> str:
        """One line for a terminal."""
        sign = {1: "+1 (dome)", -1: "-1 (saddle)", 0: "0 (flat)"}[self.gaussian_sign]
        edges = ", ".join(f"{m} at {v:g} mm/s {e.text()}" for (m, v), e in self.edge_ratios.items())
        out = (
            f"lattice: area ratio {self.area_ratio.text()}, Gaussian curvature sign {sign}; "
            f"edge L/L0: {edges} [{self.label}]"
        )
        if self.extrapolated:
            out += "; EXTRAPOLATED: " + "; ".join(self.extrapolated)
        return out


def _edge_program(lattice: Any, mode: str, speed: float, spacing: float) -> Any:
    """One lattice edge printed on its own: a sine period with the edge's side and speed."""
    from rotomorph.io.designfile import Filament
    from rotomorph.prediction.band import calibrated_set

    return Filament.model_validate(
        {
            "name": mode,
            "speed": speed,
            "active_side": "outer" if mode == "expanding" else "inner",
            "flip_length": lattice.flip_length,
            "spacing": spacing,
            "radius": lattice.radius,
            "active_fraction": lattice.active_fraction,
            "active_material": lattice.active_material,
            "passive_material": lattice.passive_material,
            "segments": [
                {
                    "kind": "sinusoid",
                    "amplitude": lattice.amplitude,
                    "wavelength": lattice.spacing,
                    "periods": 1,
                }
            ],
        },
        context={"materials": calibrated_set()},  # the design's inks, if it names a file
    ).to_program()


def metric_gaussian_sign(n: int, edge_nodes: FloatArray, ratios: FloatArray) -> int:
    """Sign of the summed Gaussian curvature of the conformal metric the edges prescribe.

    Parameters
    ----------
    n
        Branch nodes per side.
    edge_nodes
        ``(E, 2)`` branch-node indices ``k = n i + j`` of each edge.
    ratios
        ``(E,)`` end-to-end ratio of each edge.
    """
    log = np.log(np.asarray(ratios, dtype=float))
    total = np.zeros(n * n)
    count = np.zeros(n * n)
    for (a, b), value in zip(np.asarray(edge_nodes), log, strict=True):
        total[[a, b]] += value
        count[[a, b]] += 1
    u = (total / np.maximum(count, 1)).reshape(n, n)
    lap = u[:-2, 1:-1] + u[2:, 1:-1] + u[1:-1, :-2] + u[1:-1, 2:] - 4.0 * u[1:-1, 1:-1]
    k = -(lap / np.exp(2.0 * u[1:-1, 1:-1])).sum()
    scale = max(float(np.max(np.abs(log))), 1e-12)
    return 0 if abs(k) <= 1e-9 * scale else int(np.sign(k))


def _cell_area(n: int, ratios: FloatArray) -> float:
    m = n - 1
    nx = n * m
    rx = ratios[:nx].reshape(n, m)  # x-edge (i, j) -> (i+1, j) at [j, i]
    ry = ratios[nx:].reshape(n, m)  # y-edge (i, j) -> (i, j+1) at [i, j]
    area = 0.0
    for i in range(m):
        for j in range(m):
            lx = 0.5 * (rx[j, i] + rx[j + 1, i])
            ly = 0.5 * (ry[i, j] + ry[i + 1, j])
            area += lx * ly
    return area / (m * m)


def predict_lattice(
    design_lattice: Any, *, temperature: float = CALIBRATION_TEMPERATURE
) -> LatticePrediction:
    """Independent-edge estimate of a design's ``[lattice]`` heated to ``temperature`` (°C).

    Parameters
    ----------
    design_lattice
        The design file's :class:`~rotomorph.io.designfile.LatticeModel`.
    temperature
        Heating temperature (°C).
    """
    from rotomorph.simulate.validation import end_to_end, free_shape

    if design_lattice.amplitude <= 0:
        raise InvalidDesignError(
            "lattice.amplitude",
            "is 0: straight Janus edges curl on their own, so independent edges estimate "
            "nothing; use rotomorph simulate",
        )
    lat = design_lattice.to_lattice()
    speeds = lat.speeds
    kinds = sorted({(m, float(v)) for m, v in zip(lat.edge_mode, speeds, strict=True)})
    spacing = min(0.05, lat.spacing / 50.0)
    programs = [_edge_program(lat, m, v, spacing) for m, v in kinds]
    index = {k: i for i, k in enumerate(kinds)}
    which = np.array([index[(m, float(v))] for m, v in zip(lat.edge_mode, speeds, strict=True)])

    def ratios(model: FilamentModel) -> FloatArray:
        return np.array([end_to_end(free_shape(p, model, temperature), p.points) for p in programs])

    def quantities(model: FilamentModel) -> FloatArray:
        r = ratios(model)
        return np.append(r, _cell_area(lat.n, r[which]))

    est = with_band(quantities, ["1"] * (len(kinds) + 1))
    nominal = np.array([e.value for e in est[:-1]])
    sign = metric_gaussian_sign(lat.n, lat.edge_nodes, nominal[which])
    extrapolated = calibrated_range().outside(
        speed=speeds,
        temperature=temperature,
        radius=lat.radius,
        active_fraction=lat.active_fraction,
        materials=(lat.active_material, lat.passive_material),
    )
    return LatticePrediction(
        area_ratio=est[-1],
        gaussian_sign=sign,
        edge_ratios=dict(zip(kinds, est[:-1], strict=True)),
        extrapolated=tuple(extrapolated),
    )

"""Mesh convergence of the filament and sinusoid predictions, and the two-resolution helper."""

from __future__ import annotations

import math

import pytest

from rotomorph.errors import InvalidParameterError
from rotomorph.io.designfile import Filament
from rotomorph.materials.calibrate import paper_calibration
from rotomorph.simulate.convergence import at_two_resolutions
from rotomorph.simulate.filament import simulate_filament


@pytest.fixture(scope="module")
def model():
    return paper_calibration().chosen.model


def _sinusoid(side: str, spacing: float) -> Filament:
    return Filament(
        name=side,
        speed=3.0,
        active_side=side,  # type: ignore[arg-type]
        spacing=spacing,
        segments=[{"kind": "sinusoid", "amplitude": 1.25, "wavelength": 5.0, "periods": 2}],  # type: ignore[list-item]
    )


def _ratio(fil: Filament, model, steps: int = 8) -> float:
    return simulate_filament(fil.to_program(), steps=steps, model=model).final_ratio


def test_contracting_sinusoid_converges_with_node_spacing(model):
    # sharp flips of the active side between two vertices act as steps at the edge midpoint;
    # sampling the edge's mean nozzle angle put the active half on top over each flip edge
    # (out-of-plane curvature K_J h per flip) and the ratio moved 0.2 -> 0.5 with h
    # and the nozzle's flip rotation wound a spurious director helix over the two vertices
    # around each flip (eigen-twist of order 0.3 rad per flip at h = 0.45 mm)
    res = at_two_resolutions(lambda h: _ratio(_sinusoid("inner", h), model), 0.2, rtol=1e-2)
    assert res.converged, res
    assert 0.2 < res.value < 0.6


def test_rotated_filament_converges_with_node_spacing(model):
    def ratio(h: float) -> float:
        fil = Filament(
            name="w0.25",
            speed=3.0,
            rotation_number=0.25,
            spacing=h,
            segments=[{"kind": "line", "length": 12.0}],  # type: ignore[list-item]
        )
        return _ratio(fil, model, steps=4)

    res = at_two_resolutions(ratio, 0.2, order=2.0, rtol=2e-3)
    assert res.converged, res


def test_two_resolution_estimate():
    res = at_two_resolutions(lambda h: 2.0 + 3.0 * h, 0.2)
    assert res.value == pytest.approx(2.3) and res.coarse == pytest.approx(2.6)
    # order 1, r = 2: the error of the finer value equals the difference
    assert res.error == pytest.approx(0.3)
    assert not res.converged and res.relative_error == pytest.approx(0.3 / 2.3)
    exact = at_two_resolutions(lambda h: 1.0, 0.1)
    assert exact.converged and exact.error == 0.0
    assert not at_two_resolutions(lambda h: math.nan, 0.1).converged
    for kw, field in (
        ({"spacing": 0.0}, "spacing"),
        ({"spacing": 0.1, "refinement": 1.0}, "refinement"),
        ({"spacing": 0.1, "order": -1.0}, "order"),
        ({"spacing": 0.1, "rtol": -1.0}, "rtol"),
    ):
        with pytest.raises(InvalidParameterError, match=field):
            at_two_resolutions(lambda h: 1.0, **kw)

"""The paper report's 3-D figures: the active side of a free filament and the tube pictures."""

from __future__ import annotations

import numpy as np
import pytest
from matplotlib.colors import to_rgb

from rotomorph.design.program import PrintProgram
from rotomorph.materials import FilamentModel
from rotomorph.plot.figure import figure_to_rgb
from rotomorph.plot.tubes import ACTIVE_COLOUR, PASSIVE_COLOUR
from rotomorph.simulate.report_shapes import filament_shapes_figure, free_shape_normals
from rotomorph.simulate.validation import free_shape


def _straight(omega_star: float, fraction: float = 0.5) -> PrintProgram:
    from rotomorph.io.designfile import Filament

    return Filament(
        speed=3.0,
        rotation_number=omega_star,
        radius=0.3,
        active_fraction=fraction,
        spacing=0.1,
        segments=[{"kind": "line", "length": 30.0}],  # type: ignore[list-item]
    ).to_program()


@pytest.fixture(scope="module")
def model():
    return FilamentModel()


@pytest.mark.parametrize("omega_star", [0.06, 0.25])
def test_the_active_half_faces_the_centre_of_curvature(model, omega_star):
    """The LCE half contracts on heating: a free Janus filament bends (and twists) toward it,
    so at every node of the heated coil or helix the carried interface normal points to the
    centre of curvature — which fails if the material frame is carried wrongly."""
    prog = _straight(omega_star)
    x = free_shape(prog, model)
    n = free_shape_normals(prog, model, x)
    t = np.diff(x, axis=0)
    t /= np.linalg.norm(t, axis=1)[:, None]
    assert np.allclose(np.linalg.norm(n, axis=1), 1.0) and np.abs((n * t).sum(1)).max() < 1e-9
    assert np.linalg.norm(x[-1] - x[0]) < 0.95 * 30.0  # it did coil up
    bend = t[1:] - t[:-1]
    towards = (0.5 * (n[1:] + n[:-1]) * bend).sum(1) / np.linalg.norm(bend, axis=1)
    assert towards.min() > 0.99
    # unheated, the shape is the printed one and so are the normals
    cold = free_shape(prog, model, temperature=25.0)
    n_cold = free_shape_normals(prog, model, cold, temperature=25.0)
    assert np.abs(n_cold - prog.interface_normals).max() < 0.05


def _pixels(rgb: np.ndarray, colour: str) -> int:
    target = np.array(to_rgb(colour))
    px = rgb.reshape(-1, 3) / 255.0
    bright = px.max(axis=1)
    hue = px / np.maximum(bright, 1e-6)[:, None]
    ref = target / target.max()
    return int(((np.abs(hue - ref).max(axis=1) < 0.22) & (bright > 0.2)).sum())


def test_filament_figure_draws_janus_tubes_on_one_scale(model):
    shapes = {}
    for label, fraction in (("pure LCE", 1.0), ("composite", 0.5)):
        for w in (0.06, 2.0):
            prog = _straight(w, fraction)
            x = free_shape(prog, model)
            shapes[(label, w)] = (prog, x, free_shape_normals(prog, model, x))
    fig = filament_shapes_figure(shapes)
    axes = [ax for ax in fig.axes if ax.get_label() == "panel"]
    assert len(axes) == 4
    # one scale: every panel's box spans the same millimetres
    spans = {tuple(np.round([np.ptp(ax.get_xlim()), np.ptp(ax.get_ylim())], 6)) for ax in axes}
    assert len(spans) == 1
    titles = [t.get_text() for t in fig.texts if "L/L0" in t.get_text()]
    assert len(titles) == 4 and any("composite, ω* = 0.06" in t for t in titles)
    rgb = figure_to_rgb(fig)
    assert _pixels(rgb, ACTIVE_COLOUR) > 200 and _pixels(rgb, PASSIVE_COLOUR) > 200

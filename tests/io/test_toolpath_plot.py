"""Toolpath preview PNG (rotomorph.plot.toolpath): written atomically, not blank, legible."""

from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

from rotomorph.design.lattices import sinusoidal_lattice
from rotomorph.design.path import Path, Sinusoid
from rotomorph.design.program import PrintProgram
from rotomorph.errors import InvalidParameterError
from rotomorph.plot.toolpath import save_toolpath_png


def test_png_exists_and_is_not_blank(tmp_path):
    lattice = sinusoidal_lattice(n=3, ghost_nodes=4, layers=2, pattern="dome")
    sine = Path.from_segments([Sinusoid(1.0, 5.0, 2)], spacing=0.1)
    progs = [PrintProgram.sinusoid_with_active_side(sine, 3.0, "outer"), *lattice.print_programs()]
    out = save_toolpath_png(sorted(progs, key=lambda p: p.layer), tmp_path / "preview.png")
    assert [p.name for p in tmp_path.iterdir()] == ["preview.png"]
    img = np.asarray(Image.open(out).convert("RGB"), dtype=float)
    assert img.shape[0] > 100 and img.std() > 5.0
    # legible: a square part gets a 6 in panel at 150 dpi, about 900 px a side
    assert img.shape[0] >= 900 and img.shape[1] >= 900
    # coloured pixels (the twilight map), not only black glyphs on white
    assert np.sum(np.ptp(img, axis=2) > 40) > 500


def test_empty_preview_is_refused(tmp_path):
    with pytest.raises(InvalidParameterError):
        save_toolpath_png([], tmp_path / "x.png")
    assert list(tmp_path.iterdir()) == []

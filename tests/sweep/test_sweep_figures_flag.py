"""Sweep figures flag the points whose state is not physical, as every other output does."""

from __future__ import annotations

import numpy as np
import pyarrow as pa

from rotomorph.sweep.figures import plot_curve, plot_heatmap


def _table():
    return pa.table(
        {
            "speed": [0.5, 1.0, 1.5, 2.0],
            "rotation": [0.0, 0.0, 1.0, 1.0],
            "end_to_end_ratio": [0.9, 0.1, 0.2, 0.3],
            "status": ["ok", "ok", "ok", "failed"],
            "physical": [True, False, None, False],
        }
    )


def test_curve_rings_the_unphysical_points_only():
    # before: a sweep whose coils pass through themselves was drawn as ordinary results
    fig = plot_curve(_table(), "speed", ["end_to_end_ratio"])
    ax = fig.axes[0]
    rings = [ln for ln in ax.get_lines() if ln.get_markerfacecolor() == "none"]
    assert len(rings) == 1
    assert list(rings[0].get_xdata()) == [1.0]  # not the unknown one, not the failed run
    assert np.allclose(rings[0].get_ydata(), [0.1])
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "not physical (see physical_reason)" in labels


def test_heatmap_crosses_the_unphysical_points():
    fig = plot_heatmap(_table(), "speed", "rotation", "end_to_end_ratio")
    ax = fig.axes[0]
    crosses = [c for c in ax.collections if c.get_label().startswith("not physical")]
    assert len(crosses) == 1
    assert crosses[0].get_offsets().tolist() == [[1.0, 0.0]]


def test_panels_share_one_legend_with_each_entry_once():
    table = _table().append_column("curvature", pa.array([0.1, 0.2, 0.3, 0.4]))
    fig = plot_curve(table, "speed", ["end_to_end_ratio", "curvature"], group="rotation")
    assert all(ax.get_legend() is None for ax in fig.axes)  # no legend repeated per panel
    (legend,) = fig.legends
    labels = [t.get_text() for t in legend.get_texts()]
    assert labels.count("rotation = 0.0") == 1 and labels.count("rotation = 1.0") == 1
    assert labels.count("not physical (see physical_reason)") == 1
    # a single curve needs no legend at all
    one = plot_curve(_table().slice(0, 1), "speed", ["end_to_end_ratio"])
    assert one.axes[0].get_legend() is None and not one.legends

"""The paper's parameter sweeps
==============================

Computed with rotomorph's sweep runner, next to its measurements.

Three sweep files in ``examples/sweeps/`` (each also runs with ``rotomorph sweep FILE -o DIR``):

* ``janus_curvature_speed.toml``: Janus curvature against print speed (Fig. 2D), run with both
  calibrations: ``warner_terentjev`` (E_a/E_p is a *fit* to the 3 mm/s point) and
  ``empirical_threshold`` (gain and threshold are *fits* to 0.25 and 3 mm/s); the other speeds
  are predictions. ``curvature`` is that of the solved rod's shape, per current length (what a
  photograph measures); the rows also give ``closed_form_curvature``, the closed-form free
  helix's, which the rod reproduces. Both are K/stretch, while the calibration fitted the
  natural curvature K per *printed* length to the measurement, so even the fitted points sit
  above the measurement by the filament's axial contraction (about 18 % at 3 mm/s).
* ``length_vs_rotation.toml``: L/L0 against ω* for pure LCE (Fig. 2F) and composite (Fig. 2G)
  filaments; no parameter is fitted to these points.
* ``morphology_phase.toml``: the morphology (twisted rod / helix / coil) over (ω*, v), which
  the paper does not have (a prediction).

Writes ``OUT/<sweep>/`` (run records, ``results.parquet``) and ``OUT/figures/*.png``, and prints
one JSON object per measured point and output: ``quantity, output, model, condition, x,
measured, spread, predicted, calibration`` (true for a fitted point), ``physical``.

Run: ``python examples/sweeps_vs_paper.py -o sweeps_out`` (``--quick``: 3-4 points per sweep on
coarse filaments, for tests). Interrupted? Run the same command again: finished runs are kept.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

import pyarrow as pa

from rotomorph.materials.measurements import load_table
from rotomorph.plot.figure import save_figure
from rotomorph.sweep import Sweep, load_sweep, local_executor, run_sweep
from rotomorph.sweep.figures import plot_curve, plot_heatmap, plot_phase_diagram

HERE = Path(__file__).resolve().parent / "sweeps"


def quick(sweep: Sweep, keep: dict[str, list[float]]) -> Sweep:
    """The same sweep on coarse filaments over a few values (``keep``: column → values)."""
    params = [
        p.model_copy(update={"values": keep[p.column], "range": None}) if p.column in keep else p
        for p in sweep.parameters
    ]
    settings = sweep.settings.model_copy(update={"spacing": 1.0, "steps": 2})
    return sweep.model_copy(update={"parameters": params, "settings": settings})


def _rows(table: Any, x: str, output: str, where: dict[str, Any] | None = None) -> dict:
    rows = {}
    for r in table.to_pylist():
        if r["status"] == "ok" and all(r[k] == v for k, v in (where or {}).items()):
            rows[r[x]] = r
    return rows


def compare(
    table: Any,
    data: Any,
    x: str,
    output: str,
    fitted: tuple[float, ...] = (),
    where: dict[str, Any] | None = None,
    tag: str = "",
) -> list[dict[str, Any]]:
    """Measured vs predicted rows at the measured x values present in the table."""
    rows = _rows(table, x, output, where)
    out = []
    for xi, cond, value, spread in zip(
        data.x, data.condition, data.value, data.spread, strict=True
    ):
        r = rows.get(float(xi))
        if r is None:
            continue
        out.append(
            {
                "quantity": data.name,
                "output": output,
                "model": tag or "warner_terentjev",
                "condition": cond,
                "x": float(xi),
                "measured": float(value),
                "spread": float(spread),
                "predicted": None if r[output] is None else round(r[output], 4),
                "calibration": float(xi) in fitted,
                "physical": r["physical"],
            }
        )
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-o", "--output", default="sweeps_out", help="output folder")
    parser.add_argument("--quick", action="store_true", help="few points, coarse (for tests)")
    parser.add_argument("--workers", type=int, default=None, help="local worker processes")
    args = parser.parse_args(argv)
    out = Path(args.output)
    figs = out / "figures"
    figs.mkdir(parents=True, exist_ok=True)

    janus = load_sweep(HERE / "janus_curvature_speed.toml")
    rotation = load_sweep(HERE / "length_vs_rotation.toml")
    phase = load_sweep(HERE / "morphology_phase.toml")
    if args.quick:
        janus = quick(janus, {"speed": [0.25, 1.75, 3.0]})
        rotation = quick(rotation, {"omega_star": [0.06, 1.0, 2.0]})
        phase = quick(phase, {"omega_star": [0.06, 2.0], "speed": [0.5, 3.0]})

    with local_executor(args.workers) as pool:
        rows = run_all(janus, rotation, phase, out, figs, pool)
    for row in rows:
        sys.stdout.write(json.dumps(row) + "\n")
    return 0


def run_all(janus: Sweep, rotation: Sweep, phase: Sweep, out: Path, figs: Path, pool: Any) -> list:
    """Run the three sweeps on ``pool``, draw the figures, return the comparison rows."""
    rows: list[dict[str, Any]] = []
    curv = load_table("janus_curvature")
    tables = []
    for model, fitted in (("warner_terentjev", (3.0,)), ("empirical_threshold", (0.25, 3.0))):
        settings = janus.settings.model_copy(update={"filament_model": model})
        sweep = janus.model_copy(update={"settings": settings})
        t = run_sweep(sweep, out / f"janus_curvature_speed_{model}", executor=pool).table
        for output in ("curvature", "closed_form_curvature"):
            rows += compare(t, curv, "speed", output, fitted=fitted, tag=model)
        tables.append(t.append_column("filament_model", pa.array([model] * t.num_rows)))
    both = pa.concat_tables(tables, promote_options="default")
    fig = plot_curve(
        both,
        "speed",
        ["curvature"],
        group="filament_model",
        measured=[(curv, "curvature")],
        title="Janus curvature vs speed (fits: WT at 3 mm/s; threshold at 0.25 and 3 mm/s)",
    )
    save_figure(fig, figs / "janus_curvature_speed.png")

    pure, comp = load_table("pure_lce_length"), load_table("composite_length")
    t = run_sweep(rotation, out / "length_vs_rotation", executor=pool).table
    rows += compare(t, pure, "omega_star", "end_to_end_ratio", where={"active_fraction": 1.0})
    rows += compare(t, comp, "omega_star", "end_to_end_ratio", where={"active_fraction": 0.5})
    fig = plot_curve(
        t,
        "omega_star",
        ["end_to_end_ratio"],
        group="active_fraction",
        measured=[(comp, "end_to_end_ratio@0.5"), (pure, "end_to_end_ratio@1.0")],
        title="L/L0 vs ω* at 3 mm/s (predictions)",
    )
    fig.axes[0].set_xscale("log")
    save_figure(fig, figs / "length_vs_rotation.png")

    t = run_sweep(phase, out / "morphology_phase", executor=pool).table
    fig = plot_phase_diagram(
        t, "omega_star", "speed", title="Composite filaments: morphology over (ω*, v) (prediction)"
    )
    fig.axes[0].set_xscale("log")
    save_figure(fig, figs / "morphology_phase.png")
    fig = plot_heatmap(t, "omega_star", "speed", "end_to_end_ratio")
    fig.axes[0].set_xscale("log")
    save_figure(fig, figs / "morphology_phase_length.png")

    return rows


if __name__ == "__main__":
    raise SystemExit(main())

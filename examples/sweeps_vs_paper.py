"""The paper's parameter sweeps
==============================

Computed with rotomorph's sweep runner, next to its measurements.

Three sweep files in ``examples/sweeps/`` (each also runs with ``rotomorph sweep FILE -o DIR``):

* ``janus_curvature_speed.toml``: Janus curvature against print speed (Fig. 2D), run with two
  materials models: ``calibrated-without-janus_curvature`` (the joint calibration without these
  points: every point is an out-of-sample prediction, as in ``rotomorph paper``) and
  ``calibrated`` (the default model, whose fit *includes* these points: in-sample fits, labelled
  so). ``curvature`` is that of the solved rod's shape, per current length (what a photograph
  measures); the rows also give ``closed_form_curvature``, the closed-form free helix's, which
  the rod reproduces.
* ``length_vs_rotation.toml``: L/L0 against ω* for pure LCE (Fig. 2F) and composite (Fig. 2G)
  filaments, each group predicted by the calibration that left it out
  (``calibrated-without-pure_lce_length``, ``calibrated-without-composite_length``).
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
import pyarrow.compute as pc

from rotomorph.materials.measurements import load_table
from rotomorph.plot.figure import save_figure
from rotomorph.sweep import Sweep, load_sweep, local_executor, run_sweep
from rotomorph.sweep.figures import plot_curve, plot_heatmap, plot_phase_diagram

#: The sweep files (sphinx-gallery runs examples without ``__file__``, from this folder).
HERE = Path(globals().get("__file__", "sweeps_vs_paper.py")).resolve().parent / "sweeps"


def with_model(sweep: Sweep, model: str) -> Sweep:
    """The same sweep computed with the materials model ``model`` (a settings name)."""
    settings = sweep.settings.model_copy(update={"filament_model": model})
    return sweep.model_copy(update={"settings": settings})


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
    tag: str,
    fitted: bool = False,
    where: dict[str, Any] | None = None,
) -> list[dict[str, Any]]:
    """Measured vs predicted rows at the measured x values present in the table.

    ``tag`` names the materials model; ``fitted``: that model's calibration used these
    measurements (the rows are fits, not predictions).
    """
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
                "model": tag,
                "condition": cond,
                "x": float(xi),
                "measured": float(value),
                "spread": float(spread),
                "predicted": None if r[output] is None else round(r[output], 4),
                "calibration": fitted,
                "physical": r["physical"],
            }
        )
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=(__doc__ or "").strip().partition("\n")[0])
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
    for model, fitted in (("calibrated-without-janus_curvature", False), ("calibrated", True)):
        t = run_sweep(with_model(janus, model), out / f"janus_{model}", executor=pool).table
        for output in ("curvature", "closed_form_curvature"):
            rows += compare(t, curv, "speed", output, tag=model, fitted=fitted)
        tables.append(t.append_column("filament_model", pa.array([model] * t.num_rows)))
    both = pa.concat_tables(tables, promote_options="default")
    fig = plot_curve(
        both,
        "speed",
        ["curvature"],
        group="filament_model",
        measured=[(curv, "curvature")],
        title="Janus curvature vs speed: out of sample (fit without them) and in-sample fit",
    )
    save_figure(fig, figs / "janus_curvature_speed.png")

    parts = []
    for group, fraction in (("pure_lce_length", 1.0), ("composite_length", 0.5)):
        model, data = f"calibrated-without-{group}", load_table(group)
        t = run_sweep(with_model(rotation, model), out / f"length_{model}", executor=pool).table
        rows += compare(
            t,
            data,
            "omega_star",
            "end_to_end_ratio",
            tag=model,
            where={"active_fraction": fraction},
        )
        parts.append(t.filter(pc.equal(t["active_fraction"], fraction)))
    pure, comp = load_table("pure_lce_length"), load_table("composite_length")
    fig = plot_curve(
        pa.concat_tables(parts),
        "omega_star",
        ["end_to_end_ratio"],
        group="active_fraction",
        measured=[(comp, "end_to_end_ratio@0.5"), (pure, "end_to_end_ratio@1.0")],
        title="L/L0 vs ω* at 3 mm/s (each group out of sample)",
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
    main()  # always 0; not SystemExit, which would end a documentation build running it

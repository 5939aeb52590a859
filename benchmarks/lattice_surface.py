"""Are the heated dome and saddle surfaces? What keeps them from it (JSON lines, a figure).

For the report's contact-resolved dome and saddle ramps (5 x 5, the calibrated model, the
bath floor under buoyant weight, every edge presenting its printed three-layer stack; the
same ramps as ``rotomorph paper``, served from its disk cache where it ran), one line per ramp
step with:

* ``residual_over_rise``: RMS residual of the quadratic fitted to the branch nodes over their
  rise along its normal, and ``crossing_edges``: lattice edges whose projection onto the
  fit's plane crosses itself (:mod:`rotomorph.analysis.surface`);
* the elastic energy by kind (N mm): bending toward the sheet normal (``bend_out``, the stack's
  stiff direction), in the sheet (``bend_in``), ``twist`` and ``stretch``, each against the
  natural state of that step;
* ``roll_deg``: median angle between the material director (printed: the sheet normal) and
  the fitted surface's normal, on the expanding and on the contracting edges: an edge that
  has rolled onto its side shows 90°.

``--torsion F1,F2,...``: the same ramps (8 steps, on the floor, without the path check) with
the rod's torsion constant multiplied by each factor, a *what-if* that is no option of the
package (a stack fused over its whole height would twist like a solid bar, about 2.7 × the
line-bonded stack's N C): one line each with the end state's surface quality and roll. Not a
calibration: the package keeps the section its geometry gives.

``--fused H``: the same with the layers H mm apart (overlapping below one diameter: the fused
section's own torsion, bending and contact shape).

``--figure PATH`` draws the residual, the roll, the energy shares and the what-if;
``--replot LINES`` draws it from the JSON lines of an earlier run instead of running. Run:
``python benchmarks/lattice_surface.py [--ghosts G] [--torsion 1,3,10] [--fused H]
[--figure PATH] [--replot LINES]``
(default 20 ghost nodes per edge, the report's counted resolution).
"""

from __future__ import annotations

import json
import sys

import numpy as np

from rotomorph.analysis.surface import surface_quality
from rotomorph.geometry import pair_strains
from rotomorph.lattice.actuation import ProgramActuation
from rotomorph.simulate.report import (
    LATTICE_STEPS,
    LIFT_OFF_TOLERANCE,
    PATH_CHECK_FACTOR,
    _heat,
    calibrated_model,
)


def energies(model, state) -> dict[str, float]:  # type: ignore[no-untyped-def]
    """Elastic energy of ``state`` by kind against ``model``'s natural state (N mm)."""
    st = model.stencils
    x = state.positions
    m1, _ = state.material_directors()
    e = x[st.nodes[:, 1]] - x[st.nodes[:, 0]]
    f = x[st.nodes[:, 2]] - x[st.nodes[:, 1]]
    k1, k2, tw = pair_strains(e, f, m1[st.edge_e], m1[st.edge_f])
    b1, b2, c = model.stencil_stiffness
    n1, n2, nt = model.integrated_natural()
    vor = model.voronoi_length
    length = np.linalg.norm(x[model.network.edges[:, 1]] - x[model.network.edges[:, 0]], axis=1)
    rest = np.asarray(model.rest_length)
    ea = np.asarray(model.axial_stiffness)
    return {
        "bend_out": float(np.sum(0.5 * b1 * (k1 - n1) ** 2 / vor)),
        "bend_in": float(np.sum(0.5 * b2 * (k2 - n2) ** 2 / vor)),
        "twist": float(np.sum(0.5 * c * (tw - nt) ** 2 / vor)),
        "stretch": float(np.sum(0.5 * ea * (length / rest - 1.0) ** 2 * rest)),
    }


def roll(lattice, state, normal) -> dict[str, float]:  # type: ignore[no-untyped-def]
    """Median angle (degrees) between the material director and ``normal`` per edge mode."""
    m1, _ = state.material_directors()
    per = lattice.ghost_nodes + 1
    mode = np.repeat(np.asarray(lattice.edge_mode), per)
    angle = np.degrees(np.arccos(np.clip(np.abs(m1 @ normal), 0.0, 1.0)))
    return {m: round(float(np.median(angle[mode == m])), 1) for m in ("expanding", "contracting")}


def what_if(pattern: str, fm, torsion: float, ghosts: int, layer_height: float = 0.6) -> dict:  # type: ignore[no-untyped-def]
    """The report's ramp of ``pattern`` with the torsion constant times ``torsion`` (and
    another ``layer_height``, mm: overlapping layers fuse into another section)."""
    import dataclasses

    import rotomorph.lattice.heating as heating
    from rotomorph.design.lattices import sinusoidal_lattice
    from rotomorph.lattice.heating import lattice_buoyancy

    built = heating.lattice_model

    def scaled(*args, **kwargs):  # type: ignore[no-untyped-def]
        lm = built(*args, **kwargs)
        c = np.asarray(lm.model.twist_stiffness) * torsion
        return dataclasses.replace(lm, model=dataclasses.replace(lm.model, twist_stiffness=c))

    lattice = sinusoidal_lattice(5, 5.0, 1.25, ghosts, pattern, layer_height=layer_height)
    heating.lattice_model = scaled
    try:
        res = heating.heat_lattice(
            lattice, actuation=ProgramActuation(filament_model=fm), steps=LATTICE_STEPS,
            floor=True, gravity=lattice_buoyancy(lattice),
        )  # fmt: skip
    finally:
        heating.lattice_model = built
    q = surface_quality(res.positions[-1], lattice.branch_indices, lattice.edge_chains)
    lifted = q.rise > 4.0 * lattice.radius
    return {
        "pattern": pattern,
        "torsion_factor": torsion,
        "layer_height_mm": layer_height,
        "ghost_nodes": ghosts,
        "rise_mm": round(q.rise, 3),
        "residual_over_rise": round(q.relative_residual, 4) if lifted else None,
        "crossing_edges": len(q.crossing_edges),
        "is_surface": bool(q.is_surface and lifted),
        "gaussian_sign": int(res.gaussian_sign[-1]),
        "characteristic_curvature": round(float(res.characteristic_curvature[-1]), 4),
        "area_ratio": round(float(res.final_area_ratio), 4),
        "stack_overlaps": int(np.max(res.stack_overlaps)),
        "roll_deg": roll(lattice, res.states[-1], q.fit.frame[2]),
    }


def main(
    ghosts: int = 20,
    figure: str | None = None,
    torsion: tuple[float, ...] = (),
    fused: float | None = None,
) -> None:
    fm, _ = calibrated_model()
    act = ProgramActuation(filament_model=fm)
    rows: dict[str, list[dict]] = {}
    for pattern in ("dome", "saddle"):
        lattice, res, why = _heat(
            pattern, False, LATTICE_STEPS, fm, ghosts, True,
            lift_off_tolerance=LIFT_OFF_TOLERANCE, path_check=PATH_CHECK_FACTOR,
        )  # fmt: skip
        if res is None:
            raise SystemExit(f"{pattern}: {why}")
        rows[pattern] = []
        for k, state in enumerate(res.states):
            q = surface_quality(res.positions[k], lattice.branch_indices, lattice.edge_chains)
            model = act.natural(res.model, float(res.parameter[k]))
            row = {
                "pattern": pattern,
                "ghost_nodes": ghosts,
                "temperature_C": round(float(res.parameter[k]), 2),
                # (a lattice flat on the floor is a plane: its residual over a rise of
                # round-off means nothing)
                "residual_over_rise": round(q.relative_residual, 4) if q.rise > 1.2 else None,
                "rise_mm": round(q.rise, 3),
                "crossing_edges": len(q.crossing_edges),
                "is_surface": bool(q.is_surface) if q.rise > 1.2 else True,
                "gaussian_sign": int(res.gaussian_sign[k]),
                "stack_overlaps": int(res.stack_overlaps[k]),
                **{key: round(v, 6) for key, v in energies(model, state).items()},
                "roll_deg": roll(lattice, state, q.fit.frame[2]),
            }
            rows[pattern].append(row)
            print(json.dumps(row), flush=True)
    tries = []
    for factor in torsion:
        for pattern in ("dome", "saddle"):
            tries.append(what_if(pattern, fm, factor, ghosts))
            print(json.dumps(tries[-1]), flush=True)
    if fused is not None:  # overlapping layers: the fused section's own stiffnesses and contact
        for pattern in ("dome", "saddle"):
            tries.append(what_if(pattern, fm, 1.0, ghosts, fused))
            print(json.dumps(tries[-1]), flush=True)
    if figure:
        _figure(rows, tries, figure)


def replot(lines: str, path: str) -> None:
    """Draw the figure from the JSON lines of an earlier run (file ``lines``)."""
    from pathlib import Path

    rows: dict[str, list[dict]] = {}
    tries: list[dict] = []
    for text in Path(lines).read_text(encoding="utf-8").splitlines():
        if text.strip():
            r = json.loads(text)
            if "torsion_factor" in r:
                tries.append(r)
            else:
                rows.setdefault(r["pattern"], []).append(r)
    _figure(rows, tries, path)


def _figure(rows: dict[str, list[dict]], tries: list[dict], path: str) -> None:
    from pathlib import Path

    from rotomorph.plot.figure import new_figure, save_figure

    fig = new_figure(14.5, 5.0)
    axes = fig.subplots(1, 4)
    colours = {"dome": "tab:red", "saddle": "tab:blue"}
    for pattern, data in rows.items():
        data = [r for r in data if r["rise_mm"] > 1.2]  # lifted off the floor (else a plane)
        t = [r["temperature_C"] for r in data]
        c = colours[pattern]
        axes[0].plot(t, [100 * r["residual_over_rise"] for r in data], "o-", color=c,
                     label=pattern)  # fmt: skip
        for r in data:
            if r["crossing_edges"]:
                axes[0].plot(r["temperature_C"], 100 * r["residual_over_rise"], "x", color="k",
                             ms=8)  # fmt: skip
        axes[1].plot(t, [r["roll_deg"]["contracting"] for r in data], "o-", color=c,
                     label=f"{pattern}: contracting edges")  # fmt: skip
        axes[1].plot(t, [r["roll_deg"]["expanding"] for r in data], "s--", color=c, mfc="none",
                     label=f"{pattern}: expanding edges")  # fmt: skip
        end = data[-1]
        kinds = ("bend_out", "bend_in", "twist", "stretch")
        total = sum(end[k] for k in kinds)
        x0 = 0.0 if pattern == "dome" else 0.4
        axes[2].bar(np.arange(4) + x0, [end[k] / total for k in kinds], width=0.4, color=c,
                    label=f"{pattern}, {end['temperature_C']:.0f} °C")  # fmt: skip
    axes[0].axhline(10.0, color="0.5", ls=":", lw=1)
    axes[0].set_xlabel("temperature (°C)")
    axes[0].set_ylabel("fit residual / rise (%)")
    axes[0].set_title("quadratic fit of the branch nodes\n(x: an edge crosses itself)", fontsize=9)
    axes[1].set_xlabel("temperature (°C)")
    axes[1].set_ylabel("director vs surface normal (°, median)")
    axes[1].set_title("roll of the edges' stacks", fontsize=9)
    axes[2].set_xticks(np.arange(4) + 0.2, ["bend\nout", "bend\nin", "twist", "stretch"])
    axes[2].set_ylabel("share of elastic energy")
    axes[2].set_title("energy at the end of the ramp\n(bending out of / in the sheet)", fontsize=9)
    for pattern in ("dome", "saddle"):
        mine = [r for r in tries if r["pattern"] == pattern and r["layer_height_mm"] == 0.6]
        fused = [r for r in tries if r["pattern"] == pattern and r["layer_height_mm"] != 0.6]
        c = colours[pattern]
        lifted = [r for r in mine if r["residual_over_rise"] is not None]
        axes[3].plot([r["torsion_factor"] for r in lifted],
                     [100 * r["residual_over_rise"] for r in lifted], "o-", color=c,
                     label=f"{pattern}")  # fmt: skip
        for r in mine:
            if r["residual_over_rise"] is None:  # never leaves the floor: a plane
                axes[3].plot(r["torsion_factor"], 0.0, "v", color=c, ms=8, mfc="none")
        for r in fused:
            if r["residual_over_rise"] is not None:
                label = f"{pattern}: layers fused ({r['layer_height_mm']:g} mm)"
                axes[3].plot(1.32, 100 * r["residual_over_rise"], "D", mfc="none", color=c,
                             label=label)  # fmt: skip
    flat = sorted({r["torsion_factor"] for r in tries if r["residual_over_rise"] is None})
    for f in flat:
        who = {
            r["pattern"]
            for r in tries
            if r["torsion_factor"] == f and r["residual_over_rise"] is None
        }
        text = "both stay flat" if len(who) == 2 else f"{who.pop()} stays flat"
        axes[3].annotate(text, (f, 1.5), fontsize=7, rotation=90, ha="center", va="bottom")
    if tries:
        axes[3].axhline(10.0, color="0.5", ls=":", lw=1)
        axes[3].set_xscale("log")
        axes[3].set_xlim(0.8, 15.0)
        axes[3].set_ylim(-1.0, None)
        axes[3].set_xlabel("torsion constant / the stack's (what-if)")
        axes[3].set_ylabel("fit residual / rise (%), 175 °C")
        axes[3].set_title("if the stack twisted stiffer", fontsize=9)
    for ax in axes:
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.2), frameon=False)
    fig.subplots_adjust(wspace=0.35, bottom=0.36, top=0.88)
    save_figure(fig, Path(path))


if __name__ == "__main__":
    args = sys.argv[1:]
    g = int(args[args.index("--ghosts") + 1]) if "--ghosts" in args else 20
    fig_path = args[args.index("--figure") + 1] if "--figure" in args else None
    factors = (
        tuple(float(v) for v in args[args.index("--torsion") + 1].split(","))
        if "--torsion" in args
        else ()
    )
    h = float(args[args.index("--fused") + 1]) if "--fused" in args else None
    if "--replot" in args:
        if fig_path is None:
            raise SystemExit("--replot needs --figure PATH")
        replot(args[args.index("--replot") + 1], fig_path)
    else:
        main(g, fig_path, factors, h)

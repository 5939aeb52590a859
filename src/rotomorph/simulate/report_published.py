"""The paper report's section on the authors' own simulation of Fig. 4, rebuilt.

The authors computed Fig. 4 with disMech; their example is public (the set-up, checked number
by number, is :mod:`rotomorph.lattice.published`). This section sweeps their stretch range
with rotomorph's curvature-rescaling actuation on their set-up, once as they ran it (on a
floor with friction 0.4 under the logged run's weight) and once weightless and free (the
limit of a negligible weight), and writes:

* ``figures/published_fig4_sweep.png``: √|k1 k2| against stretch, coloured by the Gaussian
  sign, and the rise off the floor;
* ``figures/published_fig4_shapes.png``: the dome and the saddle at stretch
  magnitudes 0.3 and 0.75;
* ``published_fig4_sweep.json``: one record per stretch value of both sweeps;
* Markdown: what was rebuilt, where the two set-ups differ, the onsets, the logged run's
  stretch, and the cost of the whole sweep next to the authors' per-run time.

Nothing here is a prediction of a measurement: it compares two simulations of one model.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from rotomorph._typing import FloatArray
from rotomorph.io.atomic import atomic_write_text
from rotomorph.lattice.published import (
    FRICTION,
    LOGGED_RUN_SECONDS,
    LOGGED_STRETCH,
    SPACING,
    UNLISTED_LIMBS,
    PublishedSweep,
    published_sweep,
    weight_ratio,
)
from rotomorph.simulate.cache import disk_cached

__all__ = [
    "PublishedSection",
    "published_section",
    "records",
    "report_sweeps",
    "shapes_figure",
    "sweep_figure",
]

#: Stretch spacing and largest stretch magnitude of the report's sweeps (quick mode: a short
#: smoke run of 11 values; coarser steps cost more, not less: each jump is a long Newton path).
GRID = {False: (0.01, 0.75), True: (0.05, 0.25)}
#: Stretch magnitudes at which the dome and saddle are drawn.
SHOWN = (0.3, 0.75)
#: Above this fit residual (over the rise) the quadratic surface no longer describes the shape.
POOR_FIT = 0.1
#: The authors' per-time-step cost measured on this class of machine (s of CPU; their example
#: built against the September 2024 disMech; not re-measured by the tests), and their
#: protocol's time steps (10 s at dt = 1e-5 s).
AUTHORS_STEP_CPU = (0.012, 0.014)
AUTHORS_TIME_STEPS = 1_000_000


@dataclass(frozen=True)
class PublishedSection:
    """What :func:`published_section` produced: Markdown lines, figures, the sweeps."""

    lines: list[str]
    figures: list[Path]
    on_floor: PublishedSweep
    weightless: PublishedSweep


def _sweep(step: float, end: float, weightless: bool) -> PublishedSweep:
    key = repr(("published_sweep", step, end, weightless))
    if weightless:
        return disk_cached(
            "published_sweep",
            key,
            lambda: published_sweep(step, end, floor=False, friction=0.0, acceleration=0.0),
        )
    return disk_cached("published_sweep", key, lambda: published_sweep(step, end))


def report_sweeps(*, quick: bool) -> tuple[PublishedSweep, PublishedSweep]:
    """The section's two sweeps on its grid (:data:`GRID`): on the floor as the authors ran it,
    and weightless and free; each cached on disk (:func:`rotomorph.simulate.cache.disk_cached`),
    so a process that computed them before (or is computing them now) supplies them."""
    step, end = GRID[quick]
    return _sweep(step, end, weightless=False), _sweep(step, end, weightless=True)


def not_physical(sweep: PublishedSweep, k: int) -> str | None:
    """Why value ``k`` of ``sweep`` is not physical (None: certified stable, no filaments
    interpenetrating; :func:`rotomorph.lattice.admissibility.admissibility`)."""
    why = []
    if sweep.stable[k] is not True:
        why.append("not certified stable")
    overlaps = None if sweep.stack_overlaps is None else int(sweep.stack_overlaps[k])
    if overlaps is None:
        why.append("admissibility not checked")
    elif overlaps:
        why.append(f"{overlaps} segment pairs interpenetrate")
    return "; ".join(why) or None


def _bad_values(sweep: PublishedSweep) -> list[int]:
    return [k for k in range(len(sweep.stretch)) if not_physical(sweep, k) is not None]


def sweep_figure(on_floor: PublishedSweep, weightless: PublishedSweep | None = None) -> Any:
    """√|k1 k2| l and the rise off the floor against stretch (the report's Fig. 4 sweep)."""
    from rotomorph.plot.figure import new_figure

    fig = new_figure(10.0, 4.4)
    curv, rise = fig.subplots(1, 2, gridspec_kw={"width_ratios": [1.5, 1.0]})
    colours = {1: "tab:red", -1: "tab:blue", 0: "0.55"}
    names = {1: "dome (K > 0)", -1: "saddle (K < 0)", 0: "flat"}
    if weightless is not None:
        curv.plot(
            weightless.stretch,
            weightless.characteristic_curvature * SPACING,
            color="0.3",
            lw=1.0,
            ls="--",
            label="weightless, no floor",
        )
    s, k = on_floor.stretch, on_floor.characteristic_curvature * SPACING
    poor = on_floor.fit_residual > POOR_FIT
    for sign in (1, -1, 0):
        for bad in (False, True):
            sel = (on_floor.gaussian_sign == sign) & (poor == bad)
            if sel.any():
                curv.scatter(
                    s[sel],
                    k[sel],
                    s=14,
                    marker="o",
                    facecolors="none" if bad else colours[sign],
                    edgecolors=colours[sign],
                    linewidths=0.8,
                    label=f"{names[sign]}{', fit residual > 10 % of rise' if bad else ''}",
                    zorder=3,
                )
    unphysical = _bad_values(on_floor)
    if unphysical:
        curv.scatter(
            s[unphysical], k[unphysical], s=30, marker="x", color="k", linewidths=0.8, zorder=4,
            label="NOT PHYSICAL (unstable or filaments interpenetrating)",
        )  # fmt: skip
    for ax in (curv, rise):
        ax.axvline(LOGGED_STRETCH, color="k", lw=0.8, ls=":")
        ax.grid(alpha=0.3)
        ax.set_xlabel("stretch (their controller's parameter)")
    curv.text(
        LOGGED_STRETCH - 0.01,
        0.97,
        "their logged run (−0.17):\nends flat on the floor",
        transform=curv.get_xaxis_transform(),
        fontsize=6.5,
        va="top",
        ha="right",
    )
    curv.set_ylabel("√|k1 k2| · l (–)")
    title = "rotomorph on the authors' set-up: curvature of the branch-node fit"
    if unphysical:
        title += f"\nNOT PHYSICAL at {len(unphysical)} of {len(s)} values (x)"
    curv.set_title(title, fontsize=9, color="tab:red" if unphysical else "k")
    curv.legend(fontsize=6.5, loc="upper right")
    if on_floor.floor_lift is not None:
        rise.plot(s, on_floor.floor_lift / SPACING, color="k", lw=1.0)
    rise.set_ylabel("highest rise off the floor / l (–)")
    rise.set_title(f"on the floor, μ = {FRICTION:g}, their weight", fontsize=9)
    fig.tight_layout()
    return fig


def shapes_figure(sweep: PublishedSweep, shown: tuple[float, ...] = SHOWN) -> Any:
    """The dome and the saddle at the stretch magnitudes ``shown``: 3-D views coloured by height."""
    from matplotlib.colors import Normalize
    from mpl_toolkits.mplot3d.art3d import Line3DCollection

    from rotomorph.plot.figure import new_figure
    from rotomorph.plot.shapes import set_equal_3d

    lat = sweep.lattice
    edges = np.asarray(lat.network.edges)
    values = sorted([-v for v in shown] + list(shown))
    fig = new_figure(3.4 * len(values), 3.9)
    for i, v in enumerate(values):
        k = sweep.at(v)
        pos = sweep.positions[k]
        ax = fig.add_subplot(1, len(values), i + 1, projection="3d")
        z = pos[:, 2]
        seg = pos[edges]
        coll = Line3DCollection(seg, linewidths=0.9, cmap="viridis")
        coll.set_array(0.5 * (z[edges[:, 0]] + z[edges[:, 1]]))
        coll.set_norm(Normalize(float(z.min()), float(z.max()) + 1e-9))
        ax.add_collection3d(coll)
        set_equal_3d(ax, pos)
        ax.view_init(elev=22.0, azim=-55.0)
        ax.set_axis_off()
        sign = int(sweep.gaussian_sign[k])
        kind = {1: "dome", -1: "saddle", 0: "flat"}[sign]
        fit = sweep.fit_residual[k]
        why = not_physical(sweep, k)
        ax.set_title(
            f"stretch {sweep.stretch[k]:+.2f}: {kind}\n√|k1k2|·l = "
            f"{sweep.characteristic_curvature[k] * SPACING:.2f}"
            f"{' (poor fit)' if fit > POOR_FIT else ''}"
            f"{'' if why is None else chr(10) + 'NOT PHYSICAL: ' + why}",
            fontsize=8,
            color="k" if why is None else "tab:red",
        )
    fig.suptitle(
        "The authors' lattice (l = 1 m cells, r = 1 mm) in rotomorph: static equilibria on the "
        f"floor (μ = {FRICTION:g}, their weight), colour = height",
        fontsize=9,
    )
    return fig


def records(sweep: PublishedSweep, case: str) -> list[dict[str, Any]]:
    """One JSON-ready record per stretch value of ``sweep`` (``case`` names the sweep)."""
    out = []
    for k, s in enumerate(sweep.stretch):
        out.append(
            {
                "case": case,
                "stretch": round(float(s), 4),
                "characteristic_curvature": float(sweep.characteristic_curvature[k]),
                "characteristic_curvature_times_l": float(
                    sweep.characteristic_curvature[k] * SPACING
                ),
                "gaussian_sign": int(sweep.gaussian_sign[k]),
                "fit_residual_over_rise": float(sweep.fit_residual[k]),
                "floor_lift_mm": None if sweep.floor_lift is None else float(sweep.floor_lift[k]),
                "stable": sweep.stable[k],
                "stack_overlaps": (
                    None if sweep.stack_overlaps is None else int(sweep.stack_overlaps[k])
                ),
                "physical": not_physical(sweep, k) is None,
                "physical_reason": not_physical(sweep, k),
                "wall_s": float(sweep.wall_time[k]),
            }
        )
    return out


def _onset(sweep: PublishedSweep, sign: int) -> str:
    v = sweep.first(sign)
    return "never" if v is None else f"{v:+.2f}"


def _range(values: FloatArray) -> str:
    return f"{float(values.min()):.2f}–{float(values.max()):.2f}"


def _logged(floor: PublishedSweep, free: PublishedSweep) -> str:
    """What rotomorph finds at the logged run's stretch, in words (computed)."""
    k, j = floor.at(LOGGED_STRETCH), free.at(LOGGED_STRETCH)
    if (
        abs(floor.stretch[k] - LOGGED_STRETCH) > 1e-9
        or abs(free.stretch[j] - LOGGED_STRETCH) > 1e-9
    ):
        return "not on this sweep's grid (quick mode)."
    kind = {1: "a dome", -1: "a saddle", 0: "flat"}
    rise = 0.0 if floor.floor_lift is None else float(floor.floor_lift[k])
    where = (
        "resting on the floor: no node above its printed height"
        if rise <= 2.0 * floor.lattice.radius
        else f"highest node {rise / SPACING:.2f} l above its printed height"
    )
    text = (
        f"on the floor rotomorph's lattice is {kind[int(floor.gaussian_sign[k])]} ({where}); "
        f"weightless and free it is {kind[int(free.gaussian_sign[j])]}"
    )
    if floor.energy[k] > 0 and free.gaussian_sign[j] != 0:
        lower = 1.0 - float(free.energy[j] / floor.energy[k])
        text += f", {100 * lower:.1f} % lower in energy than the lattice resting flat"
    gap = None if floor.lift_energy_gap is None else float(floor.lift_energy_gap[k])
    if floor.gaussian_sign[k] == 0 and gap is not None:
        if np.isnan(gap):
            text += (
                "; but under their weight every lifted candidate of the lift probe falls back "
                "flat onto the floor: no lifted equilibrium was found there."
            )
        else:
            text += (
                f"; but under their weight the best lifted equilibrium found is {gap:.3g} N mm "
                "above the resting one."
            )
    else:
        text += "."
    return text


def _admissibility_lines(floor: PublishedSweep, free: PublishedSweep) -> list[str]:
    """The section's statement on physical states: how many values of each sweep are
    certified stable with no filaments interpenetrating, and which are NOT PHYSICAL."""
    out = []
    for name, sweep in (("on the floor", floor), ("weightless", free)):
        bad = _bad_values(sweep)
        if not bad:
            out.append(
                f"- **Physical states ({name})**: all {len(sweep.stretch)} values certified "
                "stable, with no two filament segments interpenetrating "
                "(`rotomorph.lattice.admissibility`)."
            )
            continue
        listed = ", ".join(
            f"{sweep.stretch[k]:+.2f} ({not_physical(sweep, k)})" for k in bad[:8]
        ) + (" …" if len(bad) > 8 else "")
        out.append(
            f"- **NOT PHYSICAL ({name})**: {len(bad)} of {len(sweep.stretch)} values are not "
            f"certified stable or have filaments interpenetrating: {listed}. Their rows in "
            "`published_fig4_sweep.json` say `physical: false`; the figure marks them (x)."
        )
    return [*out, ""]


def published_section(folder: Path, figs: Path | None, *, quick: bool) -> PublishedSection:
    """Sweep the authors' set-up both ways, write the figures and the JSON record, and return
    the section's Markdown (module docstring)."""
    floor, free = report_sweeps(quick=quick)
    paths: list[Path] = []
    if figs is not None:
        from rotomorph.plot.figure import save_figure

        paths.append(save_figure(sweep_figure(floor, free), figs / "published_fig4_sweep.png"))
        paths.append(save_figure(shapes_figure(floor), figs / "published_fig4_shapes.png"))
    record = {
        "source": "github.com/yeonsu-jung/shape-morphing-network (MIT), the disMech example "
        "of the paper's Fig. 4; set-up: rotomorph.lattice.published",
        "sweep_cpu_s": {"on_floor": floor.cpu_time, "weightless": free.cpu_time},
        "authors_logged_run_s": LOGGED_RUN_SECONDS,
        "rows": records(floor, "on_floor") + records(free, "weightless"),
    }
    atomic_write_text(folder / "published_fig4_sweep.json", json.dumps(record, indent=1))
    n = len(floor.stretch)
    runs = 150  # their run.py: np.arange(-0.75, 0.75, 0.01)
    cpu_lo, cpu_hi = (c * AUTHORS_TIME_STEPS / 3600.0 for c in AUTHORS_STEP_CPU)
    poor = floor.stretch[floor.fit_residual > POOR_FIT]
    lines = [
        "## The authors' own simulation of Fig. 4 (disMech), rebuilt",
        "",
        "The paper's Fig. 4 lattices were computed with disMech; the authors' example is public "
        "(github.com/yeonsu-jung/shape-morphing-network, MIT). Rebuilt here from their files "
        "(`rotomorph.lattice.published`): a 5 × 5-node lattice of one-period sine edges, "
        "amplitude a quarter of the cell, 10 nodes per edge, offset along each edge's "
        "right-hand normal as they wrote it; natural curvature × (1 − stretch) on their 12 "
        'central "expand" edges and × (1 + stretch) on their 26 "shrink" edges; '
        f"**their limbs {UNLISTED_LIMBS[0]} and {UNLISTED_LIMBS[1]} are in neither list**, so "
        "they are never actuated (reproduced, not corrected: the lattice is not symmetric "
        "under its quarter turns). Parameters of their *logged* run (first commit of the "
        "repository: stretch −0.17): E = 2e11 Pa, ρ = 1000 kg/m³, r = 1 mm on 1 m cells, "
        f"g = 0.5 m/s², floor friction 0.4: weight over bending w l³/B = {weight_ratio():.2g}. "
        "The repository's current yml (E = 1e6 Pa, no friction, stretch 0.1) was never "
        f"logged; with it w l³/B = {weight_ratio(youngs_modulus=1.0):.0f}: the weight "
        "would dominate.",
        "",
        "rotomorph runs their recipe as its curvature-rescaling actuation (the `swapped` "
        "reading, x = stretch) with those two limbs left out, as **static equilibria** "
        "(certified stable) by continuation 0 → −0.75 and 0 → +0.75 in steps of 0.01, each "
        "value from its neighbour nearer zero; they integrate damped dynamics for 10 s from "
        "the flat print for every value, kicked by ±10 m/s on chosen edges. Symmetry is broken "
        "here by a 1 mm bump and the lift probe, which looks for a lifted equilibrium of lower "
        "total energy wherever the lattice rests flat; filaments also touch each other here "
        "(their run has no filament contact). Where the two differ and why: "
        "`docs/published-simulation.md`.",
        "",
        f"- **On their floor, with their weight and friction** ({n} values): first saddle at "
        f"stretch {_onset(floor, -1)}, first dome at {_onset(floor, +1)}; √|k1 k2|·l "
        f"{_range(floor.characteristic_curvature[floor.gaussian_sign == -1] * SPACING)} "
        "(saddles), "
        f"{_range(floor.characteristic_curvature[floor.gaussian_sign == 1] * SPACING)} "
        "(domes).",
        f"- **Weightless and free** (no floor): first saddle at {_onset(free, -1)}, first dome "
        f"at {_onset(free, +1)}. Their weight (w l³/B = {weight_ratio():.2g}) looks "
        "negligible but delays the lift-off past the buckling: lifting the lattice costs "
        "weight × height to first order, while the bending energy a just-buckled lattice "
        "releases is of second order in its rise.",
        f"- **Their logged run's stretch (−0.17)**: {_logged(floor, free)} Their run ends "
        "flat too: its last 61 log lines (t = 9.4–10 s) report all 345 nodes within the floor's "
        "contact distance.",
        "- **Shape quality**: the quadratic surface describes the branch nodes to within 10 % of "
        "the rise only for moderate stretches"
        + (
            f"; its residual exceeds 10 % at {len(poor)} values (|stretch| ≥ "
            f"{float(np.abs(poor).min()):.2f}; hollow markers), where edges fold and crumple and "
            "√|k1 k2| is a fit to a shape it does not describe."
            if len(poor)
            else "."
        ),
        f"- **Cost**: the whole {n}-value sweep on the floor took {floor.cpu_time:.0f} s of "
        f"CPU here (weightless: {free.cpu_time:.0f} s). The authors' logged run of one value "
        f"took {LOGGED_RUN_SECONDS / 60:.1f} min (real 11 min 46 s, one core), so their "
        f"{runs}-run sweep (run.py) is ~{runs * LOGGED_RUN_SECONDS / 3600:.0f} CPU-hours at "
        "that rate; their example built on this class of machine was measured at 12–14 ms of "
        f"CPU per time step, which makes the 10 s protocol {cpu_lo:.1f}–{cpu_hi:.1f} h of CPU "
        f"per value (~{runs * cpu_lo:.0f}–{runs * cpu_hi:.0f} CPU-hours for the sweep).",
        "",
    ]
    lines += _admissibility_lines(floor, free)
    for p in paths:
        lines += [f"![{p.stem}](figures/{p.name})", ""]
    return PublishedSection(lines=lines, figures=paths, on_floor=floor, weightless=free)

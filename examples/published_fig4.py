"""The authors' own Fig. 4 simulation, rebuilt
============================================

The paper's dome and saddle lattices (Fig. 4) were computed with disMech, and the authors
published that set-up (``github.com/yeonsu-jung/shape-morphing-network``, MIT licence). This
example runs their stretch sweep with rotomorph on their set-up, rebuilt number by number in
:mod:`rotomorph.lattice.published`:

* their 5 × 5-node lattice of one-period sine edges (amplitude a quarter of the 1 m cell, 10
  nodes per edge, r = 1 mm), their limb numbering;
* their controller: natural curvature × (1 − stretch) on the 12 central "expand" edges,
  × (1 + stretch) on the 26 "shrink" edges, and limbs 29 and 30, which their lists leave out,
  never actuated (as written);
* the parameters of their logged run: E = 2e11 Pa, floor friction 0.4, their weight
  (g = 0.5 m/s², ρ = 1000 kg/m³: w l³/B = 0.01);
* the stretch range −0.75 … +0.75 by 0.01, by continuation from the flat print both ways.

rotomorph computes static equilibria (each value from its neighbour nearer zero) where the
authors integrate damped dynamics from the flat print for every value; ``docs/published-
simulation.md`` discusses the differences. The same sweep without floor and weight shows how
much their small weight delays the lift-off.

Prints one JSON object per stretch value and sweep (``case``, ``stretch``,
``characteristic_curvature`` (1/mm) and ``characteristic_curvature_times_l``,
``gaussian_sign``, ``fit_residual_over_rise``, ``floor_lift_mm``, ``stable``,
``stack_overlaps``, ``physical`` and ``physical_reason`` (NOT PHYSICAL: not certified stable
or filaments interpenetrating), ``wall_s``) and a
``case = "total"`` line with the CPU time of each sweep next to the authors' 11 min 46 s per
value; writes ``OUT/published_fig4_sweep.png`` (``√|k₁k₂|`` and sign against stretch) and
``OUT/published_fig4_shapes.png`` (domes and saddles).

Run: ``python examples/published_fig4.py -o published_out`` (the full sweep, about two
minutes of CPU on the floor); ``--quick``: 11 values, stretch magnitude ≤ 0.25 by 0.05.

The documentation build does not run this sweep (about 25 s of CPU even with ``--quick``): the
figures below are the stored result of the full sweep, made by the command above.

.. image:: /gallery/published_fig4_sweep.png
   :alt: the characteristic curvature times l against stretch, on the floor and weightless

.. image:: /gallery/published_fig4_shapes.png
   :alt: the dome and the saddle of the sweep
"""

# sphinx_gallery_thumbnail_path = "gallery/published_fig4_sweep.png"

from __future__ import annotations

import argparse
import json
from pathlib import Path

from rotomorph.lattice.published import LOGGED_RUN_SECONDS, published_sweep
from rotomorph.plot.figure import save_figure
from rotomorph.simulate.report_published import records, shapes_figure, sweep_figure


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=(__doc__ or "").strip().partition("\n")[0])
    parser.add_argument("-o", "--out", type=Path, default=Path("published_out"))
    parser.add_argument("--quick", action="store_true", help="11 values, |stretch| <= 0.25")
    args = parser.parse_args(argv)
    step, end = (0.05, 0.25) if args.quick else (0.01, 0.75)
    args.out.mkdir(parents=True, exist_ok=True)
    on_floor = published_sweep(step, end)
    weightless = published_sweep(step, end, floor=False, friction=0.0, acceleration=0.0)
    for row in records(on_floor, "on_floor") + records(weightless, "weightless"):
        print(json.dumps(row))
    print(
        json.dumps(
            {
                "case": "total",
                "values": len(on_floor.stretch),
                "cpu_s_on_floor": round(on_floor.cpu_time, 2),
                "cpu_s_weightless": round(weightless.cpu_time, 2),
                "authors_run_s": LOGGED_RUN_SECONDS,
                "first_saddle": on_floor.first(-1),
                "first_dome": on_floor.first(+1),
                "first_saddle_weightless": weightless.first(-1),
                "first_dome_weightless": weightless.first(+1),
            }
        )
    )
    shown = (0.25,) if args.quick else (0.3, 0.75)
    save_figure(sweep_figure(on_floor, weightless), args.out / "published_fig4_sweep.png")
    save_figure(shapes_figure(on_floor, shown), args.out / "published_fig4_shapes.png")
    return 0


if __name__ == "__main__":
    main()  # always 0; not SystemExit, which would end a documentation build running it

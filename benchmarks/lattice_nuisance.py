"""Lattice nuisance propagation: the report's lattices over a Latin hypercube of the priors of
the inputs the paper does not give (JSON lines on stdout).

For each pattern (expanding, contracting, dome, saddle) every sample of
``rotomorph.simulate.nuisance.latin_hypercube(count, seed=1)`` fixes the cell size and
amplitude, the in-plane filament width, T_NI and the densities
(``rotomorph.simulate.nuisance_lattices``); its 5 x 5 lattice is ramped 25 -> 175 °C in 8
steps at 10 ghost nodes per edge through the full calibration's model, with self-contact and
the bath floor under the sample's buoyant weight (the report's counted ramp at its coarser
resolution, without the path check).

One line per sample: ``{"case": "sample", "pattern", "sample": {...}, "area_ratio",
"gaussian_sign", "cpu_s"}``; then per pattern ``{"case": "pattern", "pattern",
"sd_nuisance_area", "area_range", "sign_agreement", "samples", "cpu_s"}``; with
``--calibration`` also the area's calibration sd and its prior-held part by one-sided secants
of the same ramp at the priors' centres (``{"case": "calibration", ...}``); with
``--lift-off`` the dome's and saddle's lift-off and weightless buckling bisected to 0.5 °C at
the filament-density prior's two ends, the weight's delay as a function of ρ − ρ_bath
(``{"case": "lift-off", "pattern", "delays": [...]}``). ``cpu_s`` is this
process's CPU time (the cost on one core, whatever the load). The ramps are cached on disk
(``ROTOMORPH_CACHE_DIR``), so a second run prints the same numbers at once.

Run: ``python benchmarks/lattice_nuisance.py [--count N] [--calibration] [--lift-off]
[PATTERN ...]``
(default 8 samples, all four patterns).
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np

from rotomorph.materials.calibrate import paper_calibration
from rotomorph.simulate.nuisance import latin_hypercube
from rotomorph.simulate.nuisance_lattices import (
    LATTICE_SAMPLES,
    LATTICE_SEED,
    area_band,
    heat_sample,
    lift_off_delays,
    spread,
)
from rotomorph.simulate.validation import at_resolution

N, GHOSTS, STEPS = 5, 10, 8


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "patterns", nargs="*", default=["expanding", "contracting", "dome", "saddle"]
    )
    parser.add_argument("--count", type=int, default=LATTICE_SAMPLES)
    parser.add_argument("--calibration", action="store_true")
    parser.add_argument("--lift-off", action="store_true")
    args = parser.parse_args()
    fit = paper_calibration().chosen
    model = at_resolution(fit.model)
    heat_sample("expanding", 2, 2, 1, model)  # compile kernels first
    for pattern in args.patterns:
        t_pattern = time.process_time()
        areas, signs = [], []
        for sample in latin_hypercube(args.count, seed=LATTICE_SEED):
            t0 = time.process_time()
            _, res, why = heat_sample(pattern, N, GHOSTS, STEPS, model, sample, contact=True)
            area = None if res is None else float(res.final_area_ratio)
            sign = None if res is None else float(res.gaussian_sign[-1])
            areas.append(area)
            signs.append(sign)
            line = {
                "case": "sample",
                "pattern": pattern,
                "sample": sample.record(),
                "area_ratio": area,
                "gaussian_sign": sign,
                "failed": why or None,
                "cpu_s": round(time.process_time() - t0, 2),
            }
            print(json.dumps(line), flush=True)
        _, nominal, _ = heat_sample(pattern, N, GHOSTS, STEPS, model, contact=True)
        finite = [a for a in areas if a is not None]
        got = [s for s in signs if s is not None]
        nominal_sign = None if nominal is None else np.sign(nominal.gaussian_sign[-1])
        summary = {
            "case": "pattern",
            "pattern": pattern,
            "nominal_area_ratio": None if nominal is None else float(nominal.final_area_ratio),
            "sd_nuisance_area": spread(areas),
            "area_range": [min(finite), max(finite)] if finite else None,
            "sign_agreement": None
            if nominal_sign is None or not got
            else float(np.mean([np.sign(s) == nominal_sign for s in got])),
            "samples": len(areas),
            "failed": sum(a is None for a in areas),
            "cpu_s": round(time.process_time() - t_pattern, 2),
        }
        print(json.dumps(summary), flush=True)
        if args.calibration:
            t0 = time.process_time()
            cal, prior, _, _ = area_band(
                fit, pattern, N, GHOSTS, STEPS, model, contact=True, count=args.count
            )
            line = {
                "case": "calibration",
                "pattern": pattern,
                "sd_calibration_area": cal,
                "sd_calibration_prior_area": prior,
                "cpu_s": round(time.process_time() - t0, 2),
            }
            print(json.dumps(line), flush=True)
        if args.lift_off and pattern in ("dome", "saddle"):
            t0 = time.process_time()
            delays = lift_off_delays(pattern, N, GHOSTS, STEPS, model, tolerance=0.5)
            line = {
                "case": "lift-off",
                "pattern": pattern,
                "delays": delays,
                "cpu_s": round(time.process_time() - t0, 2),
            }
            print(json.dumps(line), flush=True)


if __name__ == "__main__":
    main()

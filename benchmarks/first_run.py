"""Benchmark: the first run of ``rotomorph paper`` (numba cache cold) and the second (warm).

The package source is copied into a temporary folder without any ``__pycache__`` (so numba
has no cached machine code), then ``python -m rotomorph paper`` runs twice from that copy, with
the report's result cache (``ROTOMORPH_CACHE_DIR``) in a fresh folder of its own, as for a new
user (the shared ``~/.cache/rotomorph`` would serve results other runs of the same source
computed):

* ``paper-cold``: the first run compiles every kernel (``cache=True`` writes the cache) and
  computes every result;
* ``paper-warm``: the second run loads the kernels from the cache (and the results the first run
  stored, as a user's second run does).

Prints one JSON object per line: ``{"case": "paper-cold", "wall_s": …, "cpu_s": …}``, the same
for ``paper-warm``, and ``{"case": "compile", …}`` with the difference and its share of the cold
run. With ``--split`` a third run, ``paper-compute``, has the kernels cached but no stored
results (the computation alone), and ``compile`` is cold minus compute (the compile cost);
without it, cold minus warm (compile plus the results the warm run reads back). ``cpu_s``
(user + system time of the child) is the robust number on a shared machine; ``wall_s`` is
what a user waits.

Run: ``python benchmarks/first_run.py [--quick] [--split]`` from the repository root
(``--quick`` passes ``--quick`` to ``rotomorph paper``: coarse, for a fast check).

Measured on the 2-core machine shared with other work (CPU seconds are the robust figure; wall
seconds at the load average given):

=====================================  ===============  ==================  =================
run                                    cold CPU (wall)  warm CPU (wall)     compile, in-process
=====================================  ===============  ==================  =================
``paper --quick``, before this round   ≈ 48 s           –                   77 % of cold
``paper --quick``                      34-39 s (40 s,   9.8-10.6 s (10 s,   16-21 s, 47 kernels
                                       load 2)          load 2)             (96 before)
``paper`` (full)                       128 s (247 s,    11.8 s (18 s,       ≈ 33 s
                                       load 3.3)        load 3.4)
=====================================  ===============  ==================  =================

The floor, and why a cold full report cannot take 30 s on this machine: with every kernel
cached but no stored results the full report still needs **95 s CPU** of computation (its
lattice rows solve heating ramps with contact at two resolutions; ``_lattice_section`` is 90 %
of it), one process, so no compile saving brings it near 30 s. The warm run (≤ 15 s CPU) reads
those results from the result cache. What is still compiled, every piece used by the report:

* the rod energy, gradient and Hessian (``evaluate_network`` with ``assemble``,
  ``bend_twist_stencil``, ``stretch_edge``, frames): 8-10 s, every Newton solve needs it;
  inlining ``assemble`` (numba ``inline="always"``) did not change it (10.8 -> 10.3 s, noise);
* sparse Cholesky (elimination tree, column counts, numeric factor, solve): 2.7-3.7 s, every
  lattice solve;
* the edge-rotation retraction and rigid-motion removal: 1.9-2.9 s, every line search;
* reference twist 1-1.5 s, free-filament shapes 1-1.5 s (the filament rows); a filament
  Newton solve adds the banded Cholesky and its tree search (≈ 4 s) where one runs;
* contact (broad phase, barrier, CCD, distances): ≈ 15 s (was 35 s), only the full report's
  contact-resolved lattice rows.

Removed: shape-checked array expressions in the free-filament builder, the contact PSD
projection and the broad-phase buffer (each made numba compile its formatted-error machinery,
5-10 s), literal-valued helper specialisations (13 -> 5 stencil helpers; one
``segment_distance2`` and ``_grow`` instead of two) and the second ``reference_twist`` and
``pair_distances`` types (non-contiguous and read-only arrays).
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src"


def _run(src: Path, out: Path, quick: bool, results: str) -> tuple[float, float, int]:
    env = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_CACHE")}
    env["PYTHONPATH"] = str(src)
    env["ROTOMORPH_CACHE_DIR"] = str(src.parent / results)
    cmd = [sys.executable, "-m", "rotomorph", "paper", "-o", str(out)]
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    proc = subprocess.run(
        cmd + (["--quick"] if quick else []), env=env, capture_output=True, text=True
    )
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    if proc.returncode not in (0, 1):  # 1: a row not converged between resolutions (reported)
        sys.stderr.write(proc.stderr)
        raise SystemExit(f"rotomorph paper failed with exit status {proc.returncode}")
    return wall, cpu, proc.returncode


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="rotomorph paper --quick")
    parser.add_argument(
        "--split",
        action="store_true",
        help="also run with the kernels cached but no stored results (paper-compute), so that "
        "compile = cold - compute",
    )
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="rotomorph-first-run-") as tmp:
        src = Path(tmp) / "src"
        shutil.copytree(SRC, src, ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
        results = {}
        cases = ["paper-cold", "paper-warm"] + (["paper-compute"] if args.split else [])
        for case in cases:
            store = "results-compute" if case == "paper-compute" else "results-cache"
            wall, cpu, code = _run(src, Path(tmp) / case, args.quick, store)
            results[case] = (wall, cpu)
            row = {
                "case": case,
                "wall_s": round(wall, 2),
                "cpu_s": round(cpu, 2),
                "quick": args.quick,
                "exit_status": code,
                "cpus": os.cpu_count(),
                "load_1min": round(os.getloadavg()[0], 2),
            }
            print(json.dumps(row), flush=True)
    (cold_wall, cold_cpu) = results["paper-cold"]
    base = "paper-compute" if args.split else "paper-warm"
    (base_wall, base_cpu) = results[base]
    print(
        json.dumps(
            {
                "case": "compile",
                "minus": base,  # paper-warm also reads the results the cold run stored
                "wall_s": round(cold_wall - base_wall, 2),
                "cpu_s": round(cold_cpu - base_cpu, 2),
                "share_of_cold_cpu": round((cold_cpu - base_cpu) / cold_cpu, 3),
                "quick": args.quick,
            }
        )
    )


if __name__ == "__main__":
    main()

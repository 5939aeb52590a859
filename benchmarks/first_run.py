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
for ``paper-warm``, and ``{"case": "compile", …}`` with the difference (the compile cost) and
its share of the cold run. ``cpu_s`` (user + system time of the child) is the robust number on
a shared machine; ``wall_s`` is what a user waits.

Run: ``python benchmarks/first_run.py [--quick]`` from the repository root (``--quick`` passes
``--quick`` to ``rotomorph paper``: coarse, for a fast check).
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


def _run(src: Path, out: Path, quick: bool) -> tuple[float, float, int]:
    env = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_CACHE")}
    env["PYTHONPATH"] = str(src)
    env["ROTOMORPH_CACHE_DIR"] = str(src.parent / "results-cache")
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
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="rotomorph-first-run-") as tmp:
        src = Path(tmp) / "src"
        shutil.copytree(SRC, src, ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
        results = {}
        for case in ("paper-cold", "paper-warm"):
            wall, cpu, code = _run(src, Path(tmp) / case, args.quick)
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
    (cold_wall, cold_cpu), (warm_wall, warm_cpu) = results["paper-cold"], results["paper-warm"]
    print(
        json.dumps(
            {
                "case": "compile",
                "wall_s": round(cold_wall - warm_wall, 2),
                "cpu_s": round(cold_cpu - warm_cpu, 2),
                "share_of_cold_cpu": round((cold_cpu - warm_cpu) / cold_cpu, 3),
                "quick": args.quick,
            }
        )
    )


if __name__ == "__main__":
    main()

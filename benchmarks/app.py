"""Benchmark: how quickly ``rotomorph serve`` answers, measured in Debian's headless Chromium.

Starts ``rotomorph serve`` on a free port, opens it in Chromium through Playwright (as the
browser test does) and prints one JSON object per line:

* ``{"case": "page_weight", "bytes": …, "requests": …}``: everything the first load of the
  page transfers (scripts, styles, layout, the first callbacks' answers);
* ``{"case": "edit_to_prediction", "design": …, "median_ms": …, "max_ms": …, "n": …,
  "target_ms": 200}``: from typing a new value into a field (a filament's speed, then a
  lattice's amplitude) to the closed-form prediction shown for it;
* ``{"case": "simulate_to_first_step", "design": "lattice_dome" (5 × 5), "wall_s": …,
  "target_s": 2}``: from the "simulate" click to the first converged step of the ramp shown,
  with the session's worker warm (kernels compiled and loaded: a first, untimed run first).

Wall-clock times include the browser and the server on the same machine; on a shared machine
repeat and take the smaller figures (``--repeat``). Needs the ``app`` and ``test`` extras and
``chromium`` (``apt-get install chromium``).

Run: ``python benchmarks/app.py [--repeat N]`` from the repository root.

Measured (2-core machine shared with other work, load average 3-7, Dash 4.4, Chromium 143):
see docs/app.md.
"""

from __future__ import annotations

import argparse
import json
import re
import shutil
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
ARGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]


def _prediction(pg) -> str:
    return pg.inner_text("#prediction")


def _edit_times(pg, path: str, values: list[str]) -> list[float]:
    box = pg.locator(f'[id*="{path}"][id*="field"]')
    out = []
    for value in values:
        before = _prediction(pg)
        t0 = time.perf_counter()
        box.fill(value)
        pg.wait_for_function(
            "(p) => document.querySelector('#prediction').innerText != p", arg=before
        )
        out.append(1000 * (time.perf_counter() - t0))
    return out


def _open(pg, name: str) -> None:
    pg.click("#example")
    pg.click(f"text={name}")
    pg.wait_for_function(f"document.querySelector('#prediction').innerText.includes(\"'{name}'\")")


def _simulate(pg, steps: str) -> float:
    pg.fill("#steps", steps)
    t0 = time.perf_counter()
    pg.click("#simulate")
    pg.wait_for_function(  # this run's (the click clears the last run's status and bar)
        "!document.querySelector('#job-status').innerText.startsWith('done') && "
        "Number(document.querySelector('#progress').getAttribute('value')) >= 2",
        timeout=300_000,
    )
    first = time.perf_counter() - t0
    pg.wait_for_function(
        "document.querySelector('#job-status').innerText.match(/^(done|failed)/)",
        timeout=600_000,
    )
    return first


def main() -> None:
    from playwright.sync_api import sync_playwright

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    chromium = shutil.which("chromium")
    if chromium is None:
        sys.exit("benchmarks/app.py: needs chromium (apt-get install chromium)")
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "rotomorph",
            "serve",
            "--no-open",
            "--port",
            "0",
            "--examples",
            str(ROOT / "examples"),
        ],
        stderr=subprocess.PIPE,
        text=True,
    )
    assert proc.stderr is not None
    url = re.search(r"(http://\S+/)", proc.stderr.readline())
    assert url, "no URL from rotomorph serve"
    try:
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path=chromium, args=ARGS)
            pg = browser.new_page(viewport={"width": 1500, "height": 1000})
            sizes: list[int] = []
            pg.on("requestfinished", lambda r: sizes.append(r.sizes()["responseBodySize"]))
            pg.goto(url.group(1), wait_until="networkidle")
            pg.wait_for_selector(".prediction-line", timeout=60_000)
            pg.wait_for_load_state("networkidle")
            print(json.dumps({"case": "page_weight", "bytes": sum(sizes), "requests": len(sizes)}))
            values = [f"{v:.2f}" for v in (2.0, 2.5, 3.0, 3.5, 4.0, 4.5, 5.0, 5.5)]
            for design, path in (
                ("composite_rotation", "filaments[0].speed"),
                ("lattice_dome", "lattice.amplitude"),
            ):
                _open(pg, design)
                times = []
                for _ in range(args.repeat):
                    vals = (
                        values
                        if path.endswith("speed")
                        else [f"{1 + 0.05 * i:.2f}" for i in range(8)]
                    )
                    times += _edit_times(pg, path, vals)
                print(
                    json.dumps(
                        {
                            "case": "edit_to_prediction",
                            "design": design,
                            "field": path,
                            "median_ms": round(statistics.median(times), 1),
                            "max_ms": round(max(times), 1),
                            "n": len(times),
                            "target_ms": 200,
                        }
                    )
                )
            _open(pg, "lattice_dome")
            _simulate(pg, "1")  # the worker warm: kernels compiled and loaded
            firsts = [_simulate(pg, "8") for _ in range(args.repeat)]
            print(
                json.dumps(
                    {
                        "case": "simulate_to_first_step",
                        "design": "lattice_dome",
                        "lattice": "5x5",
                        "wall_s": round(min(firsts), 3),
                        "all_s": [round(f, 3) for f in firsts],
                        "target_s": 2,
                    }
                )
            )
            browser.close()
    finally:
        proc.terminate()
        proc.wait(timeout=30)


if __name__ == "__main__":
    main()

"""Benchmark: how quickly ``rotomorph serve`` answers, measured in Debian's headless Chromium.

Starts ``rotomorph serve`` on a free port, opens it in Chromium through Playwright (as the
browser test does) and prints one JSON object per line:

* ``{"case": "page_weight", "bytes": …, "requests": …}``: everything the first load of the
  page transfers (scripts, styles, layout, the first callbacks' answers);
* ``{"case": "edit_to_prediction", "design": …, "median_ms": …, "max_ms": …, "n": …,
  "target_ms": 200, "band_median_ms": …}``: from typing a new value into a field (a
  filament's speed, then a lattice's amplitude) to the closed-form nominal prediction shown
  for it (one request), and to its calibration band shown (asked once the field has stood
  still for 300 ms);
* ``{"case": "simulate_to_first_step", "design": "lattice_dome" (5 × 5), "wall_s": …,
  "target_s": 2}``: from the "simulate" click to the first converged step of the ramp shown,
  with the session's worker warm (it imports the solver and runs a tiny filament and a 3 × 3
  lattice with contact when it starts, which compiles or loads the kernels); each timed run
  is cancelled after its first step and the fresh worker given time to warm up;
* ``{"case": "edit_server_cpu", "design": …, "check_ms", "nominal_ms", "plan_ms",
  "band_ms"}``: the server's CPU (``time.process_time``, in-process) for an edit's one
  request (validation, nominal prediction, the lattice's plan) and the band's request after.

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


def _edit_times(pg, path: str, values: list[str]) -> tuple[list[float], list[float]]:
    """Per typed value: ms to its nominal prediction shown, and ms to its band shown."""
    box = pg.locator(f'[id*="{path}"][id*="field"]')
    nominal, band = [], []
    for value in values:
        before = _prediction(pg)
        sent = len(REQUESTS)
        t0 = time.perf_counter()
        box.fill(value)
        pg.wait_for_function(
            "(p) => document.querySelector('#prediction').innerText != p", arg=before
        )
        nominal.append(1000 * (time.perf_counter() - t0))
        if len(REQUESTS) > sent:
            EDITS.append(REQUESTS[sent])
        pg.wait_for_function(
            "document.querySelector('#prediction').innerText.includes('± calibration band')",
            timeout=60_000,
        )
        band.append(1000 * (time.perf_counter() - t0))
    return nominal, band


#: ms from sent to the answer's end, per callback request (see ``_answered``)
REQUESTS: list[float] = []
#: the same for each edit's one request
EDITS: list[float] = []


def _answered(request, out: list[float]) -> None:
    if request.method == "POST" and "_dash-update-component" in request.url:
        t = request.timing
        out.append(t["responseEnd"] - t["requestStart"])


def _server_cpu(repeat: int) -> None:
    """The server's CPU for one edit, in-process: validation, nominal prediction, plan; and
    the band that follows (``time.process_time``, after one untimed round)."""
    from rotomorph.app import editing, views
    from rotomorph.io.tomlfile import decode_toml_bytes
    from rotomorph.prediction.band import nominal_only
    from rotomorph.prediction.design import predict_design

    for name in ("composite_rotation", "lattice_dome"):
        path = ROOT / "examples" / "designs" / f"{name}.toml"
        data = decode_toml_bytes(path.read_bytes(), path.name)
        parts: dict[str, list[float]] = {"check": [], "nominal": [], "plan": [], "band": []}
        for k in range(repeat + 1):
            t0 = time.process_time()
            design, _ = editing.check(data)
            t1 = time.process_time()
            with nominal_only():
                predict_design(design)
            t2 = time.process_time()
            if design.lattice is not None:
                views.lattice_plan(design, editing.edge_modes(design.lattice), None)
            t3 = time.process_time()
            predict_design(design)
            t4 = time.process_time()
            if k:
                for key, dt in zip(parts, (t1 - t0, t2 - t1, t3 - t2, t4 - t3), strict=True):
                    parts[key].append(1000 * dt)
        print(
            json.dumps(
                {
                    "case": "edit_server_cpu",
                    "design": name,
                    **{f"{k}_ms": round(statistics.median(v), 1) for k, v in parts.items()},
                    "n": repeat,
                }
            )
        )


def _open(pg, name: str) -> None:
    pg.click("#example")
    pg.click(f"text={name}")
    pg.wait_for_function(f"document.querySelector('#prediction').innerText.includes(\"'{name}'\")")


def _first_step(pg, steps: str) -> float:
    """s from the "simulate" click to the first converged step shown; the run then cancelled
    and the fresh worker it leaves given time to warm up (as it does when the page opens)."""
    pg.fill("#steps", steps)
    t0 = time.perf_counter()
    pg.click("#simulate")
    pg.wait_for_function(
        "!document.querySelector('#job-status').innerText.startsWith('cancelled') && "
        "Number(document.querySelector('#progress').getAttribute('value')) >= 2",
        timeout=300_000,
    )
    first = time.perf_counter() - t0
    pg.click("#cancel")
    time.sleep(WARM_S)
    return first


#: s a fresh worker is given to import and warm up before it is timed (it warms while the
#: person designs; about 7 s on an idle core)
WARM_S = 25.0


def main() -> None:
    from playwright.sync_api import sync_playwright

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=2)
    parser.add_argument("--no-simulate", action="store_true", help="skip the simulate case")
    parser.add_argument("--no-edits", action="store_true", help="skip the edit cases")
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

            def weigh(r) -> None:
                sizes.append(r.sizes()["responseBodySize"])

            pg.on("requestfinished", weigh)
            pg.goto(url.group(1), wait_until="networkidle")
            pg.wait_for_selector(".prediction-line", timeout=60_000)
            pg.wait_for_load_state("networkidle")
            pg.remove_listener("requestfinished", weigh)
            print(json.dumps({"case": "page_weight", "bytes": sum(sizes), "requests": len(sizes)}))
            # each callback request's time from sent to answered (the server's share of an
            # edit's wall time; the rest is the browser's)
            pg.on("requestfinished", lambda r: _answered(r, REQUESTS))
            time.sleep(WARM_S)  # the session's worker warms up as the person starts designing
            values = [f"{v:.2f}" for v in (2.0, 2.5, 3.0, 3.5, 4.0, 4.5, 5.0, 5.5)]
            edits = (
                ("composite_rotation", "filaments[0].speed"),
                ("lattice_dome", "lattice.amplitude"),
            )
            for design, path in () if args.no_edits else edits:
                _open(pg, design)
                times, bands = [], []
                EDITS.clear()
                for _ in range(args.repeat):
                    vals = (
                        values
                        if path.endswith("speed")
                        else [f"{1 + 0.05 * i:.2f}" for i in range(8)]
                    )
                    got = _edit_times(pg, path, vals)
                    times += got[0]
                    bands += got[1]
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
                            "band_median_ms": round(statistics.median(bands), 1),
                            "request_median_ms": round(statistics.median(EDITS), 1)
                            if EDITS
                            else None,
                        }
                    )
                )
            _open(pg, "lattice_dome")
            firsts = [] if args.no_simulate else [_first_step(pg, "8") for _ in range(args.repeat)]
            if firsts:
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
        _server_cpu(args.repeat)
    finally:
        proc.terminate()
        proc.wait(timeout=30)


if __name__ == "__main__":
    main()

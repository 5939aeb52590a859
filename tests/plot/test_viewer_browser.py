"""Referee: a real browser (Debian's headless Chromium, driven by Playwright) opens a
``view.html`` built from a design whose every text field holds markup, and nothing of it renders
as markup: no link, no styled or bold text, no injected element, no script; the text shows
literally, character for character.

plotly.js interprets a subset of HTML in every text it draws (``<a href>``, ``<span style>``,
``<b>``, ``<br>``, entities), so this can only be decided by running plotly.js in a browser.
"""

from __future__ import annotations

import json
from pathlib import Path

import h5py
import pytest
import tomli_w

from rotomorph.cli import EXIT_OK, main

pytestmark = pytest.mark.referee

#: Launch flags for Debian's Chromium in a container (no sandbox, no GPU, no network chatter).
CHROMIUM_ARGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]

LINK = "<a href='https://evil.example/login'>verify your account</a>"
STYLE = (
    "<span style='position:fixed;top:0;left:0;font-size:90px;color:lime'>ALL CHECKS PASSED</span>"
)
BOLD = "<b>bold</b><i>it</i><br>line<sup>2</sup>"
SCRIPT = "<img src=x onerror=alert(1)><script>alert(2)</script>"
ENTITY = "&lt;b&gt;not bold&lt;/b&gt; &amp; &#60;"
UNIT = "<a href='https://evil.example'>1/mm</a>"
PAYLOADS = {"design": LINK + " " + STYLE, "f0": BOLD + " " + ENTITY, "f1": SCRIPT + " " + LINK}


def _design(tmp_path: Path) -> Path:
    def filament(name: str, y: float) -> dict:
        return {
            "name": name,
            "rotation_number": 0.25,
            "spacing": 0.5,
            "start": [0.0, y, 0.0],
            "segments": [{"kind": "line", "length": 8.0}],
        }

    doc = {
        "schema_version": 1,
        "name": PAYLOADS["design"],
        "description": STYLE + "\n" + LINK,
        "filaments": [filament(PAYLOADS["f0"], 0.0), filament(PAYLOADS["f1"], 6.0)],
    }
    path = tmp_path / "markup.toml"
    path.write_text(tomli_w.dumps(doc), encoding="utf-8")
    return path


def _tamper_field_names(run: Path) -> str:
    """Give the stored ``curvature`` field a markup name and unit (what a tampered or foreign
    results file may hold; an HDF5 name cannot hold '/'); returns the new name."""
    name = "<span style='font-size:90px;color:lime'>kappa<b>bold"
    with h5py.File(run / "results.h5", "r+") as h5:
        fields = h5["steps/fields"]
        fields.move("curvature", name)
        fields[name].attrs["units"] = UNIT
    return name


def _open(html: Path, chromium: str) -> dict:
    """Open ``html`` in headless Chromium (the executable ``chromium``); return what the
    rendered page holds."""
    from playwright.sync_api import sync_playwright

    dialogs: list[str] = []
    with sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=chromium, args=CHROMIUM_ARGS)
        try:
            page = browser.new_page()
            page.on("dialog", lambda d: (dialogs.append(d.message), d.dismiss()))
            page.goto(html.resolve().as_uri())
            page.wait_for_selector(".main-svg text", timeout=30_000)
            page.wait_for_timeout(500)
            found = page.evaluate(
                """() => ({
                anchors: [...document.querySelectorAll('a')].map(a => a.outerHTML),
                styled: [...document.querySelectorAll('svg tspan[style]')]
                    .map(t => t.getAttribute('style')),
                bold: [...document.querySelectorAll('svg tspan, svg text')]
                    .filter(t => /bold|italic/.test(t.getAttribute('style') || '')).length,
                lines: document.querySelectorAll('svg tspan.line').length,
                images: document.querySelectorAll('img').length,
                texts: [...document.querySelectorAll('svg text')].map(t => t.textContent),
            })"""
            )
        finally:
            browser.close()
    found["dialogs"] = dialogs
    return found


def _assert_nothing_renders_as_markup(found: dict, expected: list[str]) -> None:
    assert found["anchors"] == [], "a link rendered"
    colours = {"fill:black", "fill:#b2182b"} | {  # the page's own coloured legend and verdict
        "fill:#d7301f",
        "fill:#2b6cb0",
        "fill:rgb(175,175,175)",
    }
    for style in found["styled"]:
        assert style.replace(" ", "") in colours, f"styled text rendered: {style}"
    assert found["bold"] == 0 and found["lines"] == 0
    assert found["images"] == 0 and found["dialogs"] == []
    text = "\n".join(found["texts"])
    for literal in expected:
        assert literal in text, f"{literal!r} not shown literally"


def test_view_html_shows_markup_in_names_literally(tmp_path, require_tool):
    chromium = require_tool("chromium", "apt-get install chromium")
    design = _design(tmp_path)
    run = tmp_path / "run"
    assert main(["simulate", str(design), "-o", str(run), "--steps", "2", "--no-movie"]) == 0
    assert main(["view", str(run), "--no-open"]) == EXIT_OK
    found = _open(run / "view.html", chromium)
    _assert_nothing_renders_as_markup(found, list(PAYLOADS.values()))
    stored = json.loads((run / "summary.json").read_text())
    assert stored["metadata"]["design_name"] == PAYLOADS["design"]  # kept as written

    name = _tamper_field_names(run)
    out = tmp_path / "field.html"
    assert main(["view", str(run), "--no-open", "--field", name, "-o", str(out)]) == EXIT_OK
    _assert_nothing_renders_as_markup(_open(out, chromium), [f"{name} ({UNIT})", PAYLOADS["f1"]])

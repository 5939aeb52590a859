"""Interactive toolpath preview (rotomorph.plot.toolpath_html): the figure's structure, the
escaping of everything a design names, the page `gcode --preview` writes, and (referee) what a
real browser renders of it."""

from __future__ import annotations

import numpy as np
import pytest
from _gcode_cases import ROOT, case, design

from rotomorph.cli import EXIT_OK, main
from rotomorph.design.program import PrintProgram
from rotomorph.errors import InvalidParameterError
from rotomorph.io.designfile import parse_design, parse_design_bytes
from rotomorph.io.gcode import plan_programs
from rotomorph.io.machine import load_machine_profile
from rotomorph.plot.toolpath_html import COLOURINGS, toolpath_figure, write_toolpath_html

pytest.importorskip("plotly")

MACHINE = load_machine_profile(ROOT / "machines" / "linuxcnc.toml")
#: Markup, a hover-template field and a script end, as a design may write them in a name.
LINE = {"kind": "line", "length": 10.0}
HOSTILE = '<b>bold</b> %{x} <a href="javascript:alert(1)">x</a></script><script>alert(2)'


def _segments(trace) -> list[np.ndarray]:
    """The polylines of a line trace (NaN-separated), each ``(k, 2)``."""
    xy = np.column_stack([np.asarray(trace.x, float), np.asarray(trace.y, float)])
    cut = np.flatnonzero(np.isnan(xy[:, 0]))
    parts = [part[~np.isnan(part[:, 0])] for part in np.split(xy, cut)]
    return [part for part in parts if len(part)]


@pytest.fixture(scope="module")
def dome():
    """The 6 x 6 dome as printed, its names and its figure."""
    printed = plan_programs(case("lattice_dome_6x6")[0], MACHINE)
    names = design("lattice_dome_6x6").program_names()
    return printed, names, toolpath_figure(printed, names=names, title="dome", lift=2.0)


def test_a_6x6_lattice_in_two_panels_with_every_edge_once_per_colouring(dome):
    printed, names, fig = dome
    roles = [tuple(r) for r in fig.layout.meta["roles"]]
    assert len(roles) == len(fig.data)
    # layer 0, and layers 1-2 printed alike (serpentine makes layer 0 differ)
    assert [a.text for a in fig.layout.annotations] == ["layer 0", "layers 1, 2"]
    first = [p for p in printed if p.layer in (0, 1)]
    edges = sum(len(p.points) - 1 for p in first)
    for key in COLOURINGS:
        traces = [t for t, r in zip(fig.data, roles, strict=True) if r == ("edges", key)]
        assert sum(len(s) - 1 for t in traces for s in _segments(t)) == edges
        for panel in ("x", "x2"):  # one colour step a trace, in each panel
            colours = [t.line.color for t in traces if t.xaxis == panel]
            assert len(set(colours)) == len(colours) > 1
    # the hover points carry each edge's values: one colour step holds one range of alpha
    hover = [t for t, r in zip(fig.data, roles, strict=True) if r[0] == "hover"]
    assert len(hover) == len(first) and sum(len(t.x) for t in hover) == edges
    alpha = {}
    for t in hover:
        for x, y, row in zip(t.x, t.y, t.customdata, strict=True):
            alpha[t.xaxis, round(x, 6), round(y, 6)] = row[2]
    for t, r in zip(fig.data, roles, strict=True):
        if r == ("edges", "alpha"):
            mids = [0.5 * (s[1:] + s[:-1]) for s in _segments(t)]
            mids = np.concatenate(mids)
            got = [alpha[t.xaxis, round(m[0], 6), round(m[1], 6)] for m in mids]
            assert np.ptp(got) <= 360.0 / 32 + 1e-9
    # the names, escaped, in the hover text; the print order numbered at the starts
    assert names[0] in hover[0].hovertemplate and "(layer 0" in hover[0].hovertemplate
    starts = [t for t, r in zip(fig.data, roles, strict=True) if r[0] == "starts"]
    numbers = sorted(int(n) for t in starts for label in t.text for n in label.split(", ") if n)
    assert numbers == list(range(1, 25))  # layer 0 and layer 1: layer 2 is printed as layer 1
    travel = [t for t, r in zip(fig.data, roles, strict=True) if r[0] == "travel"]
    assert sum(len(_segments(t)) for t in travel) == len(first) - 1
    assert "lifted 2 mm" in travel[0].name


def test_the_menu_shows_one_colouring_and_everything_else(dome):
    _, _, fig = dome
    roles = [tuple(r) for r in fig.layout.meta["roles"]]
    buttons = fig.layout.updatemenus[0].buttons
    assert [b.label for b in buttons] == [label for label, _, _ in COLOURINGS.values()]
    for key, button in zip(COLOURINGS, buttons, strict=True):
        shown = button.args[0]["visible"]
        assert shown == [c is None or c == key for _, c in roles]
    assert [t.visible is not False for t in fig.data] == buttons[0].args[0]["visible"]
    assert [c for kind, c in roles if kind == "colourbar"] == list(COLOURINGS)


def test_active_side_ticks_point_toward_the_active_half():
    prog = PrintProgram.from_rotation(
        np.column_stack([np.linspace(0, 10, 101), *[np.zeros(101)] * 2]), 3.0, 2.0
    )
    fig = toolpath_figure([prog])
    roles = [tuple(r) for r in fig.layout.meta["roles"]]
    ticks = next(t for t, r in zip(fig.data, roles, strict=True) if r[0] == "ticks")
    segs = _segments(ticks)
    # ω/v = 2/3 rad/mm: 1.06 turns in 10 mm, a tick per eighth of a turn at least
    assert len(segs) >= 8 * 10 * (2.0 / 3.0) / (2 * np.pi)
    normals = prog.interface_normals[:, :2]
    mids = 0.5 * (prog.points[1:, :2] + prog.points[:-1, :2])
    for seg in segs:  # from an edge's middle along its in-plane normal, toward the active half
        i = int(np.argmin(np.linalg.norm(mids - seg[0], axis=1)))
        step = seg[1] - seg[0]
        assert np.linalg.norm(seg[0] - mids[i]) < 1e-9
        assert abs(step[0] * normals[i, 1] - step[1] * normals[i, 0]) < 1e-9
        assert step @ normals[i] >= 0


def test_names_and_title_reach_the_page_as_text_never_as_markup(tmp_path):
    d = parse_design_bytes(
        (
            'schema_version = 1\nname = "{0}"\n[[filaments]]\nname = "{0}"\n'
            'segments = [{{ kind = "line", length = 10.0 }}]\nstart = [10.0, 10.0, 0.0]\n'
        )
        .format(HOSTILE.replace('"', '\\"'))
        .encode(),
        "hostile",
    )
    printed = plan_programs(d.to_programs(), MACHINE)
    page = write_toolpath_html(
        printed, tmp_path / "p.html", names=d.program_names(), title=d.name, include_plotlyjs=False
    )
    fig = toolpath_figure(printed, names=d.program_names(), title=d.name)
    texts = [fig.layout.title.text] + [
        s for t in fig.data for s in [t.hovertemplate or "", *(t.hovertext or ())]
    ]
    named = [s for s in texts if "bold" in s]
    assert len(named) >= 3  # the title, the edges' and the start's hover
    for s in named:
        assert "<b>bold" not in s and "<a href" not in s and "%{x}" not in s
        assert "&lt;b&gt;bold&lt;/b&gt; &#37;{x} &lt;a href=&quot;javascript" in s
    html = page.read_text()
    assert "<b>bold" not in html and "alert(2)" in html.replace("\\u003c", "<")
    assert "</script><script>alert(2)" not in html  # no way out of the figure's script


def test_any_program_renders_and_bad_input_is_refused():
    rising = PrintProgram(
        np.column_stack([np.linspace(0, 5, 6), np.zeros(6), np.linspace(0, 1, 6)]), 2.0, 0.0
    )
    two = PrintProgram([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]], 1.0, 0.0, layer=3)
    fig = toolpath_figure([rising, two])
    assert [a.text for a in fig.layout.annotations] == ["layer 0", "layer 3"]
    with pytest.raises(InvalidParameterError, match="programs"):
        toolpath_figure([])
    with pytest.raises(InvalidParameterError, match="names"):
        toolpath_figure([two], names=["a", "b"])
    with pytest.raises(InvalidParameterError, match="colour"):
        toolpath_figure([two], colour="speed")


def test_gcode_preview_writes_the_png_and_the_page_beside_the_program(tmp_path, capsys):
    from PIL import Image

    src = ROOT / "designs" / "lattice_dome.toml"
    out = tmp_path / "dome.gcode"
    code = main(
        [
            "gcode",
            str(src),
            "-o",
            str(out),
            "--machine",
            str(ROOT / "machines" / "linuxcnc.toml"),
            "--preview",
        ]
    )
    assert code == EXIT_OK
    said = capsys.readouterr().out
    assert (
        f"wrote {tmp_path / 'dome.png'}" in said
        and f"wrote {tmp_path / 'dome.preview.html'}" in said
    )
    page = (tmp_path / "dome.preview.html").read_text()
    assert "<script src=" not in page and "plotly.js v" in page  # self-contained: offline
    assert "lattice_dome on LinuxCNC" in page and "x-line 0, layer 0" in page
    width, height = Image.open(tmp_path / "dome.png").size
    assert width >= 1800 and height >= 900  # two 900 px panels


#: Debian's Chromium in a container: no sandbox, no GPU, no network chatter.
CHROMIUM_ARGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]
#: Markup of every kind plotly.js draws from text: a link, styled, bold and italic text, a line
#: break, an entity, a hover-template field, and an element with a script.
MARKUP = {
    "design": "<a href='https://evil.example'>verify</a> <i>it</i>",
    "f0": "<b>bold</b><br><span style='font-size:90px'>big</span> &lt;b&gt; %{x}",
    "f1": "<img src=x onerror=alert(1)><script>alert(2)</script>",
}


@pytest.mark.referee
def test_a_browser_draws_the_page_and_shows_every_name_as_text(require_tool, tmp_path):
    """Headless Chromium (driven by Playwright) opens the page as written: plotly draws the
    panels and the print order; hovering an edge shows its filament's name; the colouring menu
    switches the edges and the colour bar; and nothing a design names renders as markup (no
    link, no styled, bold or italic text, no element, no script), it shows literally."""
    chromium = require_tool("chromium", "apt-get install chromium")
    from playwright.sync_api import sync_playwright

    d = parse_design(
        {
            "schema_version": 1,
            "name": MARKUP["design"],
            "filaments": [
                {"name": MARKUP["f0"], "start": [10.0, 10.0, 0.0], "segments": [LINE]},
                {
                    "name": MARKUP["f1"],
                    "rotation_number": 0.1,
                    "start": [10.0, 20.0, 0.0],
                    "segments": [{"kind": "arc", "radius": 8.0, "angle_deg": 90.0}],
                },
            ],
        }
    )
    printed = plan_programs(d.to_programs(), MACHINE)
    fig = toolpath_figure(printed, names=d.program_names(), title=d.name)
    roles = [tuple(r) for r in fig.layout.meta["roles"]]
    hover = [i for i, r in enumerate(roles) if r[0] == "hover"]
    page_path = write_toolpath_html(
        printed, tmp_path / "p.html", names=d.program_names(), title=d.name
    )
    dialogs: list[str] = []
    with sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=chromium, args=CHROMIUM_ARGS)
        try:
            page = browser.new_page(viewport={"width": 1400, "height": 900})
            page.on("dialog", lambda dialog: (dialogs.append(dialog.message), dialog.dismiss()))
            page.goto(page_path.resolve().as_uri())
            page.wait_for_selector(".main-svg text", timeout=30_000)
            drawn = page.evaluate(DRAWN)
            names = []
            for trace in hover:  # the mouse on an edge in the middle of each filament
                xy = page.evaluate(PIXEL, [trace, len(fig.data[trace].x) // 2])
                page.mouse.move(*xy)
                page.wait_for_selector(".hoverlayer .hovertext", timeout=10_000)
                names.append(page.evaluate(HOVER))
                page.mouse.move(5, 5)
            page.get_by_text("colour: nozzle turns").click()
            page.wait_for_timeout(500)
            switched = page.evaluate(DRAWN)
            found = page.evaluate(MARKUP_FOUND)
        finally:
            browser.close()
    assert drawn["traces"] == sum(t.visible is not False for t in fig.data)
    assert {"1", "2"} <= set(drawn["texts"])  # the print order at the starts
    assert drawn["title"].startswith(MARKUP["design"] + ": 2 filament(s)")  # literally
    assert "α (deg)" in drawn["colourbar"] and "nozzle turns" in switched["colourbar"]
    alpha_edges = sum(r == ("edges", "alpha") for r in roles)
    turns_edges = sum(r == ("edges", "turns") for r in roles)
    assert switched["traces"] == drawn["traces"] - alpha_edges + turns_edges
    assert MARKUP["f0"] in names[0] and MARKUP["f1"] in names[1] and "s = " in names[0]
    # the hover and title texts above hold the markup literally; no element came of it
    assert found == {"anchors": 0, "images": 0, "title_spans": 0}
    assert dialogs == []


DRAWN = """() => ({
    traces: document.querySelectorAll('.scatterlayer .trace').length,
    texts: [...document.querySelectorAll('.textpoint text')].map(t => t.textContent),
    title: document.querySelector('.gtitle').textContent,
    colourbar: [...document.querySelectorAll('.colorbar .cbtitle text')]
        .map(t => t.textContent).join(' '),
})"""
PIXEL = """([trace, point]) => {
    const gd = document.querySelector('.js-plotly-plot');
    const t = gd._fullData[trace];
    const xa = gd._fullLayout[t.xaxis === 'x' ? 'xaxis' : 'xaxis' + t.xaxis.slice(1)];
    const ya = gd._fullLayout[t.yaxis === 'y' ? 'yaxis' : 'yaxis' + t.yaxis.slice(1)];
    const box = gd.getBoundingClientRect();
    return [box.left + xa._offset + xa.l2p(t.x[point]), box.top + ya._offset + ya.l2p(t.y[point])];
}"""
HOVER = "() => document.querySelector('.hoverlayer .hovertext').textContent"
MARKUP_FOUND = """() => ({
    anchors: document.querySelectorAll('svg a, a[href]').length,
    images: document.querySelectorAll('img').length,
    title_spans: document.querySelectorAll('.gtitle tspan').length,
})"""

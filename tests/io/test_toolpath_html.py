"""Interactive toolpath preview (rotomorph.plot.toolpath_html): the figure's structure, the
escaping of everything a design names, the page `gcode --preview` writes, and (referee) what a
real browser renders of it."""

from __future__ import annotations

import re
import subprocess

import numpy as np
import pytest
from _gcode_cases import ROOT, case, design

from rotomorph.cli import EXIT_OK, main
from rotomorph.design.program import PrintProgram
from rotomorph.errors import InvalidParameterError
from rotomorph.io.designfile import parse_design_bytes
from rotomorph.io.gcode import plan_programs
from rotomorph.io.machine import load_machine_profile
from rotomorph.plot.toolpath_html import COLOURINGS, toolpath_figure, write_toolpath_html

pytest.importorskip("plotly")

MACHINE = load_machine_profile(ROOT / "machines" / "linuxcnc.toml")
#: Markup, a hover-template field and a script end, as a design may write them in a name.
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


@pytest.mark.referee
def test_a_browser_renders_the_page(require_tool, tmp_path):
    """Chromium (headless) loads the page as written: plotly draws the panels, the print
    order's numbers and the escaped name as text."""
    chromium = require_tool("chromium", "apt-get install chromium")
    d = parse_design_bytes(
        b'schema_version = 1\nname = "<i>lab</i>"\n[[filaments]]\nname = "<b>one</b>"\n'
        b'segments = [{ kind = "line", length = 10.0 }]\nstart = [10.0, 10.0, 0.0]\n'
        b'[[filaments]]\nsegments = [{ kind = "arc", radius = 8.0, angle_deg = 90.0 }]\n'
        b"start = [10.0, 14.0, 0.0]\n",
        "browser",
    )
    printed = plan_programs(d.to_programs(), MACHINE)
    page = write_toolpath_html(printed, tmp_path / "p.html", names=d.program_names(), title=d.name)
    done = subprocess.run(
        [
            chromium,
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            "--virtual-time-budget=10000",
            "--dump-dom",
            page.as_uri(),
        ],
        capture_output=True,
        text=True,
        timeout=120,
    )
    dom = done.stdout
    assert done.returncode == 0 and 'class="main-svg"' in dom, done.stderr[-500:]
    visible = sum(t.visible is not False for t in toolpath_figure(printed).data)
    assert dom.count('class="trace scatter') == visible
    assert ">1</text>" in dom and ">2</text>" in dom  # the print order at the starts
    # the name as text: escaped in the DOM, no italic element made from it
    title = re.search(r'<text class="gtitle"[^>]*>(.*?)</text>', dom)
    assert (
        title
        and title[1] == "&lt;i&gt;lab&lt;/i&gt;: 2 filament(s), 1 layer(s): the toolpath as printed"
    )
    assert "<b>one" not in dom

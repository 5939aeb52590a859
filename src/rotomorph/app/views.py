"""The page's figures: the lattice's edges to click, the streamed and final run, the toolpath.

The 3-D run view is the run viewer's own figure (:func:`rotomorph.plot.viewer.viewer_figure`:
Janus tubes, the printed ghost, the slider over temperature, each step's verdict in its title):
while a simulation runs, the steps received so far are laid out as a
:class:`~rotomorph.io.results.RunResults` and drawn by it; when the run ends, the results file
the run wrote is read back (:func:`rotomorph.io.results.read_results`) and drawn, exactly as
``rotomorph view`` draws it. The toolpath is ``rotomorph gcode --preview``'s figure. Texts
from a design reach plotly only through those figures, which escape them; the plan view here
shows numbers only.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import numpy as np

__all__ = [
    "VERDICT_WORDS",
    "final_figure",
    "lattice_plan",
    "partial_results",
    "step_verdicts",
    "stream_figure",
    "stream_update",
    "toolpath_figure",
]

EXPANDING_COLOUR = "#d6604d"
CONTRACTING_COLOUR = "#4393c3"


def _go() -> Any:
    import plotly.graph_objects as go

    return go


def lattice_plan(design: Any, modes: list[str], selected: int | None) -> Any:
    """Plan view of a lattice design's edges, coloured by mode; a marker at each edge's middle
    carries its index (``customdata``) for clicking; the selected edge drawn thick."""
    go = _go()
    lattice = design.lattice.to_lattice()
    nodes = np.asarray(lattice.network.nodes, dtype=float) + np.asarray(design.lattice.origin)
    speeds = design.lattice.edge_speeds or [design.lattice.speed] * len(modes)
    traces = []
    for mode, colour in (("expanding", EXPANDING_COLOUR), ("contracting", CONTRACTING_COLOUR)):
        xs: list[float | None] = []
        ys: list[float | None] = []
        for j, chain in enumerate(lattice.edge_chains):
            if modes[j] == mode:
                pts = nodes[np.asarray(chain)]
                xs += [*pts[:, 0].tolist(), None]
                ys += [*pts[:, 1].tolist(), None]
        traces.append(
            go.Scatter(
                x=xs,
                y=ys,
                mode="lines",
                line={"color": colour, "width": 3},
                name=mode,
                hoverinfo="skip",
            )
        )
    mids = np.array([nodes[np.asarray(c)][len(c) // 2] for c in lattice.edge_chains])
    colours = [EXPANDING_COLOUR if m == "expanding" else CONTRACTING_COLOUR for m in modes]
    sizes = [20 if j == selected else 11 for j in range(len(modes))]
    traces.append(
        go.Scatter(
            x=mids[:, 0],
            y=mids[:, 1],
            mode="markers",
            marker={"color": colours, "size": sizes, "line": {"color": "black", "width": 1.5}},
            customdata=list(range(len(modes))),
            text=[
                f"edge {j}: {m}, {float(v):g} mm/s"
                for j, (m, v) in enumerate(zip(modes, speeds, strict=True))
            ],
            hovertemplate="%{text}<extra></extra>",
            name="edges (click to edit)",
        )
    )
    fig = go.Figure(traces)
    fig.update_layout(
        margin={"l": 40, "r": 10, "t": 60, "b": 40},
        height=420,
        xaxis={"title": "x (mm)", "scaleanchor": "y"},
        yaxis={"title": "y (mm)"},
        legend={"orientation": "h", "y": 1.0, "yanchor": "bottom"},
        title={
            "text": "printed lattice (plan): click an edge's dot to edit it",
            "font": {"size": 13},
            "y": 0.98,
            "yanchor": "top",
        },
        clickmode="event",
    )
    return fig


#: How a step's verdict is named on the page: physical, unstable, not converged, not
#: admissible (filaments pass through each other or edges strained beyond the rod model), or
#: unverified (a check was not made).
VERDICT_WORDS = ("physical", "unstable", "not converged", "not admissible", "unverified")


def _word(verdict: Any) -> str:
    if verdict.verdict == "yes":
        return "physical"
    if verdict.verdict == "unknown":
        return "unverified"
    text = " ".join(verdict.reasons)
    if "did not converge" in text:
        return "not converged"
    if "unstable" in text:
        return "unstable"
    return "not admissible"


def step_verdicts(results: Any) -> list[tuple[str, str, str]]:
    """``(label, word, verdict text)`` per step of ``results`` (:mod:`rotomorph.io.validity`)."""
    from rotomorph.io.validity import assess

    verdicts = assess(results.scalars, results.metadata, results.n_steps)
    labels = results.step_labels()
    return [(labels[k], _word(v), v.text()) for k, v in enumerate(verdicts)]


def partial_results(job: Any) -> Any:
    """The steps a running simulation has streamed, as :class:`RunResults` (None before any).

    Frame after frame in the order received: a design of several filaments is solved one
    filament at a time, so in the frames of filament i the filaments before it stand at their
    last state and those after it as printed.
    """
    from rotomorph.io.results import RunResults

    topo = job.topology
    steps = job.step_events()
    if topo is None or not steps:
        return None
    printed = np.asarray(topo["printed"], dtype=float)
    edges = np.asarray(topo["edges"], dtype=np.int64)
    units = topo["units"]
    if topo["chains"]:  # filaments: chains of b - a nodes and b - a - 1 segments each
        unit_edges = np.cumsum([0] + [b - a - 1 for a, b in units])
    else:  # a lattice: one unit, the whole network
        unit_edges = np.array([0, len(edges)])
    current = printed.copy()
    normals = np.asarray(topo["normals"], dtype=float).copy()  # as printed until streamed
    pos, nrm, temp, stable, strain = [], [], [], [], []
    for ev in steps:
        a, b = units[ev["unit"]]
        current[a:b] = ev["positions"]
        ea, eb = unit_edges[ev["unit"]], unit_edges[ev["unit"] + 1]
        normals[ea:eb] = ev["normals"]
        pos.append(current.copy())
        nrm.append(normals.copy())
        temp.append(ev["value"])
        stable.append(np.nan if ev["stable"] is None else float(bool(ev["stable"])))
        strain.append(ev["max_axial_strain"])
    ramp = steps[-1]["ramp"]
    known = np.isfinite(np.stack(nrm)).all(axis=(1, 2))
    fields = {"active_normal": np.stack(nrm)} if known.all() else {}
    return RunResults(
        design={},
        edges=edges,
        branch=np.zeros(len(printed), dtype=bool),
        positions=np.stack(pos),
        scalars={
            ramp: np.array(temp),
            "converged": np.ones(len(pos)),
            "stable": np.array(stable),
            "max_axial_strain": np.array(strain),
        },
        fields=fields,
        units={"positions": "mm"},
        metadata={
            "contact": bool(topo["contact"]),
            "chains": topo["chains"],
            "design_name": str(topo["design_name"]),
        },
        static={
            "radius": np.asarray(topo["radius"], dtype=float),
            "active_fraction": np.asarray(topo["active_fraction"], dtype=float),
        },
    )


def stream_figure(job: Any) -> Any:
    """The run viewer's figure of the steps streamed so far (None before the first)."""
    from rotomorph.plot.viewer import viewer_figure

    results = partial_results(job)
    if results is None:
        return None
    field = "janus" if "active_normal" in results.fields else "max_axial_strain"
    if field != "janus":
        return None
    return _sized(viewer_figure(results, field=field, facets=8))


def _frames_from(results: Any, k0: int) -> Any:
    """``results`` from step ``k0`` on."""
    from rotomorph.io.results import RunResults

    return RunResults(
        design=results.design,
        edges=results.edges,
        branch=results.branch,
        positions=results.positions[k0:],
        scalars={k: v[k0:] for k, v in results.scalars.items()},
        fields={k: v[k0:] for k, v in results.fields.items()},
        units=results.units,
        metadata=results.metadata,
        static=results.static,
    )


_STEP_OF = re.compile(r"\(step (\d+)/\d+\)")


def _retitle(text: str, k0: int, last: int) -> str:
    """A frame title's ``(step k/n)`` as step ``k0 + k`` of the run's ``last``."""
    return _STEP_OF.sub(lambda m: f"(step {k0 + int(m.group(1))}/{last})", text, count=1)


def _typed(value: Any) -> Any:
    """``value`` with its numeric arrays as plotly.js's typed-array records (base64, as a
    figure's own arrays are sent), not as lists of decimal numbers."""
    from _plotly_utils.utils import to_typed_array_spec

    if isinstance(value, np.ndarray) and value.dtype.kind in "fiu":
        return to_typed_array_spec(value)
    if isinstance(value, dict):
        return {k: _typed(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_typed(v) for v in value]
    return value


def _scene_box(ranges: list[list[float]]) -> dict[str, Any]:
    half = np.array([0.5 * (b - a) for a, b in ranges])
    ratio = half / float(half.max())
    return {
        **{f"{c}axis": {"range": list(r)} for c, r in zip("xyz", ranges, strict=True)},
        "aspectratio": dict(zip("xyz", (float(v) for v in ratio), strict=True)),
    }


def stream_update(job: Any, shown: int | None, store: dict[str, Any]) -> tuple[Any, int] | None:
    """What the run view needs of the steps a running simulation has streamed: the run
    viewer's figure of them all, or a :class:`dash.Patch` that adds to the page's figure only
    the steps it does not show yet (their frames and slider steps, the tubes of the latest,
    the title and the box), so that each step costs the server one step's drawing.

    Parameters
    ----------
    job
        The running :class:`~rotomorph.app.jobs.Job`.
    shown
        Steps of this job the page's figure holds, as the page says (None: none).
    store
        The session's server-side store: what was drawn of which job (its coarse segments,
        the steps drawn, the box); a page that does not hold what the store says is drawn
        anew.

    Returns
    -------
    tuple or None
        ``(figure or Patch, steps shown after it)``; None before the first converged step
        (the printed state alone is not drawn), when the figure has them all, or for a run
        without interface normals (no Janus tubes).
    """
    from dash import Patch

    from rotomorph.plot.coarsen import coarsen_network
    from rotomorph.plot.viewer import viewer_figure

    if all(e["step"] == 0 for e in job.step_events()):
        return None  # the printed state only (the ghost): drawn with the first converged step,
        # so that drawing it does not hold up the server as that step arrives
    results = partial_results(job)
    if results is None or "active_normal" not in results.fields:
        return None
    s = results.n_steps
    units = len(job.topology["units"]) if job.topology else 1
    last = units * (job.steps + 1) - 1  # the run's last frame when it ends
    key = (id(job), job.started)
    state = store.get("stream")
    if state is None or state["key"] != key or shown != state["shown"] or shown is None:
        radius = float(np.max(results.static["radius"]))
        network = coarsen_network(results.positions, results.edges, radius)
        fig = _sized(viewer_figure(results, field="janus", facets=8, network=network))
        fig.layout.title.text = _retitle(fig.layout.title.text, 0, last)
        for frame in fig.frames:
            frame.layout.title.text = _retitle(frame.layout.title.text, 0, last)
        scene = fig.layout.scene
        ranges = [list(scene[f"{c}axis"].range) for c in "xyz"]
        store["stream"] = {"key": key, "network": network, "shown": s, "ranges": ranges}
        return fig, s
    if s <= shown:
        return None
    part = viewer_figure(
        _frames_from(results, shown), field="janus", facets=8, network=state["network"]
    )
    patch = Patch()
    tubes = part.data[0]
    moving = ("x", "y", "z", "intensity") if part.frames[0].data[0].intensity is not None else "xyz"
    for name in moving:  # the tubes now: the latest step's (the Janus sides' colours stay)
        patch["data"][0][name] = _typed(np.asarray(tubes[name]))
    frames = []
    for i, frame in enumerate(part.frames):
        record = frame.to_plotly_json()
        record["name"] = str(shown + i)
        record["layout"]["title"]["text"] = _retitle(record["layout"]["title"]["text"], shown, last)
        frames.append(_typed(record))
    patch["frames"].extend(frames)
    steps = []
    for i, step in enumerate(part.layout.sliders[0].steps):
        record = step.to_plotly_json()
        record["args"][0] = [str(shown + i)]
        steps.append(record)
    patch["layout"]["sliders"][0]["steps"].extend(steps)
    patch["layout"]["sliders"][0]["active"] = s - 1
    patch["layout"]["title"]["text"] = _retitle(part.layout.title.text, shown, last)
    if part.layout.scene.annotations:
        patch["layout"]["scene"]["annotations"] = [
            a.to_plotly_json() for a in part.layout.scene.annotations
        ]
    new = [list(part.layout.scene[f"{c}axis"].range) for c in "xyz"]
    ranges = [[min(a[0], b[0]), max(a[1], b[1])] for a, b in zip(state["ranges"], new, strict=True)]
    if ranges != state["ranges"]:  # the shape left the box: a box around every step so far
        box = _scene_box(ranges)
        for c in "xyz":
            patch["layout"]["scene"][f"{c}axis"]["range"] = box[f"{c}axis"]["range"]
        patch["layout"]["scene"]["aspectratio"] = box["aspectratio"]
    state.update(shown=s, ranges=ranges)
    return patch, s


def final_figure(folder: str | Path) -> tuple[Any, Any]:
    """The run viewer's figure of a finished run's ``results.h5`` and the results."""
    from rotomorph.io.results import read_results
    from rotomorph.plot.viewer import viewer_figure

    results = read_results(Path(folder) / "results.h5")
    return _sized(viewer_figure(results)), results


def _sized(fig: Any) -> Any:
    fig.update_layout(height=560, uirevision="run")  # the camera stays put as frames arrive
    return fig


def toolpath_figure(programs: list[Any], names: list[str], title: str, lift: float | None) -> Any:
    """The interactive toolpath preview of ``rotomorph gcode --preview``
    (:func:`rotomorph.plot.toolpath_html.toolpath_figure`) of planned ``programs``: names and
    title shown escaped, ``lift`` the machine's travel height (mm)."""
    from rotomorph.plot.toolpath_html import toolpath_figure as figure

    fig = figure(programs, names=names, title=title, lift=lift)
    # in a panel narrower than the preview page: the title on top, the colouring menu below it
    fig.update_layout(
        title={"y": 0.995, "yanchor": "top", "font": {"size": 13}},
        margin={"t": 130},
        uirevision="toolpath",
    )
    return fig

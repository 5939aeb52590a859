"""The page's layout: the design form built from the design's data, and the fixed panels.

Every editable field is a text input whose id names its path in the design
(``{"type": "field", "path": "filaments[0].speed"}``) with an error line beside it
(``{"type": "error", "path": …}``) where the CLI's one-line message appears. Texts from a design
are passed to Dash as text (React writes them as text nodes, never as markup).
"""

from __future__ import annotations

from typing import Any

from dash import dcc, html

from rotomorph.app.editing import format_value, get_field

__all__ = ["NEW_SEGMENTS", "TARGETS", "page", "render_form"]

_FILAMENT_FIELDS = (
    ("name", "name"),
    ("speed", "speed (mm/s)"),
    ("rotation_number", "ω* = Rω/v"),
    ("rotation", "rotation ω (rad/s)"),
    ("interface_angle_deg", "interface angle α (deg)"),
    ("flip_length", "flip length (mm)"),
    ("radius", "radius R (mm)"),
    ("spacing", "vertex spacing (mm)"),
    ("start", "start x, y, z (mm)"),
    ("heading_deg", "heading (deg)"),
    ("initial_nozzle_angle_deg", "initial nozzle angle (deg)"),
)
_SEGMENT_FIELDS = {
    "line": (("length", "length (mm)"),),
    "arc": (("radius", "radius (mm)"), ("angle_deg", "angle (deg)")),
    "sinusoid": (
        ("amplitude", "amplitude (mm)"),
        ("wavelength", "wavelength (mm)"),
        ("periods", "periods"),
    ),
    "polyline": (("resample", "resample (true/false)"),),
}
_NOZZLE_FIELDS = (
    ("diameter", "diameter (mm)"),
    ("active_pressure", "active pressure (psi)"),
    ("passive_pressure", "passive pressure (psi)"),
    ("prime_dwell", "prime dwell (s)"),
    ("release_dwell", "release dwell (s)"),
    ("active_conductance", "active conductance (mm³/s/psi)"),
    ("passive_conductance", "passive conductance (mm³/s/psi)"),
)
_CONTACT_FIELDS = (
    ("self_contact", "self contact (true/false)"),
    ("floor", "floor (true/false)"),
    ("gravity", "gravity (true/false)"),
    ("friction", "friction coefficient"),
    ("path_check", "path check sub-steps"),
)
_SEGMENT_CONTROLS = (
    ("speed", "speed (mm/s)"),
    ("rotation_number", "ω*"),
    ("rotation", "ω (rad/s)"),
    ("interface_angle_deg", "α (deg)"),
)
#: Segments the form appends (a starting shape each; every value editable after).
NEW_SEGMENTS = {
    "line": {"kind": "line", "length": 10.0},
    "arc": {"kind": "arc", "radius": 5.0, "angle_deg": 90.0},
    "sinusoid": {"kind": "sinusoid", "amplitude": 1.0, "wavelength": 5.0, "periods": 2},
}
_LATTICE_FIELDS = (
    ("n", "n (nodes per side)"),
    ("spacing", "spacing l (mm)"),
    ("amplitude", "amplitude A (mm)"),
    ("layers", "layers"),
    ("layer_height", "layer height (mm)"),
    ("speed", "speed (mm/s)"),
    ("ghost_nodes", "rod nodes per edge"),
    ("origin", "origin x, y, z (mm)"),
)

#: Target files the inverse panel starts from (TOML, parsed as ``rotomorph inverse`` parses).
TARGETS = {
    "helix": """schema_version = 1
kind = "curve"
name = "helix"

[curve]
family = "helix"
radius_start = 2.0   # mm
radius_end = 2.6
pitch = 2.0          # mm per turn (< 0: left-handed)
turns = 1.0
""",
    "spiral": """schema_version = 1
kind = "curve"
name = "spiral"

[curve]
family = "spiral"
radius_start = 1.9   # mm
radius_end = 3.4
turns = 1.2
""",
    "dome": """schema_version = 1
kind = "dome"
name = "dome"

[surface]
curvature = 0.07     # 1/mm

[lattice]
n = 5
spacing = 5.0        # mm
amplitude = 1.25     # mm
ghost_nodes = 10
""",
    "saddle": """schema_version = 1
kind = "saddle"
name = "saddle"

[surface]
curvature = 0.07     # 1/mm

[lattice]
n = 5
spacing = 5.0        # mm
amplitude = 1.25     # mm
ghost_nodes = 10
""",
    "height map": """schema_version = 1
kind = "height_map"
name = "bump"

[height_map]           # z[i][j] (mm) at (x[i], y[j]) (mm), centred on the lattice
x = [-10.0, -5.0, 0.0, 5.0, 10.0]
y = [-10.0, -5.0, 0.0, 5.0, 10.0]
z = [[0.0, 0.4, 0.7, 0.4, 0.0],
     [0.4, 1.2, 1.7, 1.2, 0.4],
     [0.7, 1.7, 2.4, 1.7, 0.7],
     [0.4, 1.2, 1.7, 1.2, 0.4],
     [0.0, 0.4, 0.7, 0.4, 0.0]]

[lattice]
n = 5
spacing = 5.0
amplitude = 1.25
ghost_nodes = 10
""",
}


def field(
    data: dict[str, Any], path: str, label: str, *, placeholder: str = "", rows: int = 0
) -> Any:
    """A labelled text input for ``path`` with its error line (``rows`` > 0: a text area of
    that many rows, for a list of points)."""
    id_ = {"type": "field", "path": path}
    value = format_value(get_field(data, path))
    box = (
        dcc.Textarea(
            id=id_,
            value=value,
            rows=rows,
            placeholder=placeholder or "x, y, z per line",
            className="field-input points",
        )
        if rows
        else dcc.Input(
            id=id_,
            value=value,
            type="text",
            placeholder=placeholder or "default",
            debounce=False,
            className="field-input",
        )
    )
    return html.Div(
        [
            html.Label(label, className="field-label"),
            box,
            html.Div(id={"type": "error", "path": path}, className="field-error"),
        ],
        className="field",
    )


def _choice(data: dict[str, Any], path: str, label: str, options: list[str]) -> Any:
    return html.Div(
        [
            html.Label(label, className="field-label"),
            dcc.Dropdown(
                id={"type": "field", "path": path},
                options=[{"label": o, "value": o} for o in options],
                value=get_field(data, path),
                clearable=True,
                placeholder="none",
                className="field-input",
            ),
            html.Div(id={"type": "error", "path": path}, className="field-error"),
        ],
        className="field",
    )


def _segment(data: dict[str, Any], i: int, j: int, seg: dict[str, Any]) -> Any:
    base = f"filaments[{i}].segments[{j}]"
    kind = str(seg.get("kind", ""))
    fields = [field(data, f"{base}.{k}", label) for k, label in _SEGMENT_FIELDS.get(kind, ())]
    if kind == "polyline":
        points = seg.get("points") or []
        rows = min(max(len(points), 2), 12)
        fields.insert(0, field(data, f"{base}.points", "points x, y, z per line (mm)", rows=rows))
    fields += [
        field(data, f"{base}.{k}", label, placeholder="filament's")
        for k, label in _SEGMENT_CONTROLS
    ]
    return html.Div(
        [html.Div(f"segment {j}: {kind}", className="segment-title"), *fields],
        className="segment",
    )


def _filament(data: dict[str, Any], i: int, fil: dict[str, Any]) -> Any:
    base = f"filaments[{i}]"
    name = str(fil.get("name") or f"filament {i}")
    return html.Details(
        [
            html.Summary(f"filament {i}: {name}"),
            html.Div(
                [field(data, f"{base}.{k}", label) for k, label in _FILAMENT_FIELDS]
                + [_choice(data, f"{base}.active_side", "active side", ["outer", "inner"])],
                className="grid",
            ),
            html.Div([_segment(data, i, j, s) for j, s in enumerate(fil.get("segments", []))]),
            html.Div(
                [
                    *(
                        html.Button(
                            f"+ {kind}",
                            id={"type": "seg-add", "fil": i, "kind": kind},
                            className="small",
                        )
                        for kind in NEW_SEGMENTS
                    ),
                    html.Button(
                        "− last segment", id={"type": "seg-remove", "fil": i}, className="small"
                    ),
                ]
            ),
        ],
        open=i == 0,
        className="filament",
    )


def render_form(data: dict[str, Any]) -> list[Any]:
    """The form of a design's data: name and description, each filament (its print program
    and segments) or the lattice (geometry, layers, speed, pattern)."""
    out: list[Any] = [
        html.Div(
            [field(data, "name", "design name"), field(data, "description", "description")],
            className="grid",
        )
    ]
    for i, fil in enumerate(data.get("filaments") or []):
        out.append(_filament(data, i, fil))
    if data.get("lattice") is not None:
        patterns = ["expanding", "contracting", "dome", "saddle", "custom"]
        out.append(
            html.Div(
                [
                    html.H4("lattice"),
                    html.Div(
                        [field(data, f"lattice.{k}", label) for k, label in _LATTICE_FIELDS]
                        + [_choice(data, "lattice.pattern", "pattern", patterns)],
                        className="grid",
                    ),
                ]
            )
        )
    out.append(
        html.Details(
            [
                html.Summary("nozzle (G-code)"),
                html.Div(
                    [field(data, f"nozzle.{k}", label) for k, label in _NOZZLE_FIELDS],
                    className="grid",
                ),
            ],
            className="filament",
        )
    )
    if data.get("contact") is not None:  # a [contact] table: the simulation's contact model
        out.append(
            html.Details(
                [
                    html.Summary("contact (simulation)"),
                    html.Div(
                        [field(data, f"contact.{k}", label) for k, label in _CONTACT_FIELDS]
                        + [_choice(data, "contact.branch", "branch", ["lowest", "continuous"])],
                        className="grid",
                    ),
                ],
                className="filament",
            )
        )
    return out


def placeholder(text: str) -> dict[str, Any]:
    """An empty figure saying what will appear there."""
    return {
        "data": [],
        "layout": {
            "height": 90,
            "xaxis": {"visible": False},
            "yaxis": {"visible": False},
            "margin": {"l": 0, "r": 0, "t": 0, "b": 0},
            "annotations": [
                {"text": text, "showarrow": False, "font": {"size": 13, "color": "#777"}}
            ],
        },
    }


def _section(title: str, children: list[Any], id_: str) -> Any:
    return html.Section([html.H3(title), *children], id=id_, className="panel")


def page(sid: str, examples: list[tuple[str, str]], machines: list[tuple[str, str]]) -> Any:
    """The whole page for a new session ``sid``; ``examples`` and ``machines`` are
    ``(value, label)`` choices the server made."""
    return html.Div(
        [
            dcc.Store(id="sid", data=sid),
            dcc.Store(id="design-data"),
            dcc.Store(id="upload-checked"),
            dcc.Store(id="selected-edge"),
            dcc.Store(id="drawn", data=-1),
            dcc.Store(id="generation", data=-1),
            dcc.Store(id="inverse-design"),
            dcc.Store(id="band-request"),
            dcc.Store(id="band-go"),
            dcc.Store(id="run-frames"),
            dcc.Interval(id="poll", interval=400, disabled=True),
            html.Header(
                [
                    html.H1("rotomorph designer"),
                    dcc.Dropdown(
                        id="example",
                        options=[{"label": label, "value": v} for v, label in examples],
                        value=examples[0][0] if examples else None,
                        placeholder="open an example design…",
                        className="example",
                    ),
                    dcc.Upload(
                        html.Button("upload a design file (.toml)"), id="upload", multiple=False
                    ),
                    html.Button("download design (.toml)", id="get-design"),
                    dcc.Download(id="design-file"),
                ],
                className="header",
            ),
            html.Div(id="upload-error", className="field-error global"),
            html.Div(
                [
                    html.Div(
                        [
                            _section(
                                "design",
                                [
                                    html.Div(id="design-error", className="field-error global"),
                                    html.Div(id="form"),
                                ],
                                "design-panel",
                            ),
                            html.Div(
                                [
                                    dcc.Graph(id="plan", config={"displaylogo": False}),
                                    html.Div(id="edge-title", className="segment-title"),
                                    dcc.RadioItems(
                                        id="edge-mode",
                                        options=["expanding", "contracting"],
                                        inline=True,
                                    ),
                                    html.Div(
                                        [
                                            html.Label("edge speed (mm/s)"),
                                            dcc.Input(id="edge-speed", type="text", debounce=True),
                                        ],
                                        className="edge-speed",
                                    ),
                                    html.Div(
                                        id={"type": "error", "path": "lattice.edge_speeds"},
                                        className="field-error",
                                    ),
                                ],
                                id="plan-box",
                                style={"display": "none"},
                            ),
                        ],
                        className="left",
                    ),
                    html.Div(
                        [
                            _section(
                                "prediction (closed form, as rotomorph predict)",
                                [html.Div(id="prediction", className="prediction")],
                                "prediction-panel",
                            ),
                            _section(
                                "simulate (rod solver over the heating ramp)",
                                [
                                    html.Div(
                                        [
                                            html.Label("steps"),
                                            dcc.Input(id="steps", value="4", type="text", size="4"),
                                            html.Button("simulate", id="simulate"),
                                            html.Button("cancel", id="cancel"),
                                            html.Progress(id="progress", value="0", max="1"),
                                        ],
                                        className="row",
                                    ),
                                    html.Div(id="job-status", className="status"),
                                    dcc.Graph(
                                        id="run-view",
                                        figure=placeholder(
                                            "each converged step appears here as it is reached"
                                        ),
                                        config={"displaylogo": False},
                                    ),
                                    html.Div(id="run-shown", className="caption"),
                                    html.Div(id="verdicts", className="verdicts"),
                                    html.Div(
                                        [
                                            html.Button("results.h5", id="get-h5"),
                                            html.Button("summary.json", id="get-summary"),
                                            html.Button("run folder (.zip)", id="get-run"),
                                            dcc.Download(id="run-file"),
                                        ],
                                        className="row",
                                    ),
                                ],
                                "simulate-panel",
                            ),
                            _section(
                                "print (G-code, as rotomorph gcode)",
                                [
                                    html.Div(
                                        [
                                            dcc.Dropdown(
                                                id="machine",
                                                options=[
                                                    {"label": label, "value": v}
                                                    for v, label in machines
                                                ],
                                                value=machines[0][0],
                                                clearable=False,
                                                className="machine",
                                            ),
                                            dcc.Upload(
                                                html.Button("upload a machine profile"),
                                                id="machine-upload",
                                            ),
                                            html.Label("UV cure per layer (s)"),
                                            dcc.Input(id="cure", value="0", type="text", size="5"),
                                        ],
                                        className="row",
                                    ),
                                    html.Div(id="machine-error", className="field-error global"),
                                    html.Div(
                                        [
                                            html.Button("preview toolpath", id="preview"),
                                            html.Button("G-code", id="get-gcode"),
                                            html.Button(
                                                "controller configuration (.zip)", id="get-config"
                                            ),
                                            dcc.Download(id="gcode-file"),
                                        ],
                                        className="row",
                                    ),
                                    dcc.Graph(
                                        id="toolpath",
                                        figure=placeholder("preview the toolpath on the machine"),
                                        config={"displaylogo": False},
                                    ),
                                ],
                                "print-panel",
                            ),
                            _section(
                                "inverse design (as rotomorph inverse)",
                                [
                                    dcc.Dropdown(
                                        id="target-kind",
                                        options=list(TARGETS),
                                        value="helix",
                                        clearable=False,
                                    ),
                                    dcc.Textarea(
                                        id="target-text",
                                        value=TARGETS["helix"],
                                        rows=12,
                                        className="target",
                                    ),
                                    html.Div(
                                        [
                                            html.Button("design it", id="inverse"),
                                            html.Button(
                                                "open the result as the design",
                                                id="inverse-open",
                                                disabled=True,
                                            ),
                                        ],
                                        className="row",
                                    ),
                                    html.Div(id="inverse-status", className="status"),
                                ],
                                "inverse-panel",
                            ),
                        ],
                        className="right",
                    ),
                ],
                className="columns",
            ),
        ]
    )

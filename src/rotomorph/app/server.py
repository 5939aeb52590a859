"""The Dash application of ``rotomorph serve``: callbacks between the page and the public API.

Each callback is a thin call into rotomorph: edits are validated by :func:`rotomorph.app.editing.
check` (``rotomorph validate``'s path), predictions come from
:func:`rotomorph.prediction.predict_design` (``rotomorph predict``), simulations and inverse
designs run in the session's worker (:mod:`rotomorph.app.jobs`), files are the CLI's
(:mod:`rotomorph.app.files`). No callback waits on a computation longer than a prediction.
"""

from __future__ import annotations

import base64
import binascii
import logging
import threading
import uuid
from pathlib import Path
from typing import Any
from urllib.parse import urlsplit

from dash import ALL, Dash, Input, Output, State, ctx, dcc, html, no_update

from rotomorph.app import editing, files, views
from rotomorph.app.jobs import BusyError, Job, Sessions
from rotomorph.app.layout import NEW_SEGMENTS, TARGETS, page, render_form
from rotomorph.errors import InvalidParameterError, MachineLimitError, RotomorphError
from rotomorph.io.tomlfile import MAX_TOML_BYTES

__all__ = ["create_app"]

_STYLE = Path(__file__).with_name("style.css")
_log = logging.getLogger(__name__)

# The browser refuses an upload over the limit before sending it, in the CLI's words
# (rotomorph.io.tomlfile.decode_toml_bytes); the server checks again (MAX_CONTENT_LENGTH and
# the same parser).
_CHECK_UPLOAD = """
function(contents, name) {
    if (!contents) { return [null, ""]; }
    var comma = contents.indexOf(",");
    var b64 = contents.length - comma - 1;
    var pad = contents.endsWith("==") ? 2 : (contents.endsWith("=") ? 1 : 0);
    var bytes = Math.floor(b64 * 3 / 4) - pad;
    if (bytes > LIMIT) {
        return [null, name + ": is " + bytes + " bytes; the limit is LIMIT bytes for a TOML file"];
    }
    return [{"name": name, "contents": contents}, ""];
}
""".replace("LIMIT", str(MAX_TOML_BYTES))

# The calibration band of a prediction follows its nominal value: asked for once the design
# has stood still for BAND_DELAY_MS (a newer edit's request supersedes an older one's).
BAND_DELAY_MS = 300
_DEBOUNCE_BAND = """
function(request) {
    if (!request) { return window.dash_clientside.no_update; }
    window.rotomorphBand = request.rev;
    return new Promise(function(resolve) {
        setTimeout(function() {
            resolve(window.rotomorphBand === request.rev
                ? request : window.dash_clientside.no_update);
        }, DELAY);
    });
}
""".replace("DELAY", str(BAND_DELAY_MS))

#: What the run view shows, said under it.
FINAL_CAPTION = "the finished run, read back from its results.h5 (as rotomorph view shows it)"
STREAM_CAPTION = "the steps converged so far, as they arrive"

#: Names of this computer's loopback interface (the default ``--host 127.0.0.1``).
LOCAL_HOSTS = frozenset({"127.0.0.1", "localhost", "::1"})
_TEXT = {"Content-Type": "text/plain; charset=utf-8"}


def _decode(contents: str) -> bytes:
    _, _, b64 = contents.partition(",")
    try:
        return base64.b64decode(b64, validate=True)
    except binascii.Error:
        raise InvalidParameterError("upload", "is not a file the browser sent whole") from None


def _message(err: BaseException) -> str:
    if isinstance(err, MachineLimitError):
        return f"machine limits: {err}"
    return str(err)


def create_app(
    *,
    examples: Path | None = None,
    sessions: Sessions | None = None,
    allowed_hosts: frozenset[str] | None = LOCAL_HOSTS,
) -> tuple[Dash, Sessions]:
    """The Dash app and its sessions.

    Every request's ``Host`` must name one of ``allowed_hosts`` (a page elsewhere on the web
    that resolves its own name to this computer cannot drive the app: DNS rebinding), bodies
    are limited to twice the design-file limit, and a refused or failed request is answered
    with one line of text (never a traceback).

    Parameters
    ----------
    examples
        A folder with ``designs/`` and ``machines/`` of design files and machine profiles the
        page offers (the repository's ``examples/``); None: none (uploads and built-ins only).
    sessions
        Session registry (caps on jobs and workers); default :class:`Sessions`.
    allowed_hosts
        Host names the page may be reached by (default: this computer's loopback names);
        None: any (``rotomorph serve --host`` other than loopback).
    """
    sessions = sessions or Sessions()
    designs = files.list_toml(examples / "designs" if examples else None)
    machine_files = files.list_toml(examples / "machines" if examples else None)
    example_choices = [(str(i), p.stem) for i, p in enumerate(designs)]
    machine_choices = [(f"builtin:{d}", f"built-in default ({d})") for d in files.BUILTIN_MACHINES]
    machine_choices += [(f"example:{i}", p.stem) for i, p in enumerate(machine_files)]

    app = Dash(
        __name__,
        title="rotomorph designer",
        update_title="",
        suppress_callback_exceptions=True,
        serve_locally=True,
    )
    app.server.config["MAX_CONTENT_LENGTH"] = 2 * MAX_TOML_BYTES  # a refused file's base64 fits
    app.index_string = app.index_string.replace(
        "{%css%}", "{%css%}<style>" + _STYLE.read_text(encoding="utf-8") + "</style>"
    )
    app.layout = lambda: page(uuid.uuid4().hex, example_choices, machine_choices)
    _guard(app.server, allowed_hosts)
    threading.Thread(target=_import_figures, name="rotomorph-app-imports", daemon=True).start()

    def design_of(data: Any) -> Any:
        design, error = editing.check(data or {})
        if error is not None:
            field, line = error
            raise InvalidParameterError(field, line.removeprefix(f"{field}: "))
        return design

    # ------------------------------------------------------------------ loading a design
    app.clientside_callback(
        _CHECK_UPLOAD,
        Output("upload-checked", "data"),
        Output("upload-error", "children"),
        Input("upload", "contents"),
        State("upload", "filename"),
        prevent_initial_call=True,
    )

    def shown(data: Any, selected: Any, sid: str) -> tuple[Any, ...]:
        """design-error, prediction, plan, plan-box style and band request of a re-rendered
        form (its fields' error lines start empty: an error is said above the form)."""
        _, error, *rest = _derive(data, selected, [], sessions.files(sid))
        return (error, *rest)

    derived = (
        Output("design-error", "children", allow_duplicate=True),
        Output("prediction", "children", allow_duplicate=True),
        Output("plan", "figure", allow_duplicate=True),
        Output("plan-box", "style", allow_duplicate=True),
        Output("band-request", "data", allow_duplicate=True),
    )

    app.clientside_callback(
        _DEBOUNCE_BAND,
        Output("band-go", "data"),
        Input("band-request", "data"),
        prevent_initial_call=True,
    )

    @app.callback(
        Output("design-data", "data"),
        Output("form", "children"),
        Output("upload-error", "children", allow_duplicate=True),
        *derived,
        Input("example", "value"),
        Input("upload-checked", "data"),
        Input("inverse-open", "n_clicks"),
        State("inverse-design", "data"),
        State("sid", "data"),
        prevent_initial_call="initial_duplicate",
    )
    def load(example: Any, upload: Any, _open: Any, inverse: Any, sid: str) -> Any:
        out = _load(example, upload, inverse, sid)
        if out[0] is no_update:
            return (*out, *[no_update] * len(derived))
        return (*out, *shown(out[0], None, sid))

    def _load(example: Any, upload: Any, inverse: Any, sid: str) -> tuple[Any, Any, Any]:
        from rotomorph.io.designfile import parse_design_bytes
        from rotomorph.io.tomlfile import decode_toml_bytes

        try:
            sessions.worker(sid)  # warm the session's worker while the person designs
        except BusyError:
            pass  # every worker computing: this session gets one when it submits a job
        trigger = ctx.triggered_id
        if trigger == "upload-checked" and upload:
            name = str(upload.get("name") or "upload")
            try:
                raw = _decode(str(upload["contents"]))
                parse_design_bytes(raw, name)  # refused exactly as `rotomorph validate` would
                data = decode_toml_bytes(raw, name)
            except RotomorphError as err:
                return no_update, no_update, _message(err)
            return data, render_form(data), ""
        if trigger == "inverse-open" and inverse:
            return inverse, render_form(inverse), ""
        index = example if example is not None else "0" if designs else None
        if index is None or not str(index).isdigit() or int(index) >= len(designs):
            data = {
                "schema_version": 1,
                "filaments": [
                    {
                        "name": "filament",
                        "rotation_number": 0.25,
                        "segments": [{"kind": "line", "length": 30.0}],
                    }
                ],
            }
            return data, render_form(data), ""
        path = designs[int(index)]
        data = decode_toml_bytes(path.read_bytes(), path.name)
        return data, render_form(data), ""

    # ------------------------------------------------------------------ editing
    @app.callback(
        Output("design-data", "data", allow_duplicate=True),
        Output({"type": "error", "path": ALL}, "children"),
        *derived,
        Input({"type": "field", "path": ALL}, "value"),
        State({"type": "field", "path": ALL}, "id"),
        State({"type": "error", "path": ALL}, "children"),
        State("design-data", "data"),
        State("selected-edge", "data"),
        State("sid", "data"),
        prevent_initial_call=True,
    )
    def edit(
        values: list[Any],
        ids: list[dict[str, str]],
        shown_errors: list[Any],
        data: Any,
        selected: Any,
        sid: str,
    ) -> Any:
        # one request per edit: the edited design, its check and its nominal prediction
        paths = [o["id"]["path"] for o in ctx.outputs_list[1]]
        if not data or not ids:
            return (no_update, [no_update] * len(paths), *[no_update] * len(derived))
        new = data
        for value, id_ in zip(values, ids, strict=True):
            new = editing.set_field(new, id_["path"], editing.parse_field(id_["path"], value))
        if new == data:
            return (no_update, [no_update] * len(paths), *[no_update] * len(derived))
        errors, *rest = _derive(new, selected, paths, sessions.files(sid))
        # only the error lines that change are sent (and redrawn)
        same = len(shown_errors) == len(errors)
        errors = [
            no_update if same and (shown_errors[k] or "") == e else e for k, e in enumerate(errors)
        ]
        return (new, errors, *rest)

    @app.callback(
        Output("design-data", "data", allow_duplicate=True),
        Output("form", "children", allow_duplicate=True),
        *derived,
        Input({"type": "seg-add", "fil": ALL, "kind": ALL}, "n_clicks"),
        Input({"type": "seg-remove", "fil": ALL}, "n_clicks"),
        State("design-data", "data"),
        State("selected-edge", "data"),
        State("sid", "data"),
        prevent_initial_call=True,
    )
    def segments(_add: Any, _remove: Any, data: Any, selected: Any, sid: str) -> Any:
        trigger = ctx.triggered_id
        if not isinstance(trigger, dict) or not ctx.triggered[0]["value"]:
            return (no_update, no_update, *[no_update] * len(derived))
        i = int(trigger["fil"])
        fil = data["filaments"][i]
        segs = list(fil.get("segments", []))
        if trigger["type"] == "seg-add":
            segs.append(dict(NEW_SEGMENTS[str(trigger["kind"])]))
        elif len(segs) > 1:
            segs.pop()
        new = editing.set_field(data, f"filaments[{i}].segments", segs)
        return (new, render_form(new), *shown(new, selected, sid))

    @app.callback(
        Output("prediction", "children", allow_duplicate=True),
        Input("band-go", "data"),
        State("design-data", "data"),
        State("sid", "data"),
        prevent_initial_call=True,
    )
    def band(request: Any, data: Any, sid: str) -> Any:
        # the nominal prediction is on the page already: its calibration band, unless a newer
        # edit came in meanwhile
        store = sessions.files(sid)
        if not request or request.get("rev") != store.get("rev"):
            return no_update
        design, error = editing.check(data or {})
        if error is not None:
            return no_update
        lines = _prediction_lines(design, band=True)
        return lines if store.get("rev") == request["rev"] else no_update

    @app.callback(
        Output("selected-edge", "data"),
        Output("edge-title", "children"),
        Output("edge-mode", "value"),
        Output("edge-speed", "value"),
        Input("plan", "clickData"),
        State("design-data", "data"),
        prevent_initial_call=True,
    )
    def pick_edge(click: Any, data: Any) -> Any:
        if not click or not click.get("points"):
            return no_update, no_update, no_update, no_update
        point = click["points"][0]
        if "customdata" not in point:
            return no_update, no_update, no_update, no_update
        edge = int(point["customdata"])
        design = design_of(data)
        modes = editing.edge_modes(design.lattice)
        speeds = design.lattice.edge_speeds or [design.lattice.speed] * len(modes)
        return edge, f"edge {edge}", modes[edge], f"{float(speeds[edge]):g}"

    @app.callback(
        Output("design-data", "data", allow_duplicate=True),
        Output("form", "children", allow_duplicate=True),
        *derived,
        Input("edge-mode", "value"),
        Input("edge-speed", "value"),
        State("selected-edge", "data"),
        State("design-data", "data"),
        State("sid", "data"),
        prevent_initial_call=True,
    )
    def edit_edge(mode: Any, speed: Any, edge: Any, data: Any, sid: str) -> Any:
        nothing = (no_update, no_update, *[no_update] * len(derived))
        if edge is None:
            return nothing
        design, _ = editing.check(data)
        if design is None or design.lattice is None:
            return nothing
        modes = editing.edge_modes(design.lattice)
        speeds = design.lattice.edge_speeds or [design.lattice.speed] * len(modes)
        new_mode = mode if mode != modes[edge] else None
        new_speed = (
            speed
            if speed not in (None, "") and editing.parse_value(speed) != speeds[edge]
            else None
        )
        if new_mode is None and new_speed is None:
            return nothing
        new = editing.set_edge(data, modes, edge, mode=new_mode, speed=new_speed)
        return (new, render_form(new), *shown(new, edge, sid))

    # ------------------------------------------------------------------ jobs
    @app.callback(
        Output("job-status", "children"),
        Output("poll", "disabled"),
        Output("progress", "value", allow_duplicate=True),
        Output("verdicts", "children", allow_duplicate=True),
        Input("simulate", "n_clicks"),
        State("design-data", "data"),
        State("steps", "value"),
        State("sid", "data"),
        prevent_initial_call=True,
    )
    def simulate(_n: Any, data: Any, steps: Any, sid: str) -> Any:
        from rotomorph.simulate.options import check_run_options

        try:
            design = design_of(data)
            count = editing.parse_value(steps)
            check_run_options("lattice" if design.lattice else "filaments", steps=count)
            sessions.submit(
                sid,
                Job("simulate", steps=int(count)),
                {"kind": "simulate", "design": data, "steps": int(count)},
            )
        except (RotomorphError, BusyError) as err:
            return f"not started: {_message(err)}", no_update, no_update, no_update
        return "starting…", False, "0", []  # the last run's progress and verdicts cleared

    @app.callback(
        Output("inverse-status", "children"),
        Output("poll", "disabled", allow_duplicate=True),
        Input("inverse", "n_clicks"),
        State("target-text", "value"),
        State("sid", "data"),
        prevent_initial_call=True,
    )
    def inverse(_n: Any, text: Any, sid: str) -> Any:
        from rotomorph.inverse.targets import parse_target_bytes

        raw = str(text or "").encode("utf-8")
        try:
            parse_target_bytes(raw, "target")  # refused as `rotomorph inverse` refuses a file
            sessions.submit(sid, Job("inverse"), {"kind": "inverse", "target": raw})
        except (RotomorphError, BusyError) as err:
            return f"not started: {_message(err)}", no_update
        return "designing…", False

    @app.callback(
        Output("target-text", "value"),
        Input("target-kind", "value"),
        prevent_initial_call=True,
    )
    def target_template(kind: Any) -> Any:
        return TARGETS.get(str(kind), no_update)

    @app.callback(
        Output("job-status", "children", allow_duplicate=True),
        Input("cancel", "n_clicks"),
        State("sid", "data"),
        prevent_initial_call=True,
    )
    def cancel(_n: Any, sid: str) -> Any:
        sessions.cancel(sid)
        return "cancelled"

    @app.callback(
        Output("progress", "value"),
        Output("progress", "max"),
        Output("job-status", "children", allow_duplicate=True),
        Output("generation", "data"),
        Output("verdicts", "children"),
        Output("drawn", "data"),
        Output("poll", "disabled", allow_duplicate=True),
        Output("inverse-status", "children", allow_duplicate=True),
        Output("inverse-design", "data"),
        Output("inverse-open", "disabled"),
        Input("poll", "n_intervals"),
        State("drawn", "data"),
        State("sid", "data"),
        prevent_initial_call=True,
    )
    def poll(_n: Any, drawn: Any, sid: str) -> Any:
        job = sessions.job(sid)
        keep = [no_update] * 10
        if job is None:
            return [*keep[:6], True, *keep[7:]]
        if job.kind == "inverse":
            done = not job.running
            if job.running:
                status = job.phase
            elif job.state == "done" and job.result:
                status = f"done: {job.result['line']}"
            else:
                status = job.state + (f": {job.error}" if job.error else "")
            design = job.result["design"] if job.state == "done" and job.result else no_update
            return (*keep[:6], done, status, design, job.state != "done")
        steps = job.step_events()
        total = job.steps + 1
        value = sum(1 for e in steps if e["step"] >= 0)
        units = steps[-1]["units"] if steps else 1
        status = _status(job, steps, units)
        generation: Any = no_update
        verdicts: Any = no_update
        if job.generation != drawn:  # something new: the view is drawn by `draw`
            generation = job.generation
            if job.state == "done" and job.result:
                from rotomorph.io.results import read_results

                results = read_results(Path(job.result["folder"]) / "results.h5")
                verdicts = _verdict_rows(views.step_verdicts(results))
            else:
                partial = views.partial_results(job)
                if partial is not None:
                    verdicts = _verdict_rows(views.step_verdicts(partial))
        maximum = total * units
        return (
            str(min(value, maximum)),
            str(maximum),
            status,
            generation,
            verdicts,
            job.generation,
            not job.running,
            *keep[7:],
        )

    @app.callback(
        Output("run-view", "figure"),
        Output("run-shown", "children"),
        Output("run-frames", "data"),
        Input("generation", "data"),
        State("run-frames", "data"),
        State("sid", "data"),
        prevent_initial_call=True,
    )
    def draw(_generation: Any, shown: Any, sid: str) -> Any:
        # apart from `poll`, so that a slow drawing never holds back the progress shown;
        # the caption says which figure is shown: the steps streamed so far, or the run's file.
        # While the run streams, only the steps the page lacks are sent (a Patch).
        job = sessions.job(sid)
        if job is None or job.kind != "simulate":
            return no_update, no_update, no_update
        if job.state == "done" and job.result:
            return views.final_figure(job.result["folder"])[0], FINAL_CAPTION, None
        update = views.stream_update(
            job, shown if isinstance(shown, int) else None, sessions.files(sid)
        )
        if update is None:
            return no_update, no_update, no_update
        return update[0], STREAM_CAPTION, update[1]

    # ------------------------------------------------------------------ files
    @app.callback(
        Output("design-file", "data"),
        Output("design-error", "children", allow_duplicate=True),
        Input("get-design", "n_clicks"),
        State("design-data", "data"),
        prevent_initial_call=True,
    )
    def get_design(_n: Any, data: Any) -> Any:
        try:
            design = design_of(data)
        except RotomorphError as err:
            return no_update, _message(err)
        name = _file_name(design.name, "design") + ".toml"
        return dcc.send_bytes(files.design_bytes(data), name), ""

    @app.callback(
        Output("machine", "options"),
        Output("machine", "value"),
        Output("machine-error", "children"),
        Input("machine-upload", "contents"),
        State("machine-upload", "filename"),
        State("sid", "data"),
        prevent_initial_call=True,
    )
    def machine_upload(contents: Any, name: Any, sid: str) -> Any:
        try:
            raw = _decode(str(contents))
            profile = files.parse_machine_bytes(raw, str(name or "profile.toml"))
        except RotomorphError as err:
            return no_update, no_update, _message(err)
        sessions.files(sid)["machine"] = profile
        options = [{"label": label, "value": v} for v, label in machine_choices]
        options.append({"label": f"uploaded: {profile.name}", "value": "upload"})
        return options, "upload", ""

    def machine_of(choice: Any, sid: str) -> Any:
        return files.machine_profile(str(choice), machine_files, sessions.files(sid).get("machine"))

    @app.callback(
        Output("gcode-file", "data"),
        Output("machine-error", "children", allow_duplicate=True),
        Input("get-gcode", "n_clicks"),
        Input("get-config", "n_clicks"),
        State("design-data", "data"),
        State("machine", "value"),
        State("cure", "value"),
        State("sid", "data"),
        prevent_initial_call=True,
    )
    def get_gcode(_g: Any, _c: Any, data: Any, choice: Any, cure: Any, sid: str) -> Any:
        try:
            design = design_of(data)
            program, config = files.gcode_bytes(design, machine_of(choice, sid), cure=_cure(cure))
        except RotomorphError as err:
            return no_update, _message(err)
        name = _file_name(design.name, "design")
        if ctx.triggered_id == "get-config":
            return dcc.send_bytes(files.controller_zip(config), f"{name}-config.zip"), ""
        return dcc.send_bytes(program, f"{name}.gcode"), ""

    @app.callback(
        Output("toolpath", "figure"),
        Output("machine-error", "children", allow_duplicate=True),
        Input("preview", "n_clicks"),
        Input("machine", "value"),
        State("design-data", "data"),
        State("sid", "data"),
        prevent_initial_call=True,
    )
    def preview(_n: Any, choice: Any, data: Any, sid: str) -> Any:
        from rotomorph.io.gcode import plan_programs

        if ctx.triggered_id == "machine" and not _n:
            return no_update, no_update
        try:
            design = design_of(data)
            machine = machine_of(choice, sid)
            planned = plan_programs(design.to_programs(), machine)
        except RotomorphError as err:
            return no_update, _message(err)
        title = f"{design.name or 'design'} on {machine.name}"  # as `gcode --preview` titles it
        return views.toolpath_figure(planned, design.program_names(), title, machine.lift), ""

    @app.callback(
        Output("run-file", "data"),
        Input("get-h5", "n_clicks"),
        Input("get-summary", "n_clicks"),
        Input("get-run", "n_clicks"),
        State("sid", "data"),
        prevent_initial_call=True,
    )
    def get_run(_a: Any, _b: Any, _c: Any, sid: str) -> Any:
        job = sessions.job(sid)
        if job is None or job.kind != "simulate" or job.state != "done" or not job.result:
            return no_update
        folder = Path(job.result["folder"])
        if ctx.triggered_id == "get-h5":
            return dcc.send_bytes((folder / "results.h5").read_bytes(), "results.h5")
        if ctx.triggered_id == "get-summary":
            return dcc.send_bytes((folder / "summary.json").read_bytes(), "summary.json")
        return dcc.send_bytes(files.folder_zip(folder), "run.zip")

    return app, sessions


def _guard(server: Any, allowed_hosts: frozenset[str] | None) -> None:
    """Host check, safe headers and one-line errors on the Flask server."""
    from flask import request
    from werkzeug.exceptions import HTTPException

    @server.before_request
    def check_host() -> Any:
        if allowed_hosts is None:
            return None
        try:
            host = urlsplit("//" + (request.host or "")).hostname
        except ValueError:
            host = None
        if host not in allowed_hosts:
            return (
                "rotomorph serve: refused: this server answers only to "
                f"{', '.join(sorted(allowed_hosts))}\n",
                403,
                _TEXT,
            )
        return None

    @server.after_request
    def headers(response: Any) -> Any:
        response.headers["X-Content-Type-Options"] = "nosniff"
        response.headers["X-Frame-Options"] = "DENY"
        response.headers["Referrer-Policy"] = "no-referrer"
        return response

    @server.errorhandler(HTTPException)
    def http_error(err: HTTPException) -> Any:
        return f"rotomorph serve: {err.code} {err.name}: {err.description}\n", err.code, _TEXT

    @server.errorhandler(RotomorphError)
    def bad_input(err: RotomorphError) -> Any:
        return f"rotomorph serve: {_message(err)}\n", 400, _TEXT

    @server.errorhandler(Exception)
    def internal(err: Exception) -> Any:
        if _malformed(err):  # the page never sends this: a forged or truncated request
            _log.warning("bad request: %s: %s", type(err).__name__, err)
            return (
                f"rotomorph serve: 400 Bad Request: the request does not fit this page "
                f"({type(err).__name__}); reload the page\n",
                400,
                _TEXT,
            )
        _log.error("request failed", exc_info=err)  # the traceback stays in the server's log
        return (
            f"rotomorph serve: internal error ({type(err).__name__}); "
            "the server's log has the details\n",
            500,
            _TEXT,
        )


def _malformed(err: BaseException) -> bool:
    """Whether ``err`` comes of a request that does not fit the page rather than of a defect:
    Dash refused it (an unknown callback, component or file), or a lookup or type error raised
    in Dash's request handling or in this package's callbacks on the values it carried."""
    from dash.exceptions import DashException

    if isinstance(err, DashException):
        return True
    if not isinstance(err, KeyError | IndexError | TypeError):
        return False
    tb = err.__traceback__
    while tb is not None and tb.tb_next is not None:
        tb = tb.tb_next
    where = Path(tb.tb_frame.f_code.co_filename).as_posix() if tb is not None else ""
    return "/dash/" in where or "/rotomorph/app/" in where


def _import_figures() -> None:
    """Import what the first drawings need (plotly's figure classes, the run viewer, the
    prediction), while the page loads: the first streamed step is then drawn without it."""
    import plotly.graph_objects  # noqa: F401

    import rotomorph.plot.viewer
    import rotomorph.prediction.design  # noqa: F401


def _prediction_lines(design: Any, *, band: bool) -> list[Any]:
    """The prediction panel's lines: nominal only (``band`` False: the band follows), or
    with the calibration band, as ``rotomorph predict`` prints them."""
    from rotomorph.prediction.band import nominal_only
    from rotomorph.prediction.design import predict_design

    if band:
        pred = predict_design(design)
        said = "± calibration band"
    else:
        with nominal_only():
            pred = predict_design(design)
        said = "nominal; its calibration band follows"
    lines = [f"'{pred.name}' at {pred.temperature:g} °C ({said})", *pred.lines()]
    return [html.Div(line, className="prediction-line") for line in lines]


def _derive(data: Any, selected: Any, paths: list[str], store: dict[str, Any]) -> tuple[Any, ...]:
    """What an edit of the design shows, in one answer: the error line of each field in
    ``paths`` (and the one said above the form), the nominal prediction, the lattice's plan
    and whether it is shown, and the request for the prediction's band (or no request).

    ``store`` is the session's server-side store: its ``rev`` names the latest design
    predicted, so that a band asked for an older one is not shown over a newer one.
    """
    design, error = editing.check(data or {})
    errors = ["" for _ in paths]
    rev = uuid.uuid4().hex
    store["rev"] = rev
    if error is not None:
        where = editing.error_field(error[0])
        shown = ""
        if where in paths:
            errors[paths.index(where)] = error[1]
        else:
            shown = error[1]
        waits = [html.Div("prediction waits for a valid design")]
        return errors, shown, waits, no_update, no_update, None
    prediction = _prediction_lines(design, band=False)
    if design.lattice is None:
        # a filament: the plan stays hidden (and is not drawn again: no work in the browser)
        return errors, "", prediction, no_update, {"display": "none"}, {"rev": rev}
    plan = views.lattice_plan(design, editing.edge_modes(design.lattice), selected)
    return errors, "", prediction, plan, {"display": "block"}, {"rev": rev}


def _cure(text: Any) -> float:
    import math

    from rotomorph.io.design_limits import MAX_LAYER_CURE_S

    value = editing.parse_value(text)
    if value is None:
        return 0.0
    if not isinstance(value, int | float) or not (
        0 <= value <= MAX_LAYER_CURE_S and math.isfinite(value)
    ):
        raise InvalidParameterError(
            "--cure", f"must be a UV dwell per layer in [0, {MAX_LAYER_CURE_S:g}] s; got {text!r}"
        )
    return float(value)


def _file_name(name: str, default: str) -> str:
    """A download's file name from a design's name: letters, digits, ``-_.`` only."""
    safe = "".join(c if c.isalnum() or c in "-_." else "_" for c in name)[:60].strip("._")
    return safe or default


def _status(job: Job, steps: list[dict[str, Any]], units: int) -> str:
    if job.state == "done":
        line = job.result.get("line", "") if job.result else ""
        return f"done in {job.first_step_s or 0:.1f} s to the first step; {line}"
    if job.state in ("failed", "cancelled"):
        return job.state + (f": {job.error}" if job.error else "")
    if not steps:
        return f"running: {job.phase}"
    last = steps[-1]
    if last["unit"] == units - 1 and last["step"] == last["steps"]:
        return f"running: {job.phase}"  # every step reached: describing and writing the run
    unit = f"filament {last['unit'] + 1}/{units}, " if units > 1 else ""
    ramp = "°C" if last["ramp"] == "temperature" else "(ramp x)"
    step = f"step {last['step']}/{last['steps']}"
    return f"running: {unit}{step} converged at {last['value']:.4g} {ramp}"


def _verdict_rows(rows: list[tuple[str, str, str]]) -> list[Any]:
    return [
        html.Div(
            f"step {k}: {label}: {word}" + ("" if text == word else f" — {text}"),
            className=f"verdict {word.replace(' ', '-')}",
        )
        for k, (label, word, text) in enumerate(rows)
    ]

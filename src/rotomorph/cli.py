"""The ``rotomorph`` command line: one thin command per public function.

Commands::

    rotomorph validate DESIGN.toml            check a design file (or --schema: print the schema)
    rotomorph gcode DESIGN.toml -o FILE [--machine PROFILE.toml] [--preview]   machine code
    rotomorph gcode --check FILE --machine PROFILE.toml    read a program back and check it
    rotomorph simulate DESIGN.toml -o OUT/    predicted shapes over heating (HDF5, figures, …)
    rotomorph plot RESULT.h5 -o DIR           figures and movie from a results file
    rotomorph view RUN [-o FILE.html]         interactive 3-D viewer of a run (needs plotly)
    rotomorph paper -o OUT/ [--quick]         reproduce the paper's computational figures
    rotomorph sweep SWEEP.toml -o DIR         parameter study (resumable; --scheduler for Dask)
    rotomorph inverse TARGET.toml -o DESIGN.toml   print program for a target shape
    rotomorph predict DESIGN.toml [--json]    closed-form shapes with the calibration band
    rotomorph predict --for curvature=0.4     print settings that give a wanted shape
    rotomorph calibrate TABLES.csv… -o INKS.toml   a lab's own inks from its measurements
    rotomorph serve [--port N] [--no-open]    the designer in the browser (needs [app])

Exit codes: 0 success; 1 the computation failed (solver did not converge);
2 bad input (command line, design file, machine limits, missing file, existing output folder).
Errors print one line on stderr: ``rotomorph: error: <field>: <what is wrong and the fix>``.

Folders (``simulate``, ``plot``, ``paper``) are written into a temporary sibling folder and
renamed at the end, so a failed run leaves no partial output behind.
"""

from __future__ import annotations

import argparse
import contextlib
import importlib.util
import json
import logging
import math
import sys
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

import rotomorph
from rotomorph.errors import (
    ConvergenceError,
    GcodeParseError,
    InvalidParameterError,
    MachineLimitError,
    RotomorphError,
)

__all__ = ["EXIT_FAILED", "EXIT_OK", "EXIT_USAGE", "entry_point", "main"]

EXIT_OK = 0
EXIT_FAILED = 1
EXIT_USAGE = 2
DIALECTS = ("aerotech", "rs274", "marlin")


class UsageError(Exception):
    """Bad input the user can fix (exit code 2)."""


class _Parser(argparse.ArgumentParser):
    """argparse that raises instead of exiting, so ``main`` returns the code."""

    def error(self, message: str) -> None:  # type: ignore[override]
        raise UsageError(f"{message} (see {self.prog} --help)")  # "rotomorph: error:" once


# ----------------------------------------------------------------------------- helpers


def _display(args: argparse.Namespace, desc: str, total: int | None, unit: str) -> Any:
    """Progress of a command (:mod:`rotomorph._progress`): a bar on a terminal, a line every
    10 s elsewhere, the library's ``rotomorph.progress`` messages as its note (each as a line
    with --verbose); nothing with --quiet."""
    from rotomorph._progress import progress_display

    return progress_display(
        desc, total, unit, verbose=args.verbose, quiet=getattr(args, "quiet", False)
    )


class _SafeFormatter(logging.Formatter):
    """Log lines with what a file contributed escaped (:func:`rotomorph._text.terminal_safe`)."""

    def format(self, record: logging.LogRecord) -> str:
        from rotomorph._text import terminal_safe

        return terminal_safe(super().format(record))


def _show_progress() -> bool:
    """The compile note is said at once on a terminal or with --verbose (elsewhere the
    progress lines say it when it takes long)."""
    return sys.stderr.isatty() or logging.getLogger("rotomorph").isEnabledFor(logging.INFO)


#: Commands that run compiled kernels (they say so at once when the kernel cache is cold).
_COMPILING = ("simulate", "paper")


def _announce_compiling(args: argparse.Namespace) -> None:
    """Before a compiling command imports anything heavy (about a second after start): find
    out whether the kernel cache is cold, remember it on ``args`` for
    :func:`_compiling_note`, and on a terminal or with --verbose say "compiling kernels
    (first run only)" at once."""
    args.kernels_cold = False
    if args.command not in _COMPILING or getattr(args, "quiet", False):
        return
    from rotomorph.simulate.kernel_cache import kernels_cached

    if not kernels_cached():
        args.kernels_cold = True
        if _show_progress():
            sys.stderr.write(
                "rotomorph: compiling kernels (first run only; about 20-40 s of CPU, cached "
                "after)\n"
            )
            sys.stderr.flush()


@contextlib.contextmanager
def _compiling_note(args: argparse.Namespace) -> Iterator[None]:
    """While a command runs on a cold kernel cache (:func:`_announce_compiling`): how many
    kernels are ready, as a ``rotomorph.progress`` message (the note of the command's
    progress display: its bar on a terminal, its lines elsewhere) when the count changes, at
    most every 2 s, until the core kernels are cached or the command ends."""
    if not getattr(args, "kernels_cold", False):
        yield
        return
    import threading
    import time

    from rotomorph.simulate.kernel_cache import compiled_count, dispatchers, kernels_cached

    done = threading.Event()
    t0 = time.perf_counter()
    log = logging.getLogger("rotomorph.progress")

    def watch() -> None:
        total = len(dispatchers())
        said, last = -1, t0
        while not done.wait(0.5):
            if kernels_cached():
                log.info("kernels compiled after %.0f s", time.perf_counter() - t0)
                return
            count, now = compiled_count(), time.perf_counter()
            if count != said and now - last >= 2.0:
                log.info("compiling kernels: %d of %d ready", count, total)
                said, last = count, now

    thread = threading.Thread(target=watch, daemon=True)
    thread.start()
    try:
        yield
    finally:
        done.set()
        if thread.is_alive():
            thread.join(timeout=2)


def _existing_file(path: str, what: str) -> Path:
    if not path:
        raise UsageError(f"{what}: empty path; give a file name")
    p = Path(path)
    if not p.exists():
        raise UsageError(f"{what}: {path}: no such file")
    if p.is_dir():
        raise UsageError(f"{what}: {path}: is a folder, expected a file")
    return p


def _load_design(path: str) -> Any:
    from rotomorph.io.designfile import load_design

    return load_design(_existing_file(path, "DESIGN"))


@contextlib.contextmanager
def _output_folder(
    path: str, *, force: bool, inputs: Sequence[Path] = (), previous: str | None = None
) -> Iterator[Path]:
    """Yield a temporary folder next to ``path``; swap it onto ``path`` on success.

    On error (or SIGTERM) the temporary folder is removed and ``path`` is untouched
    (:func:`rotomorph.io.atomic.atomic_folder`). A folder that holds the current folder or one
    of the ``inputs`` (the design file) is never replaced, ``--force`` or not. A non-empty
    folder is replaced only with ``force``, or, for a command ``previous`` that records its
    output (:mod:`rotomorph.io.run_manifest`), when it holds exactly that command's previous
    run.
    """
    from rotomorph.io.atomic import atomic_folder

    if not path:
        raise UsageError("-o/--output: empty path; give a folder name")
    target = Path(path)
    if target.exists() and not target.is_dir():
        raise UsageError(f"-o/--output: {path}: exists and is not a folder")
    if target.is_dir():
        here = target.resolve()
        if Path.cwd().resolve().is_relative_to(here):
            raise UsageError(
                f"-o/--output: {path}: is the current folder or holds it; replacing it would "
                "delete what is in it: give a new folder"
            )
        for item in inputs:
            if item.resolve().is_relative_to(here):
                raise UsageError(
                    f"-o/--output: {path}: holds the input {item}; replacing it would delete "
                    "it: give a new folder"
                )
    if target.is_dir() and any(target.iterdir()) and not force:
        why = "folder is not empty"
        if previous is not None:
            from rotomorph.io.run_manifest import previous_run

            reason = previous_run(target, previous)
            why = "" if reason is None else f"folder is not empty: {reason}"
        if why:
            raise UsageError(f"-o/--output: {path}: {why}; use --force to replace it")
    _check_writable(target, create_parent=True)
    with atomic_folder(target) as tmp:
        yield tmp


def _check_writable(path: Path, *, create_parent: bool, inputs: Sequence[Path] = ()) -> None:
    """Refuse an -o/--output that cannot be written, or that is one of the command's
    ``inputs`` (it would be replaced), before any computation."""
    from rotomorph.io.atomic import check_writable

    for item in inputs:
        if path.exists() and item.exists() and path.resolve() == item.resolve():
            raise UsageError(
                f"-o/--output: {path}: is the input {item}; writing there would replace it: "
                "give another file name"
            )
    check_writable(path, "-o/--output", create_parent=create_parent)


def _print(text: str) -> None:
    """Text on stdout; anything a file contributed is escaped (never a terminal command)."""
    from rotomorph._text import terminal_safe

    sys.stdout.write(terminal_safe(text, newlines=True) + "\n")


#: How to get MP4 movies (said where a GIF is written instead).
MP4_HINT = (
    "for MP4 install ffmpeg (e.g. apt install ffmpeg, conda install -c conda-forge ffmpeg or "
    "brew install ffmpeg) and redraw with rotomorph plot RUN/results.h5 -o RUN/figures"
)


def _say_movie(args: argparse.Namespace, shown: Any = None) -> None:
    """Say in one line, before the figures are drawn, that the movie is a GIF (no ffmpeg)."""
    if args.no_movie:
        return
    from rotomorph.plot.animate import ffmpeg_available

    if ffmpeg_available():
        return
    line = (
        "rotomorph: note: no ffmpeg found: the movie is figures/morphing.gif instead of "
        f"figures/morphing.mp4 ({MP4_HINT})"
    )
    if shown is not None and shown.enabled:
        shown.write(line)
    else:
        sys.stderr.write(line + "\n")


# ----------------------------------------------------------------------------- commands


def _check_materials(programs: list[Any], materials: Any = None) -> None:
    """Every material a program names must be known (raises MaterialError naming it): an ink
    of the design's materials file, or a registered material."""
    from rotomorph.io.gcode import check_materials

    check_materials(programs, materials)


def _cmd_validate(args: argparse.Namespace) -> int:
    from rotomorph.io.designfile import design_schema, design_size

    if args.schema:
        _print(json.dumps(design_schema(), indent=2))
        if args.design is None:
            return EXIT_OK
    if args.design is None:
        raise UsageError("validate: give DESIGN.toml (or --schema)")
    if _is_materials_file(args.design):
        return _validate_materials(args.design)
    # the same path as simulate and gcode: load_design (schema, ranges, size), then programs
    from rotomorph.io.gcode import gcode_text
    from rotomorph.io.placement import check_placement

    design = _load_design(args.design)
    programs = design.to_programs()
    _check_materials(programs, design.material_set)
    machine_note = f"; fits machine {args.machine or 'built-in default'}"
    try:
        check_placement(design, _machine(args, note=False))  # names the design key to change
        gcode_text(programs, _machine(args, note=False), **design.gcode_options())
    except MachineLimitError as err:
        if args.machine is not None:
            raise
        machine_note = f"; note: not printable on the built-in default machine ({err})"
    parts = []
    if design.filaments:
        parts.append(f"{len(design.filaments)} filament(s)")
    if design.lattice is not None:
        lat = design.lattice
        parts.append(f"lattice {lat.n}x{lat.n} '{lat.pattern}' in {lat.layers} layer(s)")
    length = sum(float(p.arc_length[-1]) for p in programs)
    _print(
        f"{args.design}: valid design '{design.name}': {', '.join(parts)}; "
        f"{len(programs)} print program(s), {length:.1f} mm of filament, "
        f"{design_size(design).nodes} rod nodes; sha256 {design.sha256()[:12]}"
        + _materials_note(design.material_set)
        + machine_note
    )
    return EXIT_OK


def _is_materials_file(path: str) -> bool:
    """Whether ``path`` holds a materials file (``[inks]``, no filaments or lattice)."""
    from rotomorph.errors import InvalidDesignError
    from rotomorph.io.tomlfile import read_toml

    try:
        data = read_toml(_existing_file(path, "DESIGN"), InvalidDesignError)
    except (InvalidDesignError, OSError):
        return False  # load_design says why
    return "inks" in data and "filaments" not in data and "lattice" not in data


def _materials_note(materials: Any) -> str:
    if materials is None:
        return ""
    inks = ", ".join(materials.names())
    return f"; materials '{materials.name}' ({inks}; sha256 {materials.sha256[:12]})"


def _validate_materials(path: str) -> int:
    from rotomorph.io.materials_file import load_materials

    inks = load_materials(path)
    kinds = ", ".join(f"{n} ({inks.material(n).kind})" for n in inks.names())
    assumed = sorted({f"{r.owner}.{r.key}" for r in inks.values() if r.provenance == "assumed"})
    _print(
        f"{path}: valid materials file '{inks.name}' version {inks.version}: {kinds}; "
        f"{len(assumed)} assumed value(s); sha256 {inks.sha256[:12]}"
    )
    return EXIT_OK


def _machine(args: argparse.Namespace, *, note: bool = True) -> Any:
    """The --machine profile, else the built-in default (stated on stderr with ``note``)."""
    from rotomorph.io.machine import MachineProfile, load_machine_profile

    dialect = getattr(args, "dialect", None)
    if args.machine is not None:
        machine = load_machine_profile(_existing_file(args.machine, "--machine"))
        if dialect is not None and dialect != machine.dialect:
            raise UsageError(
                f"--dialect {dialect}: the profile {args.machine} is for "
                f"'{machine.dialect}'; change its 'dialect' key or drop --dialect"
            )
        return machine
    machine = MachineProfile(dialect=dialect or "aerotech")
    if note:
        sys.stderr.write(
            "rotomorph: note: no --machine given; using the built-in default machine "
            f"'{machine.name}' ({machine.dialect}, envelope {list(machine.envelope_max)} mm, "
            f"max feed {machine.max_feed:g} mm/s, max rotation {machine.max_rotation:g} rad/s); "
            "stated in the header\n"
        )
    return machine


def _cmd_gcode(args: argparse.Namespace) -> int:
    from rotomorph.io.gcode import plan_programs, write_gcode
    from rotomorph.io.gcode_read import check_gcode
    from rotomorph.io.placement import check_placement

    if args.check is not None:
        if (
            args.design is not None
            or args.output is not None
            or args.preview
            or args.machine_config
        ):
            raise UsageError(
                "--check FILE takes only --machine (no DESIGN, -o, --preview or --machine-config)"
            )
        if args.machine is None:
            raise UsageError("--check FILE needs --machine PROFILE.toml to check against")
        path = _existing_file(args.check, "--check")
        report = check_gcode(path.read_text(encoding="utf-8", errors="replace"), _machine(args))
        _print(
            f"{args.check}: ok: {len(report.filaments)} filament(s), {report.moves} moves, "
            f"rotation <= {report.max_rotation:.4g} rad/s, print feed "
            f"{report.feed_range[0]:.4g}..{report.feed_range[1]:.4g} mm/s, rotary within "
            f"{report.max_start_turns:.3g} turn at filament starts, ~{report.time:.0f} s"
        )
        return EXIT_OK
    if args.design is None or not args.output:
        raise UsageError("gcode: give DESIGN.toml and -o FILE (or --check FILE)")
    design = _load_design(args.design)
    out = Path(args.output)
    if out.is_dir():
        raise UsageError(f"-o/--output: {args.output}: is a folder; give a file name")
    _check_writable(out, create_parent=False, inputs=[Path(args.design)])
    from rotomorph.io.design_limits import MAX_LAYER_CURE_S

    if not (0 <= args.cure <= MAX_LAYER_CURE_S and math.isfinite(args.cure)):
        raise UsageError(
            f"--cure: must be a UV dwell per layer in [0, {MAX_LAYER_CURE_S:g}] s; got "
            f"{args.cure:g} s"
        )
    machine = _machine(args)
    programs = design.to_programs()
    _check_materials(programs, design.material_set)
    options = design.gcode_options()
    check_placement(design, machine)  # a refusal that names filaments[i].start / lattice.origin
    write_gcode(programs, out, machine, **options, layer_cure_s=args.cure)
    _print(f"wrote {out} ({machine.dialect}, {len(programs)} print program(s))")
    _gcode_extras(args, out, machine, options)
    if args.preview:
        _gcode_preview(out, plan_programs(programs, machine), design, machine)
    return EXIT_OK


def _gcode_preview(out: Path, printed: Any, design: Any, machine: Any) -> None:
    """``--preview``: FILE.png and the interactive FILE.preview.html (when plotly is there)."""
    from rotomorph.plot.toolpath import save_toolpath_png

    _print(f"wrote {save_toolpath_png(printed, out.with_suffix('.png'))}")
    if importlib.util.find_spec("plotly") is None:  # an optional extra: the PNG stands alone
        sys.stderr.write(
            "rotomorph: note: no interactive preview (FILE.preview.html needs plotly: "
            "pip install 'rotomorph[html]')\n"
        )
        return
    from rotomorph.plot.toolpath_html import write_toolpath_html

    page = write_toolpath_html(
        printed,
        out.with_suffix(".preview.html"),
        names=design.program_names(),
        title=f"{design.name or out.stem} on {machine.name}",
        lift=machine.lift,
    )
    _print(f"wrote {page}")


def _gcode_extras(args: argparse.Namespace, out: Path, machine: Any, options: Any) -> None:
    """Placeholder warning and the controller configuration of ``gcode`` (after the program)."""
    from rotomorph.io.gcode import placeholder_settings

    unset = placeholder_settings(options["process"])
    if unset:
        sys.stderr.write(
            f"rotomorph: warning: placeholder process values (not set by the design): "
            f"{', '.join(unset)}; set them in its [nozzle] table (flagged in {out}'s header)\n"
        )
    if args.machine_config is not None:
        from rotomorph.io.machine_config import write_machine_config

        text = out.read_text(encoding="ascii")
        for path in write_machine_config(machine, text, args.machine_config):
            _print(f"wrote {path}")


def _cmd_simulate(args: argparse.Namespace) -> int:
    from rotomorph.materials.natural import named_model
    from rotomorph.simulate.design import simulate_design, step_count
    from rotomorph.simulate.options import check_run_options
    from rotomorph.simulate.outputs import run_line, write_run_results
    from rotomorph.simulate.run_data import describe_run

    design = _load_design(args.design)
    options = {
        "steps": args.steps,
        "start_temperature": args.start_temperature,
        "temperature": args.temperature,
        "spacing": args.spacing,
        "actuation": args.actuation,
        "model": None if args.model is None else named_model(args.model),
    }
    try:  # before any output folder exists; named as the user typed them
        check_run_options("lattice" if design.lattice else "filaments", **options)
    except InvalidParameterError as err:
        flag = "--" + err.field.replace("_", "-")
        raise UsageError(f"{flag}: {str(err).split(': ', 1)[1]}") from None
    if args.spacing is not None:  # a filament too short (or a design too large) at that spacing
        from rotomorph.io.designfile import with_spacing

        try:
            with_spacing(design, args.spacing)
        except InvalidParameterError as err:
            raise UsageError(f"--spacing: {err}") from None
    output = _output_folder(args.output, force=args.force, inputs=[Path(args.design)])
    unit = "ramp steps" if design.lattice is not None else "steps"
    with (
        output as tmp,
        _display(args, "simulate", step_count(design, args.steps), unit) as shown,
        _compiling_note(args),
    ):
        sim = simulate_design(
            design,
            steps=args.steps,
            start_temperature=args.start_temperature,
            temperature=args.temperature,
            spacing=args.spacing,
            actuation=args.actuation,
            model=options["model"],
            progress=shown.advance,
        )
        logging.getLogger("rotomorph.progress").info("describing the run (frames, twist, flags)")
        results = describe_run(sim)
        _say_movie(args, shown)
        written = write_run_results(results, tmp, movie=not args.no_movie)
    movie = next(
        (p.name for p in written if p.stem == "morphing" and p.parent.name == "figures"), ""
    )
    _print(
        f"wrote {args.output}: {run_line(results)}" + (f"; movie figures/{movie}" if movie else "")
    )
    return EXIT_OK


def _read_run(path: str, what: str) -> tuple[Path, Any]:
    """A results file, given as the file or as the run folder holding ``results.h5``."""
    from rotomorph.io.results import read_results

    p = Path(path)
    if p.is_dir():
        p = p / "results.h5"
        if not p.exists():
            raise UsageError(f"{what}: {path}: folder has no results.h5")
    p = _existing_file(str(p), what)
    try:
        return p, read_results(p)
    except OSError as err:
        raise UsageError(f"{what}: {path}: not an HDF5 results file ({err})") from None


def _cmd_plot(args: argparse.Namespace) -> int:
    from rotomorph.simulate.outputs import plot_run

    _, results = _read_run(args.result, "RESULT")
    out = Path(args.output or "")
    if not args.output:
        raise UsageError("-o/--output: empty path; give a folder name")
    if out.exists() and not out.is_dir():
        raise UsageError(f"-o/--output: {args.output}: exists and is not a folder")
    _check_writable(out / "shapes.png" if out.is_dir() else out, create_parent=True)
    _say_movie(args)
    paths = plot_run(results, out, movie=not args.no_movie)
    movie = [p.name for p in paths if p.stem == "morphing"]
    _print(
        f"wrote {len(paths)} file(s) to {args.output}" + (f" (movie: {movie[0]})" if movie else "")
    )
    return EXIT_OK


def _cmd_view(args: argparse.Namespace) -> int:
    from rotomorph.plot.viewer import write_viewer

    path, results = _read_run(args.run, "RUN")
    out = Path(args.output) if args.output else path.parent / "view.html"
    if out.is_dir():
        raise UsageError(f"-o/--output: {out}: is a folder; give an .html file name")
    _check_writable(out, create_parent=True, inputs=[path])
    write_viewer(results, out, field=args.field)
    _print(f"wrote {out}")
    if args.open:
        import webbrowser

        webbrowser.open(out.resolve().as_uri())
    return EXIT_OK


def _cmd_paper(args: argparse.Namespace) -> int:
    from rotomorph.io.run_manifest import write_manifest
    from rotomorph.simulate.report import paper_report

    with (
        _output_folder(args.output, force=args.force, previous="paper") as tmp,
        _display(args, "paper", None, "computations") as shown,
        _compiling_note(args),
    ):

        def progress(done: int, total: int) -> None:
            shown.set_total(total)
            shown.advance(done)

        report = paper_report(tmp, quick=args.quick, progress=progress)
        write_manifest(tmp, "paper")
    _print(
        f"wrote {args.output}/report.md and summary.json: {len(report.rows)} rows "
        f"in {report.wall_time:.0f} s"
    )
    if report.summary.get("not_converged"):
        sys.stderr.write(
            "NOT CONVERGED to 1 % between two resolutions (see report.md): "
            + "; ".join(report.summary["not_converged"])
            + "\n"
        )
        return EXIT_OK if args.allow_unconverged else EXIT_FAILED
    return EXIT_OK


def _cmd_inverse(args: argparse.Namespace) -> int:
    from rotomorph.inverse.run import inverse_file

    target = _existing_file(args.target, "TARGET")
    out = Path(args.output)
    if not args.output or out.suffix != ".toml":
        raise UsageError("-o/--output: give the design file to write, ending in .toml")
    if out.exists() and not args.force:
        raise UsageError(f"-o/--output: {args.output}: exists; use --force to replace it")
    _check_writable(out, create_parent=True, inputs=[target])
    from rotomorph.inverse.targets import load_target

    spec = load_target(str(target))  # checked here: a bad file is refused before any work
    lattice = spec.kind != "curve"  # a lattice's optimiser reports its iterations
    total = spec.options.max_iterations if lattice else None
    with _display(args, "inverse", total, "iterations (at most)" if lattice else "") as shown:

        def progress(iteration: int, objective: float) -> None:
            shown.set_note(f"iteration {iteration}: objective {objective:.4g}")
            shown.set_done(iteration)

        text = inverse_file(target, out, progress=progress)
    _print(text)
    return EXIT_OK


def _cmd_calibrate(args: argparse.Namespace) -> int:
    from rotomorph.materials.lab_calibration import CalibrationSettings
    from rotomorph.simulate.ink_calibration import calibrate_files

    tables = [_existing_file(p, "MEASUREMENTS") for p in args.measurements]
    out = Path(args.output)
    if not args.output or out.suffix != ".toml":
        raise UsageError("-o/--output: give the materials file to write, ending in .toml")
    if out.exists() and not args.force:
        raise UsageError(f"-o/--output: {args.output}: exists; use --force to replace it")
    _check_writable(out, create_parent=True, inputs=tables)
    folder = out.with_name(out.stem + "_calibration")
    if any(t.resolve().is_relative_to(folder.resolve()) for t in tables):
        raise UsageError(f"-o/--output: {folder} (the report folder) holds an input table")
    name = args.name or "".join(c if c.isalnum() or c in "_.+-" else "-" for c in out.stem)
    settings = CalibrationSettings(
        name=name.strip("-_.+") or "lab-inks",
        active=args.active,
        passive=args.passive,
        print_temperature=args.print_temperature,
        actuation_temperature=args.actuation_temperature,
        radius=args.radius,
        active_fraction=args.active_fraction,
    )
    for flag, value in (
        ("--print-temperature", args.print_temperature),
        ("--actuation-temperature", args.actuation_temperature),
    ):
        if value is not None and not (math.isfinite(value) and -50.0 <= value <= 300.0):
            raise UsageError(f"{flag}: must lie in [-50, 300] °C; got {value:g}")
    if args.radius is not None and not (math.isfinite(args.radius) and 0.01 <= args.radius <= 10):
        raise UsageError(f"--radius: must lie in [0.01, 10] mm; got {args.radius:g}")
    if args.active_fraction is not None and not 0.0 < args.active_fraction <= 1.0:
        raise UsageError(f"--active-fraction: must lie in (0, 1]; got {args.active_fraction:g}")
    out.parent.mkdir(parents=True, exist_ok=True)
    with _display(args, "calibrate", None, ""):
        run = calibrate_files(tables, out, settings, lattices=not args.no_lattices)
    _print(run.summary_line())
    _print("what the tables determine (at the fit):")
    for line in run.identifiability_lines():
        _print(f"  {line}")
    return EXIT_OK


# ----------------------------------------------------------------------------- parser


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of ``rotomorph`` (every command has ``--help``)."""
    parser = _Parser(
        prog="rotomorph",
        description="Design, simulate and print shape-morphing active-passive filaments.",
        epilog="Exit codes: 0 ok, 1 computation failed, 2 bad input.",
    )
    parser.add_argument("--version", action="version", version=rotomorph.__version__)
    parser.add_argument("-v", "--verbose", action="store_true", help="log progress details")
    parser.add_argument(
        "-q", "--quiet", action="store_true", help="no progress bar or progress lines"
    )
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)

    p = sub.add_parser("validate", help="check a design file", description="Check a design file.")
    p.add_argument("design", nargs="?", metavar="DESIGN.toml")
    p.add_argument("--schema", action="store_true", help="print the design file's JSON Schema")
    p.add_argument(
        "--machine", metavar="PROFILE.toml", help="also check the G-code against this machine"
    )
    p.set_defaults(func=_cmd_validate)

    p = sub.add_parser(
        "gcode",
        help="write G-code for a design, or check a program",
        description="Write G-code for DESIGN.toml (-o FILE), or read a program back strictly "
        "and check it against a machine profile (--check FILE --machine PROFILE.toml).",
    )
    p.add_argument("design", nargs="?", metavar="DESIGN.toml")
    p.add_argument("-o", "--output", metavar="FILE", help="G-code file to write")
    p.add_argument("--dialect", choices=DIALECTS, help="built-in machine's dialect (no --machine)")
    p.add_argument(
        "--machine", metavar="PROFILE.toml", help="machine profile (see examples/machines)"
    )
    p.add_argument("--cure", type=float, default=0.0, metavar="S", help="UV dwell per layer (s)")
    p.add_argument(
        "--preview",
        action="store_true",
        help="also write FILE.png and FILE.preview.html (toolpath; the page needs plotly)",
    )
    p.add_argument("--check", metavar="FILE", help="check an existing program instead")
    p.add_argument(
        "--machine-config",
        metavar="DIR",
        help="also write the controller-side configuration the program needs into DIR",
    )
    p.set_defaults(func=_cmd_gcode)

    p = sub.add_parser(
        "simulate",
        help="predict shapes over heating",
        description="Predicted shapes over heating: results.h5, summary.json, figures/, "
        "figures/morphing.mp4 and ParaView/VTK files in paraview/.",
    )
    p.add_argument("design", metavar="DESIGN.toml")
    p.add_argument("-o", "--output", required=True, metavar="OUT", help="folder to write")
    p.add_argument(
        "--steps",
        type=int,
        default=8,
        help="heating steps (default 8): filaments in equal steps of actuation (temperatures "
        "crowd around the transition, where the shape changes), lattices in equal steps of "
        "the ramp parameter",
    )
    p.add_argument(
        "--temperature",
        type=float,
        help="final temperature (°C; default 175; filaments and lattices heated by the "
        "program or thermal actuation)",
    )
    p.add_argument(
        "--start-temperature",
        type=float,
        help="print temperature (°C; default 25; as --temperature)",
    )
    p.add_argument("--spacing", type=float, help="filament vertex spacing override (mm)")
    p.add_argument(
        "--model",
        choices=("calibrated", "warner-terentjev", "room-temperature"),
        help="filament materials model (default calibrated, the one 'paper' uses; filaments and "
        "lattices heated by the program or thermal actuation)",
    )
    p.add_argument(
        "--actuation",
        choices=("program", "thermal", "literal", "swapped", "radius", "additive"),
        help="lattice actuation rule (lattices; default program: each line's print program "
        "at the heating temperature; see rotomorph.lattice.actuation)",
    )
    p.add_argument("--no-movie", "--no-gif", action="store_true", help="skip the movie")
    p.add_argument("--force", action="store_true", help="replace a non-empty OUT")
    p.set_defaults(func=_cmd_simulate)

    p = sub.add_parser(
        "plot",
        help="figures from a results file",
        description="Figures and movie from RESULT.h5 (or a run folder) into DIR, created if "
        "missing; files of the same names are replaced, nothing else is touched.",
    )
    p.add_argument("result", metavar="RESULT.h5")
    p.add_argument("-o", "--output", required=True, metavar="DIR", help="folder to write")
    p.add_argument("--no-movie", "--no-gif", action="store_true", help="skip the movie")
    p.set_defaults(func=_cmd_plot)

    p = sub.add_parser(
        "view",
        help="interactive 3-D viewer of a run (HTML)",
        description="Write a self-contained HTML 3-D viewer of a run (a slider over the heating "
        "ramp) and open it in the browser. Needs plotly: pip install 'rotomorph[html]'.",
    )
    p.add_argument("run", metavar="RUN", help="run folder or its results.h5")
    p.add_argument("-o", "--output", metavar="FILE.html", help="default RUN/view.html")
    p.add_argument("--field", default="janus",
                   help="colour by 'janus' (active/passive halves) or a stored field")  # fmt: skip
    p.add_argument("--no-open", dest="open", action="store_false", help="do not open a browser")
    p.set_defaults(func=_cmd_view)

    p = sub.add_parser(
        "paper",
        help="reproduce the paper's computational figures",
        description="Reproduce the paper's computational figures and write OUT/report.md "
        "and OUT/summary.json (measured vs predicted).",
    )
    p.add_argument("-o", "--output", required=True, metavar="OUT", help="folder to write")
    p.add_argument("--quick", action="store_true", help="coarse and fast (for tests)")
    p.add_argument("--force", action="store_true", help="replace a non-empty OUT")
    p.add_argument(
        "--allow-unconverged",
        action="store_true",
        help="exit 0 even if a number is not converged to 1 %% (still reported)",
    )
    p.set_defaults(func=_cmd_paper)

    from rotomorph.sweep.command import add_arguments, command

    p = sub.add_parser("sweep", help="run a parameter study", description=command.__doc__)
    add_arguments(p)
    p.set_defaults(func=command)

    p = sub.add_parser(
        "inverse",
        help="design a print program for a target shape",
        description="Inverse design: a target curve, dome, saddle or height map (TOML) -> a "
        "design file, verified by forward simulation, with figures and summary.json in "
        "<DESIGN>_inverse/.",
    )
    p.add_argument("target", metavar="TARGET.toml")
    p.add_argument("-o", "--output", required=True, metavar="DESIGN.toml")
    p.add_argument("--force", action="store_true", help="replace an existing design file")
    p.set_defaults(func=_cmd_inverse)

    from rotomorph.prediction import command as predict

    p = sub.add_parser(
        "predict",
        help="closed-form shapes, or the settings for a shape",
        description=predict.__doc__,
    )
    predict.add_arguments(p)
    p.set_defaults(func=predict.command)

    p = sub.add_parser(
        "calibrate",
        help="calibrate a lab's own inks from its measurement tables",
        description="Fit the materials model to measurement tables (CSV: quantity, condition, "
        "x, x_unit, value, spread, unit, source; docs/design-files.md) and write a materials "
        "file (INKS.toml) that designs name with materials = 'INKS.toml', and a report in "
        "INKS_calibration/ (identifiability, fits, leave-one-group-out predictions, figures).",
    )
    p.add_argument("measurements", nargs="+", metavar="MEASUREMENTS.csv")
    p.add_argument("-o", "--output", required=True, metavar="INKS.toml")
    p.add_argument("--name", help="name of the materials file (default: from INKS)")
    p.add_argument("--active", metavar="NAME", help="active ink name (default: the tables')")
    p.add_argument("--passive", metavar="NAME", help="passive ink name (default: the tables')")
    p.add_argument("--print-temperature", type=float, metavar="C", help="default 25 °C (assumed)")
    p.add_argument(
        "--actuation-temperature", type=float, metavar="C", help="default 175 °C (assumed)"
    )
    p.add_argument("--radius", type=float, metavar="MM", help="filament radius, default 0.3 mm")
    p.add_argument("--active-fraction", type=float, help="active share, default 0.5")
    p.add_argument(
        "--no-lattices", action="store_true", help="skip the lattice validation ramps (slow)"
    )
    p.add_argument("--force", action="store_true", help="replace an existing materials file")
    p.set_defaults(func=_cmd_calibrate)
    from rotomorph.app import command as serve

    p = sub.add_parser("serve", help="the designer in the browser", description=serve.DESCRIPTION)
    serve.add_arguments(p)
    p.set_defaults(func=serve.command)
    return parser


class _Terminated(BaseException):
    """SIGTERM (``timeout``, batch schedulers), raised so that temporaries are cleaned up."""


@contextlib.contextmanager
def _sigterm_raises() -> Iterator[None]:
    """While running a command, SIGTERM unwinds like Ctrl-C (exit status 143)."""
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def handler(signum: int, frame: Any) -> None:
        raise _Terminated()

    previous = signal.signal(signal.SIGTERM, handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


def main(argv: Sequence[str] | None = None) -> int:
    """Run ``rotomorph`` with ``argv`` (default ``sys.argv[1:]``) and return the exit code."""
    with _sigterm_raises():
        return _main(argv)


def _main(argv: Sequence[str] | None) -> int:
    parser = build_parser()
    try:
        args = parser.parse_args(None if argv is None else list(argv))
        if args.command is None:
            parser.print_help(sys.stderr)
            return EXIT_USAGE
        handler = logging.StreamHandler()
        handler.setFormatter(_SafeFormatter("rotomorph: %(levelname)s: %(message)s"))
        logging.basicConfig(
            level=logging.INFO if args.verbose else logging.WARNING, handlers=[handler]
        )
        _announce_compiling(args)
        return int(args.func(args))
    except SystemExit as exc:  # --help, --version
        return int(exc.code or 0) if isinstance(exc.code, int) else EXIT_OK
    except UsageError as err:
        return _fail(str(err), EXIT_USAGE)
    except (InvalidParameterError, GcodeParseError) as err:
        return _fail(str(err), EXIT_USAGE)
    except ConvergenceError as err:
        return _fail(f"solver: {err}", EXIT_FAILED)
    except MachineLimitError as err:
        return _fail(f"machine limits: {err}", EXIT_USAGE)
    except RotomorphError as err:
        return _fail(str(err), EXIT_FAILED)
    except OSError as err:
        name = f"{err.filename}: " if err.filename else ""
        return _fail(f"{name}{err.strerror or err}", EXIT_USAGE)
    except KeyboardInterrupt:
        return _fail("interrupted", 130)
    except _Terminated:
        return _fail("terminated (SIGTERM); no partial output left behind", 143)


def _fail(message: str, code: int) -> int:
    from rotomorph._text import terminal_safe

    line = terminal_safe(" ".join(message.split()))
    sys.stderr.write(f"rotomorph: error: {line}\n")
    return code


def entry_point() -> None:
    """Console-script entry point (``rotomorph``)."""
    raise SystemExit(main())

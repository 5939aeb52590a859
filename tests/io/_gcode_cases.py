"""The programs the G-code referee and static tests check (a helper module, not tests).

Every example design, a 6 × 6 dome lattice (the largest program: 8 300 lines) and ``arcs``, a
design of arcs joined to lines and ending on an arc at a coarse 1 mm spacing (where a chord's
heading differs most from the arc's tangent). Each program is built once per test process and
only when a test asks for it, so a pytest-xdist worker builds only the cases it runs.
"""

from __future__ import annotations

import functools
import math
from pathlib import Path

import numpy as np

from rotomorph.design.program import PrintProgram
from rotomorph.io.designfile import Design, load_design, parse_design_bytes
from rotomorph.io.gcode import Process, gcode_text, plan_programs
from rotomorph.io.machine import load_machine_profile

ROOT = Path(__file__).parents[2] / "examples"
DESIGNS = sorted((ROOT / "designs").glob("*.toml"))
PROFILES = sorted((ROOT / "machines").glob("*.toml"))
#: The example designs and the 6 x 6 dome.
NAMES = [*(p.stem for p in DESIGNS), "lattice_dome_6x6"]

#: Arcs (radius 60 mm and 30 mm) between lines, and a filament that ends on an arc; the nozzle
#: tracks the heading (a constant interface angle, the active side outer) or turns at a rate.
ARCS_TOML = b"""schema_version = 1
name = "arcs"
[nozzle]
active_pressure = 20.0
passive_pressure = 25.0
prime_dwell = 0.2
release_dwell = 0.1
[[filaments]]
name = "line-arc-line"
speed = 3.0
interface_angle_deg = 30.0
spacing = 1.0
start = [20.0, 20.0, 0.0]
segments = [
    { kind = "line", length = 20.0 },
    { kind = "arc", radius = 60.0, angle_deg = 60.0 },
    { kind = "arc", radius = 30.0, angle_deg = -40.0 },
    { kind = "line", length = 10.0 },
]
[[filaments]]
name = "ends on an arc"
speed = 3.0
active_side = "outer"
spacing = 1.0
start = [20.0, 120.0, 0.0]
segments = [{ kind = "line", length = 10.0 }, { kind = "arc", radius = 60.0, angle_deg = -45.0 }]
[[filaments]]
name = "starts on an arc"
speed = 2.0
interface_angle_deg = -60.0
spacing = 1.0
start = [120.0, 60.0, 0.0]
heading_deg = 90.0
segments = [{ kind = "arc", radius = 60.0, angle_deg = 50.0 }, { kind = "line", length = 5.0 }]
[[filaments]]
name = "rotating on an arc"
speed = 3.0
rotation = 1.0
spacing = 1.0
start = [95.0, 5.0, 0.0]
segments = [{ kind = "arc", radius = 30.0, angle_deg = 90.0 }]
"""


@functools.cache
def design(name: str) -> Design:
    """The design of case ``name``."""
    if name == "arcs":
        return parse_design_bytes(ARCS_TOML, "arcs")
    if name == "lattice_dome_6x6":
        d = load_design(ROOT / "designs" / "lattice_dome.toml")
        return d.model_copy(update={"lattice": d.lattice.model_copy(update={"n": 6})})
    return load_design(ROOT / "designs" / f"{name}.toml")


@functools.cache
def case(name: str) -> tuple[list[PrintProgram], list[Process]]:
    """(programs, process per program) of case ``name``."""
    d = design(name)
    return d.to_programs(), d.gcode_options()["process"]


@functools.cache
def written(
    name: str, profile: Path, cure: float = 20.0
) -> tuple[str, list[PrintProgram], list[Process]]:
    """(program text, the programs as printed, process) of case ``name`` on ``profile``."""
    m = load_machine_profile(profile)
    programs, process = case(name)
    text = gcode_text(programs, m, process=process, layer_cure_s=cure)
    return text, plan_programs(programs, m), process


def curve_tangents(name: str) -> list[np.ndarray]:
    """Heading (rad) of the exact tangent of each filament's designed curve at its vertices.

    From the segments' own geometry (a line's heading; on an arc, perpendicular to the radius
    through the vertex, the centre found from the arc's start and heading), independent of
    the library's tangent code: what a program's C must equal minus the interface angle.
    """
    out = []
    for filament in design(name).filaments:
        pts, owner = filament._points()
        psi = np.empty(len(pts))
        head = math.radians(filament.heading_deg)
        first = 0
        for k, seg in enumerate(filament.segments):
            idx = np.arange(first, first + np.count_nonzero(owner[:-1] == k) + 1)
            if seg.kind == "line":
                psi[idx] = head
            elif seg.kind == "arc":
                turn = 1.0 if seg.angle_deg > 0 else -1.0
                left = np.array([-math.sin(head), math.cos(head)])
                centre = pts[first, :2] + turn * seg.radius * left
                r = pts[idx, :2] - centre
                psi[idx] = np.arctan2(turn * r[:, 0], -turn * r[:, 1])
                head += math.radians(seg.angle_deg)
            else:
                raise ValueError(f"curve_tangents knows lines and arcs, not {seg.kind}")
            first = int(idx[-1])
        out.append(psi)
    return out


def tracked_interface_angles() -> list[np.ndarray | None]:
    """The interface angle α (rad) the design gives each vertex of the ``arcs`` filaments whose
    nozzle tracks the path (None: a filament driven by a rotation rate instead)."""
    out: list[np.ndarray | None] = []
    for filament in design("arcs").filaments:
        pts, owner = filament._points()
        if filament.interface_angle_deg is not None:
            out.append(np.full(len(pts), np.radians(filament.interface_angle_deg)))
        elif filament.active_side == "outer":  # on the side the arc turns away from
            turn = [np.sign(getattr(seg, "angle_deg", 0.0)) for seg in filament.segments]
            arc = np.array([turn[k] for k in owner[:-1]] + [turn[owner[-1]]])
            arc[1:][arc[:-1] != 0] = arc[:-1][arc[:-1] != 0]  # a join takes the arc's side
            out.append(np.pi / 2 * arc)
        else:
            out.append(None)
    return out


def tangent_errors(printed: list[PrintProgram]) -> list[np.ndarray]:
    """C − (tangent − α) (deg, per vertex, within a turn) of each ``arcs`` filament whose
    nozzle tracks the path, ``printed`` in the design's order (nozzle angles as a controller
    read them). A filament printed backward (serpentine) mirrors it: C = tangent + π + α."""
    out = []
    designed = case("arcs")[0]
    rows = zip(printed, designed, curve_tangents("arcs"), tracked_interface_angles(), strict=True)
    for got, prog, tangent, alpha in rows:
        if alpha is None:
            continue
        c = np.asarray(got.nozzle_angle)
        if np.allclose(got.points[0, :2], prog.points[0, :2], atol=1e-4):
            want = tangent - alpha
        else:
            c, want = c[::-1], tangent + np.pi + alpha
        out.append(np.degrees((c - want + np.pi) % (2 * np.pi) - np.pi))
    return out

"""The aerotech dialect is what mecode's documented calls write, word for word after
normalising number formatting.

The expected programs are written here by hand as a mecode user would script the same print
(``absolute``, ``feed``, ``abs_move(x=, y=, C=)``, ``set_pressure``/``toggle_pressure`` for
Nordson, ``set_alicat_pressure`` for Alicat, ``dwell``), with each call's documented output
format: ``G1 F<rate>``, ``G0``/``G1`` + ``X Y Z`` then the other axes sorted, 6 decimals,
``Call setPress P<com> Q<value>``, ``Call togglePress P<com>``,
``Call setAlicatPress P<com> Q<value>``, ``G4 P<time>``. mecode itself is not a dependency.
Numbers are compared after normalising their formatting (to 1e-6; rotary words to 1e-3 deg,
as rotomorph integrates dα/ds along the written, rounded move lengths).
"""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from rotomorph.design.path import Path as PrintPath
from rotomorph.design.path import Sinusoid
from rotomorph.design.program import PrintProgram
from rotomorph.io.gcode import Process, gcode_text
from rotomorph.io.machine import MachineProfile


class MecodeScript:
    """The lines mecode's ``G`` object writes for its documented calls (absolute mode)."""

    def __init__(self) -> None:
        self.lines: list[str] = []

    def write(self, line: str) -> None:
        self.lines.append(line)

    def absolute(self) -> None:
        self.write("G90")

    def feed(self, rate: float) -> None:
        self.write(f"G1 F{rate}")

    def abs_move(self, x=None, y=None, z=None, rapid=False, **kwargs: float) -> None:
        args = [f"{k}{v:.6f}" for k, v in (("X", x), ("Y", y), ("Z", z)) if v is not None]
        args += [f"{k}{kwargs[k]:.6f}" for k in sorted(kwargs)]
        self.write(("G0 " if rapid else "G1 ") + " ".join(args))

    def set_pressure(self, com_port: int, value: float) -> None:
        self.write(f"Call setPress P{com_port} Q{value}")

    def toggle_pressure(self, com_port: int) -> None:
        self.write(f"Call togglePress P{com_port}")

    def set_dispense(self, com_port: int, on: bool) -> None:
        """rotomorph's explicit-state call in place of mecode's ``toggle_pressure`` (a toggle
        inverts every channel after an aborted run); not a mecode call."""
        self.write(f"Call setDispense P{com_port} Q{int(on)}")

    def set_alicat_pressure(self, com_port: int, value: float) -> None:
        self.write(f"Call setAlicatPress P{com_port} Q{value}")

    def dwell(self, time: float) -> None:
        self.write(f"G4 P{time}")


def _normalised(lines: list[str]) -> list[list[object]]:
    """Words of each non-comment line; numbers as floats (compared to 1e-5 below)."""
    out = []
    for line in lines:
        if not line.strip() or line.startswith(";"):
            continue
        words: list[object] = []
        for w in line.split():
            try:
                words.append((w[0], float(w[1:])))
            except ValueError:
                words.append(w)
        out.append(words)
    return out


def _mecode_print(
    prog: PrintProgram,
    idiom: str,
    pressures: tuple[float, float],
    prime: float,
    lift: float,
    *,
    toggle: bool = False,
) -> list[str]:
    """mecode's calls for the print; ``toggle`` writes mecode's own Nordson toggles (as a lab's
    mecode script does) instead of rotomorph's explicit ``setDispense``."""

    def dispense(port: int, on: bool) -> None:
        if toggle:
            g.toggle_pressure(port)
        else:
            g.set_dispense(port, on)

    g = MecodeScript()
    g.write("G71")
    g.write("G76")
    g.absolute()
    g.write("VELOCITY ON")  # blending: the A3200 does not stop at every vertex
    if not toggle:  # every channel set off before the first move
        for port in (5, 6):
            if idiom == "nordson":
                dispense(port, False)
            else:
                g.set_alicat_pressure(port, 0)
    x0, y0, z0 = prog.points[0]
    angle = np.degrees(prog.nozzle_angle)
    g.feed(20)  # travel as mecode travels: G1 at the profile's travel feed
    g.abs_move(z=z0 + lift)
    g.abs_move(x=x0, y=y0)
    g.abs_move(z=z0, C=angle[0])  # lower while turning to the start angle
    for port, psi in ((5, pressures[0]), (6, pressures[1])):
        if idiom == "nordson":
            g.set_pressure(port, psi)
            dispense(port, True)
        else:
            g.set_alicat_pressure(port, psi)
    g.dwell(prime)
    g.feed(3)
    for (x, y, _z), c in zip(prog.points[1:], angle[1:], strict=True):
        g.abs_move(x=x, y=y, C=c)
    for port in (5, 6):
        if idiom == "nordson":
            dispense(port, False)
        else:
            g.set_alicat_pressure(port, 0)
    g.feed(20)
    g.abs_move(z=z0 + lift)
    g.write("M2")
    return g.lines


def _programs() -> dict[str, PrintProgram]:
    line = PrintPath.line((10, 10, 0), (14, 10, 0), 0.25)
    sine = PrintPath.from_segments([Sinusoid(1.0, 5.0, 2)], start=(10, 20, 0), spacing=0.1)
    return {
        "straight": PrintProgram.from_rotation(line, 3.0, 10.0),  # ω* = 1
        "sinusoid": PrintProgram.sinusoid_with_active_side(sine, 3.0, "outer", flip_length=0.5),
    }


@pytest.mark.parametrize("idiom", ["nordson", "alicat"])
@pytest.mark.parametrize("shape", ["straight", "sinusoid"])
def test_aerotech_matches_mecode_calls(shape, idiom):
    prog = _programs()[shape]
    machine = MachineProfile(dialect="aerotech", pressure_idiom=idiom, travel_feed=20.0)
    start = abs(prog.nozzle_angle[0])
    assert start * 20.0 / machine.lift <= machine.max_rotation  # lowering at the travel feed
    ours = gcode_text([prog], machine, process=Process(30.0, 25.0, prime_dwell=0.5))
    expected = _mecode_print(prog, idiom, (30.0, 25.0), 0.5, machine.lift)
    program = [ln for ln in ours.splitlines() if not ln.startswith(("DVAR", ";"))]
    got = _normalised(program[: program.index("M2") + 1])  # the DFS library follows M2
    want = _normalised(expected)
    assert len(got) == len(want)
    for a, b in zip(got, want, strict=True):  # the same words; numbers to the 6th decimal
        assert len(a) == len(b), (a, b)
        for u, w in zip(a, b, strict=True):
            if isinstance(u, tuple) and isinstance(w, tuple):
                # rotary words carry dα/ds along the written (rounded) lengths, so they may
                # differ from the design's angle by the rounding of the lengths (< 1e-3 deg)
                tol = 1e-3 if u[0] == "C" else 1.5e-6
                assert u[0] == w[0] and math.isclose(u[1], w[1], abs_tol=tol), (a, b)
            else:
                assert u == w, (a, b)
    # the rotary words are the cumulative nozzle angle: dα/ds · v = ω on the straight line
    if shape == "straight":
        words = [float(c) for c in re.findall(r"^G1 .* C(\S+)$", ours, flags=re.M)]
        assert math.isclose(words[-1], math.degrees(10.0 / 3.0 * 4.0), rel_tol=1e-9)


def test_check_reads_a_mecode_program_without_rotomorph_comments():
    """`gcode --check` reads any program in the dialect, not only rotomorph's own."""
    from rotomorph.io.gcode_read import check_gcode

    prog = _programs()["sinusoid"]
    machine = MachineProfile(dialect="aerotech", pressure_idiom="nordson", travel_feed=20.0)
    lines = _mecode_print(prog, "nordson", (30.0, 25.0), 0.5, machine.lift, toggle=True)
    text = "\n".join(lines) + "\n"
    report = check_gcode(text, machine)
    (filament,) = report.filaments
    assert filament.pressure == {"active": 30.0, "passive": 25.0}
    assert filament.prime_dwell == 0.5
    np.testing.assert_allclose(filament.program.points, prog.points, atol=1e-6)
    assert report.max_rotation <= machine.max_rotation

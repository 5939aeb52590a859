"""Self-contained Aerotech A3200 programs: the variable declarations and pressure subroutines.

An AeroBasic program only compiles if every ``Call name`` has a ``DFS name … ENDDFS`` block in
the same file and every user variable is declared with ``DVAR``. The writer therefore puts
:func:`declarations` before the set-up and :func:`subroutines` after the program's end, for the
pressure idiom of the profile, so a program runs without the lab appending files by hand.

The subroutines (written for rotomorph, in the A3200's AeroBasic) talk to the regulators over
their serial ports; ``P`` is the COM port and ``Q`` the value, as in mecode's calls:

``setAlicatPress P<com> Q<psi>``
    Sends an Alicat set-point command (unit id ``A``, ``AS<psi>`` and a carriage return).
    0 psi is the channel's off state.
``setPress P<com> Q<psi>``
    Sends a Nordson EFD Ultimus pressure-set frame (``PS`` with the pressure in 0.1 psi).
``setDispense P<com> Q<1|0>``
    Sets a Nordson dispenser *to* dispensing (1) or idle (0). The Ultimus only knows a toggle
    (``DI``), so the subroutine keeps each port's state in ``$global[<com>]`` and toggles only
    when the requested state differs: a program that starts with every channel set to 0 is
    right whatever an aborted run left behind, as long as the controller was not restarted
    with a dispenser running (the globals then read 0; docs/gcode.md says what to check).

Each subroutine opens the port, writes and closes it (no nested calls, so ``$P`` and ``$Q`` are
the caller's). Frames of the Ultimus protocol: ENQ, then STX, two digits of length, the command
and its data, a two-digit hex checksum (the two's complement of the byte sum), ETX; then EOT.
"""

from __future__ import annotations

import re

from rotomorph.io.machine import MachineProfile

__all__ = ["CALLS", "declarations", "subroutines"]

#: Subroutines each pressure idiom calls.
CALLS: dict[str, tuple[str, ...]] = {
    "alicat": ("setAlicatPress",),
    "nordson": ("setPress", "setDispense"),
}

#: User variables the subroutines of each idiom use (declared by :func:`declarations`).
_VARIABLES = {"alicat": ("$hFile",), "nordson": ("$hFile", "$sum", "$k", "$frame", "$hex")}

_OPEN = (
    '    $hFile = FILEOPEN "COM" + DBLTOSTR($P, 0), 2',
    '    COMMINIT $hFile, "baud=115200 parity=N data=8 stop=1"',
    "    COMMSETTIMEOUT $hFile, -1, -1, 1000",
)


def _nordson_frame(command: str) -> list[str]:
    """Lines that send the Ultimus frame ``command`` (an AeroBasic string expression holding
    the length digits, the command and its data) to the dispenser on COM port ``$P``."""
    return [
        *_OPEN,
        f"    $frame = {command}",
        "    $sum = 0",
        "    FOR $k = 0 TO STRLEN($frame) - 1",
        "        $sum = $sum + STRTOASCII($frame, $k)",
        "    NEXT $k",
        "    $sum = (256 - ($sum % 256)) % 256",
        '    $hex = STRUPR(MAKESTRING "{#H}" $sum)',
        "    IF STRLEN($hex) < 2 THEN",
        '        $hex = "0" + $hex',
        "    ENDIF",
        '    FILEWRITE $hFile "\\x05"',
        '    FILEWRITE $hFile "\\x02" + $frame + $hex + "\\x03"',
        '    FILEWRITE $hFile "\\x04"',
        "    FILECLOSE $hFile",
    ]


def declarations(m: MachineProfile) -> list[str]:
    """The ``DVAR`` line the profile's pressure subroutines need (none for templates)."""
    if m.dialect != "aerotech" or m.pressure_idiom not in CALLS:
        return []
    return [
        "; rotomorph: variables of the pressure subroutines at the end of this program",
        "DVAR " + " ".join(_VARIABLES[m.pressure_idiom]),
    ]


def subroutines(m: MachineProfile) -> list[str]:
    """``DFS … ENDDFS`` blocks for every subroutine the program calls (after ``M2``)."""
    if m.dialect != "aerotech" or m.pressure_idiom not in CALLS:
        return []
    head = [
        "; rotomorph: pressure subroutines called above (P = COM port, Q = value); serial",
        "; settings 115200 baud 8N1: change them here if your regulators differ",
    ]
    if m.pressure_idiom == "alicat":
        return [
            *head,
            "DFS setAlicatPress",
            *_OPEN,
            '    FILEWRITE $hFile "AS" + DBLTOSTR($Q, 3) + "\\r"',
            "    FILECLOSE $hFile",
            "ENDDFS",
        ]
    return [
        *head,
        "; rotomorph: pressure set-point in psi (the Ultimus takes tenths of a psi, 4 digits)",
        "DFS setPress",
        "    $k = ROUND($Q * 10)",
        "    $hex = DBLTOSTR($k, 0)",
        "    WHILE STRLEN($hex) < 4",
        '        $hex = "0" + $hex',
        "    ENDWHILE",
        *_nordson_frame('"08PS  " + $hex'),
        "ENDDFS",
        "; rotomorph: dispense (Q1) or stop (Q0); the port's last state is kept in $global[P]",
        "DFS setDispense",
        "    IF $global[$P] <> $Q THEN",
        *("    " + line for line in _nordson_frame('"04DI  "')),
        "        $global[$P] = $Q",
        "    ENDIF",
        "ENDDFS",
    ]


_CALL = re.compile(r"^\s*Call\s+(\w+)", re.I)
_DFS = re.compile(r"^\s*DFS\s+(\w+)", re.I)


def undefined_calls(text: str) -> list[str]:
    """Subroutine names called in ``text`` without a ``DFS`` block in the same text."""
    lines = text.splitlines()
    defined = {m[1] for line in lines if (m := _DFS.match(line))}
    return sorted({m[1] for line in lines if (m := _CALL.match(line))} - defined)

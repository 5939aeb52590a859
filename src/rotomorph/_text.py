"""Text that came from a file: refused when it could act on a terminal, escaped where shown.

A name in a design, a machine profile, a sweep or a target file ends up on a terminal (the
command line's messages), in figures, in G-code comments and in an HTML page. Three rules keep
such text from acting on its reader:

* **Refused on input** (:func:`unsafe_characters`, :func:`check_text`): every C0 control
  character (U+0000–U+001F: NUL, BEL, ESC, backspace, carriage return, newline, tab …), DEL
  (U+007F), every C1 control (U+0080–U+009F, e.g. U+009B, the one-byte CSI), the Unicode line
  and paragraph separators (U+2028, U+2029) and the bidirectional formatting characters
  (U+061C, U+200E, U+200F, U+202A–U+202E, U+2066–U+2069: "Trojan source" reordering). A
  free-text ``description`` may keep newlines and tabs (``newlines=True``).
* **Escaped on a terminal** (:func:`terminal_safe`): whatever is not printable becomes its
  Python escape (``\\x1b``, ``\\u202e``), so even text that bypassed validation (a tampered
  results file, a file name) prints as visible characters, never as a terminal command.
* **Escaped for HTML and plotly** (:func:`markup_safe`): ``&``, ``<``, ``>``, quotes become
  entities, so ``<a href=…>`` or ``<span style=…>`` in a name is shown as those characters,
  never as a link or styled text (plotly.js interprets a subset of HTML in every text it
  draws: titles, annotations, hover text, slider labels).

Figures never parse text as mathtext (:func:`rotomorph.plot.figure.literal_text`), so ``$``
in a name is a dollar sign.
"""

from __future__ import annotations

import html
import re
from typing import Final

__all__ = [
    "BIDI_CONTROLS",
    "check_text",
    "describe_character",
    "markup_safe",
    "terminal_safe",
    "unsafe_characters",
]

#: Bidirectional formatting characters (Unicode UAX #9): marks, embeddings, overrides, isolates.
BIDI_CONTROLS: Final = frozenset(
    "\u061c\u200e\u200f\u202a\u202b\u202c\u202d\u202e\u2066\u2067\u2068\u2069"
)
_UNSAFE: Final = re.compile(
    "[\x00-\x1f\x7f-\x9f\u2028\u2029" + "".join(sorted(BIDI_CONTROLS)) + "]"
)
_NAMES: Final = {
    0x00: "NUL",
    0x07: "BEL",
    0x08: "BS",
    0x09: "TAB",
    0x0A: "LF (newline)",
    0x0D: "CR",
    0x1B: "ESC",
    0x7F: "DEL",
    0x9B: "CSI",
    0x2028: "LINE SEPARATOR",
    0x2029: "PARAGRAPH SEPARATOR",
    0x202E: "RIGHT-TO-LEFT OVERRIDE",
    0x202D: "LEFT-TO-RIGHT OVERRIDE",
}


def unsafe_characters(text: str, *, newlines: bool = False) -> list[tuple[int, str]]:
    """``(position, character)`` of every character of ``text`` that is refused (module
    docstring); with ``newlines`` a newline or tab is allowed."""
    found = [(m.start(), m.group()) for m in _UNSAFE.finditer(text)]
    if newlines:
        found = [(i, c) for i, c in found if c not in "\n\t"]
    return found


def describe_character(char: str) -> str:
    """``U+001B (ESC)``-style name of one character."""
    code = ord(char)
    name = _NAMES.get(code)
    if name is None:
        kind = "bidirectional control" if char in BIDI_CONTROLS else "control character"
        name = kind
    return f"U+{code:04X} ({name})"


def check_text(text: str, *, newlines: bool = False) -> str:
    """``text`` if it holds no refused character, else raise :class:`ValueError` saying which.

    The message is one line and shows the text escaped (usable as a pydantic validator).

    Raises
    ------
    ValueError
        ``must not hold control or bidirectional-formatting characters; found U+001B (ESC)
        at position 0 in '\\x1b[2J…'; remove it``.
    """
    bad = unsafe_characters(text, newlines=newlines)
    if not bad:
        return text
    pos, char = bad[0]
    more = f" (and {len(bad) - 1} more)" if len(bad) > 1 else ""
    shown = terminal_safe(text if len(text) <= 60 else text[:57] + "...")
    raise ValueError(
        "must not hold control or bidirectional-formatting characters; found "
        f"{describe_character(char)} at position {pos}{more} in '{shown}'; remove "
        f"{'them' if more else 'it'}"
    )


def terminal_safe(text: str, *, newlines: bool = False) -> str:
    """``text`` with every character that is not printable (controls, bidirectional
    formatting, separators other than the space) written as its Python escape, e.g.
    ``"\\x1b[2J"``: safe to print on any terminal, on one line (with ``newlines``, the
    newlines are kept and each line escaped)."""
    if newlines:
        return "\n".join(terminal_safe(line) for line in text.split("\n"))
    if text.isprintable():
        return text
    return "".join(
        c if c.isprintable() else c.encode("unicode_escape").decode("ascii") for c in text
    )


def markup_safe(text: str) -> str:
    """``text`` for HTML or plotly: ``& < > " '`` as entities and, as on a terminal, every
    character that is not printable escaped; shown literally, never as markup."""
    return html.escape(terminal_safe(text), quote=True)

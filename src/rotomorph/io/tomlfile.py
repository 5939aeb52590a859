"""Reading TOML files people wrote: encodings, size and syntax errors as one-line errors.

TOML is UTF-8 by definition. Editors on some systems save "Unicode" as UTF-16 with a byte-order
mark, and older ones save Latin-1; :func:`read_toml` decodes UTF-8 (with or without a BOM) and
UTF-16/UTF-32 *with* a BOM, and refuses anything else with the byte offset of the first bad
byte and the fix ("save it as UTF-8"), never with a :class:`UnicodeDecodeError` traceback.
"""

from __future__ import annotations

import codecs
from collections.abc import Callable
from pathlib import Path as FilePath
from typing import Any, Final

from rotomorph.errors import InvalidParameterError

try:  # Python >= 3.11
    import tomllib
except ModuleNotFoundError:  # pragma: no cover - Python 3.10
    import tomli as tomllib  # type: ignore[no-redef]

__all__ = ["MAX_TOML_BYTES", "decode_toml_bytes", "read_toml"]

#: Largest TOML file read (bytes): a design or machine profile is a few kB.
MAX_TOML_BYTES: Final = 4 * 1024 * 1024

_BOMS: Final = (
    (codecs.BOM_UTF32_LE, "utf-32-le"),
    (codecs.BOM_UTF32_BE, "utf-32-be"),
    (codecs.BOM_UTF8, "utf-8"),
    (codecs.BOM_UTF16_LE, "utf-16-le"),
    (codecs.BOM_UTF16_BE, "utf-16-be"),
)

ErrorFactory = Callable[[str, str], InvalidParameterError]


def decode_toml_bytes(
    data: bytes, name: str, error: ErrorFactory = InvalidParameterError
) -> dict[str, Any]:
    """Parse TOML from ``data`` (bytes of a file called ``name``); errors via ``error(name, msg)``.

    Raises
    ------
    InvalidParameterError
        (or the class ``error`` builds) for a file over :data:`MAX_TOML_BYTES`, text that is not
        UTF-8 (or UTF-16/32 with a byte-order mark), and TOML syntax errors (with line and column).
    """
    if len(data) > MAX_TOML_BYTES:
        raise error(
            name, f"is {len(data)} bytes; the limit is {MAX_TOML_BYTES} bytes for a TOML file"
        )
    encoding = "utf-8"
    for bom, enc in _BOMS:
        if data.startswith(bom):
            data, encoding = data[len(bom) :], enc
            break
    try:
        text = data.decode(encoding)
    except UnicodeDecodeError as exc:
        raise error(
            name,
            f"is not {encoding.upper()} text (byte 0x{data[exc.start]:02x} at offset {exc.start}); "
            "save it as UTF-8",
        ) from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise error(name, f"is not valid TOML: {exc}") from None
    except RecursionError:
        raise error(name, "is not valid TOML: arrays or tables nested too deeply") from None


def read_toml(path: str | FilePath, error: ErrorFactory = InvalidParameterError) -> dict[str, Any]:
    """Read and parse a TOML file (see :func:`decode_toml_bytes`).

    Raises
    ------
    InvalidParameterError
        As :func:`decode_toml_bytes`, named by the file path.
    OSError
        The file cannot be read.
    """
    with open(path, "rb") as fh:
        data = fh.read(MAX_TOML_BYTES + 1)
    return decode_toml_bytes(data, str(path), error)

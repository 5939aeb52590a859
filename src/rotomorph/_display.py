"""Compact ``repr`` and notebook HTML for the library's value types (no dumped arrays).

:func:`compact_display` is a class decorator: applied on top of ``@dataclass`` it replaces the
generated ``__repr__`` (which prints every array in full) by one line that gives arrays as
``array(101, 3)`` and numbers to 4 significant digits, and adds ``_repr_html_`` (a small table)
for Jupyter::

    >>> program
    PrintProgram(points=array(301, 3), speed=array(301), ..., radius=0.3, layer=0)
"""

from __future__ import annotations

import dataclasses
import html
from collections.abc import Callable, Mapping
from typing import Any, TypeVar

import numpy as np

__all__ = ["compact_display", "describe_value"]

T = TypeVar("T")
_MAX_TEXT = 40


def describe_value(value: Any) -> str:
    """A short text for one attribute: shapes for arrays, 4 digits for numbers."""
    if isinstance(value, np.ndarray):
        shape = ", ".join(str(n) for n in value.shape)
        kind = "" if value.dtype == np.float64 else f", {value.dtype}"
        return f"array({shape}{kind})"
    if isinstance(value, bool | np.bool_) or value is None:
        return repr(value)
    if isinstance(value, float | np.floating):
        return f"{float(value):.4g}"
    if isinstance(value, int | np.integer):
        return str(int(value))
    if isinstance(value, str):
        return repr(value if len(value) <= _MAX_TEXT else value[: _MAX_TEXT - 1] + "…")
    if isinstance(value, tuple | list):
        if len(value) <= 4 and all(isinstance(v, int | float | str | np.ndarray) for v in value):
            inner = ", ".join(describe_value(v) for v in value)
            return f"({inner})" if isinstance(value, tuple) else f"[{inner}]"
        return f"<{len(value)} items>"
    if isinstance(value, Mapping):
        return f"<{len(value)} entries>"
    if dataclasses.is_dataclass(value) or hasattr(value, "__dataclass_fields__"):
        return f"{type(value).__name__}(…)"
    text = repr(value)
    return text if len(text) <= _MAX_TEXT else f"{type(value).__name__}(…)"


def _items(obj: Any, extra: tuple[str, ...]) -> list[tuple[str, str]]:
    names = [f.name for f in dataclasses.fields(obj) if f.repr] + list(extra)
    return [(name, describe_value(getattr(obj, name, None))) for name in names]


def compact_display(*extra: str) -> Callable[[type[T]], type[T]]:
    """Class decorator: compact ``__repr__`` and ``_repr_html_`` for a dataclass.

    Parameters
    ----------
    extra
        Names of properties to show after the fields (e.g. ``"final_ratio"``).
    """

    def decorate(cls: type[T]) -> type[T]:
        def __repr__(self: Any) -> str:
            body = ", ".join(f"{k}={v}" for k, v in _items(self, extra))
            return f"{type(self).__name__}({body})"

        def _repr_html_(self: Any) -> str:
            rows = "".join(
                f"<tr><td style='text-align:left'><code>{html.escape(k)}</code></td>"
                f"<td style='text-align:left'>{html.escape(v)}</td></tr>"
                for k, v in _items(self, extra)
            )
            return f"<table><caption>{html.escape(type(self).__name__)}</caption>{rows}</table>"

        cls.__repr__ = __repr__  # type: ignore[assignment,method-assign]
        cls._repr_html_ = _repr_html_  # type: ignore[attr-defined]
        return cls

    return decorate

"""The field reference of ``docs/design-files.md``, generated from the design file's schema.

``python -m rotomorph.io.design_docs docs/design-files.md`` rewrites the part of that page
between the ``<!-- design-reference: start -->`` and ``<!-- design-reference: end -->`` markers;
a test checks that the page is up to date, so every field, unit and range in the docs is the
one the validator enforces.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any, Final

from rotomorph.io.designfile import design_schema

__all__ = ["END", "START", "reference_markdown", "update_page"]

START: Final = "<!-- design-reference: start -->"
END: Final = "<!-- design-reference: end -->"

_SECTIONS: Final = (
    ("Top level", None),
    ("`[nozzle]`", "Nozzle"),
    ("`[[filaments]]`", "Filament"),
    ('`[[filaments.segments]]` with `kind = "line"`', "LineSegment"),
    ('`[[filaments.segments]]` with `kind = "arc"`', "ArcSegment"),
    ('`[[filaments.segments]]` with `kind = "sinusoid"`', "SinusoidSegment"),
    ('`[[filaments.segments]]` with `kind = "polyline"`', "PolylineSegment"),
    ("`[lattice]`", "LatticeModel"),
    ("`[contact]`", "ContactModel"),
)


def _num(x: float) -> str:
    return f"{x:g}" if isinstance(x, float) else str(x)


def _type(prop: dict[str, Any]) -> str:
    options = [p for p in prop.get("anyOf", [prop]) if p.get("type") != "null"]
    names = []
    for p in options:
        if "$ref" in p:
            names.append("table")
        elif "enum" in p:
            names.append(" \\| ".join(f'`"{v}"`' for v in p["enum"]))
        elif "const" in p:
            names.append(f"`{p['const']!r}`".replace("'", '"'))
        elif p.get("type") == "array":
            items = p.get("items", {})
            if "prefixItems" in p:
                names.append(f"[{len(p['prefixItems'])} numbers]")
            elif "$ref" in items or "oneOf" in items:
                names.append("array of tables")
            elif "enum" in items:
                names.append("array of " + " \\| ".join(f'`"{v}"`' for v in items["enum"]))
            elif items.get("type") == "array":
                names.append("array of [x, y, z]")
            else:
                names.append(f"array of {items.get('type', 'values')}")
        elif p.get("type") == "object":
            names.append("inline table")
        else:
            names.append(str(p.get("type", "value")))
    optional = len(options) < len(prop.get("anyOf", [prop]))
    return " or ".join(names) + (" (optional)" if optional else "")


def _range(prop: dict[str, Any]) -> str:
    p = next((o for o in prop.get("anyOf", [prop]) if o.get("type") != "null"), prop)
    if "prefixItems" in p:
        p = p["prefixItems"][0]
    lo = (
        f"> {_num(p['exclusiveMinimum'])}"
        if "exclusiveMinimum" in p
        else (f">= {_num(p['minimum'])}" if "minimum" in p else "")
    )
    hi = f"<= {_num(p['maximum'])}" if "maximum" in p else ""
    parts = [x for x in (lo, hi) if x]
    if "minLength" in p or "maxLength" in p:
        parts.append(f"{p.get('minLength', 0)}-{p.get('maxLength', '∞')} characters")
    if "minItems" in p and "prefixItems" not in prop.get("anyOf", [prop])[0]:
        parts.append(f">= {p['minItems']} items")
    return ", ".join(parts) or "—"


def _default(prop: dict[str, Any], required: bool) -> str:
    if required:
        return "**required**"
    if "default" not in prop or prop["default"] is None:
        return "—"
    value = prop["default"]
    if isinstance(value, str):
        return f'`"{value}"`' if value else '`""`'
    if isinstance(value, list):
        return "`[" + ", ".join(_num(v) for v in value) + "]`"
    if isinstance(value, dict):
        return "defaults"
    return f"`{_num(value)}`"


def _describe(prop: dict[str, Any]) -> str:
    text = prop.get("description", "")
    if not text:
        p = next((o for o in prop.get("anyOf", [prop]) if o.get("type") != "null"), prop)
        text = p.get("description", "")
        if not text and "prefixItems" in p:
            text = p["prefixItems"][0].get("description", "")
    return text.replace("|", "\\|") or "—"


def reference_markdown() -> str:
    """Markdown tables of every design-file field: type, default, accepted range, meaning."""
    schema = design_schema()
    lines = [
        "Generated from the schema (`rotomorph validate --schema`); ranges are inclusive unless",
        'marked `>`. Numbers are strict: `true`, `"3"` or `1e400` are errors, not numbers; an',
        "integer may stand for a decimal number but not the other way round.",
        "",
    ]
    for title, name in _SECTIONS:
        node = schema if name is None else schema["$defs"][name]
        required = set(node.get("required", []))
        lines += [f"### {title}", "", "| key | type | default | range | meaning |"]
        lines.append("| --- | --- | --- | --- | --- |")
        for key, prop in node["properties"].items():
            row = [
                f"`{key}`",
                _type(prop),
                _default(prop, key in required),
                _range(prop),
                _describe(prop),
            ]
            lines.append("| " + " | ".join(row) + " |")
        lines.append("")
    return "\n".join(lines).rstrip() + "\n"


def update_page(path: str | Path) -> bool:
    """Rewrite the generated part of ``path``; True if it changed."""
    from rotomorph.io.atomic import atomic_write_text

    page = Path(path).read_text(encoding="utf-8")
    head, rest = page.split(START, 1)
    _, tail = rest.split(END, 1)
    new = f"{head}{START}\n{reference_markdown()}{END}{tail}"
    if new != page:
        atomic_write_text(path, new)
    return new != page


if __name__ == "__main__":  # pragma: no cover - maintenance command
    changed = update_page(sys.argv[1] if len(sys.argv) > 1 else "docs/design-files.md")
    print("updated" if changed else "up to date")

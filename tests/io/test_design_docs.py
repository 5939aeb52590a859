"""docs/design-files.md: the field tables are the schema's, and its example is valid."""

from __future__ import annotations

import re
from pathlib import Path

from rotomorph.io.design_docs import END, START, reference_markdown
from rotomorph.io.designfile import parse_design_bytes

PAGE = Path(__file__).parents[2] / "docs" / "design-files.md"


def test_field_tables_are_up_to_date():
    page = PAGE.read_text(encoding="utf-8")
    generated = page.split(START, 1)[1].split(END, 1)[0]
    assert generated == "\n" + reference_markdown(), (
        "run: python -m rotomorph.io.design_docs docs/design-files.md"
    )
    for field in ("rotation_number", "ghost_nodes", "active_pressure", "flip_length"):
        assert f"`{field}`" in generated


def test_the_example_is_a_valid_design():
    toml = re.search(r"```toml\n(.*?)```", PAGE.read_text(encoding="utf-8"), re.S)
    design = parse_design_bytes(toml.group(1).encode())
    assert [f.name for f in design.filaments] == ["w*=0.25", "arc"]

"""The report's Markdown tables render as tables: a ``|`` inside a cell (√|k₁k₂|) stays text.

Rendered by markdown-it-py (the CommonMark/GFM parser the documentation build uses), not by
splitting strings ourselves."""

from __future__ import annotations

from markdown_it import MarkdownIt

from rotomorph.simulate.report import _table_cell


def test_a_pipe_in_a_note_stays_in_its_cell():
    note = "√|k₁k₂| of the branch-node surface fit at mean edge strain −0.12"
    cells = ["lattice_characteristic_curvature", "dome lattice, final", "0.05", note]
    text = "\n".join(
        [
            "| quantity | condition | predicted | note |",
            "| --- | --- | --- | --- |",
            "| " + " | ".join(map(_table_cell, cells)) + " |",
        ]
    )
    html = MarkdownIt("commonmark").enable("table").render(text)
    row = html.split("<tbody>")[1]
    assert row.count("<td>") == 4
    assert f"<td>{note}</td>" in row and "√/" not in html

"""The documentation build runs every example with sphinx-gallery, which executes it as
``__main__`` without ``__file__`` and an empty ``__doc__``; a ``SystemExit`` there ends the whole
build with status 0 and no pages. Each example must run under those conditions."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

EXAMPLES = sorted((Path(__file__).resolve().parents[2] / "examples").glob("*.py"))


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.stem)
def test_example_runs_in_the_gallery(path: Path) -> None:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    assert ast.get_docstring(tree), "the gallery needs a docstring (title and text)"
    for node in ast.walk(tree):
        if isinstance(node, ast.Raise) and "SystemExit" in ast.unparse(node):
            pytest.fail(f"line {node.lineno}: SystemExit ends a documentation build")
        if isinstance(node, ast.Call) and ast.unparse(node.func) == "sys.exit":
            pytest.fail(f"line {node.lineno}: sys.exit ends a documentation build")
        if isinstance(node, ast.Name) and node.id == "__file__":
            pytest.fail(f"line {node.lineno}: __file__ is not defined in the gallery")
        if isinstance(node, ast.Attribute) and ast.unparse(node).startswith("__doc__."):
            pytest.fail(f"line {node.lineno}: __doc__ is empty in the gallery")


def test_published_sweep_page_shows_the_stored_figures() -> None:
    """The gallery does not run the published sweep; the figures its page shows exist."""
    text = (EXAMPLES[0].parent / "published_fig4.py").read_text(encoding="utf-8")
    docs = EXAMPLES[0].parents[1] / "docs"
    for name in ("published_fig4_sweep.png", "published_fig4_shapes.png"):
        assert f"/gallery/{name}" in text
        assert (docs / "gallery" / name).is_file()

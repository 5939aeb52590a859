"""The README's Python examples run as written, in order, each printing something.

They run in a temporary folder holding a copy of ``examples/`` (the blocks read example files
by relative path and write their outputs under ``runs/``), so the checkout stays clean.
"""

from __future__ import annotations

import contextlib
import io
import re
import shutil
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
BLOCKS = re.findall(r"```python\n(.*?)```", README.read_text(encoding="utf-8"), flags=re.S)


def test_readme_has_python_examples():
    assert len(BLOCKS) >= 3


def test_readme_python_blocks_run_in_order(tmp_path, monkeypatch):
    shutil.copytree(ROOT / "examples", tmp_path / "examples")
    monkeypatch.chdir(tmp_path)
    namespace: dict = {}
    for index, block in enumerate(BLOCKS):
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            exec(compile(block, f"README python block {index}", "exec"), namespace)
        assert out.getvalue().strip(), f"README python block {index} printed nothing"
    assert (tmp_path / "runs" / "composite-api" / "results.h5").is_file()
    assert (tmp_path / "runs" / "composite-api.gcode").is_file()

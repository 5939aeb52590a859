"""The documentation site builds without a single warning (``sphinx-build -W``).

The build runs the API reference (numpydoc autodoc of every module), the example gallery
(sphinx-gallery; the examples themselves are executed by their own tests) and the tutorial
notebook, which is executed, so the tutorial cannot rot.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

pytest.importorskip("sphinx")
pytest.importorskip("myst_nb")
pytest.importorskip("sphinx_gallery")
pytest.importorskip("numpydoc")


@pytest.mark.slow
def test_docs_build_without_warnings(tmp_path):
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"), MPLBACKEND="Agg")
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "sphinx",
            "-W",
            "--keep-going",
            "-q",
            "-b",
            "html",
            "-d",
            str(tmp_path / "doctrees"),
            str(ROOT / "docs"),
            str(tmp_path / "html"),
        ],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=900,
    )
    assert proc.returncode == 0, proc.stderr[-6000:]
    html = tmp_path / "html"
    assert (html / "index.html").is_file()
    assert (html / "theory.html").is_file()
    assert (html / "tutorial.html").is_file()
    assert any((html / "api" / "generated").glob("rotomorph.rod.model*.html"))

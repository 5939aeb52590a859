"""Sphinx configuration of the rotomorph documentation.

Build with ``sphinx-build -W -b html docs docs/_build/html`` from the repository root. The
example gallery is generated from ``examples/*.py`` by sphinx-gallery; examples are executed
only when ``ROTOMORPH_DOCS_RUN_EXAMPLES=1`` (the test-suite already runs every example), and
the tutorial notebook is executed on every build.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

import rotomorph  # noqa: E402

project = "rotomorph"
author = "rotomorph developers"
copyright = "2026, rotomorph developers"
release = rotomorph.__version__
version = release

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "sphinx.ext.intersphinx",
    "numpydoc",
    "myst_nb",
    "sphinx_gallery.gen_gallery",
]

source_suffix = {".rst": "restructuredtext", ".md": "myst-nb", ".ipynb": "myst-nb"}
exclude_patterns = ["_build", "gallery_auto/*.ipynb", "**.ipynb_checkpoints", "gallery/*.png"]
root_doc = "index"

myst_enable_extensions = ["dollarmath", "amsmath", "deflist"]
myst_heading_anchors = 3
nb_execution_mode = os.environ.get("ROTOMORPH_DOCS_NB_EXECUTION", "force")
nb_execution_timeout = 600
nb_execution_raise_on_error = True

autosummary_generate = True
autodoc_typehints = "none"
autodoc_member_order = "bysource"
numpydoc_show_class_members = False
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False

intersphinx_mapping: dict[str, tuple[str, None]] = {}

_run_examples = os.environ.get("ROTOMORPH_DOCS_RUN_EXAMPLES", "0") == "1"
sphinx_gallery_conf = {
    "examples_dirs": str(ROOT / "examples"),
    "gallery_dirs": "gallery_auto",
    "filename_pattern": r"/.*\.py" if _run_examples else r"^$",
    "plot_gallery": "True" if _run_examples else "False",
    "download_all_examples": False,
    "within_subsection_order": "FileNameSortKey",
    "remove_config_comments": True,
    "min_reported_time": 10,
}

html_theme = "alabaster"
html_title = f"rotomorph {release}"
html_static_path: list[str] = []
suppress_warnings = ["config.cache"]

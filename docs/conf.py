"""Sphinx configuration of the rotomorph documentation.

Build with ``python -m sphinx -W -q -b html docs docs/_build/html`` from the repository root.
Every build executes the tutorials (MyST notebooks, myst-nb) and the example gallery
(``examples/*.py``, sphinx-gallery) with their small defaults, so what the pages show is what
the code does today. An example writes its figures into ``docs/_build/gallery_outputs/<name>``
(the arguments :func:`gallery_argv` gives it), and :func:`files_scraper` puts each new PNG on
the example's page; the first one is its thumbnail. ``ROTOMORPH_DOCS_RUN_EXAMPLES=0`` skips the
examples (placeholder thumbnails) for a quick look at text changes.

Theme: pydata-sphinx-theme, the theme of NumPy, SciPy, matplotlib and pandas (BSD-3): the
navigation a scientific Python user already knows, a page table of contents, and styles for
sphinx-gallery and notebook outputs.
"""

from __future__ import annotations

import os
import shutil
import sys
from pathlib import Path
from typing import Any

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
exclude_patterns = [
    "_build",
    "gallery_auto/*.ipynb",
    "gallery_auto/*.py",
    "**.ipynb_checkpoints",
    "gallery/*.png",
    "jupyter_execute",
]
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

_run_examples = os.environ.get("ROTOMORPH_DOCS_RUN_EXAMPLES", "1") == "1"
#: Where the gallery's examples write their figures (one folder per example).
GALLERY_OUTPUTS = ROOT / "docs" / "_build" / "gallery_outputs"
#: The arguments each example runs with in the gallery: its small default and where to put the
#: figures (quick modes as the test-suite runs them).
GALLERY_ARGS = {
    "rod_basics": ["--figure", "{out}/rod_basics.png"],
    "stability_modes": ["--figure", "{out}/stability_modes.png"],
    "filaments_vs_paper": ["--figure", "{out}/filaments_vs_paper.png"],
    "lattices_vs_paper": ["--quick", "--figure", "{out}/lattices_vs_paper.png"],
    "fig5_filter_gripper": ["--figure", "{out}/fig5_filter_gripper.png"],
    "sweeps_vs_paper": ["--quick", "-o", "{out}"],
}


def _outputs(src_file: str) -> Path:
    return GALLERY_OUTPUTS / Path(src_file).stem


def gallery_argv(gallery_conf: dict[str, Any], script_vars: dict[str, Any]) -> list[str]:
    """``sys.argv[1:]`` of an example in the gallery (a fresh, empty output folder)."""
    out = _outputs(script_vars["src_file"])
    shutil.rmtree(out, ignore_errors=True)
    out.mkdir(parents=True)
    args = GALLERY_ARGS.get(Path(script_vars["src_file"]).stem, [])
    return [a.format(out=out) for a in args]


class FilesScraper:
    """sphinx-gallery image scraper: the PNG files an example wrote into its output folder
    since the last code block, in name order (the figures a user running it gets)."""

    def __init__(self) -> None:
        self.seen: set[Path] = set()

    def __repr__(self) -> str:  # stable, so sphinx-gallery's config cache key is too
        return "FilesScraper()"

    def __call__(self, block: Any, block_vars: dict[str, Any], gallery_conf: dict[str, Any]) -> str:
        from sphinx_gallery.scrapers import figure_rst

        out = _outputs(block_vars["src_file"])
        new = sorted(p for p in out.rglob("*.png") if p not in self.seen)
        self.seen.update(new)
        images = []
        for png, target in zip(new, block_vars["image_path_iterator"], strict=False):
            shutil.copyfile(png, target)
            images.append(target)
        return figure_rst(images, gallery_conf["src_dir"])


files_scraper = FilesScraper()

sphinx_gallery_conf = {
    "examples_dirs": str(ROOT / "examples"),
    "gallery_dirs": "gallery_auto",
    # every example but the published sweep (25 s of CPU: its page shows the stored figures)
    "filename_pattern": r"/(?!published_fig4)[^/]*\.py$" if _run_examples else r"^$",
    "plot_gallery": "True" if _run_examples else "False",
    "download_all_examples": False,
    "within_subsection_order": "FileNameSortKey",
    "remove_config_comments": True,
    "min_reported_time": 10,
    "reset_argv": gallery_argv,
    "image_scrapers": (files_scraper,),
    "matplotlib_animations": False,
    "capture_repr": (),
    "show_memory": False,
}

html_theme = "pydata_sphinx_theme"
html_title = f"rotomorph {release}"
html_static_path = ["_static"]
html_css_files = ["rotomorph.css"]
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
    "navbar_align": "left",
    "header_links_before_dropdown": 3,  # Tutorials, Examples, Theory; the rest under More
    "secondary_sidebar_items": ["page-toc"],
    "footer_start": ["copyright"],
    "footer_end": ["sphinx-version"],
}
html_sidebars = {"index": [], "changelog": []}
html_show_sourcelink = False
suppress_warnings = ["config.cache"]

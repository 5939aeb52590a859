"""One version everywhere: the package, its metadata, the command line, CITATION.cff, the
changelog and the documentation all say ``rotomorph.__version__``."""

from __future__ import annotations

import re
import sys
from importlib import metadata
from pathlib import Path

import rotomorph
from rotomorph.cli import main

ROOT = Path(__file__).resolve().parents[1]


def _pyproject() -> dict:
    if sys.version_info >= (3, 11):
        import tomllib
    else:  # pragma: no cover - Python 3.10
        import tomli as tomllib
    return tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))


def test_version_is_semantic():
    assert re.fullmatch(r"\d+\.\d+\.\d+", rotomorph.__version__), rotomorph.__version__


def test_pyproject_takes_the_version_from_the_package():
    data = _pyproject()
    assert "version" not in data["project"] and "version" in data["project"]["dynamic"]
    assert data["tool"]["setuptools"]["dynamic"]["version"] == {"attr": "rotomorph.__version__"}


def test_installed_metadata_and_command_line(capsys):
    assert metadata.version("rotomorph") == rotomorph.__version__, (
        "the installed metadata is from an older checkout: pip install -e ."
    )
    assert main(["--version"]) == 0
    assert capsys.readouterr().out.strip() == rotomorph.__version__


def test_changelog_and_citation():
    changelog = (ROOT / "CHANGELOG.md").read_text(encoding="utf-8")
    headings = re.findall(r"^## (.+)$", changelog, flags=re.M)
    released = [h for h in headings if h != "Unreleased"]
    match = re.fullmatch(r"(\d+\.\d+\.\d+) — (\d{4}-\d{2}-\d{2})", released[0])
    assert match, f"CHANGELOG.md: the newest version heading {released[0]!r} is not 'X.Y.Z — date'"
    assert match.group(1) == rotomorph.__version__
    cff = (ROOT / "CITATION.cff").read_text(encoding="utf-8")
    assert re.search(r"^version: (.+)$", cff, flags=re.M).group(1) == rotomorph.__version__
    assert re.search(r"^date-released: (.+)$", cff, flags=re.M).group(1) == match.group(2)


def test_documentation_takes_the_package_version():
    conf = (ROOT / "docs" / "conf.py").read_text(encoding="utf-8")
    assert re.search(r"^release = rotomorph\.__version__$", conf, flags=re.M)
    assert "../CHANGELOG.md" in (ROOT / "docs" / "changelog.md").read_text(encoding="utf-8")
    # no other page states a version of the package
    for page in (ROOT / "docs").glob("*.md"):
        text = page.read_text(encoding="utf-8")
        assert not re.search(r"rotomorph (?:version )?v?\d+\.\d+\.\d+", text), page.name

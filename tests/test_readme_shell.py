"""Every shell command in the README runs verbatim, in order, in a fresh copy of the repository,
in the environment that the README's own install line for it makes.

Each ``bash`` block is governed by the last ``pip install`` line at or before it: the
Quickstart's ``pip install -e ".[test]"`` for the Quickstart, the command line and the
documentation build; the Development block's own ``pip install -e ".[dev]"`` for ruff and
mypy. Two checks follow from that:

* every tool a block calls (``ruff``, ``python -m sphinx``, ``rotomorph``) must be installed by
  its block's install line (the packages of those extras and what they require) or be one of a
  few base tools of every system (:data:`BASE_TOOLS`): a README block needing a tool its
  install line does not provide fails :func:`test_every_readme_tool_comes_from_its_install_line`
  (the ``ruff`` of the Development block was once run in the test extra's environment, and
  passed only where a developer's ``ruff`` happened to be on the PATH);
* the commands of an install line run where that install line is in effect (every package it
  names installed), with the PATH reduced to this Python's folder and the system's base tool
  folders and an empty HOME, so nothing of a developer's shell helps them. Where it is not in
  effect (the Development block in the test extra's environment) that test is skipped with the
  install line in the reason; ``.ci/run`` installs it afterwards and runs it, and
  ``ROTOMORPH_README_INSTALLS`` (what ``.ci/run`` sets) turns such a skip into a failure.

The two commands that install the package and run this very test suite are proven by CI
(``.ci/run`` runs the README's install line and test command, checked here to be the
README's); every other command runs here exactly as written and must exit 0. Among them is the
documentation build with ``-W`` (every warning an error), which executes the example gallery
and the tutorials, so neither can rot; the tutorials' page and the gallery index are then opened
in headless Chromium (a real browser, not a parser): every image loads, the gallery thumbnails
are the examples' own figures (not sphinx-gallery's placeholder) and no code or output block
scrolls sideways.
"""

from __future__ import annotations

import importlib.util
import os
import re
import shlex
import shutil
import subprocess
import sys
from dataclasses import dataclass
from functools import cache
from importlib import metadata
from pathlib import Path

import pytest
from packaging.markers import default_environment
from packaging.requirements import Requirement
from packaging.utils import canonicalize_name

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
CI = ROOT / ".ci" / "run"
#: Commands proven by CI rather than run here (installing, and the suite itself).
SKIP = ("pip install", "python -m pytest", "pytest", ".ci/run", "bash .ci/run")
#: Tools every system has; anything else a README block calls must come from its install line.
BASE_TOOLS = frozenset({"bash", "sh", "cd", "echo", "ls", "cat", "git", "test", "true"})
#: The folders of the system's base tools: the PATH of a README command is this Python's
#: folder (the virtual environment) and these.
SYSTEM_PATH = ("/usr/local/bin", "/usr/bin", "/bin")


# ----------------------------------------------------------------------------- the README


@dataclass(frozen=True)
class Block:
    """One ``bash`` block: its section, its commands and the install line governing it."""

    section: str
    commands: tuple[str, ...]
    install: str | None


def _split(block: str) -> list[str]:
    """Commands of a bash block, in order, split at ``&&``, comments removed."""
    out: list[str] = []
    for line in block.replace("\\\n", " ").splitlines():
        line = re.sub(r"\s+#.*$", "", line).strip()
        if not line or line.startswith("#"):
            continue
        out += [part.strip() for part in line.split("&&") if part.strip()]
    return out


def readme_blocks(text: str) -> list[Block]:
    """The bash blocks of a README, each with its section heading and governing install line
    (the last ``pip install`` command at or before the block's commands)."""
    blocks: list[Block] = []
    install: str | None = None
    section = ""
    fences = r"^```(\w*)\n(.*?)^```[ \t]*$"  # whole fenced blocks first: their "#" lines
    for match in re.finditer(fences + r"|^#{1,6} ([^\n]+)$", text, flags=re.S | re.M):
        if match.group(3) is not None:
            section = match.group(3).strip()
            continue
        if match.group(1) != "bash":
            continue
        commands = _split(match.group(2))
        own = [c for c in commands if c.startswith("pip install")]
        if own:
            install = own[0]
        blocks.append(Block(section, tuple(commands), install))
    return blocks


def shell_commands(text: str) -> list[str]:
    """Commands of the README's bash blocks, in order (:func:`readme_blocks`)."""
    return [c for b in readme_blocks(text) for c in b.commands]


def install_lines(text: str) -> dict[str, str]:
    """Install line -> the section it appears in, in README order."""
    out: dict[str, str] = {}
    for b in readme_blocks(text):
        if b.install is not None and b.install in b.commands:
            out.setdefault(b.install, b.section)
    return out


# ----------------------------------------------------------------------------- packages


def install_extras(install: str) -> tuple[str, ...]:
    """The extras of an editable install of this project: ``pip install -e ".[a,b]"``."""
    words = shlex.split(install)
    targets = [w for w in words[2:] if not w.startswith("-")]
    assert targets and targets[0].split("[")[0] in (".", "./"), (
        f'README install line {install!r}: expected pip install -e ".[extras]"'
    )
    match = re.search(r"\[(.*)\]", targets[0])
    return tuple(e.strip() for e in match.group(1).split(",")) if match else ()


@cache
def _project() -> dict:
    if sys.version_info >= (3, 11):
        import tomllib
    else:  # pragma: no cover - Python 3.10
        import tomli as tomllib
    return tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]


def direct_requirements(extras: tuple[str, ...]) -> list[Requirement]:
    """Requirements that installing this project with ``extras`` names (self-references to
    other extras, ``rotomorph[sweep]``, followed), markers evaluated for this Python."""
    project = _project()
    name = canonicalize_name(project["name"])
    seen: set[str] = set()
    out: list[Requirement] = []
    todo = [(r, "") for r in project["dependencies"]] + [
        (r, e) for e in extras for r in project["optional-dependencies"].get(e, [])
    ]
    for e in extras:
        assert e in project["optional-dependencies"], f"no extra [{e}] in pyproject.toml"
    while todo:
        text, extra = todo.pop()
        req = Requirement(text)
        if req.marker is not None and not req.marker.evaluate({"extra": extra}):
            continue
        if canonicalize_name(req.name) == name:
            for e in req.extras - seen:
                seen.add(e)
                todo += [(r, e) for r in project["optional-dependencies"][e]]
            continue
        out.append(req)
    return out


def missing_requirements(extras: tuple[str, ...]) -> list[str]:
    """The packages of ``extras`` not installed here in a version the requirement allows."""
    missing = []
    for req in direct_requirements(extras):
        try:
            version = metadata.version(req.name)
        except metadata.PackageNotFoundError:
            missing.append(str(req))
            continue
        if req.specifier and not req.specifier.contains(version, prereleases=True):
            missing.append(f"{req} (installed {version})")
    return missing


def installed_closure(extras: tuple[str, ...]) -> set[str]:
    """Canonical names of the installed distributions that installing this project with
    ``extras`` brings: its requirements and, transitively, theirs."""
    env = default_environment()
    todo = [(canonicalize_name(r.name), frozenset(r.extras)) for r in direct_requirements(extras)]
    seen: set[tuple[str, frozenset[str]]] = set()
    names: set[str] = set()
    while todo:
        item = todo.pop()
        if item in seen:
            continue
        seen.add(item)
        name, wanted = item
        try:
            requires = metadata.requires(name) or []
        except metadata.PackageNotFoundError:
            continue
        names.add(name)
        for text in requires:
            req = Requirement(text)
            if req.marker is not None and not any(
                req.marker.evaluate({**env, "extra": e}) for e in (wanted or {""})
            ):
                continue
            todo.append((canonicalize_name(req.name), frozenset(req.extras)))
    return names


@cache
def _script_owners() -> dict[str, set[str]]:
    """Executable name -> distributions installing it, from the entry points (cheap)."""
    scripts: dict[str, set[str]] = {}
    for dist in metadata.distributions():
        name = canonicalize_name(dist.metadata["Name"] or "")
        for ep in dist.entry_points:
            if ep.group in ("console_scripts", "gui_scripts"):
                scripts.setdefault(ep.name, set()).add(name)
    return scripts


@cache
def _file_owners() -> dict[str, set[str]]:
    """Executable name -> distributions whose installed files put it in ``bin/`` (reads every
    distribution's RECORD: only asked for tools that are not entry points, like ruff)."""
    scripts: dict[str, set[str]] = {}
    for dist in metadata.distributions():
        name = canonicalize_name(dist.metadata["Name"] or "")
        for file in dist.files or ():
            parts = Path(str(file)).parts
            if len(parts) >= 2 and parts[-2] == "bin":
                scripts.setdefault(parts[-1], set()).add(name)
    return scripts


def _owners_of(kind: str, name: str) -> set[str]:
    """Distributions that provide the executable or top-level module ``name``."""
    if kind == "module":
        dists = metadata.packages_distributions().get(name, [])
        return {canonicalize_name(d) for d in dists}
    return _script_owners().get(name) or _file_owners().get(name, set())


def tool_of(command: str) -> tuple[str, str]:
    """``("module", name)`` for ``python -m name ...``, else ``("executable", first word)``."""
    words = shlex.split(command)
    if words[0] in ("python", "python3") and len(words) > 2 and words[1] == "-m":
        return "module", words[2].split(".")[0]
    return "executable", words[0]


def unprovided_tools(text: str) -> list[str]:
    """What the README's blocks call that their install lines do not provide (one line each).

    Only blocks whose install line is in effect here can be checked against the installed
    packages (where it is not, the packages that would provide a tool are not there to ask);
    :func:`test_readme_install_lines_in_effect_here` makes sure CI has each one in effect.
    """
    problems = []
    project = canonicalize_name(_project()["name"])
    for block in readme_blocks(text):
        if block.install is None:
            problems.append(f"{block.section}: a bash block before any pip install line")
            continue
        extras = install_extras(block.install)
        if missing_requirements(extras):
            continue
        provided = installed_closure(extras) | {project}
        for command in block.commands:
            if command.startswith("pip install"):
                continue
            kind, name = tool_of(command)
            if kind == "executable" and name in ("python", "python3", "pip", *BASE_TOOLS):
                continue
            if kind == "module" and name in sys.stdlib_module_names:
                continue
            owners = _owners_of(kind, name)
            if not owners & provided:
                source = f"installed by {sorted(owners)}" if owners else "not installed by any"
                problems.append(
                    f"{block.section}: `{command}` needs the {kind} {name!r} ({source} "
                    f"package), which `{block.install}` does not install: add it to that "
                    "extra or give the block its own install line"
                )
    return problems


# ----------------------------------------------------------------------------- tests


def test_readme_has_the_two_quickstart_commands():
    cmds = shell_commands(README.read_text(encoding="utf-8"))
    assert any(c.startswith("pip install") for c in cmds)
    assert any(c.startswith("python -m pytest") for c in cmds)
    assert any(c.startswith("rotomorph ") for c in cmds)
    # the quick answers: a design's closed-form shapes and the settings for a wanted shape
    assert any(c.startswith("rotomorph predict examples/designs/") for c in cmds)
    assert any(c.startswith("rotomorph predict --for ") for c in cmds)


def test_ci_runs_the_readme_quickstart():
    """``.ci/run`` runs the Quickstart's install line and test command and the Development
    install line, as the README writes them."""
    blocks = readme_blocks(README.read_text(encoding="utf-8"))
    quick = next(b for b in blocks if b.section == "Quickstart")
    dev = next(b for b in blocks if b.section == "Development")
    ci = CI.read_text(encoding="utf-8")
    values = dict(re.findall(r"^(README_\w+)='(.*)'$", ci, flags=re.M))
    assert values["README_INSTALL"] == quick.install
    assert values["README_TEST"] in quick.commands
    assert values["README_TEST"].startswith("python -m pytest")
    assert values["README_DEV_INSTALL"] == dev.install
    # it runs them in an environment that is not the caller's
    assert "env -i" in ci and "PATH=/usr/local/bin:/usr/bin:/bin" in ci
    assert "ROTOMORPH_REQUIRE_REFEREES=1" in ci and "REFEREE_PACKAGES=(" in ci


def test_every_readme_tool_comes_from_its_install_line():
    problems = unprovided_tools(README.read_text(encoding="utf-8"))
    assert not problems, "\n".join(problems)


def test_a_tool_missing_from_its_install_line_is_found():
    """The check above can fail: a block calling ``ruff`` under the Quickstart's install line
    (the test extra, which has no ruff) and a block calling a tool no package installs."""
    text = (
        '## Quickstart\n\n```bash\npip install -e ".[test]"\npython -m pytest\n```\n\n'
        "## Lint\n\n```bash\nruff check . && mypy src\n```\n\n"
        "## Movies\n\n```bash\nffmpeg -i a.gif a.mp4\n```\n"
    )
    if missing_requirements(("test",)):
        pytest.skip("needs the test extra installed")
    problems = unprovided_tools(text)
    assert any("Lint: `ruff check .`" in p for p in problems), problems
    assert any("Lint: `mypy src`" in p for p in problems), problems
    assert any("Movies: `ffmpeg" in p and "not installed by any" in p for p in problems), problems
    assert not any("python -m pytest" in p for p in problems), problems
    # with its own install line the Lint block is governed by it (checked where it is in effect)
    dev = 'pip install -e ".[dev]"'
    blocks = readme_blocks(text.replace("```bash\nruff", f"```bash\n{dev}\nruff"))
    assert [b.install for b in blocks] == ['pip install -e ".[test]"', dev, dev]


def _required_installs() -> set[str]:
    """What ``ROTOMORPH_README_INSTALLS`` names (``.ci/run`` sets it, e.g. ``.[dev]``, where
    it has run those install lines): their README commands must run, not be skipped."""
    return set(os.environ.get("ROTOMORPH_README_INSTALLS", "").split())


def test_readme_install_lines_in_effect_here():
    """The install lines ``ROTOMORPH_README_INSTALLS`` names are in effect: every package
    they name is installed."""
    for spec in _required_installs():
        missing = missing_requirements(install_extras(f"pip install -e {spec!r}"))
        assert not missing, f"ROTOMORPH_README_INSTALLS names {spec}, but {missing} missing"


def _tracked_copy(dest: Path) -> None:
    files = subprocess.run(
        ["git", "ls-files", "-z"], cwd=ROOT, capture_output=True, check=True
    ).stdout.split(b"\0")
    for raw in files:
        if not raw:
            continue
        rel = Path(raw.decode())
        src = ROOT / rel
        if src.is_file():
            (dest / rel).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(src, dest / rel)


def _clean_env(home: Path) -> dict[str, str]:
    """The environment of a README command: this Python's folder and the system's tool
    folders on PATH, an empty HOME, the session's result cache, headless matplotlib."""
    env = {
        "PATH": os.pathsep.join((str(Path(sys.executable).parent), *SYSTEM_PATH)),
        "HOME": str(home),
        "LANG": os.environ.get("LANG", "C.UTF-8"),
        "MPLBACKEND": "Agg",
        "PYTHONPATH": str(ROOT / "src"),
    }
    for name in ("ROTOMORPH_CACHE_DIR", "NUMBA_CACHE_DIR", "TMPDIR", "LC_ALL"):
        if name in os.environ:
            env[name] = os.environ[name]
    return env


def _block_params() -> list:
    """One test per bash block with a command to run here. On the xdist workers each is a unit
    of its own (the blocks run in parallel), and the Quickstart's, which runs the full
    ``rotomorph paper``, shares one with the README table test, which computes the same report
    (``tests/conftest.py``, ``SHARED_WORK``)."""
    params = []
    for block in readme_blocks(README.read_text(encoding="utf-8")):
        if not any(not c.startswith(SKIP) for c in block.commands):
            continue
        slug = re.sub(r"[^a-z0-9]+", "-", block.section.lower()).strip("-")
        params.append(pytest.param(block, id=slug))
    return params


#: What a block's commands promise, by section: files that must exist after them.
PROMISED = {
    "Quickstart": ("out/report.md", "out/summary.json", "out/rotomorph-run.json"),
    "The command line": (
        "runs/composite/results.h5",
        "runs/composite/summary.json",
        "runs/composite/view.html",
        "runs/sinusoids.gcode",
        "runs/tendril.toml",
        "runs/sweep/results.parquet",
        "runs/inks.toml",
        "runs/inks_calibration/calibration.md",
    ),
    "Documentation": ("docs/_build/html/index.html", "docs/_build/html/tutorial.html"),
}


@pytest.mark.slow
@pytest.mark.parametrize("block", _block_params())
def test_readme_commands_run_verbatim(block, tmp_path, require_tool):
    """Every command of a README bash block runs as written, in order, in a fresh copy of the
    tracked files, under the install line that governs the block, and exits 0."""
    if shutil.which("git") is None or not (ROOT / ".git").exists():
        pytest.skip("needs a git checkout to copy the tracked files")
    install = block.install
    assert install is not None, f"{block.section}: a bash block before any pip install line"
    missing = missing_requirements(install_extras(install))
    if missing:
        message = f"`{install}` is not in effect here ({', '.join(missing)} missing)"
        if shlex.split(install)[-1] in _required_installs():
            pytest.fail(message + "; ROTOMORPH_README_INSTALLS requires it", pytrace=False)
        pytest.skip(message + "; .ci/run installs it and runs these commands")
    repo = tmp_path / "clone"
    repo.mkdir()
    _tracked_copy(repo)
    home = tmp_path / "home"
    home.mkdir()
    env = _clean_env(home)
    ran = 0
    for cmd in block.commands:
        if cmd.startswith(SKIP):
            continue
        proc = subprocess.run(  # a guard against hangs: the full report is ~13 min of CPU
            ["bash", "-c", cmd], cwd=repo, env=env, capture_output=True, text=True, timeout=2400
        )
        assert proc.returncode == 0, f"README command failed: {cmd}\n{proc.stderr[-3000:]}"
        ran += 1
    assert ran >= 1
    for rel in PROMISED.get(block.section, ()):
        assert (repo / rel).is_file(), f"{block.section}: {rel} missing after its commands"
    if block.section == "Documentation":
        html = repo / "docs" / "_build" / "html"
        assert any((html / "api" / "generated").glob("rotomorph.rod.model*.html"))
        for name in ("filament", "lattice", "gcode", "inverse", "sweeps"):
            assert (html / "tutorials" / f"{name}.html").is_file()
        gallery = (html / "gallery_auto" / "index.html").read_text(encoding="utf-8")
        thumbs = re.findall(r'src="([^"]*thumb[^"]*\.png)"', gallery)
        assert len(thumbs) >= 7, thumbs
        placeholders = _placeholder_thumbnails(tmp_path)
        for thumb in thumbs:
            png = (html / "gallery_auto" / thumb).read_bytes()
            assert png not in placeholders, f"{thumb}: sphinx-gallery's placeholder, not a figure"
        for page in (html / "gallery_auto").glob("*.html"):
            if page.stem not in ("index", "sg_execution_times", "published_fig4"):
                text = page.read_text(encoding="utf-8")
                shown = "sphx-glr-single-img" in text or "sphx-glr-multi-img" in text
                assert shown, f"{page.name}: no figure (not executed)"
        _assert_pages_render(html, require_tool("chromium", "apt-get install chromium"))


def _placeholder_thumbnails(tmp: Path) -> set[bytes]:
    """The thumbnails sphinx-gallery makes where an example drew nothing or failed: its stock
    pictures scaled as it scales them."""
    import sphinx_gallery
    from sphinx_gallery.gen_rst import scale_image

    static = Path(sphinx_gallery.__file__).parent / "_static"
    out = set()
    for stock in ("no_image.png", "broken_example.png"):
        scaled = tmp / f"placeholder_{stock}"
        scale_image(str(static / stock), str(scaled), 400, 280)
        out.add(scaled.read_bytes())
    return out


CHROMIUM_ARGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]


def _assert_pages_render(html: Path, chromium: str) -> None:
    """The tutorials' page, a tutorial and the gallery index in a real browser: a screenshot
    that is not blank, every image loaded, no ``pre`` wider than its box."""
    from PIL import Image
    from playwright.sync_api import sync_playwright

    pages = ["tutorial.html", "tutorials/filament.html", "gallery_auto/index.html"]
    with sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=chromium, args=CHROMIUM_ARGS)
        try:
            page = browser.new_page(viewport={"width": 1280, "height": 900})
            for name in pages:
                page.goto((html / name).resolve().as_uri())
                page.wait_for_load_state("load")
                shot = html.parent / (name.replace("/", "_") + ".png")
                page.screenshot(path=str(shot), full_page=True)
                grey = Image.open(shot).convert("L")
                assert len(set(grey.getdata())) > 50, f"{name}: a blank page"
                broken = page.evaluate(
                    "() => [...document.images].filter(i => !i.complete || i.naturalWidth === 0)"
                    ".map(i => i.getAttribute('src'))"
                )
                assert not broken, f"{name}: images that do not load: {broken}"
                wide = page.evaluate(
                    "() => [...document.querySelectorAll('pre')]"
                    ".filter(e => e.scrollWidth > e.clientWidth + 1).length"
                )
                assert wide == 0, f"{name}: {wide} code blocks scroll sideways"
            shown = page.evaluate(
                "() => [...document.querySelectorAll('.sphx-glr-thumbcontainer img')]"
                ".map(i => i.naturalWidth)"
            )
            assert len(shown) >= 7 and min(shown) > 0, shown
        finally:
            browser.close()


def test_every_runnable_block_has_its_promises_or_none():
    """A renamed README section keeps its promised files checked (or the table is updated)."""
    sections = {b.section for b in readme_blocks(README.read_text(encoding="utf-8"))}
    assert set(PROMISED) <= sections, set(PROMISED) - sections


def test_the_shared_report_units_name_real_tests():
    """``tests/conftest.py`` keeps the README's full ``rotomorph paper`` and the README table
    test on one xdist worker by node id: both ids must exist (a rename would part them)."""
    path = ROOT / "tests" / "conftest.py"
    spec = importlib.util.spec_from_file_location("tests_root_conftest", path)
    assert spec is not None and spec.loader is not None
    root_conftest = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(root_conftest)  # by path: ``conftest`` may name another folder's
    shared_work = root_conftest.SHARED_WORK

    ids = {p.id for p in _block_params()}
    for nodeid in shared_work:
        path, name = nodeid.split("::", 1)
        function, _, param = name.partition("[")
        assert f"def {function}(" in (ROOT / path).read_text(encoding="utf-8"), nodeid
        assert not param or param.rstrip("]") in ids, nodeid


def test_the_shared_report_unit_starts_first():
    """The report unit is the suite's longest: it is sorted before every other test (slow or
    not), so the scheduler hands it out first and its worker is not the last to finish."""
    path = ROOT / "tests" / "conftest.py"
    spec = importlib.util.spec_from_file_location("tests_root_conftest_order", path)
    assert spec is not None and spec.loader is not None
    root_conftest = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(root_conftest)

    class Item:
        def __init__(self, nodeid: str, slow: bool) -> None:
            self.nodeid, self.slow = nodeid, slow

        def get_closest_marker(self, name: str) -> object:
            return object() if name == "slow" and self.slow else None

    shared = list(root_conftest.SHARED_WORK)
    beside = [p + "test_x" for p in root_conftest.BESIDE_THE_REPORT]
    after = root_conftest.AFTER_THE_REPORTS_FILAMENTS[0] + "test_x"
    items = [Item("tests/a.py::fast", False), Item(beside[1], True), Item(after, True)]
    items += [Item("tests/b.py::slow", True), Item(beside[0], True)]
    items += [Item(n, True) for n in reversed(shared)] + [Item("tests/z.py::slow", True)]
    items.sort(key=root_conftest.start_rank)
    assert [i.nodeid for i in items[: len(shared)]] == list(reversed(shared))
    assert [i.nodeid for i in items[len(shared) :]] == [
        *beside,
        "tests/b.py::slow",
        "tests/z.py::slow",
        after,
        "tests/a.py::fast",
    ]
    # the scheduler's first unit is the report's, then those computing parts of it beside it
    assert root_conftest.xdist_scope(items[0].nodeid) == "paper-report"
    assert all(root_conftest.xdist_scope(b) != "paper-report" for b in beside)
    for prefix in root_conftest.BESIDE_THE_REPORT:
        assert (ROOT / prefix.split("::")[0]).is_file(), prefix
    for prefix in root_conftest.AFTER_THE_REPORTS_FILAMENTS:
        assert (ROOT / prefix.split("::")[0]).is_file(), prefix

"""Every shell command in the README runs verbatim, in order, in a fresh copy of the repository.

The two commands that install the package and run this very test-suite are proven by CI
(``.ci/run`` installs from a clean checkout and runs the README's test command); every other
command of every ``bash`` block runs here exactly as written, in a temporary copy of the
tracked files, and must exit 0. Among them is the documentation build with ``-W`` (every
warning an error): the API reference of every module, the example gallery and the tutorial
notebook, which the build executes, so the tutorial cannot rot either.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
SKIP = ("pip install", "python -m pytest", "pytest", ".ci/run", "bash .ci/run")


def shell_commands(text: str) -> list[str]:
    """Commands of the README's bash blocks, in order, split at ``&&``, comments removed."""
    out: list[str] = []
    for block in re.findall(r"```bash\n(.*?)```", text, flags=re.S):
        joined = block.replace("\\\n", " ")
        for line in joined.splitlines():
            line = re.sub(r"\s+#.*$", "", line).strip()
            if not line or line.startswith("#"):
                continue
            out += [part.strip() for part in line.split("&&") if part.strip()]
    return out


def test_readme_has_the_two_quickstart_commands():
    cmds = shell_commands(README.read_text(encoding="utf-8"))
    assert any(c.startswith("pip install") for c in cmds)
    assert any(c.startswith("python -m pytest") for c in cmds)
    assert any(c.startswith("rotomorph ") for c in cmds)
    # the quick answers: a design's closed-form shapes and the settings for a wanted shape
    assert any(c.startswith("rotomorph predict examples/designs/") for c in cmds)
    assert any(c.startswith("rotomorph predict --for ") for c in cmds)


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


@pytest.mark.slow
def test_readme_shell_commands_run_verbatim(tmp_path):
    if shutil.which("git") is None or not (ROOT / ".git").exists():
        pytest.skip("needs a git checkout to copy the tracked files")
    repo = tmp_path / "clone"
    repo.mkdir()
    _tracked_copy(repo)
    env = dict(os.environ, MPLBACKEND="Agg", PYTHONPATH=str(ROOT / "src"))
    env["PATH"] = str(Path(sys.executable).parent) + os.pathsep + env.get("PATH", "")
    ran = 0
    for cmd in shell_commands(README.read_text(encoding="utf-8")):
        if cmd.startswith(SKIP):
            continue
        proc = subprocess.run(
            ["bash", "-c", cmd], cwd=repo, env=env, capture_output=True, text=True, timeout=900
        )
        assert proc.returncode == 0, f"README command failed: {cmd}\n{proc.stderr[-3000:]}"
        ran += 1
    assert ran >= 3
    # what the commands promise is there
    assert (repo / "out" / "report.md").is_file() and (repo / "out" / "summary.json").is_file()
    assert (repo / "runs" / "composite" / "results.h5").is_file()
    assert (repo / "runs" / "composite" / "view.html").is_file()
    assert (repo / "runs" / "inks.toml").is_file()
    assert (repo / "runs" / "inks_calibration" / "calibration.md").is_file()
    html = repo / "docs" / "_build" / "html"
    assert (html / "index.html").is_file() and (html / "tutorial.html").is_file()
    assert any((html / "api" / "generated").glob("rotomorph.rod.model*.html"))

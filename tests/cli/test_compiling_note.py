"""A first run says "compiling kernels (first run only)" before anything else it does."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

DESIGN = Path(__file__).resolve().parents[2] / "examples" / "designs" / "composite_rotation.toml"


def _first_lines(tmp_path: Path, cache: Path, count: int) -> list[str]:
    """The first ``count`` stderr lines of ``rotomorph -v simulate`` with numba's cache in
    ``cache``; the run is stopped there (nothing is compiled or written)."""
    env = {**os.environ, "NUMBA_CACHE_DIR": str(cache), "ROTOMORPH_CACHE_DIR": "off"}
    cmd = [sys.executable, "-m", "rotomorph", "-v", "simulate", str(DESIGN), "--steps", "1"]
    proc = subprocess.Popen(
        [*cmd, "-o", str(tmp_path / "out")],
        stderr=subprocess.PIPE,
        stdout=subprocess.DEVNULL,
        text=True,
        env=env,
    )
    assert proc.stderr is not None
    lines = []
    try:
        for line in proc.stderr:
            lines.append(line)
            if len(lines) == count:
                break
    finally:
        proc.kill()
        proc.wait()
    return lines


def test_cold_cache_says_compiling_first(tmp_path: Path) -> None:
    empty = tmp_path / "numba-cache"
    empty.mkdir()
    first = _first_lines(tmp_path, empty, 1)
    assert first and "compiling kernels (first run only" in first[0]


def test_a_later_command_phase_follows_the_note(tmp_path: Path) -> None:
    empty = tmp_path / "numba-cache"
    empty.mkdir()
    lines = _first_lines(tmp_path, empty, 2)
    assert "compiling kernels" in lines[0]
    assert "compiling kernels (first run only" not in lines[1]  # said once

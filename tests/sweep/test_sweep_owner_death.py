"""Sweep workers die with their owner, even while the owner is an unreaped zombie.

A SIGKILLed process stays a zombie until its parent reaps it, and a zombie still "exists" for
``os.kill(pid, 0)``; workers that only ask that outlive their owner, holding the owner's
stdout and stderr open, so a Python caller reading the owner's pipes waits forever. Here the
test process is the owner's parent and deliberately does not reap it.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from conftest import SWEEP_TOML

HERE = Path(__file__).resolve().parent
SRC = HERE.parents[1] / "src"


def _state(pid: int) -> str | None:
    """The process state letter of ``pid`` (``None`` once it is gone)."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except (FileNotFoundError, ProcessLookupError):
        return None
    return stat[stat.rindex(")") + 2]


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="needs Linux /proc")
def test_workers_exit_within_5_s_of_an_unreaped_sigkilled_owner(tmp_path):
    sweep = tmp_path / "s.toml"
    sweep.write_text(SWEEP_TOML.replace("steps = 2", "steps = 1"), encoding="utf-8")
    pids = tmp_path / "pids"
    pids.mkdir()
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(SRC), str(HERE)])}
    owner = subprocess.Popen(
        [sys.executable, str(HERE / "_owner.py"), str(sweep), str(tmp_path / "out"), str(pids)],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
    )
    try:
        assert owner.stdout is not None
        assert owner.stdout.readline().startswith(b"owner")
        deadline = time.monotonic() + 120
        while len(list(pids.iterdir())) < 2 and time.monotonic() < deadline:
            time.sleep(0.05)
        workers = [int(p.name) for p in pids.iterdir()]
        assert len(workers) == 2, "the workers did not start"
        os.kill(owner.pid, signal.SIGKILL)  # and never wait(): the owner stays a zombie
        t0 = time.monotonic()
        while _state(owner.pid) != "Z" and time.monotonic() - t0 < 5:
            time.sleep(0.01)
        assert _state(owner.pid) == "Z"
        os.kill(owner.pid, 0)  # the zombie passes the old liveness check
        while any(_state(w) not in (None, "Z") for w in workers) and time.monotonic() - t0 < 5:
            time.sleep(0.05)
        alive = [w for w in workers if _state(w) not in (None, "Z")]
        assert not alive, f"workers {alive} outlived their owner by 5 s"
        # nothing holds the owner's pipe any more: the caller reads to the end at once
        rest = owner.stdout.read()  # would block for the workers' 60 s sleep otherwise
        assert time.monotonic() - t0 < 6, rest
    finally:
        for w in [int(p.name) for p in pids.iterdir()]:
            if _state(w) not in (None, "Z"):
                os.kill(w, signal.SIGKILL)
        owner.wait()

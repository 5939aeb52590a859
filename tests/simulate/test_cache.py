"""The report's disk cache: an entry is computed once however many processes ask for it at the
same time (two runs at once, a test suite's workers), and read back by the others."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

from rotomorph.simulate.cache import disk_cached

SCRIPT = textwrap.dedent(
    """
    import sys, time
    from rotomorph.simulate.cache import disk_cached

    def compute():
        with open(sys.argv[1], "a") as fh:
            fh.write("computed\\n")
        time.sleep(1.0)
        return {"value": 42}

    print(disk_cached("test_entry", "k", compute)["value"])
    """
)


def test_concurrent_processes_compute_an_entry_once(tmp_path, monkeypatch):
    cache = tmp_path / "cache"
    log = tmp_path / "computed.log"
    env = {"ROTOMORPH_CACHE_DIR": str(cache)}
    procs = [
        subprocess.Popen(
            [sys.executable, "-c", SCRIPT, str(log)],
            env={**os.environ, **env},
            stdout=subprocess.PIPE,
            text=True,
        )
        for _ in range(3)
    ]
    outs = [p.communicate(timeout=120)[0].strip() for p in procs]
    assert outs == ["42", "42", "42"]
    assert log.read_text().splitlines() == ["computed"]
    # and this process reads it too, without computing
    monkeypatch.setenv("ROTOMORPH_CACHE_DIR", str(cache))
    assert disk_cached("test_entry", "k", lambda: {"value": -1}) == {"value": 42}
    assert len(list(Path(cache).glob("test_entry-*.pickle"))) == 1

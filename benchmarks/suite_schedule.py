"""Benchmark: the test suite's wall time on two workers, predicted from measured test times.

Reads the output of ``python -m pytest --durations=0 -vv`` (lines ``12.34s call
tests/x.py::test_y``; setup, call and teardown of a test are added up) and replays the
xdist scheduling of ``tests/conftest.py`` on ``--workers`` workers: the tests in
``start_rank`` order, grouped into the units of ``xdist_scope``, each worker given its next
unit when it is down to its last pending test (``--pending 1``, the suite's scheduler) or two
(``--pending 2``, xdist's own default). Tests run back to back on their worker; a test that
waits on another worker's cache entry is not modelled (it counts its own measured time).

Prints one JSON line per pending threshold: predicted wall (s), each worker's busy time, the
report unit's worker and the time its last test ends.

Run: ``python benchmarks/suite_schedule.py DURATIONS.log [--workers 2]``. Times measured
under load from other work are wall times: scale them (``--scale``) by the load's factor, or
compare the policies only.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import re
from collections import OrderedDict
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
LINE = re.compile(r"^\s*([0-9.]+)s\s+(setup|call|teardown)\s+(\S+::\S.*?)\s*$")


def _conftest() -> Any:
    spec = importlib.util.spec_from_file_location("suite_conftest", ROOT / "tests" / "conftest.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def read_durations(text: str) -> dict[str, float]:
    """Seconds per node id (setup + call + teardown) from pytest's ``--durations`` lines."""
    out: dict[str, float] = {}
    for line in text.splitlines():
        m = LINE.match(line)
        if m:
            out[m.group(3)] = out.get(m.group(3), 0.0) + float(m.group(1))
    return out


class _Item:
    def __init__(self, nodeid: str, slow: bool) -> None:
        self.nodeid, self.slow = nodeid, slow

    def get_closest_marker(self, name: str) -> object:
        return object() if name == "slow" and self.slow else None


def replay(
    durations: dict[str, float], workers: int, pending: int, slow_above: float = 20.0
) -> dict[str, Any]:
    """Replay the suite's scheduling on ``workers`` workers (module docstring); a test longer
    than ``slow_above`` s stands for one marked slow."""
    conf = _conftest()
    items = [_Item(n, t >= slow_above) for n, t in durations.items()]
    items.sort(key=conf.start_rank)
    units: OrderedDict[str, list[str]] = OrderedDict()
    for item in items:
        units.setdefault(conf.xdist_scope(item.nodeid), []).append(item.nodeid)
    queue = list(units.items())
    # per worker: tests assigned and not yet started, the time its current test ends
    assigned: list[list[str]] = [[] for _ in range(workers)]
    clock = [0.0] * workers
    report_end, report_worker = 0.0, None

    def give(w: int) -> None:
        if queue:
            scope, tests = queue.pop(0)
            assigned[w].extend(tests)
            if scope == "paper-report":
                nonlocal report_worker
                report_worker = w

    for w in range(workers):
        give(w)
    for w in range(workers):
        if len(assigned[w]) <= pending:
            give(w)
    while any(assigned):
        # the worker whose current test ends first runs its next one
        w = min((k for k in range(workers) if assigned[k]), key=lambda k: clock[k])
        nodeid = assigned[w].pop(0)
        clock[w] += durations[nodeid]
        if conf.xdist_scope(nodeid) == "paper-report":
            report_end = clock[w]
        if len(assigned[w]) <= pending:
            give(w)
    return {
        "pending": pending,
        "workers": workers,
        "wall_s": round(max(clock), 1),
        "worker_busy_s": [round(c, 1) for c in clock],
        "total_s": round(sum(durations.values()), 1),
        "report_worker": report_worker,
        "report_unit_ends_s": round(report_end, 1),
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=(__doc__ or "").strip().partition("\n")[0])
    parser.add_argument("durations", type=Path)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--scale", type=float, default=1.0, help="multiply every time by this")
    args = parser.parse_args(argv)
    durations = read_durations(args.durations.read_text(encoding="utf-8", errors="replace"))
    durations = {k: v * args.scale for k, v in durations.items()}
    for pending in (1, 2):
        print(json.dumps(replay(durations, args.workers, pending)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

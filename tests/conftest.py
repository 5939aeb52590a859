"""Session-wide test settings."""

from __future__ import annotations

import os
from typing import Any

import pytest


@pytest.fixture(scope="session", autouse=True)
def _result_cache(tmp_path_factory: pytest.TempPathFactory) -> None:
    """Keep rotomorph's disk cache of report results inside the test run: shared by every
    test of the run, the xdist workers' included (the run's common temporary folder; the
    cache computes an entry once however many processes ask for it at the same time), never
    read from or written to the user's ~/.cache."""
    if "ROTOMORPH_CACHE_DIR" not in os.environ:
        base = tmp_path_factory.getbasetemp()
        if os.environ.get("PYTEST_XDIST_WORKER"):  # base is this worker's: popen-gw0, ...
            base = base.parent
        folder = base / "rotomorph-cache"
        folder.mkdir(exist_ok=True)
        os.environ["ROTOMORPH_CACHE_DIR"] = str(folder)


#: Set to 1 by ``.ci/run``: a referee tool that is missing fails the run instead of skipping.
REQUIRE_REFEREES = os.environ.get("ROTOMORPH_REQUIRE_REFEREES") == "1"


@pytest.fixture(scope="session")
def require_tool():
    """A function ``require_tool(executable, install)`` returning the tool's path.

    Referee tests run software outside the project (a controller's own interpreter, a real
    browser). Where the tool is not installed they are skipped with the install line in the
    reason (``pytest -ra`` lists it); under ``ROTOMORPH_REQUIRE_REFEREES=1`` (what ``.ci/run``
    sets after installing them) a missing tool fails the test, so CI can never pass by
    skipping its referees.
    """
    import shutil

    def _require(executable: str, install: str) -> str:
        path = shutil.which(executable)
        if path is not None:
            return path
        message = f"referee '{executable}' is not installed ({install})"
        if REQUIRE_REFEREES:
            pytest.fail(message + "; ROTOMORPH_REQUIRE_REFEREES=1 requires it", pytrace=False)
        pytest.skip(message + "; .ci/run installs it and requires it")

    return _require


#: Tests that share one heavy computation, kept on one worker one after the other (the
#: second reads the first's cached result instead of waiting for it on another worker): the
#: README's ``rotomorph paper`` and the README table test compute the same report.
SHARED_WORK = {
    "tests/test_readme_shell.py::test_readme_commands_run_verbatim[quickstart]": "paper-report",
    "tests/simulate/test_readme_table.py::test_readme_table_equals_the_report": "paper-report",
}
#: Long, independent tests of one file that may run on different workers (one scope each).
EACH_ITS_OWN = ("tests/test_readme_shell.py::test_readme_commands_run_verbatim[",)


def xdist_scope(nodeid: str) -> str:
    """The unit of work a test belongs to on the xdist workers: its file (module- and
    session-scoped fixtures are then computed once, not once per worker), or its own or a
    shared unit (:data:`SHARED_WORK`, :data:`EACH_ITS_OWN`)."""
    if nodeid in SHARED_WORK:
        return SHARED_WORK[nodeid]
    if nodeid.startswith(EACH_ITS_OWN):
        return nodeid
    return nodeid.split("::", 1)[0]


#: Test files (in this order) that compute, into the run's shared result cache, parts of the
#: report the report unit needs later: the authors' Fig. 4 sweeps (about a third of the
#: report's CPU, needed last) and the counted contact-resolved lattice ramps at the finer
#: resolution. Started second and third, on the other worker, beside the report unit, which
#: then reads them.
BESIDE_THE_REPORT = (
    "tests/simulate/test_report_published_full.py::",
    "tests/lattice/test_lattices_as_printed.py::",
)


#: Test files that read the report's filament rows (``validate_filaments``, cached once for
#: the run: the calibrations and the self-contact sinusoids, which the report unit computes
#: first): started after the other slow tests, when the report unit has them cached, instead of
#: waiting on its lock (or computing them while the report unit waits).
AFTER_THE_REPORTS_FILAMENTS = (
    "tests/cli/test_paper.py::",
    "tests/simulate/test_simulate_matches_report.py::",
)


def start_rank(item: pytest.Item) -> tuple[int, int]:
    """When a test starts (stable sort, lower first): the shared report unit
    (:data:`SHARED_WORK`, the longest unit by far) before everything, so its worker is never
    the last to finish; then :data:`BESIDE_THE_REPORT`, which the scheduler hands to the
    other worker; then the other slow tests while every worker is free, then
    :data:`AFTER_THE_REPORTS_FILAMENTS`; the short ones fill in behind them."""
    if item.nodeid in SHARED_WORK:
        return 0, 0
    for k, prefix in enumerate(BESIDE_THE_REPORT):
        if item.nodeid.startswith(prefix):
            return 1, k
    if item.nodeid.startswith(AFTER_THE_REPORTS_FILAMENTS):
        return 3, 0
    return (2, 0) if item.get_closest_marker("slow") is not None else (4, 0)


@pytest.hookimpl(tryfirst=True)
def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Tests in :func:`start_rank` order: on the xdist workers the long ones start while every
    worker is free and the short ones fill in behind them, instead of one long test starting
    last and running alone."""
    items.sort(key=start_rank)


@pytest.hookimpl(tryfirst=True)
def pytest_xdist_make_scheduler(config: pytest.Config, log: object) -> object:
    """``--dist loadfile`` (pyproject's addopts) with the units of :func:`xdist_scope`, taken in
    collection order (slow tests first). The ``xdist_group`` mark cannot do this: pytest-xdist
    3.8 groups by rewriting node ids, which pytest 9.2 no longer honours, so the mark is
    silently ignored (pytest-dev/pytest-xdist#1386)."""
    if config.getoption("dist") != "loadfile":
        return None
    from xdist.scheduler import LoadScopeScheduling

    class SuiteScheduling(LoadScopeScheduling):
        def _split_scope(self, nodeid: str) -> str:
            return xdist_scope(nodeid)

        def _reschedule(self, node: Any) -> None:
            # a node gets its next unit when it is down to its last test (a worker runs a
            # test once it knows the next one), not while it still holds two or more:
            # xdist's default of two pending tests queues a whole unit behind the report's
            # long unit, and a unit behind a worker's last long test, that the other worker
            # could have run
            if node.shutting_down:
                return
            if not self.workqueue:
                node.shutdown()
                return
            if self._pending_of(self.assigned_work[node]) > 1:
                return
            self._assign_work_unit(node)

    config.option.loadscopereorder = False  # keep the collection order: slow units first
    return SuiteScheduling(config, log)  # type: ignore[arg-type]


@pytest.fixture(scope="session")
def vtk():
    """VTK's own Python package (the readers ParaView uses), a referee of our VTK files.

    It is in the ``test`` extra; where it is missing the test is skipped with the install
    line, and under ``ROTOMORPH_REQUIRE_REFEREES=1`` it fails.
    """
    try:
        import vtk as module  # type: ignore[import-not-found]
    except ImportError:
        message = "referee 'vtk' (VTK's own readers) is not installed (pip install -e \".[test]\")"
        if REQUIRE_REFEREES:
            pytest.fail(message + "; ROTOMORPH_REQUIRE_REFEREES=1 requires it", pytrace=False)
        pytest.skip(message)
    return module

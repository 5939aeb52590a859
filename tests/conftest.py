"""Session-wide test settings."""

from __future__ import annotations

import os

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


@pytest.hookimpl(tryfirst=True)
def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Order and group the suite for its xdist workers (``-n auto --dist loadgroup``).

    * Slow tests first (a stable sort): the long ones start while every worker is free and
      the short ones fill in behind them, instead of one long test starting last.
    * The tests of one file run on one worker unless a test names its own ``xdist_group``:
      module- and session-scoped fixtures (a simulated run, a sweep on a process pool) are
      then computed once, not once per worker. Runs before xdist's own hook, which reads the
      groups (``tryfirst``).
    """
    items.sort(key=lambda item: item.get_closest_marker("slow") is None)
    if getattr(config.option, "dist", "no") != "loadgroup":
        return
    for item in items:
        if item.get_closest_marker("xdist_group") is None:
            item.add_marker(pytest.mark.xdist_group(item.nodeid.split("::", 1)[0]))

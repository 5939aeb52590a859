"""Session-wide test settings."""

from __future__ import annotations

import os

import pytest


@pytest.fixture(scope="session", autouse=True)
def _result_cache(tmp_path_factory: pytest.TempPathFactory) -> None:
    """Keep rotomorph's disk cache of report results inside the test session (shared by the
    tests of one session, never read from or written to the user's ~/.cache)."""
    if "ROTOMORPH_CACHE_DIR" not in os.environ:
        os.environ["ROTOMORPH_CACHE_DIR"] = str(tmp_path_factory.mktemp("rotomorph-cache"))

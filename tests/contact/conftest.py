"""Fixtures for contact tests."""

from __future__ import annotations

import numpy as np
import pytest


@pytest.fixture
def rng() -> np.random.Generator:
    """A fixed random generator (reproducible configurations)."""
    return np.random.default_rng(20261122)

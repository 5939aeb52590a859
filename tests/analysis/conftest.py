"""Fixtures of the analysis tests."""

from __future__ import annotations

import pytest
from _analysis_builders import sinusoidal_lattice


@pytest.fixture
def lattice():
    """The paper's 5 x 5 sinusoidal lattice: positions (425, 3) and 40 edge chains."""
    return sinusoidal_lattice()

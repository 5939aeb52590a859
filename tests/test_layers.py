"""Imports flow one way: design -> materials -> rod -> contact -> solve -> analysis ->
lattice -> io -> plot -> simulate -> inverse | sweep | prediction -> app -> cli; errors, type
aliases and geometry sit below all."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1] / "src" / "rotomorph"
LAYERS = [
    {"", "__init__", "errors", "_typing", "_display", "_progress", "_text", "geometry"},
    {"design"},
    {"materials"},
    {"rod"},
    {"contact"},
    {"solve"},
    {"analysis"},
    {"lattice"},
    {"io"},
    {"plot"},
    {"simulate"},
    {"inverse", "sweep", "prediction"},
    {"app"},
    {"cli", "__main__"},
]
RANK = {name: i for i, layer in enumerate(LAYERS) for name in layer}


def _package(module: str) -> str:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else ""


def _imports(path: Path) -> set[str]:
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("rotomorph"):
            found.add(_package(node.module))
        elif isinstance(node, ast.Import):
            found |= {_package(a.name) for a in node.names if a.name.startswith("rotomorph")}
    return found


FILES = sorted(ROOT.rglob("*.py"))


@pytest.mark.parametrize("path", FILES, ids=lambda p: str(p.relative_to(ROOT)))
def test_module_imports_only_lower_layers(path):
    own = _package(".".join(("rotomorph", *path.relative_to(ROOT).with_suffix("").parts)))
    assert own in RANK, f"{own!r} is not placed in a layer; add it to LAYERS"
    for dep in _imports(path):
        assert dep in RANK, f"{path.name} imports unknown package rotomorph.{dep}"
        assert RANK[dep] <= RANK[own], f"{own} must not import {dep} (higher layer)"

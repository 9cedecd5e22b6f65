"""The world's tissue physics never calls the estimator's contact laws (DESIGN.md)."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
SOURCES = [*sorted((ROOT / "sim" / "fem").glob("*.py")), ROOT / "sim" / "viscoelastic.py"]


def imported_modules(path: Path) -> set[str]:
    names: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(), filename=str(path))):
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module:
            names.add(node.module)
            names.update(f"{node.module}.{alias.name}" for alias in node.names)
    return names


@pytest.mark.parametrize("path", SOURCES, ids=lambda p: p.name)
def test_no_estimator_contact_law_in_the_world(path: Path) -> None:
    bad = {
        name
        for name in imported_modules(path)
        if name == "estimation" or name.startswith("estimation.")
    }
    assert not bad, f"{path.relative_to(ROOT)} imports {sorted(bad)}"


def test_the_scan_sees_the_package() -> None:
    assert len(SOURCES) >= 8
    assert "sim.fem.problem" in imported_modules(ROOT / "sim" / "fem" / "table.py")

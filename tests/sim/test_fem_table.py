"""Force tables on disk: keys, round trips, the lookup order, and no stale reads."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest

from palpate.sim.fem import table as table_mod
from palpate.sim.fem.problem import LayerProblem
from palpate.sim.fem.table import ForceTable, load_table, read_table, save_table, table_key

TINY = LayerProblem(thickness_ratio=1.0, radius_ratio=4.0, n_depths=3, depth_max=0.09, resolution=2)

CHANGES = {
    "thickness_ratio": 1.01,
    "radius_ratio": 4.5,
    "poisson": 0.46,
    "material": "neo-hookean",
    "base": "sliding",
    "contact": "stick",
    "depth_max": 0.1,
    "n_depths": 4,
    "resolution": 3,
    "inclusion": (0.5, 0.2, 5.0, 0.45),
}


def fake_table(problem: LayerProblem, scale: float = 1.0) -> ForceTable:
    x = np.array(problem.depths())
    return ForceTable(
        key=table_key(problem),
        problem=problem,
        depths=x,
        forces=scale * x**1.5,
        contact_radii=np.sqrt(x),
        success=True,
        message="fake",
        build_seconds=0.0,
    )


def test_every_parameter_changes_the_key() -> None:
    assert set(CHANGES) == {f.name for f in dataclasses.fields(LayerProblem)}
    keys = {
        table_key(dataclasses.replace(TINY, **{name: value})) for name, value in CHANGES.items()
    }
    assert len(keys) == len(CHANGES)
    assert table_key(TINY) not in keys


def test_the_solver_version_is_in_the_key(monkeypatch: pytest.MonkeyPatch) -> None:
    before = table_key(TINY)
    monkeypatch.setattr(table_mod, "SOLVER_VERSION", table_mod.SOLVER_VERSION + 1)
    assert table_key(TINY) != before


def test_a_table_reads_back_equal(tmp_path: Path) -> None:
    original = fake_table(TINY)
    save_table(original, tmp_path)
    back = read_table(TINY, tmp_path)
    assert back is not None
    for name in ("depths", "forces", "contact_radii"):
        np.testing.assert_array_equal(getattr(back, name), getattr(original, name))
    assert (back.key, back.success, back.message) == (original.key, True, "fake")


def test_a_changed_parameter_never_reads_a_stale_table(tmp_path: Path) -> None:
    save_table(fake_table(TINY), tmp_path)
    for name, value in CHANGES.items():
        assert read_table(dataclasses.replace(TINY, **{name: value}), tmp_path) is None
    # a file under the right name whose record is another problem's is not used either
    other = dataclasses.replace(TINY, poisson=0.3)
    path = save_table(fake_table(other), tmp_path)
    path.rename(tmp_path / f"{table_key(TINY)}.npz")
    assert read_table(TINY, tmp_path) is None


def test_lookup_order_shipped_then_cache_then_solve(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    shipped, cache = tmp_path / "shipped", tmp_path / "cache"
    monkeypatch.setattr(table_mod, "SHIPPED_DIR", shipped)
    monkeypatch.setenv("PALPATE_CACHE_DIR", str(cache))
    load_table.cache_clear()
    problem = dataclasses.replace(TINY, poisson=0.4)
    try:
        solved = load_table(problem)  # nothing on disk: solved, then cached
        assert solved.message == "all depths converged"
        assert json.loads(str(np.load(cache / f"{solved.key}.npz")["record"]))["poisson"] == 0.4
        load_table.cache_clear()
        save_table(fake_table(problem, scale=2.0), cache)
        assert load_table(problem).message == "fake"  # the cache before a solve
        load_table.cache_clear()
        save_table(dataclasses.replace(fake_table(problem, 3.0), message="shipped"), shipped)
        assert load_table(problem).message == "shipped"  # the package before the cache
    finally:
        load_table.cache_clear()


def test_shipped_tables_are_current() -> None:
    """Every shipped problem has its table in the package, complete, under the current key."""
    from palpate.sim.fem.generate import SHIPPED

    for name, problem in SHIPPED.items():
        table = read_table(problem, table_mod.SHIPPED_DIR)
        assert table is not None, f"{name}: run python -m sim.fem.generate"
        if table.success:
            assert table.depths[-1] == pytest.approx(problem.depth_max)
            continue
        # or past 90 % of its deepest point, where the mesh inverts: a sphere pushed nearly its
        # whole radius into a neo-Hookean layer as thin as that radius (the lung scene's 10 mm
        # layers under R = 10 mm, indented to delta/R = 0.3 at most)
        assert "inverted" in table.message, f"{name}: {table.message}"
        assert table.depths[-1] >= 0.9 * problem.depth_max, f"{name}: {table.message}"

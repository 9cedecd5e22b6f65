"""The user's table cache: solved once, read back bit for bit, never served for another record."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from palpate.store.cache import cached_arrays


def test_arrays_are_built_once_and_read_back_exactly(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("PALPATE_CACHE_DIR", str(tmp_path))
    calls = []

    def build() -> dict[str, np.ndarray]:
        calls.append(1)
        return {"x": np.array([0.1, 1.0 / 3.0, np.pi]) * 1e-7}

    first = cached_arrays("t", "record A", build)
    again = cached_arrays("t", "record A", build)
    assert len(calls) == 1
    assert again["x"].tobytes() == first["x"].tobytes()  # bit for bit
    other = cached_arrays("t", "record B", build)  # another record: solved again
    assert len(calls) == 2
    np.testing.assert_array_equal(other["x"], first["x"])


def test_a_file_holding_another_record_is_not_served(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setenv("PALPATE_CACHE_DIR", str(tmp_path))
    cached_arrays("t", "record A", lambda: {"x": np.zeros(2)})
    (path,) = tmp_path.glob("t-*.npz")
    np.savez(path, record=np.array("record Z"), x=np.ones(2))  # a stale or foreign file
    assert cached_arrays("t", "record A", lambda: {"x": np.full(2, 5.0)})["x"][0] == 5.0


def test_an_unwritable_cache_costs_a_solve_not_an_error(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("not a folder", encoding="utf-8")
    monkeypatch.setenv("PALPATE_CACHE_DIR", str(blocker / "cache"))
    assert cached_arrays("t", "r", lambda: {"x": np.ones(1)})["x"][0] == 1.0

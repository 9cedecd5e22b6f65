"""Stored poses: loading, atomic saving, replacing by name, errors naming the file and key."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from palpate.config import resolve
from palpate.config.loader import ConfigError
from palpate.config.targets import TargetConfig, load_targets, save_target


def test_the_shipped_example_loads() -> None:
    targets = load_targets(resolve("targets.yaml"))
    t = targets.get("example-downward")
    assert t.tube == "bent30"
    assert t.translation == pytest.approx(40e-3)
    assert t.roll == 0.0


def test_a_missing_file_is_an_empty_set(tmp_path: Path) -> None:
    assert load_targets(tmp_path / "none.yaml").targets == ()


def test_save_adds_replaces_by_name_and_keeps_the_others(tmp_path: Path) -> None:
    path = tmp_path / "sub" / "targets.yaml"
    save_target(path, TargetConfig("a", "bent15", 90.0, 30.0, "first"))
    save_target(path, TargetConfig("b", "bent30", -45.5, 41.25))
    save_target(path, TargetConfig("a", "bent50", 180.0, 35.0, "moved"))
    loaded = load_targets(path)
    assert [t.name for t in loaded.targets] == ["b", "a"]
    a = loaded.get("a")
    assert (a.tube, a.roll, a.translation_mm, a.note) == ("bent50", math.pi, 35.0, "moved")
    assert loaded.get("b").roll_deg == -45.5
    assert sorted(p.name for p in path.parent.iterdir()) == ["targets.yaml"]  # no temp files


def test_unknown_target_names_the_known_ones(tmp_path: Path) -> None:
    path = tmp_path / "t.yaml"
    save_target(path, TargetConfig("a", "straight", 0.0, 10.0))
    with pytest.raises(KeyError, match=r"no target named 'zz'; known: \['a'\]"):
        load_targets(path).get("zz")


@pytest.mark.parametrize(
    ("text", "key"),
    [
        ("targets:\n  - {name: a, tube: x, roll_deg: 0, translation_mm: 1}\n"
         "  - {name: a, tube: x, roll_deg: 0, translation_mm: 2}\n", "<top>"),
        ("targets:\n  - {name: a, tube: x, roll_deg: 0, translation_mm: 2000}\n",
         "targets[0].translation_mm"),
        ("targets:\n  - {name: a, tube: x, roll_deg: 0}\n", "targets[0].translation_mm"),
        ("targets:\n  - {name: a, tube: x, roll_deg: 0, translation_mm: 1, pose: 3}\n",
         "targets[0].pose"),
    ],
)  # fmt: skip
def test_bad_files_are_rejected_with_the_file_and_key(tmp_path: Path, text: str, key: str) -> None:
    path = tmp_path / "bad.yaml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(ConfigError) as info:
        load_targets(path)
    assert info.value.source == str(path)
    assert info.value.key == key


def test_a_refused_save_leaves_the_file_as_it_was(tmp_path: Path) -> None:
    path = tmp_path / "targets.yaml"
    save_target(path, TargetConfig("a", "straight", 0.0, 10.0))
    before = path.read_text(encoding="utf-8")
    with pytest.raises(ConfigError, match=r"targets\[1\]\.roll_deg"):
        save_target(path, TargetConfig("b", "straight", math.nan, 10.0))
    with pytest.raises(ConfigError, match=r"targets\[1\]\.translation_mm"):
        save_target(path, TargetConfig("b", "straight", 0.0, 5000.0))
    assert path.read_text(encoding="utf-8") == before
    broken = tmp_path / "broken.yaml"
    broken.write_text("targets: [1, 2\n", encoding="utf-8")
    with pytest.raises(ConfigError, match="malformed YAML"):
        save_target(broken, TargetConfig("c", "straight", 0.0, 1.0))
    assert broken.read_text(encoding="utf-8") == "targets: [1, 2\n"

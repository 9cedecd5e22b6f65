"""The config loader: typed values, defaults from the paper, and errors naming file and key."""

from __future__ import annotations

import contextlib
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from palpate.config import ConfigError, StackConfig, from_mapping, load, load_stack
from palpate.config.schema import SensorConfig


def write(tmp_path: Path, text: str) -> Path:
    p = tmp_path / "robot.yaml"
    p.write_text(text, encoding="utf-8")
    return p


def test_shipped_robot_config_loads_with_paper_values() -> None:
    cfg = load_stack()
    assert cfg.sensor.fiber_radius == pytest.approx(0.115e-3)
    assert cfg.sensor.wire_count == 4
    assert cfg.fbg.strain_coefficient_pm_per_ue == pytest.approx(0.424)
    assert cfg.sensor.tip_radius == pytest.approx(3.5e-3)
    assert [t.tip_angle_deg for t in cfg.tubes] == [0, 15, 30, 50]


def test_empty_file_gives_defaults(tmp_path: Path) -> None:
    assert load(StackConfig, write(tmp_path, "")) == StackConfig()


def test_unknown_key_names_file_and_key(tmp_path: Path) -> None:
    p = write(tmp_path, "sensor:\n  fibre_radius_mm: 0.1\n")
    with pytest.raises(ConfigError) as err:
        load(StackConfig, p)
    assert str(p) in str(err.value)
    assert "sensor.fibre_radius_mm" in str(err.value)
    assert "unknown key" in str(err.value)


def test_wrong_type_names_key(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match=r"sensor\.wire_count: expected an integer"):
        load(StackConfig, write(tmp_path, "sensor: {wire_count: four}\n"))


def test_out_of_range_names_key(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match=r"sensor\.tip_radius_mm: must be > 0"):
        load(StackConfig, write(tmp_path, "sensor: {tip_radius_mm: -1}\n"))


def test_list_item_error_names_index(tmp_path: Path) -> None:
    text = "tubes:\n  - {name: a}\n  - {name: b, tip_angle_deg: wrong}\n"
    with pytest.raises(ConfigError, match=r"tubes\[1\]\.tip_angle_deg"):
        load(StackConfig, write(tmp_path, text))


def test_cross_field_rule_names_section(tmp_path: Path) -> None:
    text = "drive: {translation_min_mm: 50, translation_max_mm: 10}\n"
    with pytest.raises(ConfigError, match=r"drive: translation_min_mm must be below"):
        load(StackConfig, write(tmp_path, text))


def test_a_stream_lost_before_it_is_stale_is_refused(tmp_path: Path) -> None:
    text = "board: {stale_timeout_s: 0.5, lost_timeout_s: 0.2}\n"
    with pytest.raises(ConfigError, match=r"board: lost_timeout_s: must be >= stale_timeout_s"):
        load(StackConfig, write(tmp_path, text))


def test_malformed_yaml_names_file_and_line(tmp_path: Path) -> None:
    p = write(tmp_path, "sensor:\n  wire_count: [1, 2\n")
    with pytest.raises(ConfigError, match=r"malformed YAML: line \d+"):
        load(StackConfig, p)


def test_missing_file_is_a_config_error(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match="file not found"):
        load_stack(tmp_path / "nope.yaml")


def test_bool_is_not_a_number() -> None:
    with pytest.raises(ConfigError, match="expected a number"):
        from_mapping(SensorConfig, {"tip_radius_mm": True}, "x.yaml")


def test_nan_rejected() -> None:
    with pytest.raises(ConfigError, match="finite"):
        from_mapping(SensorConfig, {"tip_radius_mm": float("nan")}, "x.yaml")


@pytest.mark.slow
@given(st.dictionaries(st.text(max_size=8), st.integers() | st.text(max_size=4) | st.none()))
def test_fuzzed_mappings_raise_only_config_error(data: dict[str, object]) -> None:
    with contextlib.suppress(ConfigError):
        from_mapping(StackConfig, {"sensor": data}, "fuzz.yaml")

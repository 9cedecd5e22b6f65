"""Temperature in the body (issue 42): the world's insertion step and each grating's own thermal
shift, the thermal calibration from a free sensor's raw frames (`palpate calibrate --thermal`,
through the wire encoding), and the compensation of every grating with its calibrated ratio."""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

import numpy as np
import pytest

from palpate.api import load_scene
from palpate.cli import main
from palpate.config import load_stack
from palpate.config.loader import ConfigError, from_mapping, write_yaml
from palpate.config.schema import FbgConfig, StackConfig, TipGratingConfig
from palpate.config.thermal import TemperatureConfig
from palpate.sensor.strain import StrainChain
from palpate.sim.thermal import ThermalHistory, true_coefficients
from palpate.simulation.insertion import insertion_frames

SCENE = load_scene("scenes/invivo/temperature.yaml")
STACK = load_stack(SCENE.robot)


def test_the_insertion_warms_the_sensor_with_its_time_constant() -> None:
    step = TemperatureConfig(step_degc=15.0, at_s=2.0, time_constant_s=5.0)
    history = ThermalHistory(0.01, step)
    assert history.change(1.0) == pytest.approx(0.01)  # before the insertion: the drift alone
    assert history.change(7.0) == pytest.approx(0.07 + 15.0 * (1 - math.exp(-1.0)))
    assert history.change(100.0) == pytest.approx(1.0 + 15.0, abs=1e-6)
    assert ThermalHistory(0.0, dataclasses.replace(step, time_constant_s=0.0)).change(2.1) == 15.0
    assert ThermalHistory(0.02).change(3.0) == 0.02 * 3.0  # no insertion: as before


def test_each_grating_shifts_by_its_own_coefficient() -> None:
    coefficients = true_coefficients(STACK.sensor, STACK.fbg, SCENE.fidelity)
    assert coefficients.reference == pytest.approx(10e-12)
    # S_T in proportion to the Bragg wavelength, plus 4 pm/degC on the beam's gratings
    expected = [10e-12 * nm / 1525.0 + 4e-12 for nm in (1530.0, 1535.0, 1540.0)]
    assert coefficients.gratings == pytest.approx(expected)
    assert coefficients.tip == pytest.approx(10e-12 * 1560.0 / 1525.0)
    plain = true_coefficients(
        STACK.sensor, STACK.fbg, dataclasses.replace(SCENE.fidelity, temperature=None)
    )
    assert plain.gratings == (10e-12,) * 3
    assert plain.tip == 10e-12


def record(tmp_path: Path, seed: int, name: str) -> Path:
    path = tmp_path / name
    path.write_bytes(insertion_frames(STACK, SCENE, seconds=20.0, seed=seed))
    return path


def calibrate(path: Path, config: Path | str, capsys: pytest.CaptureFixture[str]) -> dict:  # type: ignore[type-arg]
    assert main(["calibrate", "--thermal", str(path), "--config", str(config), "--json"]) == 0
    return json.loads(capsys.readouterr().out)  # type: ignore[no-any-return]


def test_the_ratios_come_back_from_an_insertion_record_and_compensate_a_second_one(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    truth = true_coefficients(STACK.sensor, STACK.fbg, SCENE.fidelity)
    ratios = [c / truth.reference for c in (*truth.gratings, truth.tip)]
    plain = tmp_path / "plain.yaml"  # the sensor with one coefficient for every grating
    fbg = dataclasses.replace(STACK.fbg, thermal_ratios=None)
    assert STACK.sensor.tip_grating is not None
    tip = dataclasses.replace(STACK.sensor.tip_grating, thermal_ratio=None)
    write_yaml(with_ratios(fbg, tip), plain)
    found = calibrate(record(tmp_path, 1, "a.bin"), plain, capsys)
    assert found["reference_span_pm"] > 140.0  # about 15 degC at 10 pm/degC
    rows = found["gratings"]
    assert [r["grating"] for r in rows] == ["1", "2", "3", "tip"]
    for row, true in zip(rows, ratios, strict=True):
        lo, hi = row["ci"]  # 0.2 % of 150 pm is 0.3 pm
        assert row["ratio"] == pytest.approx(true, abs=2e-3)
        assert lo < row["ratio"] < hi < lo + 4e-3
        assert row["configured_ratio"] == 1.0
        assert row["residual_calibrated_pm"] < 1.0
    # one coefficient for every grating leaves 55 pm on the beam's gratings, 3 on the tip's
    assert min(r["residual_configured_pm"] for r in rows[:3]) > 40.0
    assert rows[3]["residual_configured_pm"] > 2.0
    # the fitted ratios stored, a second insertion (another seed) is compensated within 1 pm
    stored = tmp_path / "calibrated.yaml"
    lines = dict(line.split(": ", 1) for line in found["config"])
    fbg = dataclasses.replace(
        STACK.fbg, thermal_ratios=tuple(json.loads(lines["fbg.thermal_ratios"]))
    )
    tip = dataclasses.replace(tip, thermal_ratio=float(lines["sensor.tip_grating.thermal_ratio"]))
    write_yaml(with_ratios(fbg, tip), stored)
    again = calibrate(record(tmp_path, 2, "b.bin"), stored, capsys)
    assert max(r["residual_configured_pm"] for r in again["gratings"]) < 1.0


def test_a_record_without_a_temperature_change_or_a_reference_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    still = dataclasses.replace(
        SCENE, fidelity=dataclasses.replace(SCENE.fidelity, temperature=None)
    )
    path = tmp_path / "still.bin"
    path.write_bytes(insertion_frames(STACK, still, seconds=5.0))
    assert main(["calibrate", "--thermal", str(path), "--config", "robot-lung-invivo.yaml"]) == 2
    assert "temperature change" in capsys.readouterr().err
    # the paper's sensor has no reference grating: its frames carry none
    assert main(["calibrate", "--thermal", str(path), "--config", "robot.yaml"]) == 2
    err = capsys.readouterr().err
    assert "no valid frame" in err or "no reference grating" in err


def test_the_chain_takes_each_gratings_share_of_the_reference_out() -> None:
    fbg = FbgConfig(
        temperature_compensation="reference",
        reference_wavelength_nm=1525.0,
        thermal_ratios=(1.4, 1.5, 1.6, 1.0, 1.0),
    )
    chain = StrainChain.from_config(fbg, (1, 3)).zeroed(
        np.full((4, 2), 1.53e-6), np.full(4, 1.525e-6)
    )
    d_ref = 150e-12
    warm = np.array([1.53e-6 + 1.4 * d_ref + 0.424e-12 * 20, 1.53e-6 + 1.6 * d_ref])
    assert chain.strains(warm, reference=1.525e-6 + d_ref) == pytest.approx([20e-6, 0.0], abs=1e-9)
    flat = StrainChain.from_config(fbg)  # no gratings named: one coefficient
    assert flat.ratios is None


def test_thermal_ratios_one_per_grating(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match="fbg: thermal_ratios: one per base_wavelengths_nm"):
        from_mapping(StackConfig, {"fbg": {"thermal_ratios": [1.0, 1.1]}}, "robot.yaml")
    with pytest.raises(ConfigError, match="fbg: thermal_ratios: each in"):
        from_mapping(StackConfig, {"fbg": {"thermal_ratios": [1, 1, 1, 1, -1]}}, "robot.yaml")


def with_ratios(fbg: FbgConfig, tip: TipGratingConfig) -> StackConfig:
    return dataclasses.replace(
        STACK, fbg=fbg, sensor=dataclasses.replace(STACK.sensor, tip_grating=tip)
    )

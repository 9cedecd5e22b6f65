"""What the estimator is told: the operator's belief, the rig's compliance, old logs' inputs."""

from __future__ import annotations

import math

import pytest

from palpate.config.loader import ConfigError, from_mapping
from palpate.config.sample import AssumedConfig
from palpate.config.schema import StackConfig
from palpate.estimation.trial.inputs import EstimatorInputs, belief_fields

TRUTH = {"thickness": 6e-3, "bonded": False, "poisson": 0.45}


def test_without_assumed_a_scene_tells_the_samples_own_values() -> None:
    assert belief_fields(None, **TRUTH) == {
        "thickness": 6e-3,
        "bonded": False,
        "poisson": 0.45,
        "material": "linear",
        "tip_contact": "frictionless",
    }
    own = belief_fields(None, **TRUTH, material="neo-hookean", tip_contact="sticking")
    assert (own["material"], own["tip_contact"]) == ("neo-hookean", "sticking")


def test_assumed_values_ranges_and_unknowns_become_ranges() -> None:
    a = AssumedConfig(thickness_mm=(5.0, 20.0), bonded="unknown", poisson=(0.40, 0.50))
    f = belief_fields(a, **TRUTH)
    assert f["thickness_range"] == pytest.approx((5e-3, 20e-3))
    assert 5e-3 < f["thickness"] < 20e-3
    assert f["bonded_options"] == (True, False)
    assert f["poisson_range"] == (0.40, 0.50)
    assert f["poisson"] == pytest.approx(0.45)
    half = belief_fields(AssumedConfig(thickness_mm="half-space", poisson="unknown"), **TRUTH)
    assert half["thickness"] is None
    assert half["poisson_range"] == (0.0, 0.5)
    assert half["bonded"] is False  # left out: the sample's own value
    told = belief_fields(AssumedConfig(thickness_mm=10.0, bonded=True), **TRUTH)
    assert told == {
        "thickness": 10e-3,
        "bonded": True,
        "poisson": 0.45,
        "material": "linear",
        "tip_contact": "frictionless",
    }
    unknown = belief_fields(AssumedConfig(material="neo-hookean", friction="unknown"), **TRUTH)
    assert unknown["material"] == "neo-hookean"
    assert unknown["tip_contact_options"] == ("frictionless", "sticking")
    inputs = EstimatorInputs(
        "bench", 0.044, 0.0, 3.5e-3, encoder_resolution=5e-6, misalignment=0.0, **unknown
    )
    belief = inputs.belief()
    assert belief.tips == ("frictionless", "sticking")
    assert "tip" in belief.open_keys
    assert {h.law.tip for h in belief.hypotheses(2e-4)} == {"frictionless", "sticking"}


def test_on_the_bench_thickness_and_bonding_default_to_unknown() -> None:
    f = belief_fields(None, thickness="unknown", bonded="unknown", poisson=0.45)
    assert f["thickness_range"] == (0.0, None)
    assert f["bonded_options"] == (True, False)
    inputs = EstimatorInputs(
        "robot", 0.042, 0.0, 3.5e-3, encoder_resolution=5e-6, misalignment=0.0, **f
    )
    b = inputs.belief()
    assert b.thickness == (0.0, math.inf)
    assert b.open_keys == ("thickness", "bonded")


def test_inputs_round_trip_and_an_old_logs_inputs_are_version_1() -> None:
    f = belief_fields(AssumedConfig(thickness_mm=(5.0, 20.0)), **TRUTH)
    new = EstimatorInputs(
        "bench",
        0.044,
        0.0,
        3.5e-3,
        encoder_resolution=5e-6,
        misalignment=0.0,
        compliance=(1e-5, 2e-5),
        compliance_calibrated=True,
        travel_window=2.5e-3,
        **f,
    )
    assert EstimatorInputs.from_dict(new.as_dict()) == new
    old = {  # a version-1 header: no ranges, no compliance, no version
        "kind": "bench",
        "exposed_length": 0.044,
        "flush_translation": 0.0,
        "tip_radius": 3.5e-3,
        "poisson": 0.45,
        "thickness": 0.01,
        "bonded": True,
        "encoder_resolution": 5e-6,
        "misalignment": 0.0,
    }
    legacy = EstimatorInputs.from_dict(old)
    assert legacy.version == 1
    assert legacy.compliance == (0.0, 0.0)
    assert legacy.belief().open_keys == ()
    with pytest.raises(TypeError, match="unknown estimator inputs"):
        EstimatorInputs.from_dict({**old, "colour": "red"})


def test_the_robot_configuration_states_each_compliance_or_its_absence() -> None:
    stack = from_mapping(
        StackConfig,
        {
            "tubes": [
                {"name": "a", "compliance_mm_per_n": 0.1},
                {"name": "b", "compliance_mm_per_n": [0.09, 0.11]},
                {"name": "c"},
            ],
            "calibration": {"uncalibrated_compliance_max_mm_per_n": 0.2},
        },
    )
    assert stack.compliance("a") == (pytest.approx((1e-4, 1e-4)), True)
    assert stack.compliance("b") == (pytest.approx((0.9e-4, 1.1e-4)), True)
    assert stack.compliance("c") == (pytest.approx((0.0, 2e-4)), False)
    assert stack.compliance(None) == (pytest.approx((0.0, 2e-4)), False)  # the stage
    with pytest.raises(ConfigError, match="compliance_mm_per_n"):
        from_mapping(StackConfig, {"tubes": [{"name": "a", "compliance_mm_per_n": [0.2, 0.1]}]})
    with pytest.raises(ConfigError, match="temperature_compensation"):
        from_mapping(StackConfig, {"fbg": {"temperature_compensation": "measured"}})


def test_rows_whose_gratings_are_off_the_beam_are_left_out_of_the_fit() -> None:
    """An advance taken against a drift estimated far beyond the record's can leave rows
    before the sensor left the tube: they have no beam state, the fit says so, never raises."""
    import numpy as np

    from palpate.config import load_stack, resolve
    from palpate.estimation.trial.estimate import MIN_POINTS, fit_record
    from palpate.robot.trial.setup import sensor_section

    stack = load_stack(resolve("robot-lung-lumen-2.8.yaml"))
    inputs = EstimatorInputs(
        "robot", 0.1, 0.0, 1.3e-3, encoder_resolution=5e-6, misalignment=0.0, **TRUTH
    )
    n = 3 * MIN_POINTS
    strains = np.zeros((n, len(stack.sensor.used_gratings)))
    advance = np.linspace(-0.12, -0.01, n)  # every row: the gratings still inside the tube
    forces = np.zeros(n)
    out = fit_record(advance, strains, inputs, stack.sensor, sensor_section(stack), forces)
    assert out.joint is not None
    assert out.joint.success is False
    assert "too few points: 0 loading samples" in out.joint.message

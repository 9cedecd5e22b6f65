"""The sample schema: the world's truth, its pose, and what the operator believes."""

from __future__ import annotations

import math

import pytest

from palpate.config.loader import ConfigError, from_mapping
from palpate.config.sample import AssumedConfig, SampleConfig
from palpate.config.scene import SceneConfig


def test_assumed_takes_a_value_a_range_or_unknown() -> None:
    s = from_mapping(
        SampleConfig,
        {
            "name": "S8",
            "modulus_kpa": 314.53,
            "thickness_mm": 6,
            "bonded": False,
            "assumed": {"thickness_mm": [5, 20], "bonded": "unknown", "poisson": 0.45},
        },
        "scene.yaml",
        "samples[0]",
    )
    assert s.assumed == AssumedConfig(thickness_mm=(5.0, 20.0), bonded="unknown", poisson=0.45)
    assert s.thickness == pytest.approx(6e-3)
    half = from_mapping(AssumedConfig, {"thickness_mm": "half-space", "poisson": "unknown"})
    assert half.thickness_mm == "half-space"
    assert half.bonded is None  # left out: the sample's own value


@pytest.mark.parametrize(
    ("assumed", "key"),
    [
        ({"thickness_mm": [20, 5]}, "samples[0].assumed"),
        ({"poisson": [0.4, 0.6]}, "samples[0].assumed.poisson"),
        ({"bonded": "maybe"}, "samples[0].assumed.bonded"),
        ({"thickness_mm": -3}, "samples[0].assumed.thickness_mm"),
        ({"curvature_radius_mm": [40, 30]}, "samples[0].assumed"),
        ({"curvature_radius_mm": 0}, "samples[0].assumed.curvature_radius_mm"),
    ],
)
def test_bad_beliefs_name_the_key(assumed: dict[str, object], key: str) -> None:
    data = {"name": "S1", "modulus_kpa": 500, "assumed": assumed}
    with pytest.raises(ConfigError, match=key.replace("[", r"\[").replace("]", r"\]")):
        from_mapping(SampleConfig, data, "scene.yaml", "samples[0]")


def test_surface_pose_in_si() -> None:
    s = SampleConfig(
        name="T", modulus_kpa=300, tilt_deg=20, curvature_radius_mm=25, offset_mm=(1, -2, 3)
    )
    assert s.tilt == pytest.approx(math.radians(20))
    assert s.curvature_radius == pytest.approx(25e-3)
    assert s.offset == pytest.approx((1e-3, -2e-3, 3e-3))
    assert SampleConfig(name="F", modulus_kpa=300).curvature_radius is None


def test_a_believed_surface_radius_is_the_samples_own_a_value_a_range_or_unknown() -> None:
    """Probing fits a sphere of the believed radius (m); None: flat or unknown (a plane)."""
    assert AssumedConfig().surface_radius(None) is None
    assert AssumedConfig().surface_radius(30e-3) == (30e-3, 30e-3)  # a scene: the sample's own
    assert AssumedConfig(curvature_radius_mm=60).surface_radius(30e-3) == pytest.approx(
        (60e-3, 60e-3)
    )
    assert AssumedConfig(curvature_radius_mm=(27, 33)).surface_radius(None) == pytest.approx(
        (27e-3, 33e-3)
    )
    assert AssumedConfig(curvature_radius_mm="unknown").surface_radius(30e-3) is None


def test_scene_defaults_are_the_papers_phantoms() -> None:
    scene = SceneConfig()
    assert [s.name for s in scene.samples][:2] == ["S1", "S2"]
    assert scene.fidelity.tissue_model in ("fe", "closed-form")
    assert scene.campaign.probe is None


def _inclusion_sample(*inclusions: dict, **sample: object) -> SampleConfig:
    data = {"name": "T", "modulus_kpa": 5.0, "thickness_mm": 35, "inclusions": list(inclusions)}
    return from_mapping(SampleConfig, {**data, **sample}, "scene.yaml", "samples[0]")


def test_a_sample_holds_inclusions_in_its_units() -> None:
    s = _inclusion_sample({"center_mm": [1, -2, 10], "radius_mm": 4, "modulus_kpa": 40})
    (inc,) = s.inclusions
    assert inc.center == pytest.approx((1e-3, -2e-3, 10e-3))
    assert (inc.radius, inc.modulus, inc.poisson) == pytest.approx((4e-3, 40e3, 0.45))
    assert _inclusion_sample().inclusions == ()


@pytest.mark.parametrize(
    ("inclusion", "sample", "key", "says"),
    [
        ({"center_mm": [0, 0, 3], "radius_mm": 4, "modulus_kpa": 40}, {},
         "samples[0].inclusions[0]", "must exceed radius_mm"),
        ({"center_mm": [0, 0, 30], "radius_mm": 6, "modulus_kpa": 40}, {},
         "samples[0]", "inclusions[0]: reaches the base"),
        ({"center_mm": [38, 0, 10], "radius_mm": 3, "modulus_kpa": 40}, {},
         "samples[0]", "inclusions[0]: reaches the sample's edge"),
        ({"center_mm": [0, 0, 10], "radius_mm": 3, "modulus_kpa": 40}, {"rigid": True},
         "samples[0]", "rigid sample"),
        ({"center_mm": [0, 0, 10], "radius_mm": 3, "modulus_kpa": -1}, {},
         "samples[0].inclusions[0].modulus_kpa", ""),
        ({"center_mm": [0, 10], "radius_mm": 3, "modulus_kpa": 40}, {},
         "samples[0].inclusions[0].center_mm", ""),
        ({"center_mm": [0, 0, 10], "radius_mm": 3, "modulus_kpa": 40, "shape": "egg"}, {},
         "samples[0].inclusions[0].shape", "unknown key"),
    ],
)  # fmt: skip
def test_a_bad_inclusion_names_the_file_and_the_key(inclusion, sample, key, says) -> None:
    with pytest.raises(ConfigError) as err:
        _inclusion_sample(inclusion, **sample)
    assert err.value.source == "scene.yaml"
    assert err.value.key == key
    assert says in str(err.value)


def test_inclusions_need_the_finite_element_world() -> None:
    scene = {
        "name": "x",
        "samples": [{"name": "T", "modulus_kpa": 5, "inclusions": [
            {"center_mm": [0, 0, 5], "radius_mm": 2, "modulus_kpa": 40}]}],
        "fidelity": {"tissue_model": "closed-form"},
    }  # fmt: skip
    with pytest.raises(ConfigError, match=r"samples\[0\].inclusions: the world feels"):
        from_mapping(SceneConfig, scene, "scene.yaml")

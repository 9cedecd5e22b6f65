"""A map scene's keys (campaign.kind: map) are checked with their file and key."""

from __future__ import annotations

from typing import Any

import pytest

from palpate.config import resolve
from palpate.config.loader import ConfigError, from_mapping, load
from palpate.config.scene import SceneConfig

INCLUSION = {"center_mm": [0, 0, 4], "radius_mm": 2, "modulus_kpa": 40}


def scene(campaign: dict[str, Any], samples: int = 1, inclusions: int = 1) -> dict[str, Any]:
    return {
        "name": "m",
        "samples": [
            {
                "name": f"S{k}",
                "modulus_kpa": 5,
                "thickness_mm": 10,
                "inclusions": [INCLUSION] * inclusions,
            }
            for k in range(samples)
        ],
        "fidelity": {"tissue_model": "fe", "inclusion_offsets": "interpolated"},
        "campaign": {"kind": "map", **campaign},
    }


def test_the_shipped_map_scene_loads() -> None:
    s = load(SceneConfig, resolve("scenes/maps/inclusion.yaml"))
    assert s.campaign.kind == "map"
    assert not s.campaign.on_tubes
    assert s.campaign.stage_speed == pytest.approx(5e-3)
    assert [x.name for x in s.campaign_samples()] == ["stiff"]


@pytest.mark.parametrize(
    ("campaign", "samples", "inclusions", "key", "says"),
    [
        ({"patch_mm": [0, 0, 10]}, 1, 1, "campaign.patch_mm", "[x_min, y_min, x_max, y_max]"),
        ({"patch_mm": [5, 0, -5, 10]}, 1, 1, "campaign.patch_mm", "x_max > x_min"),
        ({}, 2, 1, "campaign.samples", "a map surveys one sample"),
        ({}, 1, 2, "samples[0].inclusions", "holds one inclusion a sample"),
        ({"strategy": "spiral"}, 1, 1, "campaign.strategy", "spiral"),
        ({"max_probes": 0}, 1, 1, "campaign.max_probes", ">= 1"),
    ],
)
def test_a_bad_map_scene_names_its_key(campaign, samples, inclusions, key, says) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(ConfigError) as err:
        from_mapping(SceneConfig, scene(campaign, samples, inclusions), "map.yaml")
    assert err.value.source == "map.yaml"
    assert key in f"{err.value.key} {err.value}"
    assert says in str(err.value)

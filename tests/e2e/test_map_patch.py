"""A map on the world of a whole patch (fidelity.inclusion_offsets: patch): the sample stays
where it is, the trial says where the tip presses, one factorisation serves every probe, and a
sample may hold several inclusions (issue 57). A small patch, so the factorisation is seconds."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest

from palpate.campaigns.survey import moved_scene, probe_spec, run_survey
from palpate.cli import main
from palpate.config import load, load_stack, resolve
from palpate.config.scene import SceneConfig
from palpate.sim.fem3d.patch import PatchWorld
from palpate.sim.sample_law import fe_world

SCENE = resolve("scenes/maps/several.yaml")
pytestmark = pytest.mark.slow  # two factorisations of a small patch: 20-40 s


@pytest.fixture(scope="module")
def small(tmp_path_factory) -> SceneConfig:
    """``several.yaml`` on a 4 x 4 mm patch about its 5x sphere, the sample 15 mm in lateral
    radius (a smaller mesh), in a cache of its own."""
    scene = load(SceneConfig, SCENE)
    patch = (2.0, -6.0, 6.0, -2.0)
    narrow = tuple(dataclasses.replace(s, lateral_radius_mm=15.0) for s in scene.samples)
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("PALPATE_CACHE_DIR", str(tmp_path_factory.mktemp("patch")))
        yield dataclasses.replace(
            scene,
            samples=narrow,
            fidelity=dataclasses.replace(scene.fidelity, inclusion_patch_mm=patch),
            campaign=dataclasses.replace(scene.campaign, patch_mm=patch),
        )


def test_the_sample_stays_and_the_trial_says_where_the_tip_presses(small: SceneConfig) -> None:
    sample = small.campaign_samples()[0]
    assert moved_scene(small, sample, (4e-3, -4e-3)) is small
    spec = probe_spec(small, sample, 0, (4e-3, -4e-3), seed=0)
    assert spec.at == (4e-3, -4e-3)
    tip = load_stack(resolve(small.robot)).sensor.tip_radius
    world = fe_world(sample, small.fidelity, tip, spec.at)
    assert isinstance(world, PatchWorld)
    aside = fe_world(sample, small.fidelity, tip, (2e-3, -6e-3))
    assert world.problem == aside.problem  # one factorisation for the survey
    assert world.table().forces[-1] > 1.1 * aside.table().forces[-1]


def test_a_survey_on_the_patch_reads_the_sphere_stiffer_over_it(
    small: SceneConfig, tmp_path: Path
) -> None:
    stack = load_stack(resolve(small.robot))
    result = run_survey(small, stack, strategy="raster", max_probes=4, run_dir=tmp_path)
    moduli = {(round(p.x * 1e3, 1), round(p.y * 1e3, 1)): p.modulus for p in result.probes}
    assert all(v is not None for v in moduli.values())
    assert len(result.truth.others) == 2  # the pair and the cyst, in the truth too
    assert len(result.as_dict()["truth"]["inclusions"]) == 3
    assert "inclusions" in result.as_dict()


def test_a_world_patch_that_does_not_hold_the_map_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    bad = tmp_path / "m.yaml"
    text = SCENE.read_text(encoding="utf-8").replace(
        "inclusion_patch_mm: [-10, -10, 10, 10]", "inclusion_patch_mm: [-5, -5, 5, 5]"
    )
    bad.write_text(text, encoding="utf-8")
    assert main(["map", "--scene", str(bad), "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert "fidelity.inclusion_patch_mm" in err
    assert str(bad) in err

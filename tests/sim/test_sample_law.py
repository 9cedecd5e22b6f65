"""A scene's sample mapped onto the world's tissue: levels, the FE problem, friction, rigid."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from palpate.config import load, load_stack, resolve
from palpate.config.sample import SampleConfig
from palpate.config.scene import FidelityConfig, SceneConfig
from palpate.sim.fem import FeTissueLaw, table_key
from palpate.sim.fem.generate import SHIPPED
from palpate.sim.fem.table import SHIPPED_DIR, read_table
from palpate.sim.fem3d import InclusionWorld
from palpate.sim.fem3d.offsets import MapWorld, node_problems
from palpate.sim.fem3d.table import SHIPPED_DIR as RATIOS_DIR
from palpate.sim.fem3d.table import read_ratios
from palpate.sim.sample_law import (
    HALF_SPACE_RATIO,
    RigidBlock,
    contact_condition,
    describe,
    fe_problem,
    fe_world,
    relaxation,
    world_tissue,
)
from palpate.sim.tissue import TissueModel

R = 3.5e-3
SAMPLE = SampleConfig(name="S", modulus_kpa=500.0)
FE = FidelityConfig(tissue_model="fe")


def test_friction_maps_to_the_nearer_limit() -> None:
    assert contact_condition(0.0, 0.45) == "frictionless"
    beta = 0.1 / 1.1  # (1 - 2 nu) / (2 (1 - nu)) at nu = 0.45
    assert contact_condition(0.9 * beta, 0.45) == "frictionless"
    assert contact_condition(1.1 * beta, 0.45) == "stick"
    assert contact_condition(1e-3, 0.5) == "stick"  # incompressible: any friction sticks
    assert contact_condition(0.4, 0.0) == "frictionless"  # beta = 0.5


def test_the_default_sample_is_the_shipped_paper_phantom() -> None:
    # the default friction (0.5) sticks; a frictionless sample is the other shipped table
    assert fe_problem(SAMPLE, FE, R) == SHIPPED["paper-linear-stick"]
    neo = dataclasses.replace(SAMPLE, material="neo-hookean")
    assert fe_problem(neo, FE, R) == SHIPPED["paper-neo-hookean-stick"]
    slick = dataclasses.replace(SAMPLE, friction=0.0)
    assert fe_problem(slick, FE, R) == SHIPPED["paper-linear"]


def test_half_space_and_layer_switch_give_the_deep_block() -> None:
    half = fe_problem(dataclasses.replace(SAMPLE, thickness_mm=None), FE, R)
    off = fe_problem(SAMPLE, dataclasses.replace(FE, finite_thickness=False), R)
    assert half == off
    assert half.thickness_ratio == half.radius_ratio == HALF_SPACE_RATIO
    assert half == SHIPPED["half-space-linear-stick"]  # the default friction sticks
    wide_tip = fe_problem(dataclasses.replace(SAMPLE, thickness_mm=None), FE, 6e-3)
    assert wide_tip == half  # one stand-in for every tip radius


@pytest.mark.parametrize(
    "change",
    [
        {"poisson": 0.49},
        {"thickness_mm": 12.0},
        {"lateral_radius_mm": 30.0},
        {"material": "neo-hookean"},
        {"bonded": False},
        {"friction": 0.0},  # the default 0.5 sticks; 0 slides
    ],
    ids=lambda c: next(iter(c)),
)
def test_every_sample_key_of_the_layer_changes_the_table_key(change: dict[str, object]) -> None:
    """A changed sample never reads another sample's table."""
    before = table_key(fe_problem(SAMPLE, FE, R))
    after = table_key(fe_problem(dataclasses.replace(SAMPLE, **change), FE, R))  # type: ignore[arg-type]
    assert before != after


def test_modulus_is_not_in_the_key_but_in_the_law() -> None:
    stiff = dataclasses.replace(SAMPLE, modulus_kpa=1000.0)
    assert fe_problem(stiff, FE, R) == fe_problem(SAMPLE, FE, R)
    a, b = world_tissue(SAMPLE, FE, R), world_tissue(stiff, FE, R)
    assert b.force_and_stiffness_at(1e-4)[0] == pytest.approx(2 * a.force_and_stiffness_at(1e-4)[0])


def test_a_lateral_radius_inside_the_tip_is_refused_by_name() -> None:
    with pytest.raises(ValueError, match="sample S: lateral_radius_mm"):
        fe_problem(dataclasses.replace(SAMPLE, lateral_radius_mm=2.0), FE, R)


def test_levels() -> None:
    fe = world_tissue(SAMPLE, FE, R)
    assert isinstance(fe, FeTissueLaw)
    assert fe.modulus == pytest.approx(500e3)
    closed = world_tissue(SAMPLE, FidelityConfig(tissue_model="closed-form"), R)
    assert isinstance(closed, TissueModel)
    assert closed.thickness == pytest.approx(10e-3)
    # the two levels agree on the paper phantom to ~1 % (docs/tissue-fe.md), not to the bit
    f_fe, f_cf = fe.force_and_stiffness_at(0.5e-3)[0], closed.force_and_stiffness_at(0.5e-3)[0]
    assert f_fe != f_cf
    assert f_fe == pytest.approx(f_cf, rel=0.02)
    assert isinstance(world_tissue(dataclasses.replace(SAMPLE, rigid=True), FE, R), RigidBlock)


def test_viscoelastic_modulus_is_the_relaxed_one() -> None:
    ve = dataclasses.replace(SAMPLE, relaxation_time_s=2.0, relaxed_ratio=0.8)
    assert relaxation(ve, FE) is None  # the scene's switch is off
    on = dataclasses.replace(FE, viscoelastic=True)
    sls = relaxation(ve, on)
    assert sls is not None
    assert (sls.tau, sls.ratio) == (2.0, 0.8)
    assert relaxation(SAMPLE, on) is None  # no relaxation time: elastic
    law = world_tissue(ve, on, R)
    assert isinstance(law, FeTissueLaw)
    assert law.modulus == pytest.approx(500e3 / 0.8)  # the instantaneous E_0 = E_inf / r


def test_rigid_block_is_a_stiff_consistent_law() -> None:
    block = RigidBlock(R)
    depth = block.inverse_at(1.4)
    assert 0 < depth < 1e-6
    assert block.force_and_stiffness_at(depth)[0] == pytest.approx(1.4)
    d = np.array([0.0, 1e-8, 1e-7])
    f, k = block.force_and_stiffness(d)
    assert f.tolist() == [block.force_and_stiffness_at(x)[0] for x in d.tolist()]
    assert np.allclose(block.inverse(f), d, rtol=1e-12, atol=1e-20)
    assert k[0] == 0.0
    with pytest.raises(ValueError, match="force must be finite"):
        block.inverse_at(-1.0)


def test_description_names_the_table() -> None:
    d = describe(SAMPLE, FE, R)
    assert d["level"] == "fe"
    assert d["table"] == table_key(SHIPPED["paper-linear-stick"])
    assert d["viscoelastic"] is None
    assert describe(SAMPLE, FidelityConfig(tissue_model="closed-form"), R)["level"] == "closed-form"
    assert "table_stops" not in d  # the shipped table reached its depth


def test_a_table_whose_solve_stopped_short_is_reported(monkeypatch: pytest.MonkeyPatch) -> None:
    """A finite-element solve that stopped early (an element inverted) leaves the world's force
    past it an extrapolation: the description says where, so a campaign can say so."""
    import palpate.sim.sample_law as law

    problem = fe_problem(SAMPLE, FE, R)
    shipped = read_table(problem, SHIPPED_DIR)
    assert shipped is not None
    reach = 0.2 * problem.depth_max
    short = dataclasses.replace(
        shipped,
        depths=shipped.depths[shipped.depths <= reach],
        success=False,
        message="stopped at delta/R = 0.08 after 6 bisections: element inverted (det F <= 0)",
    )
    monkeypatch.setattr(law, "solved_table", lambda p: short)
    stops = describe(SAMPLE, FE, R)["table_stops"]
    assert stops["delta_over_r"] == pytest.approx(float(short.depths[-1]))
    assert stops["asked_delta_over_r"] == problem.depth_max
    assert "element inverted" in stops["message"]
    monkeypatch.setattr(law, "solved_table", lambda p: dataclasses.replace(short, success=True))
    assert "table_stops" not in describe(SAMPLE, FE, R)
    monkeypatch.setattr(law, "solved_table", lambda p: None)  # not solved yet: none is solved
    assert "table_stops" not in describe(SAMPLE, FE, R)


SCENES = [
    p
    for pattern in (
        "*.yaml",
        "inclusions/*.yaml",
        "layers/*.yaml",
        "lung/*.yaml",
        "invivo/*.yaml",
        "maps/*.yaml",
        "mismatch/*.yaml",
        "oblique/*.yaml",
        "viscoelastic/*.yaml",
    )
    for p in sorted(Path(resolve("scenes/bench.yaml")).parent.glob(pattern))
]


@pytest.mark.parametrize("path", SCENES, ids=lambda p: p.name)
def test_shipped_scenes_need_no_finite_element_solve(path: Path) -> None:
    """A fresh clone runs every shipped scene from the package's tables."""
    scene = load(SceneConfig, path)
    stack = load_stack(resolve(scene.robot))
    for sample in scene.samples:
        if scene.fidelity.tissue_model != "fe" or sample.rigid:
            continue
        problem = fe_problem(sample, scene.fidelity, stack.sensor.tip_radius)
        assert read_table(problem, SHIPPED_DIR) is not None, f"{path.name}: {sample.name}"
        world = fe_world(sample, scene.fidelity, stack.sensor.tip_radius)
        if isinstance(world, InclusionWorld):
            found = read_ratios(world.solid, RATIOS_DIR)
            assert found is not None, f"{path.name}: {sample.name}'s 3-D table"
        if isinstance(world, MapWorld):  # a map's world: every solved distance is shipped
            for node in node_problems(world.solid):
                found = read_ratios(node.canonical_problem(), RATIOS_DIR)
                assert found is not None, f"{path.name}: {sample.name}'s 3-D table at {node}"


def test_the_paper_scenes_use_the_independent_world() -> None:
    for name in ("bench", "robot"):
        scene = load(SceneConfig, resolve(f"scenes/{name}.yaml"))
        assert scene.fidelity.tissue_model == "fe"


def test_a_power_law_sample_gets_the_power_law_relaxation() -> None:
    from palpate.sim.viscoelastic import PowerLawSolid

    on = FidelityConfig(viscoelastic=True)
    sample = SampleConfig(
        name="P", modulus_kpa=500.0, relaxation="power-law", relaxation_time_s=0.1,
        relaxation_exponent=0.8, relaxed_ratio=0.6,
    )  # fmt: skip
    relax = relaxation(sample, on)
    assert isinstance(relax, PowerLawSolid)
    assert (relax.tau, relax.ratio, relax.exponent) == (0.1, 0.6, 0.8)


def test_a_tip_anywhere_sees_the_inclusion_from_where_it_presses() -> None:
    """The world under a tip 3.5 mm from the shipped scene's inclusion is the one the scene's
    `aside-3.5mm` sample has at its origin: the same shipped 3-D table."""
    scene = load(SceneConfig, resolve("scenes/inclusions/bench.yaml"))
    by_name = {s.name: s for s in scene.samples}
    moved = fe_world(by_name["below"], scene.fidelity, R, at=(0.0, -3.5e-3))
    aside = fe_world(by_name["aside-3.5mm"], scene.fidelity, R)
    assert isinstance(moved, InclusionWorld)
    assert isinstance(aside, InclusionWorld)
    assert moved.key == aside.key
    assert read_ratios(moved.solid.canonical_problem(), RATIOS_DIR) is not None

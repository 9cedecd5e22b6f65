"""A map's world: the 3-D inclusion factor read between solves at fixed distances (shipped
tables of config/scenes/maps/inclusion.yaml; no solve here)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from palpate.config import load, load_stack, resolve
from palpate.config.scene import SceneConfig
from palpate.sim.fem3d import Inclusion
from palpate.sim.fem3d.offsets import OFFSET_NODES, MapWorld, factor_at, node_problems, on_axis
from palpate.sim.fem3d.table import load_ratios
from palpate.sim.sample_law import fe_world


@pytest.fixture(scope="module")
def world() -> MapWorld:
    scene = load(SceneConfig, resolve("scenes/maps/inclusion.yaml"))
    tip = load_stack(resolve(scene.robot)).sensor.tip_radius
    w = fe_world(scene.campaign_samples()[0], scene.fidelity, tip)
    assert isinstance(w, MapWorld)
    return w


def test_at_a_node_the_factor_is_that_solve_s(world: MapWorld) -> None:
    for node, problem in zip(OFFSET_NODES, node_problems(world.solid), strict=True):
        np.testing.assert_array_equal(factor_at(world.solid, node), load_ratios(problem).ratios)


def test_between_nodes_the_factor_is_linear_and_beyond_them_the_last(world: MapWorld) -> None:
    a, b = factor_at(world.solid, 0.5), factor_at(world.solid, 0.75)
    np.testing.assert_allclose(factor_at(world.solid, 0.6), 0.6 * a + 0.4 * b, rtol=1e-12)
    np.testing.assert_array_equal(
        factor_at(world.solid, 9.0), factor_at(world.solid, OFFSET_NODES[-1])
    )
    over, far = factor_at(world.solid, 0.0), factor_at(world.solid, OFFSET_NODES[-1])
    assert np.all(over > 1.0)
    assert over.max() > 1.4
    assert np.all(np.abs(far - 1.0) < 1e-3)  # nothing at four tip radii


def test_a_map_world_holds_one_inclusion_on_its_axis(world: MapWorld) -> None:
    two = dataclasses.replace(world.solid, inclusions=world.solid.inclusions * 2)
    with pytest.raises(ValueError, match="one inclusion"):
        on_axis(two)
    aside = dataclasses.replace(
        world.solid, inclusions=(dataclasses.replace(world.solid.inclusions[0], x=1.0),)
    )
    with pytest.raises(ValueError, match="sits on the axis"):
        MapWorld(world.layer, aside, 0.0)
    with pytest.raises(ValueError, match="offset must be >= 0"):
        MapWorld(world.layer, world.solid, -1.0)
    assert (
        MapWorld(world.layer, world.solid, 0.3).key != MapWorld(world.layer, world.solid, 0.31).key
    )
    assert isinstance(world.solid.inclusions[0], Inclusion)

"""A stiffness map on the bench path (issue 40): the x-y stage's two servos on the drive's bus,
emulated, driven through dynamixel-sdk; ``palpate trial`` with a bench file's ``map:`` runs the
survey probe by probe, the stage sliding the sample between trials, on a virtual clock."""

from __future__ import annotations

import contextlib
import math
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from palpate.config import ConfigError, load, resolve
from palpate.config.bench import LoadedBench, load_bench
from palpate.config.scene import SceneConfig
from palpate.lab.hardware import Hardware, open_hardware
from palpate.lab.plan import plan_bench_map, plan_session
from palpate.reports.maprecording import write_map_recording
from palpate.robot import kinematics
from palpate.robot.records.recording import read_recording
from palpate.robot.xystage import STAGE_SERVOS, StageMoveError
from palpate.services.lab import run_map_session
from palpate.sim.clock import VirtualClock
from palpate.simulation.twin import SimulatedBench, stations_for

MAP_SCENE = load(SceneConfig, resolve("scenes/maps/inclusion.yaml"))
# the shipped robot-stage.yaml with a quick drive powered up 2 mm behind the stand-off pose and a
# generous reply timeout (the emulator answers from a thread; the trial runs on a virtual clock)
ROBOT = (
    (resolve("robot-stage.yaml").read_text(encoding="utf-8"))
    .replace("  home_translation_mm: 0 ", "  home_translation_mm: 43 ")
    .replace("  max_speed_mm_per_s: 5\n  max_roll", "  max_speed_mm_per_s: 20\n  max_roll")
    .replace("  timeout_ms: 20 ", "  timeout_ms: 2000 ")
)


# robot-gantry.yaml (the stage carries the robot) with the same quick drive and patient bus
GANTRY = resolve("robot-gantry.yaml").read_text(encoding="utf-8") + (
    "drive: {home_translation_mm: 43, max_speed_mm_per_s: 20}\nservos: {timeout_ms: 2000}\n"
)


def bench_map(
    tmp_path: Path, map_keys: str, robot: str = ROBOT, bench: str = "bench-map.yaml"
) -> LoadedBench:
    """The shipped ``bench`` file (bench-map.yaml) with its robot, targets and logs under
    ``tmp_path`` and the ``map:`` keys given."""
    (tmp_path / "robot.yaml").write_text(robot, encoding="utf-8")
    text = resolve(bench).read_text(encoding="utf-8")
    head = text[: text.index("map:\n")]
    for shipped in ("robot: robot-stage.yaml", "robot: robot-gantry.yaml"):
        head = head.replace(shipped, f"robot: {tmp_path}/robot.yaml")
    head = head.replace("log_dir: out/trial", f"log_dir: {tmp_path}/logs")
    path = tmp_path / "bench.yaml"
    path.write_text(head + f"map: {{target: map-downward, {map_keys}}}\n", encoding="utf-8")
    return load_bench(path)


@contextlib.contextmanager
def stage_bench(loaded: LoadedBench, *, wire: bool) -> Iterator[tuple[SimulatedBench, Hardware]]:
    """The map scene's emulated bench (its stage on the bus) opened as the hardware is, on a
    virtual clock (``hw.clock``)."""
    clock = VirtualClock()
    stations = stations_for(MAP_SCENE, loaded)
    with (
        SimulatedBench(loaded.stack, MAP_SCENE, clock=clock, wire=wire, stations=stations) as sim,
        open_hardware(
            loaded.stack, servo_port=sim.servo_port, board_port=sim.board_port, clock=clock
        ) as hw,
    ):
        yield sim, hw


def test_robot_stage_yaml_loads_with_the_stage_on_the_bus() -> None:
    loaded = load_bench("bench-map.yaml")
    stage = loaded.stack.stage
    assert stage is not None
    assert {stage.x.id, stage.y.id}.isdisjoint({1, 2, 3})
    trials, survey = plan_session(loaded, None)
    assert trials == []
    assert survey is not None
    assert survey.target.name == "map-downward"


@pytest.mark.parametrize(
    ("keys", "robot", "where"),
    [
        ("patch_mm: [-20, -10, 10, 10]", ROBOT, "map.patch_mm"),
        ("patch_mm: [5, -10, -5, 10]", ROBOT, "map: patch_mm"),
        ("patch_mm: [-5, -5, 5, 5]", "servos: {timeout_ms: 2000}\n", "map"),
        ("patch_mm: [-5, -5, 5, 5]", ROBOT.replace("id: 5,", "id: 3,"), "stage.y.id"),
    ],
)
def test_a_bad_map_is_refused_with_its_key(
    tmp_path: Path, keys: str, robot: str, where: str
) -> None:
    with pytest.raises(ConfigError) as err:
        bench_map(tmp_path, keys, robot)
    assert where in str(err.value)


@pytest.mark.slow
@pytest.mark.parametrize(
    ("robot", "bench"), [(ROBOT, "bench-map.yaml"), (GANTRY, "bench-map-robot.yaml")]
)
def test_a_raster_map_on_the_emulated_stage_finds_the_inclusion(
    tmp_path: Path, robot: str, bench: str
) -> None:
    """Nine probes of a 3 x 3 raster over the map scene's inclusion (5x, 2.5 mm radius, 3.5 mm
    deep at (3, -2) mm): the stage's servos take the sample to each point, or carry the robot
    there (the world sees the inclusion from where the tip presses), every probe a whole trial
    over the wire path, the map names the stiff corner."""
    keys = "patch_mm: [-6, -8, 6, 4], strategy: raster, max_probes: 9"
    loaded = bench_map(tmp_path, keys, robot, bench)
    clock = VirtualClock()
    stations = stations_for(MAP_SCENE, loaded)
    with SimulatedBench(loaded.stack, MAP_SCENE, clock=clock, wire=False, stations=stations) as sim:
        outcomes, result = run_map_session(
            loaded,
            [],
            plan_bench_map(loaded),
            tmp_path / "logs",
            servo_port=sim.servo_port,
            board_port=sim.board_port,
            clock=clock,
            sync_to_clock=True,
        )
        last = sim.at
        base = sim.world.pose(0.0, 0.0)[0] - kinematics.forward(sim.tube, 0.0, 0.0).tube_tip
    assert outcomes == []
    carried = loaded.stack.stage is not None and loaded.stack.stage.carries == "robot"
    here = (result.probes[-1].x, result.probes[-1].y)
    moved = (0.0, here[0], -here[1]) if carried else (0.0, 0.0, 0.0)
    assert base == pytest.approx(moved, abs=0.05e-3)  # the robot moved, or the sample did
    rec = read_recording(write_map_recording(result, tmp_path / "map.mcap"))
    if carried:  # where the gantry put the robot's base at each probe, as /tf
        assert rec.count("/tf") == 9
        (last_tf,) = rec.messages["/tf"][-1][1].transforms
        t = last_tf.transform.translation
        assert (t.x, t.y, t.z) == pytest.approx(moved, abs=1e-12)
    else:
        assert "/tf" not in rec.messages
    assert result is not None
    assert len(result.probes) == 9
    assert all(p.usable for p in result.probes)
    assert math.dist(last, (result.probes[-1].x, result.probes[-1].y)) < 0.05e-3
    stiffest = max(result.probes, key=lambda p: p.modulus or 0.0)
    assert math.dist((stiffest.x, stiffest.y), (3e-3, -2e-3)) < 3e-3
    softest = min(result.probes, key=lambda p: p.modulus or math.inf)
    assert (stiffest.modulus or 0.0) > 1.3 * (softest.modulus or math.inf)
    assert result.summary is not None
    assert result.summary.found
    assert (tmp_path / "logs" / "probes.jsonl").read_text().count("\n") == 9
    assert all(o.state == "done" for o in result.outcomes)
    assert result.lab_time > sum(o.duration for o in result.outcomes)  # the stage's moves too


def test_the_stage_will_not_move_while_the_sensor_is_out(tmp_path: Path) -> None:
    """A stage move asked with the sensor away from its retract pose raises and holds."""
    loaded = bench_map(tmp_path, "patch_mm: [-5, -5, 5, 5]")
    with stage_bench(loaded, wire=True) as (sim, hw):
        clock = hw.clock
        assert hw.stage is not None
        before = hw.stage.read()
        with pytest.raises(StageMoveError, match="not back"):
            hw.stage.move_to((4e-3, 0.0), clock, tick=0.004, clear=lambda: False)
        assert hw.stage.read() == pytest.approx(before, abs=1e-6)
        here = hw.stage.move_to((4e-3, -3e-3), clock, tick=0.004, clear=lambda: True)
        assert here == pytest.approx((4e-3, -3e-3), abs=0.02e-3)
        ticks = [sim.servo(n).position_ticks for n in STAGE_SERVOS]
        assert ticks == pytest.approx([4 / 2 * 4096, -3 / 2 * 4096], abs=10)  # 2 mm a turn


def test_teleop_jogs_the_stage_step_by_step_within_its_travel(tmp_path: Path) -> None:
    """The jog's goal moves a step a key, clamps at the travel's end, holds while the tip is
    not free; the stage follows it one clamped goal per tick over the bus."""
    from palpate.robot.teleop.stagejog import StageJog

    loaded = bench_map(tmp_path, "patch_mm: [-5, -5, 5, 5]")
    cfg = loaded.stack.stage
    assert cfg is not None
    jog = StageJog(cfg, (0.0, 0.0))
    assert not jog.press("k", step=1e-3, free=True)  # not the stage's key
    assert jog.press("x", step=5e-3, free=True)
    assert jog.press("Y", step=5e-3, free=True)
    assert jog.goal == pytest.approx((5e-3, -5e-3))
    assert jog.press("y", step=5e-3, free=False)
    assert jog.goal == pytest.approx((5e-3, -5e-3))
    assert "not free" in jog.message
    for _ in range(3):
        jog.press("x", step=5e-3, free=True)
    assert jog.goal[0] == pytest.approx(15e-3)
    assert "end of its travel" in jog.message
    with stage_bench(loaded, wire=False) as (_, hw):
        clock = hw.clock
        assert hw.stage is not None
        sent = [hw.stage.follow((2e-3, -1e-3))]
        assert sent[0][0] < 2e-3  # one tick: the bus's step clamp (10 deg of shaft)
        for _ in range(200):
            sent.append(hw.stage.follow((2e-3, -1e-3)))
            clock.sleep(0.01)
        assert sent[-1] == (2e-3, -1e-3)
        assert hw.stage.read() == pytest.approx((2e-3, -1e-3), abs=2e-6)


@pytest.mark.parametrize(
    ("line", "key"),
    [
        ("  x_direction: [0, 1, 0]", "  x_direction: [0, 2, 0]"),
        ("  y_direction: [0, 0, -1]", "  y_direction: [0, 1, 1]"),
    ],
)
def test_a_gantry_whose_directions_are_not_unit_and_orthogonal_is_refused(
    tmp_path: Path, line: str, key: str
) -> None:
    assert line in GANTRY
    with pytest.raises(ConfigError) as err:
        bench_map(
            tmp_path, "patch_mm: [-5, -5, 5, 5]", GANTRY.replace(line, key), "bench-map-robot.yaml"
        )
    assert key.split(":", maxsplit=1)[0].strip() in str(err.value)


def test_a_carried_robot_presses_the_point_its_line_meets() -> None:
    from palpate.config.xystage import XYStageConfig
    from palpate.simulation.twin import carried_touch

    straight = load_bench("bench-map.yaml").stack.tube("straight")
    cfg = XYStageConfig(carries="robot")
    base = 3e-3 * np.asarray(cfg.x_direction) - 2e-3 * np.asarray(cfg.y_direction)
    facing = np.array([-1.0, 0.0, 0.0])  # square to the straight tube: the stage's own point
    assert carried_touch(base, facing, 0.0, straight, cfg) == pytest.approx((3e-3, -2e-3))
    tilted = np.array([-math.cos(0.3), 0.0, math.sin(0.3)])  # the face turned about y
    x, y = carried_touch(base, tilted, 0.0, straight, cfg)
    assert x == pytest.approx(3e-3)
    assert y == pytest.approx(-2e-3)  # the line slides along x: the same point of the face's
    off = 1e-3 * np.array([1.0, 0.0, 0.0])  # ...but a base moved along the tube is no move
    assert carried_touch(base + off, tilted, 0.0, straight, cfg) == pytest.approx((x, y))

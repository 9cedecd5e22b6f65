"""Probing's simulated cost and the FBG interlock on a roll that meets the surface (issue 18).

Seeded trials on the virtual clock: ``probing_time`` is simulated seconds, deterministic, so a
bound on it is a property of the algorithm, not of the machine running the test."""

from __future__ import annotations

import dataclasses
import math
import statistics

import pytest

from palpate.config import load, load_stack, resolve
from palpate.config.scene import SceneConfig
from palpate.config.schema import ServoBusConfig
from palpate.estimation.beam.section import euler_load
from palpate.robot.trial.setup import sensor_section
from palpate.sim.board import BoardEmulator, BoardFaults
from palpate.sim.clock import VirtualClock
from palpate.sim.dynamixel.bus import EmulatedBus
from palpate.sim.world import World, WorldState
from palpate.simulation.trial import TrialOutcome, TrialSpec, run_sim_trial

pytestmark = pytest.mark.slow  # a heavy module fixture: the quick subset leaves it out

STACK = load_stack()
TILTED = load(SceneConfig, resolve("scenes/tilted.yaml"))
LENGTH = 42e-3
P_CR = euler_load(sensor_section(STACK).EI, LENGTH)
# A subset of the tilted scene: both moduli, tilts 0-25 deg, the three bent tubes, downward.
SUBSET = [
    ("S7-t0", "bent15"), ("S8-t5", "bent30"), ("S7-t10", "bent50"),
    ("S8-t15", "bent15"), ("S7-t20", "bent30"), ("S8-t25", "bent50"),
]  # fmt: skip


def spec(sample: str, tube: str, scene: SceneConfig = TILTED, seed: int = 0) -> TrialSpec:
    modulus = next(s.modulus for s in scene.samples if s.name == sample)
    return TrialSpec(
        f"{sample}-{tube}-downward", "robot", sample, modulus, 0.45,
        STACK.tube(tube), "downward", 0.0,
        LENGTH, seed,
    )  # fmt: skip


@pytest.fixture(scope="module")
def subset() -> list[TrialOutcome]:
    return [run_sim_trial(spec(sample, tube), TILTED, STACK) for sample, tube in SUBSET]


def test_probing_on_the_subset_stays_square_within_its_measured_budget(
    subset: list[TrialOutcome],
) -> None:
    """Every trial indents within 1 deg of the world's normal; the median probing time is where
    docs/orientation.md measured it (5.7 s on this subset; 6.4 s before the directional spread
    of the predictions)."""
    for out in subset:
        assert out.state == "done", out.reason
        assert out.true_misalignment is not None
        assert math.degrees(out.true_misalignment) <= 1.0, out.spec.trial_id
    assert statistics.median(out.probing_time for out in subset) < 6.0


class RollWatch:
    """An emulator hook that records the largest axial load the world put on the beam while
    the tube was rolling (two successive board samples at different rolls)."""

    board_faults: BoardFaults | None = None

    def make_bus(self, cfg: ServoBusConfig, clock: VirtualClock) -> EmulatedBus:
        return EmulatedBus.from_config(cfg, clock=clock)

    def attach(
        self, clock: VirtualClock, bus: EmulatedBus, board: BoardEmulator, world: World
    ) -> None:
        self.world = world
        self.peak = 0.0
        self.touched_rolling = 0
        inner = world.state
        last: list[WorldState] = []

        def state(t: float) -> WorldState:
            st = inner(t)
            if last and abs(st.roll - last[0].roll) > 1e-9 and st.P > 0.0:
                self.touched_rolling += 1
                self.peak = max(self.peak, st.P)
            last[:] = [st]
            return st

        world.state = state  # type: ignore[method-assign]

    def log_opened(self, log: object) -> None:
        pass

    def detach(self) -> None:
        pass


def test_a_surface_nearer_than_predicted_during_a_roll_stops_it_below_the_bound() -> None:
    """A surface tilted 38 deg toward the roll, beyond the 30 deg the moves allow for: the roll
    to the second touch meets it before it arrives (the stage is not behind it there). The load
    the beam carried while rolling stays far below its buckling load (measured 0.08 P_cr) and
    the trial ends safely: beyond the search's bound the normal it finds is not to be trusted
    (its doubt once let it indent 19 deg off), and no pose past 5 deg is indented."""
    steep = dataclasses.replace(
        TILTED.samples[6], name="steep", tilt_deg=38.0, tilt_azimuth_deg=90.0
    )  # S8, 315 kPa
    scene = dataclasses.replace(TILTED, samples=(steep,))
    watch = RollWatch()
    out = run_sim_trial(spec("steep", "bent30", scene, seed=2), scene, STACK, hook=watch)  # type: ignore[arg-type]
    assert watch.touched_rolling > 0  # the roll did meet the surface
    assert watch.peak < 0.25 * P_CR
    assert out.state in ("done", "unreachable"), out.reason
    if out.state == "done":
        assert out.misalignment is not None
        assert math.degrees(out.misalignment) <= 5.0 + 1e-9

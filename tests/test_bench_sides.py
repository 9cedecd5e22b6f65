"""The CPU-by-side benchmark: exclusive accounting, wrappers removed, estimates untouched."""

from __future__ import annotations

import itertools
from pathlib import Path

import pytest

import palpate.robot.trial.run
import palpate.robot.trial.session
import palpate.sim.contact_table
from benchmarks.sides import (
    BOUNDARIES,
    CONTROL,
    ESTIMATOR,
    SIMULATOR,
    Ledger,
    measure_sides,
    measured,
)
from palpate.campaigns.campaign import campaign_trials, run_campaign
from palpate.config import load, load_stack, resolve
from palpate.config.scene import SceneConfig
from palpate.sim.clock import VirtualClock
from palpate.sim.dynamixel.bus import EmulatedBus


def test_ledger_counts_each_part_exclusively() -> None:
    ticks = itertools.count()
    ledger = Ledger(clock=lambda: float(next(ticks)))  # every clock read is one "second" later

    inner = ledger.wrap("inner", lambda: None)

    def body() -> None:
        inner()
        inner()

    ledger.wrap("outer", body)()
    # inner: two calls of 1 s each (t0, t1); outer: 5 s in all (reads 0 and 5) less the 2 s
    assert ledger.seconds["inner"] == 2.0
    assert ledger.seconds["outer"] == 5.0 - 2.0
    assert ledger.calls == {"inner": 2, "outer": 1}
    assert ledger.children["outer"] == 2
    assert ledger.children["inner"] == 0


def _hooked() -> tuple[object, ...]:
    """What the benchmark replaces, as it is now."""
    return (
        VirtualClock.__dict__["advance"],
        EmulatedBus.__dict__["exchange"],
        palpate.sim.contact_table.equilibrium_on_grid,
        palpate.robot.trial.session.run_trial,
        palpate.robot.trial.run._tick,
    )


def test_measured_puts_every_original_back_even_on_error() -> None:
    originals = _hooked()

    def fail_inside() -> None:
        with measured():
            assert all(a is not b for a, b in zip(_hooked(), originals, strict=True))
            raise RuntimeError("boom")

    with pytest.raises(RuntimeError):
        fail_inside()
    assert all(a is b for a, b in zip(_hooked(), originals, strict=True))


@pytest.mark.slow
def test_sides_of_two_trials_add_up_and_leave_the_estimates_alone(tmp_path: Path) -> None:
    sides = measure_sides(quick=True, seed=0, log_dir=tmp_path / "m", limit=2)
    assert sides.trials == 2
    assert sides.ticks > 100
    assert sides.startup > 0
    for b in BOUNDARIES:
        assert sides.calls.get(b.part, 0) > 0, b.part
    assert all(sides.side(s) > 0 for s in (SIMULATOR, CONTROL, ESTIMATOR))
    assert sum(sides.parts.values()) == pytest.approx(sides.whole)
    assert sides.real_time_per_core(CONTROL, startup=False) > sides.real_time_per_core(
        CONTROL, ESTIMATOR, startup=True
    )

    scene = load(SceneConfig, resolve("scenes/bench.yaml"))
    stack = load_stack(resolve(scene.robot))
    spec = campaign_trials(scene, stack, 0)[:1]
    plain = run_campaign(spec, scene, stack, log_dir=tmp_path / "a")[0]
    with measured():
        timed = run_campaign(spec, scene, stack, log_dir=tmp_path / "b")[0]
    assert plain.modulus("joint") == timed.modulus("joint")
    assert plain.modulus("paper") == timed.modulus("paper")


def test_the_estimator_check_says_when_the_estimate_got_slower() -> None:
    from benchmarks.sides import REGRESSION, Sides, estimator_check

    def sides(estimator_s: float) -> Sides:
        parts = {b.part: 0.0 for b in BOUNDARIES}
        parts[next(b.part for b in BOUNDARIES if b.side == ESTIMATOR)] = estimator_s
        return Sides(trials=10, ticks=1000, sim_time=40.0, whole=4.0, parts=parts, calls={},
                     startup=1.0, removed=0.0)  # fmt: skip

    within = estimator_check(sides(1.0), reference_ms=100.0)  # 100 ms a trial
    assert within["ratio"] == pytest.approx(1.0)
    assert within["share"] == pytest.approx(0.25)
    assert within["regression"] is False
    slower = estimator_check(sides(1.0 * REGRESSION + 0.01), reference_ms=100.0)
    assert slower["regression"] is True

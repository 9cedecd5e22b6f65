"""An operator's stop (``run_trial(stop=...)``, the ROS 2 node's ``stop`` service and a caller
that leaves) reaches the retract within one control tick: the tick after the stop is asked for
already retracts, and the trial ends ``aborted`` with its log complete."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from palpate.config import load, load_stack, resolve
from palpate.config.scene import SceneConfig
from palpate.estimation.beam.stage import Stage
from palpate.live import Publisher
from palpate.robot.guards import Observation
from palpate.robot.indentation import State
from palpate.robot.records.log import read_log
from palpate.simulation.trial import TrialSpec, run_sim_trial
from palpate.simulation.world import BENCH_COLUMN


class StopWhenIndenting:
    """A view that records each tick's state and asks for a stop on the first indenting tick."""

    def __init__(self) -> None:
        self.ticks: list[tuple[float, State]] = []
        self.asked_at: int | None = None  # the tick index at which the stop was asked for

    def trial(self, stage: Stage) -> Publisher:
        def publish(obs: Observation, state: State) -> None:
            self.ticks.append((obs.t, state))
            if state is State.INDENTING and self.asked_at is None:
                self.asked_at = len(self.ticks) - 1

        return publish

    def cloud(
        self, topic: str, stamp: int, names: Sequence[str], columns: Sequence[NDArray[np.float64]]
    ) -> None:
        raise AssertionError("a trial publishes no map")

    def stop(self) -> bool:
        return self.asked_at is not None


def test_the_tick_after_a_stop_retracts(tmp_path: Path) -> None:
    bench = load(SceneConfig, resolve("scenes/bench.yaml"))
    spec = TrialSpec(
        "S8-L44", "bench", "S8", 314.53e3, 0.45, BENCH_COLUMN, "downward", 0.0, 44e-3, 3
    )
    view = StopWhenIndenting()
    out = run_sim_trial(spec, bench, load_stack(), log_dir=tmp_path, live=view, stop=view.stop)
    assert view.asked_at is not None  # the trial reached indenting
    states = [s for _, s in view.ticks]
    assert states[view.asked_at + 1] is State.RETRACTING  # the very next control tick
    assert states[-1] is State.ABORTED
    assert out.state == "aborted"
    assert out.reason == "aborted: stop requested"
    log = read_log(Path(str(out.log_path)))
    assert log.end["state"] == "aborted"

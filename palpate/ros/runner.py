"""What the node runs when asked: a simulated scene's campaign, a trial at a time, and its
survey when it is a map scene. The same trials as ``palpate sim`` with the same seed, so a trial
run over ROS 2 gives the estimate the command line gives::

    runner = SimRunner(Path("config/scenes/robot.yaml"), seed=0, out=Path("out/ros"))
    spec = runner.spec("")                       # the next trial ("3" or a trial id: that one)
    outcome = runner.run(spec, view, stop=lambda: False)
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING

from palpate.config import InputError, load, load_stack, resolve
from palpate.config.scene import CampaignConfig, SceneConfig
from palpate.config.schema import StackConfig
from palpate.lab.hardware import Hardware, open_hardware
from palpate.live import View
from palpate.sensor.clock import SystemClock
from palpate.services.campaign import CampaignRequest, prepare
from palpate.simulation.trial import TrialOutcome, TrialSpec, run_sim_trial
from palpate.simulation.twin import SimulatedBench

if TYPE_CHECKING:  # the maps import scikit-learn: only when asked for a survey
    from palpate.campaigns.survey import SurveyResult


class SimRunner:
    """A scene's campaign (checked as ``palpate sim`` checks it), its trials on request; logs
    and recordings under ``out`` (None: none)."""

    simulated = True

    def __init__(self, scene: Path, *, seed: int = 0, out: Path | None = None) -> None:
        self.scene = load(SceneConfig, scene)
        self.stack: StackConfig = load_stack(resolve(self.scene.robot))
        # a map scene's trials are its survey's probes: no campaign of its own
        mapping = self.scene.campaign.kind == "map"
        self.campaign = None if mapping else prepare(scene, CampaignRequest((scene,), seed=seed))
        self.seed, self.out, self.next = seed, out, 0
        self.surveys = 0

    @property
    def label(self) -> str:
        n = 0 if self.campaign is None else len(self.campaign.specs)
        return f"simulator: scene {self.scene.name} ({n} trials, seed {self.seed})"

    @property
    def campaign_config(self) -> CampaignConfig:
        """The scene's campaign settings (the guards' and detector's, for jogging)."""
        return self.scene.campaign

    @contextlib.contextmanager
    def jog_hardware(self) -> Iterator[Hardware]:
        """The robot to jog in real time: the scene's bench twin, its first sample in front
        (as ``palpate teleop`` runs without hardware); torque off on the way out."""
        with (
            SimulatedBench(self.stack, self.scene, wire=False) as sim,
            open_hardware(
                self.stack,
                clock=SystemClock(),
                servo_port=sim.servo_port,
                board_port=sim.board_port,
            ) as hw,
        ):
            yield hw

    def spec(self, which: str) -> TrialSpec:
        """The trial ``which`` names (its id, or its index in the campaign), or the next one in
        order for ''; an ``InputError`` for a name the campaign does not have, or past the end."""
        if self.campaign is None:
            raise InputError(f"run_trial: scene {self.scene.name!r} is a map scene: run_survey")
        specs = self.campaign.specs
        if which == "":
            if self.next >= len(specs):
                raise InputError(f"all {len(specs)} trials of the campaign have run")
            return specs[self.next]
        if which.isdigit() and int(which) < len(specs):
            return specs[int(which)]
        for spec in specs:
            if spec.trial_id == which:
                return spec
        raise InputError(
            f"trial: no trial {which!r} in scene {self.scene.name!r} (an id, or an "
            f"index 0-{len(specs) - 1})"
        )

    def run(self, spec: TrialSpec, view: View, stop: Callable[[], bool]) -> TrialOutcome:
        """One trial, its ticks on ``view``; ``stop`` asked every tick."""
        c = self.campaign
        assert c is not None, "spec() refuses a map scene"
        self.next = c.specs.index(spec) + 1
        logs = None if self.out is None else self.out / "logs"
        if logs is not None:
            logs.mkdir(parents=True, exist_ok=True)
        return run_sim_trial(
            spec, c.scene, c.stack, transport=c.transport, log_dir=logs, live=view, stop=stop
        )

    def survey(self, view: View, max_probes: int | None = None) -> SurveyResult:
        """The map scene's survey (at most ``max_probes``, None: the scene's), each probe's
        trial and the map after it on ``view``."""
        from palpate.campaigns.survey import run_survey

        scene = self.scene
        if scene.campaign.kind != "map":
            raise InputError(f"run_survey: scene {scene.name!r} is not a map scene (kind: map)")
        self.surveys += 1
        run_dir = None if self.out is None else self.out / f"survey-{self.surveys}"
        if run_dir is not None:
            run_dir.mkdir(parents=True, exist_ok=True)
        return run_survey(
            scene, self.stack, seed=self.seed, max_probes=max_probes, run_dir=run_dir, live=view
        )


__all__ = ["SimRunner"]

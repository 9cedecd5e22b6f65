"""What the node runs when asked, a trial at a time, and a survey.

In simulation (:class:`SimRunner`) a scene's campaign: the same trials as ``palpate sim`` with
the same seed, so a trial run over ROS 2 gives the estimate the command line gives. On the bench
(:class:`BenchRunner`) a bench file's trials and map, as ``palpate trial`` runs them, on
hardware the runner holds open while the node serves (the ports from the bench file)::

    runner = SimRunner(Path("config/scenes/robot.yaml"), seed=0, out=Path("out/ros"))
    spec = runner.spec("")                       # the next trial ("3" or a trial id: that one)
    outcome = runner.run(spec, view, stop=lambda: False)

    with BenchRunner(Path("config/bench.yaml"), out=Path("out/ros")) as bench:   # opens ports
        outcome = bench.run(bench.spec(""), view, stop=lambda: False)
"""

from __future__ import annotations

import contextlib
import dataclasses
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from types import TracebackType
from typing import TYPE_CHECKING, Protocol, Self, TypeVar

from palpate.config import InputError, load, load_stack, resolve
from palpate.config.bench import load_bench
from palpate.config.scene import CampaignConfig, SceneConfig
from palpate.config.schema import StackConfig
from palpate.lab.hardware import Hardware, open_hardware
from palpate.lab.plan import plan_session
from palpate.lab.trial import BenchOutcome, BenchTrial, Session, run_bench_trials
from palpate.live import View
from palpate.sensor.clock import SystemClock
from palpate.services.campaign import CampaignRequest, prepare
from palpate.services.lab import with_ports
from palpate.simulation.trial import TrialOutcome, TrialSpec, run_sim_trial
from palpate.simulation.twin import SimulatedBench

if TYPE_CHECKING:  # the maps import scikit-learn: only when asked for a survey
    from palpate.campaigns.survey import SurveyResult


class _Trial(Protocol):
    @property
    def trial_id(self) -> str: ...


T = TypeVar("T", bound=_Trial)


def pick(trials: Sequence[T], which: str, following: int, where: str) -> T:
    """The trial ``which`` names (its id, or its index), or the one at ``following`` for '';
    an ``InputError`` for a name ``where`` (the scene, the bench file) lacks, or past the end."""
    if which == "":
        if following >= len(trials):
            raise InputError(f"all {len(trials)} trials of {where} have run")
        return trials[following]
    if which.isdigit() and int(which) < len(trials):
        return trials[int(which)]
    for trial in trials:
        if trial.trial_id == which:
            return trial
    raise InputError(
        f"trial: no trial {which!r} in {where} (an id, or an index 0-{len(trials) - 1})"
    )


class _NoContext:
    """A runner with nothing held between requests (``with`` accepted, nothing to close)."""

    def __enter__(self) -> Self:
        return self

    def __exit__(
        self, kind: type[BaseException] | None, exc: BaseException | None, tb: TracebackType | None
    ) -> None:
        return None


class SimRunner(_NoContext):
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
        return pick(self.campaign.specs, which, self.next, f"scene {self.scene.name!r}")

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


class BenchRunner:
    """A bench file's trials and map on the bench it names (``servo_port``, ``board_port``:
    instead of the file's, e.g. ``palpate emulate``'s ptys), as ``palpate trial`` runs them;
    logs under ``out``. The hardware opens on ``with`` and stays open (torque on, the robot
    held) until the block ends: then torque off and the ports closed."""

    simulated = False

    def __init__(
        self,
        config: str | Path,
        *,
        servo_port: str | None = None,
        board_port: str | None = None,
        out: Path,
    ) -> None:
        self.loaded = with_ports(load_bench(config), servo_port, board_port)
        self.trials, self.template = plan_session(self.loaded, None)
        self.stack: StackConfig = self.loaded.stack
        self.session = Session(self.stack)
        self.log_dir, self.next = out / "logs", 0
        self._held = contextlib.ExitStack()
        self._hw: Hardware | None = None

    def __enter__(self) -> BenchRunner:
        key = str(self.loaded.path)
        self._hw = self._held.enter_context(
            open_hardware(
                self.stack, servo_key=f"servos.port in {key}", board_key=f"board.port in {key}"
            )
        )
        return self

    def __exit__(
        self, kind: type[BaseException] | None, exc: BaseException | None, tb: TracebackType | None
    ) -> None:
        self._hw = None
        self._held.close()  # torque off, ports closed

    @property
    def hw(self) -> Hardware:
        if self._hw is None:
            raise RuntimeError("BenchRunner: open it with `with` first")
        return self._hw

    @property
    def label(self) -> str:
        s = self.stack
        where = f"servos {s.servos.port}, board {s.board.port}"
        return f"bench: {self.loaded.path} ({len(self.trials)} trials; {where})"

    @property
    def campaign_config(self) -> CampaignConfig:
        return self.loaded.bench.campaign

    def jog_hardware(self) -> contextlib.AbstractContextManager[Hardware]:
        """The open bench (a jog session ends with torque off; the next trial turns it on)."""
        return contextlib.nullcontext(self.hw)

    def spec(self, which: str) -> BenchTrial:
        """The bench file's trial ``which`` names (see :func:`pick`), or the first at the
        stored target of that name."""
        at_target = [t for t in self.trials if t.target.name == which]
        if at_target and which not in {t.trial_id for t in self.trials}:
            return at_target[0]
        return pick(self.trials, which, self.next, str(self.loaded.path))

    def run(self, spec: BenchTrial, view: View, stop: Callable[[], bool]) -> BenchOutcome:
        """One trial with the session's calibration so far, as ``palpate trial`` runs each
        (``lab.trial.run_bench_trials``: the calibration kept, the file's ``after_trial``);
        ``stop`` asked every tick."""
        self.next = self.trials.index(spec) + 1
        hw, session = self._ready(), self.session
        [outcome] = run_bench_trials(
            hw, [spec], self.loaded, self.log_dir, live=view, session=session, stop=stop
        )
        return outcome

    def survey(self, view: View, max_probes: int | None = None) -> SurveyResult:
        """The bench file's map on the x-y stage (at most ``max_probes``; None: the file's)."""
        from palpate.services.benchmap import run_bench_map

        m, loaded = self.loaded.bench.map, self.loaded
        if self.template is None or m is None:
            raise InputError(f"run_survey: {loaded.path} has no map: section")
        if max_probes is not None:
            bench = dataclasses.replace(
                loaded.bench, map=dataclasses.replace(m, max_probes=max_probes)
            )
            loaded = dataclasses.replace(loaded, bench=bench)
        return run_bench_map(
            self._ready(), self.template, loaded, self.session.stack, self.log_dir, live=view
        )

    def _ready(self) -> Hardware:
        """The open bench, torque on (a jog, a fault or a release may have turned it off), the
        log folder made."""
        self.log_dir.mkdir(parents=True, exist_ok=True)
        self.hw.drive.bus.set_torque(True)
        return self.hw


__all__ = ["BenchRunner", "SimRunner", "pick"]

"""The stack from Python: what the commands do, as functions returning typed results.

    import palpate

    scene = palpate.load_scene("scenes/bench.yaml")          # a file, or a shipped scene
    report = palpate.simulate(scene, limit=4)                # a simulated campaign
    for trial in report.trials:                              # typed outcomes
        print(trial.spec.trial_id, trial.modulus("joint"), trial.verdict)
    report.as_dict()["samples"]                              # what ``palpate sim --json`` prints

Every result has the fields of the matching command's ``--json`` (``as_dict()``); moduli are in
Pa on the objects and in kPa in the dictionaries (``joint_kpa``: the joint fit, ``paper_kpa``:
the paper's single-point estimate). Bad input raises :class:`palpate.config.InputError` (a
``ValueError``) naming the file (or ``<python>``) and the key. docs/python-api.md shows each
call; examples/ holds whole scripts.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # the heavy modules load when a function needs them: `import palpate` is cheap
    from palpate.campaigns.survey import SurveyResult
    from palpate.config.scene import SceneConfig
    from palpate.config.schema import StackConfig
    from palpate.reports.payload import CampaignReport
    from palpate.robot.records.log import TrialLog
    from palpate.robot.records.recording import Recording
    from palpate.services.design import DesignOutcome
    from palpate.simulation.trial import TrialOutcome, TrialSpec

PYTHON = "<python>"  # the source named in errors about a scene built in code


def load_scene(path: str | Path) -> SceneConfig:
    """A scene file (the format of config/scenes/*.yaml), checked; a name that is not a file
    is looked up among the shipped ones (``"scenes/bench.yaml"``).

    >>> scene = load_scene("scenes/bench.yaml")
    >>> scene.name, len(scene.samples)
    ('bench', 11)
    """
    from palpate.config import load, resolve
    from palpate.config.scene import SceneConfig

    return load(SceneConfig, resolve(path))


def scene_from_dict(data: Mapping[str, Any]) -> SceneConfig:
    """A scene built in code: the mapping a scene file holds (``name``, ``samples``,
    ``campaign``, ...), checked like a file (errors name ``<python>`` and the key).

    >>> sample = {"name": "gel", "modulus_kpa": 300.0, "poisson": 0.45}
    >>> campaign = {"kind": "bench", "exposed_lengths_mm": [44], "repeats": 1}
    >>> scene = scene_from_dict({"name": "mine", "samples": [sample], "campaign": campaign})
    >>> [(s.name, s.modulus) for s in scene.samples]  # SI inside: Pa
    [('gel', 300000.0)]
    >>> scene_from_dict({"name": "bad", "samples": [{**sample, "modulus_kpa": -1}]})
    Traceback (most recent call last):
    ...
    palpate.config.loader.ConfigError: <python>: samples[0].modulus_kpa: must be > 0, got -1.0
    """
    from palpate.config import from_mapping
    from palpate.config.scene import SceneConfig

    return from_mapping(SceneConfig, dict(data), PYTHON)


def load_robot(path: str | Path = "robot.yaml") -> StackConfig:
    """A robot configuration (robot, sensor, drive, tubes, board); the shipped one by default.

    >>> robot = load_robot()
    >>> robot.sensor.exposed_length, [tube.name for tube in robot.tubes]
    (0.042, ['straight', 'bent15', 'bent30', 'bent50'])
    """
    from palpate.config import load_stack

    return load_stack(path)


def trials(
    scene: SceneConfig, *, seed: int = 0, robot: StackConfig | None = None
) -> list[TrialSpec]:
    """The campaign's trials in order (each seeded from ``seed``), checked to be reachable.

    >>> specs = trials(load_scene("scenes/robot.yaml"))
    >>> len(specs), specs[0].trial_id
    (20, 'S7-straight-downward-L42')
    """
    from palpate.campaigns.campaign import campaign_trials
    from palpate.simulation.preflight import check_campaign, check_reachable

    stack = robot if robot is not None else load_robot(scene.robot)
    check_campaign(scene, stack, PYTHON, scene.robot)
    specs = campaign_trials(scene, stack, seed)
    check_reachable(specs, stack, PYTHON, scene.robot)
    return specs


def simulate(
    scene: SceneConfig,
    *,
    limit: int | None = None,
    seed: int = 0,
    workers: int = 1,
    out: str | Path | None = None,
    robot: StackConfig | None = None,
) -> CampaignReport:
    """Run the scene's campaign in simulation (its first ``limit`` trials); ``out``: a folder
    for the trials' logs (``out/logs``) and the results files (``results.json``,
    ``trials.csv``, ``samples.csv``), None for none. The report's ``as_dict()`` is what
    ``palpate sim --json`` prints.

    >>> report = simulate(load_scene("scenes/bench.yaml"), limit=2)
    >>> [trial.as_dict()["verdict"] for trial in report.trials]
    ['ok', 'ok']
    """
    from palpate.services import campaign

    stack = robot if robot is not None else load_robot(scene.robot)
    executor = "serial" if workers <= 1 else "process"
    request = campaign.CampaignRequest(
        (), seed=seed, workers=workers, executor=executor, limit=limit, plots=False
    )
    c = campaign.prepared(scene, stack, request)
    if out is not None:
        campaign.in_folder(c, Path(out))
    campaign.run([c], request)
    return campaign.finish(c, request).report


def simulate_trial(
    scene: SceneConfig,
    trial: int | str = 0,
    *,
    seed: int = 0,
    log_dir: str | Path | None = None,
    robot: StackConfig | None = None,
) -> TrialOutcome:
    """One trial of the scene's campaign (by index or trial id), its log in ``log_dir``.

    >>> import tempfile
    >>> trial = simulate_trial(load_scene("scenes/bench.yaml"), 0, log_dir=tempfile.mkdtemp())
    >>> trial.spec.trial_id, trial.status, 0.95 < trial.modulus("joint") / trial.spec.modulus < 1.05
    ('S1-straight-downward-L42', 'ok', True)
    >>> read_log(trial.log_path).end["state"]
    'done'
    >>> replay(trial.log_path)["identical"]  # the estimates re-run on the log, as recorded
    True
    >>> read_recording(trial.log_path.replace(".jsonl", ".mcap")).complete
    True
    """
    from palpate.config import InputError
    from palpate.simulation.trial import run_sim_trial

    stack = robot if robot is not None else load_robot(scene.robot)
    specs = trials(scene, seed=seed, robot=stack)
    if isinstance(trial, str):
        chosen = [s for s in specs if s.trial_id == trial]
        if not chosen:
            raise InputError(f"no trial {trial!r} in scene {scene.name!r}")
        spec = chosen[0]
    elif 0 <= trial < len(specs):
        spec = specs[trial]
    else:
        raise InputError(f"trial index {trial} outside 0-{len(specs) - 1} of {scene.name!r}")
    folder = None if log_dir is None else Path(log_dir)
    if folder is not None:
        folder.mkdir(parents=True, exist_ok=True)
    return run_sim_trial(spec, scene, stack, log_dir=folder)


def replay(log: str | Path) -> dict[str, Any]:
    """Both estimates re-run on a trial log, compared with the recorded ones: what ``palpate
    replay --json`` prints (``paper_kpa``, ``joint_kpa``, ``joint_ci_kpa``, the recorded ones,
    ``identical``, the truth where the log has it)."""
    from palpate.reports.replay import replay as replay_log

    return replay_log(Path(log))


def read_log(path: str | Path) -> TrialLog:
    """A trial log (``.jsonl``): its header, records by kind (``log.of_kind("sample")``), end."""
    from palpate.robot.records.log import read_log as read

    return read(Path(path))


def read_recording(path: str | Path) -> Recording:
    """A trial's MCAP recording, every message decoded (no ROS needed)."""
    from palpate.robot.records.recording import read_recording as read

    return read(path)


def survey(
    scene: SceneConfig,
    *,
    seed: int = 0,
    strategy: str | None = None,
    max_probes: int | None = None,
    run_dir: str | Path | None = None,
    robot: StackConfig | None = None,
) -> SurveyResult:
    """``palpate map``: a map scene's survey (``campaign.kind: map``), probe by probe through
    whole simulated trials; ``.summary`` is the map's answer (``found``, ``centre``,
    ``centre_ci``, ``radius``), ``.scores()`` compares it with the truth, ``.as_dict()`` is
    what ``--json`` prints. ``run_dir``: the probes file and trial logs (a second call
    carries on from its probes).

    >>> scene = load_scene("scenes/maps/inclusion.yaml")
    >>> result = survey(scene, strategy="raster", max_probes=4)
    >>> len(result.probes), result.stopped
    (4, '4 of 4 probes')
    """
    from palpate.campaigns.survey import run_survey
    from palpate.config import InputError

    if scene.campaign.kind != "map":
        raise InputError(
            f"{PYTHON}: campaign.kind: a survey needs kind: map, got {scene.campaign.kind!r}"
        )
    stack = robot if robot is not None else load_robot(scene.robot)
    path = None if run_dir is None else Path(run_dir)
    if path is not None:
        path.mkdir(parents=True, exist_ok=True)
    return run_survey(
        scene, stack, seed=seed, strategy=strategy, max_probes=max_probes, run_dir=path
    )


def design(
    modulus_range: tuple[float, float], *, unit: str = "kPa", **options: Any
) -> DesignOutcome:
    """``palpate design``: a sensor for ``modulus_range`` (in ``unit``), its checks and its
    simulated check, with the verdict (``.verdict.usable``, ``.reasons``). ``options`` are the
    command's options by name (``tip_grating=True``, ``moduli=3``, ``no_sim=True``,
    ``thickness_mm=10``, ...); ``.as_dict()`` is what ``--json`` prints.

    >>> found = design((300, 1100), unit="kPa", no_sim=True, thickness_mm=10)
    >>> found.result.success, found.verdict.usable  # a design; not simulated: not judged
    (True, None)
    """
    from palpate.services.design import DesignRequest, evaluate

    try:
        request = DesignRequest((float(modulus_range[0]), float(modulus_range[1])), unit, **options)
    except TypeError as exc:  # an option the command does not have
        from palpate.config import InputError

        raise InputError(f"{PYTHON}: palpate.design: {exc}") from None
    return evaluate(request)

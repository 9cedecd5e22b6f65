"""Fuzz targets for the files a user hands to ``palpate``: trial logs (``palpate replay``) and
scene YAML (``palpate sim --scene``), both as mutations of valid files.

- ``replay logs``: a real trial's log (bench and robot) with records mutated (values, keys,
  types, NaN, 1e300), lines deleted, duplicated, swapped, cut, or garbage bytes inserted, then
  :func:`palpate.reports.replay.replay`. It must return a report or raise ``ValueError`` (the CLI's
  bad input, exit 2: ``TrialLogError``, ``ConfigError``); anything else is a failure.
- ``scene yaml``: a shipped scene (bench, robot, faults) with its YAML text or its mapping
  mutated, then what ``palpate sim --scene`` does before any trial runs (load, check, plan,
  reachability) and, for one input in :data:`RUN_EVERY`, the first trial itself. Only
  ``ValueError`` may come out.

:func:`file_targets` builds both (the valid logs come from two short simulated trials);
:mod:`benchmarks.fuzz` runs them with a hang guard, ``tests/fuzz`` from Hypothesis.
"""

from __future__ import annotations

import json
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from benchmarks.fuzzconfig import mutate_mapping, mutate_text
from palpate.campaigns.campaign import campaign_trials
from palpate.config import load, load_stack, resolve
from palpate.config.scene import SceneConfig
from palpate.reports.replay import replay
from palpate.simulation.preflight import check_campaign, check_reachable
from palpate.simulation.trial import TrialSpec, run_sim_trial

Rng = np.random.Generator
RUN_EVERY = 100  # one scene input in this many also runs its first trial
SCENES = ("bench", "robot", "faults")


# -- replay logs -------------------------------------------------------------------------------


def sample_logs(tmp: Path) -> list[list[str]]:
    """The lines of two real trial logs: a bench trial and a robot trial (seeded)."""
    bench = load(SceneConfig, resolve("scenes/bench.yaml"))
    robot = load(SceneConfig, resolve("scenes/robot.yaml"))
    stack = load_stack(resolve(bench.robot))
    logs = []
    for scene in (bench, robot):
        spec = campaign_trials(scene, stack, 0)[0]
        out = run_sim_trial(spec, scene, stack, log_dir=tmp)
        assert out.log_path is not None
        logs.append(Path(out.log_path).read_text(encoding="utf-8").splitlines())
    return logs


def mutate_log(lines: list[str], rng: Rng) -> bytes:
    """A valid log's lines, changed one to three times (see the module docstring)."""
    out = list(lines)
    for _ in range(int(rng.integers(1, 4))):
        r = rng.random()
        if r < 0.45:
            i = _record_index(out, rng)
            try:
                record = json.loads(out[i])
            except ValueError:
                continue
            out[i] = json.dumps(mutate_mapping(record, rng))  # NaN and Infinity as JSON allows
        elif r < 0.6 and out:
            i = int(rng.integers(len(out)))
            out[i] = mutate_text(out[i], rng)
        elif r < 0.7 and out:
            del out[int(rng.integers(len(out)))]
        elif r < 0.8 and out:
            i, j = (int(x) for x in rng.integers(len(out), size=2))
            out[i], out[j] = out[j], out[i]
            out.insert(i, out[j])
        elif r < 0.9:
            garbage = rng.integers(0, 256, size=int(rng.integers(1, 40)), dtype=np.uint8)
            out.insert(int(rng.integers(len(out) + 1)), garbage.tobytes().decode("latin-1"))
        else:
            text = "\n".join(out).encode("latin-1", errors="replace")
            return text[: int(rng.integers(len(text) + 1))]
    data = "\n".join(out) + "\n"
    if rng.random() < 0.05:  # a byte that is not UTF-8 somewhere
        pos = int(rng.integers(len(data) + 1))
        return data[:pos].encode() + b"\xff" + data[pos:].encode()
    return data.encode("utf-8", errors="surrogatepass")


def _record_index(lines: list[str], rng: Rng) -> int:
    """The header, the estimate, the end record, or any record (about a quarter each)."""
    r = rng.random()
    if r < 0.25 or len(lines) < 3:
        return 0
    if r < 0.5:
        return len(lines) - 1
    if r < 0.75:
        return len(lines) - 2
    return int(rng.integers(len(lines)))


def replay_case(data: bytes, path: Path) -> str:
    """Write ``data`` as a log and replay it: "identical", "different", "truncated", "damaged"
    or "bad input" (a ValueError, exit 2 in the CLI); any other exception propagates."""
    path.write_bytes(data)
    try:
        with warnings.catch_warnings():  # absurd numbers may warn (overflow): not a failure
            warnings.simplefilter("ignore", RuntimeWarning)
            report = replay(path)
    except ValueError:
        return "bad input"
    json.dumps(report, allow_nan=True)  # the --json output can be written
    if report.get("damaged"):
        return "damaged"
    if "message" in report:
        return "truncated"
    return "identical" if report["identical"] else "different"


# -- scene yaml --------------------------------------------------------------------------------


def scene_texts() -> list[str]:
    return [resolve(f"scenes/{name}.yaml").read_text(encoding="utf-8") for name in SCENES]


def scene_case(text: str, path: Path, *, run_first: bool = False) -> str:
    """Write ``text`` as a scene and do what ``palpate sim --scene`` does before (and, with
    ``run_first``, for) its first trial: "accepted" or "refused" (a ValueError, exit 2)."""
    path.write_text(text, encoding="utf-8", errors="surrogatepass")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            specs, scene, stack = _plan(path)
            if run_first:
                run_sim_trial(specs[0], scene, stack)
    except ValueError:
        return "refused"
    return "accepted"


def _plan(path: Path) -> tuple[list[TrialSpec], SceneConfig, Any]:
    scene = load(SceneConfig, path)
    robot = resolve(scene.robot)
    stack = load_stack(robot)
    check_campaign(scene, stack, str(path), str(robot))
    specs = campaign_trials(scene, stack, 0)
    if not specs:
        raise ValueError(f"{path}: the campaign has no trials")
    check_reachable(specs, stack, str(path), str(robot))
    return specs, scene, stack


def mutate_scene(text: str, rng: Rng) -> str:
    """A scene's text mutated as text, or as a YAML mapping dumped back."""
    if rng.random() < 0.5:
        return mutate_text(text, rng)
    data = yaml.safe_load(text)
    return yaml.safe_dump(mutate_mapping(data, rng), allow_unicode=True)


def file_targets(tmp: Path) -> dict[str, Callable[[Rng], object]]:
    """The two targets, each drawing an input from the generator and checking it."""
    logs = sample_logs(tmp / "logs")
    scenes = scene_texts()
    log_path, scene_path = tmp / "fuzz.jsonl", tmp / "fuzz-scene.yaml"

    def logs_target(rng: Rng) -> object:
        lines = logs[int(rng.integers(len(logs)))]
        return replay_case(mutate_log(lines, rng), log_path)

    def scenes_target(rng: Rng) -> object:
        text = mutate_scene(scenes[int(rng.integers(len(scenes)))], rng)
        return scene_case(text, scene_path, run_first=rng.random() < 1 / RUN_EVERY)

    return {"replay logs": logs_target, "scene yaml": scenes_target}

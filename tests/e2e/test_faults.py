"""The fault campaign: each injected fault ends in a safe stop with its data kept, judged from the
emulators and the logs; the judge itself catches unsafe ends; no network listener is opened."""

from __future__ import annotations

import dataclasses
import json
import os
from pathlib import Path

import pytest

from palpate.cli import main
from palpate.config import load, load_stack, resolve
from palpate.config.faults import FaultCase
from palpate.config.scene import SceneConfig
from palpate.faults import (
    FaultJob,
    GroundTruth,
    ServoSnapshot,
    fault_jobs,
    fault_table,
    judge,
    run_fault_trial,
)
from palpate.simulation.trial import TrialOutcome

SCENE_PATH = resolve("scenes/faults.yaml")
SCENE = load(SceneConfig, SCENE_PATH)
STACK = load_stack(resolve(SCENE.robot))

# case -> what the log must give as the reason (a cheap subset of config/scenes/faults.yaml)
EXPECTED = {
    "servo-timeout": "bus transport",
    "servo-corrupt-replies": "Incorrect status packet",
    "servo-corrupt-burst": "completed",  # a read missed is a tick held, not a fault (issue 35)
    "overload": "Overload",
    "stall": "Overload",
    "stream-stops": "FBG stream lost",
    "early-contact": "unexpected contact",
    "tube-tip-compliance": "no buckling",
    "killed": "SIGKILL",
}


def _job(name: str, tmp_path: Path) -> FaultJob:
    jobs = fault_jobs(SCENE, STACK, str(SCENE_PATH), 0, tmp_path, "fast")
    return next(j for j in jobs if j.case.name == name)


@pytest.mark.slow
@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_fault_ends_in_a_safe_stop_with_data_kept(name: str, tmp_path: Path) -> None:
    result = run_fault_trial(_job(name, tmp_path))
    assert result.safe, result.problems
    assert result.data_kept, result.problems
    assert EXPECTED[name] in result.reason
    truth = result.truth
    assert truth.fired_at is not None  # the fault really was injected
    if name == "stall":  # the blocked stage cannot pull back: it must be left torque-free
        assert truth.translation_blocked == "stalled"
        assert not truth.servos["translation"].torque
    elif name != "killed":
        assert truth.end_past_contact < 0.0  # retracted off the tissue...
        assert all(not s.torque for s in truth.servos.values())  # ...and left torque-free
    else:
        assert truth.records_written is not None
        assert truth.records_written > 10


def test_servo_timeout_retracts_blind_once_the_bus_returns(tmp_path: Path) -> None:
    """A 0.3 s reply outage while indenting: the stage still pulls back off the tissue."""
    result = run_fault_trial(_job("servo-timeout", tmp_path))
    assert result.state == "fault"
    assert result.truth.link["muted"] > 0
    assert result.truth.end_past_contact < -1e-3


def _outcome(job: FaultJob, log: str | None, state: str = "fault") -> TrialOutcome:
    return TrialOutcome(
        spec=job.spec,
        ik_residual=0.0,
        ticks=5,
        sim_time=1.0,
        state=state,
        reason="servo fault",
        log_path=log,
    )


def test_judge_catches_a_servo_left_pushing_and_a_missing_log(tmp_path: Path) -> None:
    job = _job("overload", tmp_path)
    truth = GroundTruth(
        fired_at=1.0,
        max_strain=1e-3,
        max_past_contact=0.5e-3,
        end_past_contact=0.2e-3,  # still in the tissue
        end_force=0.05,
        servos={
            "outer_roll": ServoSnapshot(False, 0.0, 0, 0),
            "inner_roll": ServoSnapshot(False, 0.0, 0, 0),
            "translation": ServoSnapshot(True, 40.0, 30, 0),  # torqued and still moving
        },
    )
    result = judge(job, _outcome(job, None), truth)
    assert not result.safe
    assert not result.data_kept
    text = " ".join(result.problems)
    assert "still moving" in text
    assert "not retracted" in text
    assert "no log" in text


def test_judge_catches_strain_and_travel_beyond_the_guards(tmp_path: Path) -> None:
    job = _job("overload", tmp_path)
    truth = GroundTruth(max_strain=6e-3, max_past_contact=3e-3, end_past_contact=-1e-3)
    result = judge(job, None, truth, "raised RuntimeError: boom")
    assert not result.safe
    assert result.state == "crash"
    assert any("strain" in p for p in result.problems)
    assert any("travel past contact" in p for p in result.problems)
    assert any("RuntimeError" in p for p in result.problems)


def _listening_inodes() -> set[str]:
    """Inodes of TCP/UDP sockets in LISTEN (or bound UDP) state visible to this process."""
    inodes: set[str] = set()
    for name in ("tcp", "tcp6", "udp", "udp6"):
        path = Path(f"/proc/self/net/{name}")
        if not path.exists():
            continue
        for line in path.read_text().splitlines()[1:]:
            cols = line.split()
            if (name.startswith("tcp") and cols[3] == "0A") or name.startswith("udp"):
                inodes.add(cols[9])
    return inodes


def _own_socket_inodes() -> set[str]:
    out = set()
    for fd in os.listdir("/proc/self/fd"):
        try:
            target = os.readlink(f"/proc/self/fd/{fd}")
        except OSError:
            continue
        if target.startswith("socket:["):
            out.add(target[8:-1])
    return out


def _small_fault_scene(tmp_path: Path, cases: list[dict[str, object]]) -> Path:
    text = SCENE_PATH.read_text(encoding="utf-8").split("faults:")[0]
    body = json.dumps({"trials_per_case": 1, "cases": cases})
    path = tmp_path / "faults.yaml"
    path.write_text(text + f"faults: {body}\n", encoding="utf-8")
    return path


@pytest.mark.skipif(not Path("/proc/self/net/tcp").exists(), reason="needs Linux /proc")
def test_cli_fault_campaign_table_and_no_listener(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scene = _small_fault_scene(
        tmp_path, [{"name": "overheat", "hardware_error": ["overheating"], "delay_s": 0.1}]
    )
    code = main(["sim", "--faults", "--scene", str(scene), "--workers", "1", "--json",
                 "--out", str(tmp_path / "out")])  # fmt: skip
    assert code == 0
    payload = json.loads(capsys.readouterr().out)
    assert payload["faults"] == [
        {"fault": "overheat", "trials": 1, "safe_stops": 1, "data_kept": 1,
         "outcome": payload["faults"][0]["outcome"]}
    ]  # fmt: skip
    assert "Overheating" in payload["faults"][0]["outcome"]
    assert not (_own_socket_inodes() & _listening_inodes())


def test_cli_fault_scene_with_a_bad_board_key_exits_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scene = _small_fault_scene(tmp_path, [{"name": "x", "board": {"bitflip_prob": 0.1}}])
    assert main(["sim", "--faults", "--scene", str(scene), "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert str(scene) in err
    assert "faults.cases[0].board.bitflip_prob" in err


def test_fault_table_counts_per_case(tmp_path: Path) -> None:
    job = _job("overload", tmp_path)
    ok = judge(job, None, GroundTruth(end_past_contact=-1.0), "raised X: y")
    rows = fault_table([ok, dataclasses.replace(ok, safe=True, data_kept=True)])
    assert len(rows) == 1
    assert (rows[0].trials, rows[0].safe_stops, rows[0].data_kept) == (2, 1, 1)


def test_fault_case_names_must_be_unique(tmp_path: Path) -> None:
    scene = _small_fault_scene(tmp_path, [{"name": "a"}, {"name": "a"}])
    assert main(["sim", "--faults", "--scene", str(scene), "--out", str(tmp_path)]) == 2
    assert FaultCase(name="a").trigger == "contact"

"""A soft trial end to end on the wire path (issue 28): the lung scene's designed sensor with its
tip force grating, dynamixel-sdk and pyserial over pseudo-terminals, the tip grating in every
frame, the joint fit reading the load from it, the log and its replay."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from config import load, load_stack, resolve
from config.scene import SceneConfig
from palpate.campaigns.campaign import campaign_trials
from palpate.reports.replay import replay
from palpate.simulation.trial import TrialOutcome, run_sim_trial

LUNG = load(SceneConfig, resolve("scenes/lung.yaml"))
STACK = load_stack(LUNG.robot)


@pytest.fixture(scope="module")
def fibrotic(tmp_path_factory: pytest.TempPathFactory) -> TrialOutcome:
    spec = next(
        s
        for s in campaign_trials(LUNG, STACK, 0)
        if s.sample == "F2" and s.tube == "bent30" and s.orientation == "sideways"
    )
    logs = tmp_path_factory.mktemp("logs")
    return run_sim_trial(spec, LUNG, STACK, transport="wire", log_dir=logs)


def test_the_soft_trial_reads_its_load_from_the_tip_grating(fibrotic: TrialOutcome) -> None:
    assert fibrotic.state == "done", fibrotic.reason
    assert fibrotic.joint is not None
    assert fibrotic.joint.success, fibrotic.joint.message
    assert fibrotic.joint.modulus == pytest.approx(14e3, rel=0.05)
    assert fibrotic.joint.covers(14e3)
    assert fibrotic.verdict is not None
    assert fibrotic.verdict.status == "ok", fibrotic.verdict


def test_the_log_carries_the_tip_load_and_replays_identically(fibrotic: TrialOutcome) -> None:
    assert fibrotic.log_path is not None
    rows = [json.loads(line) for line in Path(fibrotic.log_path).read_text().splitlines()]
    samples = [r for r in rows if r["kind"] == "sample"]
    tips = [r["tip_force"] for r in samples if r["state"] == "buckled"]
    assert tips
    assert min(tips) > 0.5 * 18e-3
    free = [r["tip_force"] for r in samples if r["state"] == "approach"]
    assert max(abs(f) for f in free) < 1e-3  # zeroed at rest, compensated for the drift
    report = replay(Path(fibrotic.log_path))
    assert report["identical"], report


def test_without_its_tip_grating_the_board_and_reader_disagree_cleanly() -> None:
    """A sensor file with a tip grating and a board whose frames lack it: the reader's layout
    has the tip bit, so the frames are rejected as bad headers, never misread."""
    from sensor.parser import FrameParser, layout_from_config
    from wire.frame import encode, frame_from_si

    layout = layout_from_config(STACK.sensor, STACK.board)
    assert layout.has_tip
    assert layout.has_reference
    old = encode(frame_from_si(1, 0.0, 0, [1.53e-6, 1.535e-6, 1.54e-6], reference=1.525e-6))
    parser = FrameParser(layout)
    assert parser.feed(old) == []
    assert parser.counters.bad_headers == 1

"""A soft trial end to end on the wire path (issue 28): the lung scene's designed sensor with its
tip force grating, dynamixel-sdk and pyserial over pseudo-terminals, the tip grating in every
frame, the joint fit reading the load from it, the log and its replay."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from palpate.campaigns.campaign import campaign_trials
from palpate.config import load, load_stack, resolve
from palpate.config.scene import SceneConfig
from palpate.estimation.trial.states import LOADING_STATES
from palpate.reports.replay import replay
from palpate.simulation.trial import TrialOutcome, run_sim_trial

pytestmark = pytest.mark.slow  # a heavy module fixture: the quick subset leaves it out

LUNG = load(SceneConfig, resolve("scenes/lung/lung.yaml"))
STACK = load_stack(LUNG.robot)


@pytest.fixture(scope="module")
def fibrotic(tmp_path_factory: pytest.TempPathFactory) -> TrialOutcome:
    spec = next(
        s
        for s in campaign_trials(LUNG, STACK, 0)
        if s.sample == "F2" and s.tube.name == "bent30" and s.orientation == "sideways"
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


def test_the_recordings_wrench_is_the_tip_gratings_load(fibrotic: TrialOutcome) -> None:
    from palpate.robot.records.recording import read_recording

    assert fibrotic.log_path is not None
    log = Path(fibrotic.log_path)
    rows = [json.loads(line) for line in log.read_text().splitlines()]
    tips = np.array([r.get("tip_force", np.nan) for r in rows if r["kind"] == "sample"])
    rec = read_recording(log.with_suffix(".mcap"))
    force = np.array([m.wrench.force.z for _, m in rec.messages["/tip/wrench"]])
    np.testing.assert_array_equal(force, -tips)


def test_without_its_tip_grating_the_board_and_reader_disagree_cleanly() -> None:
    """A sensor file with a tip grating and a board whose frames lack it: the reader's layout
    has the tip bit, so the frames are rejected as bad headers, never misread."""
    from palpate.sensor.parser import FrameParser, layout_from_config
    from palpate.wire.frame import encode, frame_from_si

    layout = layout_from_config(STACK.sensor, STACK.board)
    assert layout.has_tip
    assert layout.has_reference
    old = encode(frame_from_si(1, 0.0, 0, [1.53e-6, 1.535e-6, 1.54e-6], reference=1.525e-6))
    parser = FrameParser(layout)
    assert parser.feed(old) == []
    assert parser.counters.bad_headers == 1


def test_a_bench_rehearsal_on_the_twin_reads_the_tip_grating(tmp_path: Path) -> None:
    """`palpate emulate --scene` + `palpate trial`: the designed sensor's robot file (as
    `palpate design --write` wrote it) in a bench file, a fibrotic sample in front of the twin,
    the session on the ptys reads its load from the tip grating and estimates it."""
    import dataclasses

    from palpate.config.bench import load_bench
    from palpate.config.loader import write_yaml
    from palpate.lab.trial import plan_bench_trials
    from palpate.services.lab import run_session
    from palpate.sim.clock import VirtualClock
    from palpate.simulation.twin import SimulatedBench, surface_at

    contact_mm = STACK.sensor.exposed_length_mm  # the tube flush at 0: the contact's translation
    quick = dataclasses.replace(
        STACK,
        drive=dataclasses.replace(STACK.drive, home_translation_mm=contact_mm - 2.5),
        servos=dataclasses.replace(STACK.servos, timeout_ms=2000.0),
    )
    write_yaml(quick, tmp_path / "robot.yaml")
    (tmp_path / "targets.yaml").write_text(
        "targets:\n  - {name: side, tube: bent30, roll_deg: 90, "
        f"translation_mm: {contact_mm - 1.0}}}\n",
        encoding="utf-8",
    )
    bench = tmp_path / "bench.yaml"
    bench.write_text(
        f"servos: {{port: {tmp_path}/ttyNOPE0}}\nboard: {{port: {tmp_path}/ttyNOPE1}}\n"
        f"robot: {tmp_path}/robot.yaml\ntargets: {tmp_path}/targets.yaml\n"
        f"log_dir: {tmp_path}/logs\n"
        "campaign: {contact: tip, detector_threshold_ue: 141, max_travel_past_contact_mm: 8,\n"
        "           approach_speed_mm_per_s: 1.0}\n"
        "trials:\n  - {target: side, sample: F2, modulus_kpa: 14, poisson: 0.45}\n",
        encoding="utf-8",
    )
    loaded = load_bench(bench)
    surface = surface_at(quick.tube("bent30"), 0.5 * 3.141592653589793, contact_mm * 1e-3, 10e-3)
    clock = VirtualClock()
    with SimulatedBench(
        loaded.stack, LUNG, sample="F2", surface=surface, tube="bent30", clock=clock, wire=True
    ) as sim:
        (o,) = run_session(
            loaded,
            plan_bench_trials(loaded),
            tmp_path / "logs",
            servo_port=sim.servo_port,
            board_port=sim.board_port,
            clock=clock,
            sync_to_clock=True,
        )
    assert o.state == "done", o.reason
    log = [json.loads(line) for line in Path(str(o.log_path)).read_text().splitlines()]
    loading = [r for r in log if r["kind"] == "sample" and r["state"] in LOADING_STATES]
    assert loading
    assert all("tip_force" in r for r in loading)
    assert o.joint is not None
    assert o.joint.modulus == pytest.approx(14e3, rel=0.1)  # thickness and bonding unknown here
    assert replay(Path(str(o.log_path)))["identical"] is True


def test_palpate_emulate_streams_the_tip_grating_of_the_designed_sensor() -> None:
    """`palpate emulate --config robot-lung.yaml`: the board's pty carries revision 1.1 frames
    (reference and tip grating) that the configured reader takes."""
    import subprocess
    import sys

    from palpate.sensor.parser import layout_from_config
    from palpate.sensor.reader import FrameReader

    proc = subprocess.Popen(
        [sys.executable, "-m", "palpate", "emulate", "--config", "robot-lung.yaml",
         "--seconds", "60", "--json"],
        stdout=subprocess.PIPE,
        text=True,
    )  # fmt: skip
    try:
        assert proc.stdout is not None
        ports = json.loads(proc.stdout.readline())
        layout = layout_from_config(STACK.sensor, STACK.board)
        with FrameReader(ports["board"], layout) as reader:
            frames = reader.read_frames(5, timeout_s=30.0)
        assert len(frames) >= 5
        tip = STACK.sensor.tip_grating
        assert tip is not None
        assert all(f.tip == pytest.approx(tip.base_wavelength, abs=1e-15) for f in frames)
        assert all(f.reference is not None for f in frames)
    finally:
        proc.terminate()
        proc.communicate(timeout=30)  # reaps it and closes its stdout


def test_a_sample_stiffer_than_the_designed_range_keeps_its_number_as_suspect(
    tmp_path: Path,
) -> None:
    """60 kPa in front of the 1-20 kPa sensor: it buckles at 0.15 mm and the fit reads about
    60 kPa, whose whole interval lies outside the designed range: `suspect`, saying so, with
    its number (the answer is "stiffer than 20 kPa")."""
    import dataclasses

    from palpate.config.sample import SampleConfig

    stiff = SampleConfig(
        name="S60", modulus_kpa=60.0, poisson=0.45, thickness_mm=20.0, material="neo-hookean",
        lateral_radius_mm=60.0,
    )  # fmt: skip
    scene = dataclasses.replace(LUNG, samples=(stiff,))
    spec = next(s for s in campaign_trials(scene, STACK, 0) if s.orientation == "sideways")
    out = run_sim_trial(spec, scene, STACK, log_dir=tmp_path)
    assert out.state == "done", out.reason
    assert out.verdict is not None
    assert out.verdict.status == "suspect"
    assert out.verdict.reasons[0].startswith("above the designed range 1-20 kPa")
    assert out.modulus("joint") is not None
    assert out.modulus("joint") > 20e3


def test_probing_finds_a_tilted_soft_samples_normal_with_the_tip_grating() -> None:
    """A 10 deg tilted fibrotic sample at an azimuth the plan does not know: the touches read
    the tip grating's load (the beam's 15 ue of axial strain would not show them), the normal
    is found, the re-planned pose is orthogonal within a degree and the estimate is `ok`."""
    tilted = load(SceneConfig, resolve("scenes/lung/tilted.yaml"))
    spec = next(
        s
        for s in campaign_trials(tilted, STACK, 0)
        if s.sample == "F2-t10" and s.tube.name == "bent30" and s.orientation == "downward"
    )
    out = run_sim_trial(spec, tilted, STACK)
    assert out.state == "done", out.reason
    assert out.probe is not None
    assert out.probe.normal is not None, out.probe.reason
    assert not any(t.slipped for t in out.probe.touches)
    assert out.misalignment is not None
    assert abs(out.misalignment) < math.radians(1.0)
    assert out.verdict is not None
    assert out.verdict.status == "ok", out.verdict
    assert out.joint is not None
    assert out.joint.modulus == pytest.approx(14e3, rel=0.1)

"""Recordings that tools reading by index open: a trial's (bench and robot) and a map's MCAP go
through Rerun's own importer (``rerun mcap convert``, from the ``rerun-sdk`` wheel of the dev
extra) and every message of every channel comes out as a row. An unchunked file, as the
recordings were written before, converts to no message rows: the check can fail.
"""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
from collections import Counter
from pathlib import Path

import pytest
from mcap.reader import make_reader  # type: ignore[import-untyped,unused-ignore]
from mcap.writer import CompressionType, Writer  # type: ignore[import-untyped,unused-ignore]

import palpate
from palpate.campaigns.surveyloop import SurveyResult
from palpate.maps import Patch, Probe
from palpate.reports.maprecording import write_map_recording
from palpate.robot.records.recording import read_recording

RERUN = shutil.which("rerun", path=str(Path(sys.executable).parent)) or shutil.which("rerun")
pytestmark = pytest.mark.skipif(RERUN is None, reason="rerun-sdk (the dev extra) not installed")
CHUNK_ROW = re.compile(r"^Chunk\(\S+\) with (\d+) rows .* - (/\S+) - ")


def rerun_rows(mcap: Path, tmp_path: Path) -> Counter[str]:
    """Rows per entity path of ``mcap`` as Rerun imports it."""
    assert RERUN is not None
    rrd = tmp_path / f"{mcap.stem}.rrd"
    subprocess.run([RERUN, "mcap", "convert", str(mcap), "-o", str(rrd)], check=True, timeout=120)
    printed = subprocess.run(
        [RERUN, "rrd", "print", str(rrd)], check=True, capture_output=True, text=True, timeout=120
    ).stdout
    rows: Counter[str] = Counter()
    for line in printed.splitlines():
        if m := CHUNK_ROW.match(line):
            rows[m.group(2)] += int(m.group(1))
    return rows


def every_message_is_a_row(mcap: Path, tmp_path: Path) -> None:
    recording = read_recording(mcap)
    assert recording.complete
    assert recording.messages
    rows = rerun_rows(mcap, tmp_path)
    for topic in recording.messages:
        assert rows[topic] >= recording.count(topic), (topic, rows[topic], recording.count(topic))
    with open(mcap, "rb") as fh:  # read by index: the summary's chunk indexes find every one
        reader = make_reader(fh)
        assert reader.get_summary().chunk_indexes
        indexed = Counter(channel.topic for _, channel, _ in reader.iter_messages())
    assert indexed == Counter({t: recording.count(t) for t in recording.messages})


@pytest.mark.parametrize("scene", ["scenes/bench.yaml", "scenes/robot.yaml"])
def test_a_trial_s_recording_opens_in_rerun_message_by_message(scene: str, tmp_path: Path) -> None:
    trial = palpate.simulate_trial(palpate.load_scene(scene), 0, log_dir=tmp_path / "logs")
    assert trial.log_path is not None
    mcap = Path(trial.log_path).with_suffix(".mcap")
    every_message_is_a_row(mcap, tmp_path)
    if scene.endswith("robot.yaml"):
        assert read_recording(mcap).count("/tf") > 0  # the tip's pose, on the robot


def test_a_map_s_recording_opens_in_rerun(tmp_path: Path) -> None:
    probes = [
        Probe(x * 1e-3, y * 1e-3, e * 1e3, (0.9 * e * 1e3, 1.1 * e * 1e3), "ok", (), 30.0, 1e-3)
        for x, y, e in [(-5, -5, 300), (5, -5, 320), (-5, 5, 310), (5, 5, 900), (0, 0, 600)]
    ]
    patch = Patch(-10e-3, -10e-3, 10e-3, 10e-3)
    result = SurveyResult(probes, None, "budget", 150.0, 0.0, None, patch)
    every_message_is_a_row(write_map_recording(result, tmp_path / "map.mcap"), tmp_path)


def test_an_unchunked_file_gives_rerun_nothing_to_read(tmp_path: Path) -> None:
    """The check can fail: the same messages written without chunks or indexes (the
    recordings' old form) convert to no message rows (a channel's one static row at most)."""
    source = tmp_path / "bench"
    trial = palpate.simulate_trial(palpate.load_scene("scenes/bench.yaml"), 0, log_dir=source)
    assert trial.log_path is not None
    indexed = Path(trial.log_path).with_suffix(".mcap")
    flat = tmp_path / "flat.mcap"
    with open(indexed, "rb") as fh, open(flat, "wb") as out:
        reader = make_reader(fh)
        writer = Writer(out, use_chunking=False, compression=CompressionType.NONE)
        writer.start(profile="ros2", library="palpate")
        ids: dict[int, int] = {}
        for schema, channel, message in reader.iter_messages():
            if channel.id not in ids:
                sid = writer.register_schema(schema.name, schema.encoding, schema.data)
                ids[channel.id] = writer.register_channel(
                    channel.topic, channel.message_encoding, sid
                )
            writer.add_message(
                ids[channel.id], message.log_time, message.data, message.publish_time
            )
        writer.finish()
    rows = rerun_rows(flat, tmp_path)
    assert read_recording(flat).count("/joint_states") > 100  # the messages are there
    assert rows["/joint_states"] <= 1

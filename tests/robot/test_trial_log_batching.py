"""The trial log's batched flushes: what is on disk at any instant is what ``records`` says,
every state change is on disk at once, and pending samples never span more than 0.1 s."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from palpate.robot.records.log import TrialLogWriter


def _on_disk(path: Path) -> list[dict[str, object]]:
    text = path.read_text(encoding="utf-8")
    assert text == "" or text.endswith("\n")  # never a torn line between flushes
    return [json.loads(line) for line in text.splitlines()]


def test_samples_wait_at_most_the_flush_interval(tmp_path: Path) -> None:
    path = tmp_path / "t.jsonl"
    with TrialLogWriter(path, {"trial": "b"}, flush_every_s=0.1) as w:
        assert len(_on_disk(path)) == w.records == 1  # the header at once
        for k in range(25):  # 0 .. 0.096 s at 250 Hz: still pending
            w.write({"kind": "sample", "t": k * 0.004})
            assert len(_on_disk(path)) == w.records == 1
        w.write({"kind": "sample", "t": 25 * 0.004})  # 0.1 s after the oldest pending one
        assert len(_on_disk(path)) == w.records == w.written == 27


def test_a_state_change_flushes_what_is_pending(tmp_path: Path) -> None:
    path = tmp_path / "t.jsonl"
    with TrialLogWriter(path, {"trial": "s"}) as w:
        w.write({"kind": "sample", "t": 0.0})
        w.write({"kind": "sample", "t": 0.004})
        assert w.records == 1
        w.write({"kind": "transition", "t": 0.004, "from": "a", "to": "b"})
        kinds = [r["kind"] for r in _on_disk(path)]
        assert kinds == ["header", "sample", "sample", "transition"]
        assert w.records == w.written == 4
        w.write({"kind": "sample", "t": 0.008})
    kinds = [r["kind"] for r in _on_disk(path)]  # close flushes the rest
    assert kinds == ["header", "sample", "sample", "transition", "sample"]


def test_zero_interval_flushes_every_line(tmp_path: Path) -> None:
    path = tmp_path / "t.jsonl"
    with TrialLogWriter(path, {"trial": "z"}, flush_every_s=0.0) as w:
        w.write({"kind": "sample", "t": 0.0})
        assert len(_on_disk(path)) == w.records == 2


def test_a_negative_interval_is_rejected(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="flush_every_s"):
        TrialLogWriter(tmp_path / "t.jsonl", {}, flush_every_s=-1.0)

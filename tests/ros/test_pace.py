"""A simulated trial paced to the wall clock (``palpate ros --pace``): the feed waits until the
wall has caught up with the trial's clock, and never when it is behind. The clock and the wait
are the test's own (no wall time passes)."""

from __future__ import annotations

from types import SimpleNamespace

import pytest

pytest.importorskip("rclpy", reason="the ros extra (ROS 2 wheels) is not installed")

from palpate.ros import view as view_module


def test_the_feed_waits_for_the_wall_clock_at_its_pace(monkeypatch: pytest.MonkeyPatch) -> None:
    wall = [100.0]
    waits: list[float] = []

    def sleep(s: float) -> None:
        waits.append(s)
        wall[0] += s

    monkeypatch.setattr(view_module.time, "monotonic", lambda: wall[0])
    monkeypatch.setattr(view_module.time, "sleep", sleep)
    feed = view_module._Feed(SimpleNamespace(pace=2.0), stage=None, base=0.0)  # type: ignore[arg-type]
    feed._keep_pace(0.0, 2.0)  # the trial's 0 is now
    feed._keep_pace(1.0, 2.0)  # 1 s of trial at 2x: 0.5 s of wall
    assert waits == [pytest.approx(0.5)]
    wall[0] += 3.0  # the trial fell behind (a busy machine): no wait
    feed._keep_pace(2.0, 2.0)
    assert len(waits) == 1
    feed._keep_pace(9.0, 2.0)  # ahead again: waits until 100 + 9 / 2
    assert wall[0] == pytest.approx(104.5)


def test_a_pace_that_is_not_positive_is_refused() -> None:
    with pytest.raises(ValueError, match="pace"):
        view_module.RosView(None, None, rate=50.0, sim_time=True, pace=0.0)  # type: ignore[arg-type]


def test_pace_is_for_a_simulated_scene_only(capsys: pytest.CaptureFixture[str]) -> None:
    from palpate.cli import main

    assert main(["ros", "--config", "bench.yaml", "--pace", "2"]) == 2
    assert "--pace: only with --scene" in capsys.readouterr().err

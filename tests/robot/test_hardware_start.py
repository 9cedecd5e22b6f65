"""The servos' start at open is tried again before the bus is called silent
(``lab.hardware._start``): a host busy beside the bus can leave answers unread for longer
than one write's retries take."""

from __future__ import annotations

import pytest

from palpate.lab.hardware import START_ATTEMPTS, _start
from palpate.robot.motors import ServoTransportError


class _Drive:
    """A drive whose first ``silent`` starts find the bus silent."""

    def __init__(self, silent: int) -> None:
        self.silent, self.starts = silent, 0

    def start(self) -> None:
        self.starts += 1
        if self.starts <= self.silent:
            raise ServoTransportError(f"no status packet (start {self.starts})")


def test_a_start_that_meets_a_silent_moment_is_tried_again() -> None:
    drive = _Drive(silent=START_ATTEMPTS - 1)
    _start(drive)  # type: ignore[arg-type]
    assert drive.starts == START_ATTEMPTS


def test_a_bus_silent_at_every_start_is_reported_with_its_last_error() -> None:
    drive = _Drive(silent=START_ATTEMPTS)
    with pytest.raises(ServoTransportError, match=f"start {START_ATTEMPTS}"):
        _start(drive)  # type: ignore[arg-type]
    assert drive.starts == START_ATTEMPTS

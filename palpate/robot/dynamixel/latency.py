"""The USB adapter's latency timer on Linux: read it from sysfs and say how to lower it.

An FTDI adapter (the U2D2) hands received bytes to the host when 62 have arrived or when its
latency timer fires; Linux sets the timer to 16 ms, so every status packet waits up to 16 ms and
a read-modify cycle of the servos runs at about 60 Hz at most (``palpate bench --only robot``
shows the rates). The ftdi_sio driver exposes the timer as
``/sys/bus/usb-serial/devices/<tty>/latency_timer`` (ms); writing 1 there, or a udev rule,
lowers it to 1 ms. :func:`latency_warning` returns what the driver logs when it is above 1 ms.
"""

from __future__ import annotations

import os
from pathlib import Path

USB_SERIAL_SYSFS = Path("/sys/bus/usb-serial/devices")
UDEV_RULE = 'ACTION=="add", SUBSYSTEM=="usb-serial", DRIVER=="ftdi_sio", ATTR{latency_timer}="1"'


def latency_timer_path(port: str, sysfs: Path = USB_SERIAL_SYSFS) -> Path:
    """Where the latency timer of ``port`` (``/dev/ttyUSB0``, a symlink to it, or a name) is."""
    name = os.path.basename(os.path.realpath(port)) if os.sep in port else port
    return sysfs / name / "latency_timer"


def latency_timer_ms(port: str, sysfs: Path = USB_SERIAL_SYSFS) -> int | None:
    """The latency timer of ``port`` in ms, or None where there is none to read (not an FTDI
    adapter, not Linux, a pty, no permission, an unreadable value)."""
    try:
        return int(latency_timer_path(port, sysfs).read_text(encoding="ascii").strip())
    except (OSError, ValueError):
        return None


def latency_warning(port: str, sysfs: Path = USB_SERIAL_SYSFS) -> str | None:
    """What to tell the user when the port's latency timer is above 1 ms (None: nothing)."""
    ms = latency_timer_ms(port, sysfs)
    if ms is None or ms <= 1:
        return None
    path = latency_timer_path(port, sysfs)
    return (
        f"servo bus {port}: the USB adapter's latency timer is {ms} ms, so each reply waits up "
        f"to {ms} ms and the control loop runs at about {1000 / ms:.0f} Hz at most. Set it to "
        f"1 ms: echo 1 | sudo tee {path} (until the adapter is unplugged), or for good with a "
        f"udev rule in /etc/udev/rules.d/99-ftdi-latency.rules: {UDEV_RULE}"
    )

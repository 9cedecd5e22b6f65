"""What to tell the user when a serial port cannot be opened: one wording for every device;
and when to try again once a port was lost (:class:`Backoff`, for the board reader and the
servo driver alike).

The common case on Linux is a permission error (EACCES): serial devices belong to the
``dialout`` group (``uucp`` on some distributions), and the user is not in it.
"""

from __future__ import annotations

import errno
import math

try:  # POSIX: pyserial lets termios.error (not an OSError) through from tcflush and tcsetattr
    import termios

    PORT_ERRORS: tuple[type[Exception], ...] = (OSError, termios.error)
except ImportError:  # pragma: no cover - Windows
    PORT_ERRORS = (OSError,)
"""What a serial port raises when it fails under its user (pyserial's SerialException is an
OSError): an unplugged device, a pty whose other end closed."""
OPEN_ERRORS: tuple[type[Exception], ...] = (*PORT_ERRORS, ValueError)
"""What opening a serial port raises when it cannot (ValueError: a malformed pyserial URL)."""

DIALOUT_HINT = (
    "permission denied: add your user to the 'dialout' group "
    "(sudo usermod -aG dialout $USER, then log out and in again) or give the device to that "
    'group with a udev rule (/etc/udev/rules.d/, MODE="0660", GROUP="dialout")'
)


def open_failure(device: str, port: str, exc: BaseException) -> str:
    """The message for a port that did not open: the device, the port, the cause and, for a
    permission error, what to do about it."""
    if _is_permission_error(exc):
        return f"cannot open {device} port {port!r}: {DIALOUT_HINT} ({exc})"
    return f"cannot open {device} port {port!r}: {exc}"


def os_errno(exc: BaseException) -> int | None:
    """The OS error number behind an exception, following the chain (pyserial and the drivers
    wrap the OSError), or None."""
    seen: set[int] = set()
    e: BaseException | None = exc
    while e is not None and id(e) not in seen:
        seen.add(id(e))
        code = getattr(e, "errno", None)
        if isinstance(code, int):
            return code
        e = e.__cause__ or e.__context__
    return None


def _is_permission_error(exc: BaseException) -> bool:
    return isinstance(exc, PermissionError) or os_errno(exc) in (errno.EACCES, errno.EPERM)


class Backoff:
    """When the next attempt to reopen a lost port may run: each failed attempt doubles the
    wait, from ``first`` to at most ``longest`` (s, on whatever clock the caller passes);
    :meth:`reset` once the port works, so the next loss may be retried at once."""

    def __init__(self, first: float, longest: float) -> None:
        self.first = first
        self.longest = longest
        self.reset()

    def reset(self) -> None:
        self._wait = self.first
        self._next_at = -math.inf

    def allows(self, now: float) -> bool:
        """Whether an attempt may run at ``now``."""
        return now >= self._next_at

    def failed(self, now: float) -> None:
        """An attempt (or the port) failed at ``now``: the next one waits, the wait doubles."""
        self._next_at = now + self._wait
        self._wait = min(2 * self._wait, self.longest)

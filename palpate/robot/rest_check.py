"""A contact where the plan puts no tissue: hold still, take the zero again at rest, look again.

While the stage homes or positions, the plan keeps the sensor a stand-off away from any tissue,
so a contact then is either real (the sample is nearer than planned: stop and retract) or the
zero's own noise or drift (a strain or tip-grating contact read against a zero taken seconds
before: 3 of 216 lung-like trials with 1-1.5 pm of noise and 0.01-0.02 degC/s of drift ended
as faults that way, each the first of its campaign). The state machine
(:class:`robot.indentation.IndentationMachine`) tells them apart with a :class:`RestCheck`: it
holds still for ``settle`` ticks, takes the zero again on the frames at rest, and looks again,
``limit`` times a trial; a contact seen after that is unexpected (a fault, as before). A real
contact is held, not pushed, during the check, and the new zero absorbs at most its load at
detection: the fault comes by twice the contact threshold at most.

Usage (the machine's)::

    check = RestCheck(settle=10)
    if obs.contact and not check.seen():
        fault(f"unexpected contact ({check})")
    rezero = check.hold(homing_or_positioning)  # None: no check; else hold, re-zero if True
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass
class RestCheck:
    """Contacts seen at rest-expected states and the re-zeros they were given."""

    settle: int = 10  # ticks held still before the zero is taken again
    limit: int = 1  # re-zeros a trial allows before a contact is unexpected
    used: int = 0
    ticks: int | None = None  # ticks held so far; None: no check under way

    def seen(self) -> bool:
        """A contact where none can be: True while a check runs or starts one, False once the
        checks are used up (the contact is unexpected)."""
        if self.ticks is not None:
            return True  # judged after the check's re-zero
        if self.used >= self.limit:
            return False
        self.used += 1
        self.ticks = 0
        return True

    def hold(self, active: bool = True) -> bool | None:
        """None without a check under way (or ``active`` False: the machine left the states
        where it holds, and the check is dropped); else hold still this tick, and take the
        zero again (True) on its last."""
        if not active:
            self.ticks = None
        if self.ticks is None:
            return None
        self.ticks += 1
        if self.ticks <= self.settle:
            return False
        self.ticks = None
        return True

    def __str__(self) -> str:
        return f"seen again after {self.used} re-zero(s) at rest"

"""Buckling from the tip grating's load: the beam is a force limiter.

A buckled beam carries about P_cr whatever the stage does next, so once it buckles the tip load
stops rising while the stage advances; before, the tissue's load rises as delta**1.5, faster the
deeper. The strains cannot always tell the two apart: a long mN beam tilted or held across sags,
and its tip's load times that sag bends the gratings as buckling does, long before it (a 100 mm
channel-sized beam at 2-12 % of P_cr: docs/invivo.md). The load can.

:class:`LoadPlateau` reads (advance, load) samples from the contact on (``campaign.detector:
tip``). Over the last ``window`` of advance it compares the mean load of the last third with the
first third: the rise. It alarms when the rise falls under ``plateau_share`` of the largest rise
seen so far, once that largest rise stands ``sigmas`` standard errors above the noise and the
load ``floor_sigmas`` noise above zero. The noise is the record's own, from the second
differences of the first ``noise_samples`` loads (a linear rise drops out of them), robustly
(``detect_contact.difference_sigma``, the median absolute deviation).

    >>> d = LoadPlateau(window=0.1e-3)
    >>> u = [i * 2e-6 for i in range(600)]  # 2 um a sample: 0.5 mm/s at 250 Hz
    >>> P = [min(4e-3, 632.0 * x**1.5) + 1e-6 * (-1) ** i for i, x in enumerate(u)]
    >>> next(i for i in range(600) if d.update((), u[i], P[i]))  # 4 mN at 0.342 mm (i = 171)
    206
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, field

from .contact import difference_sigma

MAX_SAMPLES = 5000  # a stalled stage adds samples without advance: the window stops growing


@dataclass
class LoadPlateau:
    """The tip load's plateau (module docstring); ``window`` in m of advance."""

    window: float = 0.1e-3
    plateau_share: float = 0.25
    sigmas: float = 6.0
    floor_sigmas: float = 10.0
    noise_samples: int = 40
    alarm: bool = field(default=False, init=False)
    sigma: float | None = field(default=None, init=False)
    largest_rise: float = field(default=0.0, init=False)
    _advance: deque[float] = field(default_factory=lambda: deque(maxlen=MAX_SAMPLES), init=False)
    _load: deque[float] = field(default_factory=lambda: deque(maxlen=MAX_SAMPLES), init=False)
    _first: list[float] = field(default_factory=list, init=False)

    def __post_init__(self) -> None:
        if not (self.window > 0 and 0 < self.plateau_share < 1 and self.noise_samples >= 8):
            raise ValueError("window > 0, 0 < plateau_share < 1 and noise_samples >= 8")

    def reset(self) -> None:
        self.alarm, self.sigma, self.largest_rise = False, None, 0.0
        self._advance.clear()
        self._load.clear()
        self._first.clear()

    def update(
        self, strains: object = (), advance: float | None = None, load: float | None = None
    ) -> bool:
        """Feed one sample: the stage's ``advance`` (m) and the tip ``load`` (N); the strains
        are not read. True once the load has stopped rising."""
        if self.alarm:
            return True
        if advance is None or load is None or not (math.isfinite(advance) and math.isfinite(load)):
            return False
        self._advance.append(advance)
        self._load.append(load)
        if self.sigma is None:
            self._first.append(load)
            if len(self._first) < self.noise_samples:
                return False
            self.sigma = difference_sigma(self._first, order=2)
        while advance - self._advance[0] > self.window:
            self._advance.popleft()
            self._load.popleft()
        n = len(self._load)
        if n < 6 or advance - self._advance[0] < 0.9 * self.window:
            return False  # the window is not full yet
        third = n // 3
        loads = list(self._load)
        early, late = sum(loads[:third]) / third, sum(loads[-third:]) / third
        rise = late - early
        self.largest_rise = max(self.largest_rise, rise)
        error = self.sigma * math.sqrt(2.0 / third)
        self.alarm = (
            self.largest_rise > self.sigmas * error
            and late > self.floor_sigmas * self.sigma
            and rise < self.plateau_share * self.largest_rise
        )
        return self.alarm

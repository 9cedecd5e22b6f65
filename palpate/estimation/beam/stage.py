"""The stage that advances the sensor, as a trial sees it: the bench's column (the holder fixes
the exposed length) or one of the robot's tubes (the exposed length grows with the advance past
the tube's flush translation). The one place a trial's ``kind`` string is read::

    stage = Stage.column(0.042)                        # the bench
    stage = Stage.on(stack.tube("bent30"), 0.042)      # a tube, planned 42 mm out at contact
    stage.exposed_length(advance)                      # m, at a stage advance (m)
    stage.rig_key                                      # whose compliance it calibrates
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from ...config.schema import TubeConfig

STAGE = "bench-stage"  # the bench column's rig key (palpate.calibration): its compliance
Kind = Literal["bench", "robot"]


@dataclass(frozen=True)
class Stage:
    """Attributes:
    exposed: the bench's fixed exposed length (m); on a tube, the planned one at contact.
    flush_translation: the advance (m) at which the sensor leaves the tube; None: the bench.
    tube: the tube on the robot (None on the bench, or where only a log's fields are known).
    """

    exposed: float
    flush_translation: float | None = None
    tube: TubeConfig | None = None

    @classmethod
    def column(cls, exposed: float) -> Stage:
        return cls(exposed)

    @classmethod
    def on(cls, tube: TubeConfig, exposed: float) -> Stage:
        return cls(exposed, tube.flush_translation, tube)

    @classmethod
    def of(cls, kind: str, exposed: float, flush_translation: float) -> Stage:
        """From a serialised trial's fields (a log's estimator inputs: ``kind`` and the flush
        translation it recorded)."""
        return cls(exposed, flush_translation) if kind == "robot" else cls.column(exposed)

    @classmethod
    def of_tube(cls, kind: str, tube: TubeConfig, exposed: float) -> Stage:
        """A trial's stage from its ``kind`` and the tube it names (unused on the bench)."""
        return cls.on(tube, exposed) if kind == "robot" else cls.column(exposed)

    @property
    def kind(self) -> Kind:
        return "bench" if self.flush_translation is None else "robot"

    @property
    def grows(self) -> bool:
        """The exposed length grows with the advance (a tube), instead of being fixed."""
        return self.flush_translation is not None

    @property
    def flush(self) -> float:
        """The flush translation (m), 0 on the bench."""
        return 0.0 if self.flush_translation is None else self.flush_translation

    def exposed_length(self, advance: float) -> float:
        """The exposed length (m) at stage advance ``advance`` (m)."""
        if self.flush_translation is None:
            return self.exposed
        return advance - self.flush_translation

    def exposed_lengths(self, advance: NDArray[np.float64]) -> NDArray[np.float64]:
        """:meth:`exposed_length` at every advance of ``advance`` (<= 0: inside the tube)."""
        if self.flush_translation is None:
            return np.full(advance.size, self.exposed)
        return np.asarray(advance - self.flush_translation)

    @property
    def rig_key(self) -> str:
        """Whose compliance a trial on this stage uses: its tube's, or the bench column's."""
        return STAGE if self.tube is None else self.tube.name


def rig_key(kind: str, tube: str) -> str:
    """:attr:`Stage.rig_key` from a trial's ``kind`` and tube name."""
    return tube if kind == "robot" else STAGE

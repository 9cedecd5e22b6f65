"""Jogging the x-y stage from teleop (issue 40): keys ``x``/``X`` and ``y``/``Y`` move the goal
one step along +x/-x and +y/-y, clamped to the stage's travel; the stage follows one
step-clamped goal per tick (``robot.dynamixel.driver.DynamixelBus.write_goals``), so a key
moves it only while it keeps coming, as the drive's jogs. Same rule as a roll: never while the
tip is in contact (it would drag the tip across the tissue)::

    jog = StageJog(stack.stage, goal=stage.position)
    jog.press("x", step=1e-3, free=not obs.contact)    # True: the key was the stage's
    stage.follow(jog.goal)                              # once per control tick
"""

from __future__ import annotations

from dataclasses import dataclass

from ...config.xystage import XYStageConfig

STAGE_KEYS: dict[str, tuple[int, int]] = {"x": (1, 0), "X": (-1, 0), "y": (0, 1), "Y": (0, -1)}
STAGE_HELP = "x/X y/Y move the x-y stage (+/-) by the step, only with the tip free"


@dataclass
class StageJog:
    """The stage's jog goal (m) and what the last key did."""

    cfg: XYStageConfig
    goal: tuple[float, float]
    message: str = ""

    def press(self, key: str, *, step: float, free: bool) -> bool:
        """Move the goal one ``step`` (m) for a stage key; False for any other key. With the
        tip not ``free`` (in contact, a fault, a retract under way) the goal stays."""
        d = STAGE_KEYS.get(key)
        if d is None:
            return False
        if not free:
            self.message = "stage held: the tip is not free (retract it, clear the fault)"
            return True
        (xl, xh), (yl, yh) = self.cfg.travel
        x = min(max(self.goal[0] + d[0] * step, xl), xh)
        y = min(max(self.goal[1] + d[1] * step, yl), yh)
        edge = (x, y) != (self.goal[0] + d[0] * step, self.goal[1] + d[1] * step)
        self.goal = (x, y)
        self.message = f"stage goal ({x * 1e3:+.2f}, {y * 1e3:+.2f}) mm" + (
            " (at the end of its travel)" if edge else ""
        )
        return True

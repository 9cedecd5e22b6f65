"""The teleop screen: :class:`robot.teleop.TeleopView` as lines of text, and the curses side
(key codes to the key names :mod:`robot.teleop` understands, drawing lines on a window).

The jog logic, its limits and guards are :mod:`robot.teleop`; this module only shows them.
"""

from __future__ import annotations

import contextlib
import curses
import math
from typing import Any

from palpate.robot.teleop import TeleopView
from palpate.robot.teleop.stagejog import STAGE_HELP

HELP = (
    "up/k advance  down/j retract  left/h right/l roll  t/T tube  +/- step  [/] speed",
    "SPACE emergency stop (retract)  r re-arm  s save pose as target  q quit (torque off)",
)


def _mm(v: float | None, width: int = 9, digits: int = 3) -> str:
    return f"{'-':>{width}}" if v is None else f"{v * 1e3:{width}.{digits}f}"


def _flag(on: bool) -> str:
    return "YES " if on else "no  "


def _xyz(v: tuple[float, float, float] | None, scale: float, digits: int) -> str:
    if v is None:
        return "-"
    return "  ".join(f"{axis} {c * scale:+8.{digits}f}" for axis, c in zip("xyz", v, strict=True))


def render(
    view: TeleopView,
    width: int = 80,
    title: str = "palpate teleop",
    stage: tuple[tuple[float, float], tuple[float, float]] | None = None,
) -> list[str]:
    """The screen as lines of text (no terminal codes), each cut to ``width``; with ``stage``
    (the x-y stage's position and goal, m) its line and keys too."""
    g = view.goal
    roll_deg = None if view.roll is None else math.degrees(view.roll)
    goal_roll = "-" if g is None else f"{math.degrees(g.roll):8.2f}"
    goal_adv = "-" if g is None else f"{g.translation * 1e3:9.3f}"
    strains = "  ".join(f"e{i + 1} {s * 1e6:+8.1f}" for i, s in enumerate(view.strains)) or "-"
    past = view.travel_past_contact
    stream = "ok" if view.stream_age <= 0.5 else "LOST"
    lines = [
        title,
        f"state      {view.state.value.upper()}",
        f"tube       {view.tube.name} ({view.tube.tip_angle_deg:g} deg)",
        f"roll       {'-' if roll_deg is None else f'{roll_deg:9.2f}'} deg   goal {goal_roll} deg",
        f"advance    {_mm(view.advance)} mm   goal {goal_adv} mm",
        f"exposed    {_mm(view.exposed_length)} mm",
        f"step       {view.step[0] * 1e3:.3g} mm / {math.degrees(view.step[1]):.3g} deg"
        f"   speed {view.speed * 1e3:.3g} mm/s",
        *_stage_line(stage),
        "",
        f"tube tip   {_xyz(view.tube_tip, 1e3, 2)} mm",
        f"tangent    {_xyz(view.tangent, 1.0, 3)}",
        f"sensor tip {_xyz(view.sensor_tip, 1e3, 2)} mm",
        "",
        f"strains    {strains} ue",
        f"norm       {view.strain_norm * 1e6:8.1f} ue   limit {view.strain_limit * 1e6:.0f} ue"
        f"   FBG stream {stream}",
        *([] if view.tip_force is None else [f"tip load   {view.tip_force * 1e3:8.3f} mN"]),
        *([] if view.gate is None else [f"breath     {'HELD' if view.gate else 'moving'}"]),
        f"contact    {_flag(view.contact)} buckled {_flag(view.buckled)}"
        f" past contact {_mm(past, 6)} / {view.travel_limit * 1e3:.2f} mm",
        f"fault      {view.fault or '-'}",
        "",
        f"> {view.message}",
    ]
    if view.prompt is not None:
        lines.append(f"save as: {view.prompt}_")
    lines += ["", *HELP, *([] if stage is None else [STAGE_HELP])]
    return [line[:width] for line in lines]


def _stage_line(stage: tuple[tuple[float, float], tuple[float, float]] | None) -> list[str]:
    if stage is None:
        return []
    (x, y), (gx, gy) = stage
    goal = f"goal {gx * 1e3:+.2f}, {gy * 1e3:+.2f} mm"
    return [f"stage      x {x * 1e3:+8.2f}  y {y * 1e3:+8.2f} mm   {goal}"]


# -- curses ----------------------------------------------------------------------------------

_SPECIAL_KEYS = {
    curses.KEY_UP: "up",
    curses.KEY_DOWN: "down",
    curses.KEY_LEFT: "left",
    curses.KEY_RIGHT: "right",
    curses.KEY_ENTER: "enter",
    10: "enter",
    13: "enter",
    27: "escape",
    curses.KEY_BACKSPACE: "backspace",
    127: "backspace",
    8: "backspace",
}


def key_name(code: int) -> str | None:
    """A curses key code as the key name :mod:`robot.teleop` uses; None for others."""
    if code in _SPECIAL_KEYS:
        return _SPECIAL_KEYS[code]
    if 32 <= code < 127:
        return chr(code)
    return None


def screen_width(stdscr: Any) -> int:
    """Columns a line may use on the window (the last one left free)."""
    _, w = stdscr.getmaxyx()
    return max(1, int(w) - 1)


def draw(stdscr: Any, lines: list[str]) -> None:
    """Replace the window's text by ``lines`` (those below its height are dropped)."""
    stdscr.erase()
    h, _ = stdscr.getmaxyx()
    for row, line in enumerate(lines[: max(0, int(h))]):
        with contextlib.suppress(curses.error):
            stdscr.addstr(row, 0, line)
    stdscr.refresh()

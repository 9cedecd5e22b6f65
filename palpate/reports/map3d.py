"""A map through the robot in three dimensions (``map3d.png``, issue 58): the patch's plane in
the robot's base frame coloured by the map's modulus, each probe where it pressed (its colour
the normal error), and the robot's tube and sensor at the first and last probe's placement, so
a reader sees which way the tissue faces, where the robot stood and how far it travelled::

    map3d_figure(result, reach, run_dir / "map3d.png", "map-through-robot")
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from palpate.campaigns.surveyloop import SurveyResult
from palpate.campaigns.throughrobot import ThroughRobot
from palpate.robot.kinematics import body_points

MM = 1e-3
STRIDE = 3  # every third grid point of the map drawn on the plane


def map3d_figure(result: SurveyResult, reach: ThroughRobot, path: Path, title: str = "") -> Path:
    """Draw the survey in the robot's base frame (mm) as a PNG at ``path``: the robot and the
    patch (left), the patch as the robot sees it (right); returns ``path``."""
    fig = plt.figure(figsize=(13, 6), layout="constrained")
    whole: Any = fig.add_subplot(1, 2, 1, projection="3d")
    near: Any = fig.add_subplot(1, 2, 2, projection="3d")
    pressed = np.array([reach.surface.at(p.x, p.y).point for p in result.probes]) / MM
    errors = [
        math.degrees(p.normal_error) if p.normal_error is not None else math.nan
        for p in result.probes
    ]
    for ax in (whole, near):
        _patch(ax, result, reach)
        dots = ax.scatter(
            *pressed.T, c=errors, cmap="magma", vmin=0, vmax=4, s=14, depthshade=False
        )
        ax.set(xlabel="x (mm)", ylabel="y (mm)", zlabel="z (mm)")
    for k in sorted({0, len(result.probes) - 1}):
        _robot(whole, reach, (result.probes[k].x, result.probes[k].y), f"probe {k + 1}")
    whole.set_aspect("equal")
    whole.legend(loc="upper left", fontsize=8)
    span = np.ptp(pressed, axis=0).max() / 2 + 1.0
    for axis, c in zip("xyz", pressed.mean(axis=0), strict=True):
        getattr(near, f"set_{axis}lim")(c - span, c + span)
    near.view_init(elev=15, azim=-165)  # from the robot's side, toward +x
    fig.colorbar(dots, ax=near, shrink=0.6, label="normal error (deg)")
    s = result.summary
    found = "no map" if s is None else ("inclusion found" if s.found else "no inclusion found")
    fig.suptitle(f"{title}: {found}; {len(result.probes)} probes through the robot (base frame)")
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def _patch(ax: Any, result: SurveyResult, reach: ThroughRobot) -> None:
    """The map's modulus drawn on the patch's plane (nothing without a map)."""
    s = result.summary
    if s is None:
        return
    xs, ys = s.x[::STRIDE], s.y[::STRIDE]
    grid = np.array([[reach.surface.at(float(u), float(v)).point for u in xs] for v in ys]) / MM
    field = s.mean[::STRIDE, ::STRIDE]
    colour = plt.get_cmap("viridis")((field - field.min()) / max(float(np.ptp(field)), 1e-9))
    ax.plot_surface(grid[..., 0], grid[..., 1], grid[..., 2], facecolors=colour, alpha=0.7)


def _robot(ax: Any, reach: ThroughRobot, point: tuple[float, float], label: str) -> None:
    """The tube and sensor (its body points) at ``point``'s placement, and the base's origin."""
    placed = reach.place(point)
    if placed.status not in (0, 1):
        return
    tube = reach.tube(placed)
    body = (body_points(tube, placed.roll, placed.contact_translation) + placed.base) / MM
    line = ax.plot(
        *body.T, lw=1.5, label=f"{label}: {tube.name}, roll {math.degrees(placed.roll):.0f} deg"
    )
    ax.scatter(*(placed.base / MM), marker="s", color=line[0].get_color(), s=20)

"""The map figure: what a survey found, beside what it did not know.

Three panels over the patch (mm): the map's modulus (posterior median, kPa) with every probe
numbered in the order it was taken and the stage's path between them (a probe without a
number as a grey cross, a ``suspect`` one in orange); the map's uncertainty (sd of log E, %);
and the probability of being above the threshold with its one-half contour (the apparent
region), the inclusion's extent (the disc fitted through the tip's contact, solid black on every
panel: the boundary the map reports), the estimated centre with its 95 % box, and in simulation
every true inclusion's footprint (dashed) and centre (+); each inclusion's depth as the map read
it, on the left. The map's other inclusions (a map of several, ``maps.inclusions``): each disc
on every panel, black if stiff, cyan if soft, its centre and its 95 % box on the right. A
survey that found nothing says so in the title.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt
from matplotlib.lines import Line2D
from matplotlib.patches import Circle, Rectangle

from palpate.campaigns.survey import SurveyResult

MM = 1e-3
COLOURS = {"ok": "k", "suspect": "tab:orange", "none": "0.6"}
SOFT = "tab:cyan"  # a soft inclusion's marks


def map_figure(result: SurveyResult, path: Path, title: str = "") -> Path:
    """Draw ``result`` (see the module docstring) as a PNG at ``path``; returns ``path``."""
    s = result.summary
    fig, axes = plt.subplots(1, 3, figsize=(15, 5.4), layout="constrained")
    if s is None:
        for ax in axes:
            _probes(ax, result)
        fig.suptitle(f"{title}: no map ({result.stopped})")
        return _save(fig, path)
    extent = (s.x[0] / MM, s.x[-1] / MM, s.y[0] / MM, s.y[-1] / MM)
    panels = (
        (s.mean / 1e3, "modulus (kPa), posterior median", "viridis"),
        (100 * s.sd, "uncertainty: sd of log E (%)", "magma"),
        (s.p_above, f"P(E > {s.threshold / 1e3:.0f} kPa)", "RdBu_r"),
    )
    for ax, (field, label, cmap) in zip(axes, panels, strict=True):
        image = ax.imshow(field, origin="lower", extent=extent, cmap=cmap, aspect="equal")
        fig.colorbar(image, ax=ax, shrink=0.85, label=label)
        _probes(ax, result)
        _truth(ax, result)
    axes[2].contour(s.x / MM, s.y / MM, s.p_above, levels=[0.5], colors="k", linewidths=0.8)
    if s.extent is not None:
        (cx, cy), r = s.extent.centre, s.extent.radius
        for ax in axes:
            ax.add_patch(Circle((cx / MM, cy / MM), r / MM, fill=False, color="k", lw=1.5))
    if s.centre is not None and s.centre_ci is not None:
        (x0, x1), (y0, y1) = s.centre_ci
        axes[2].add_patch(
            Rectangle((x0 / MM, y0 / MM), (x1 - x0) / MM, (y1 - y0) / MM, fill=False, color="k")
        )
        axes[2].plot(s.centre[0] / MM, s.centre[1] / MM, "kx", ms=9, label="estimated centre")
    _others(axes, s.inclusions[1:])
    _depths(axes[0], s.inclusions)
    _legend(fig, result)
    verdict = "inclusion found" if s.found else "no inclusion found"
    if len(s.inclusions) > 1:
        verdict = f"{len(s.inclusions)} inclusions found"
    fig.suptitle(
        f"{title}: {verdict}; {len(result.probes)} probes, {result.lab_time:.0f} s of lab time "
        f"({result.stopped})"
    )
    return _save(fig, path)


def _legend(fig: Any, result: SurveyResult) -> None:
    """What each mark means, below the panels (on grey: the path and the truth are white)."""
    s = result.summary
    handles = [
        Line2D([], [], color="w", lw=0.6, marker="o", ms=4, mfc="w", mec="k",
               label="probe, numbered in the order taken, and the path between"),
        Line2D([], [], ls="", marker="o", ms=4, mfc="w", mec="tab:orange", label="suspect probe"),
        Line2D([], [], ls="", marker="x", ms=4, color="0.6", label="probe without a number"),
    ]  # fmt: skip
    if s is not None and s.extent is not None:
        handles.append(Line2D([], [], color="k", lw=1.5, label="the inclusion's extent (reported)"))
    if s is not None and s.found:
        handles.append(Line2D([], [], color="k", lw=0.8, label="P(above) = 0.5 (apparent region)"))
    if s is not None and s.centre is not None:
        handles.append(Line2D([], [], ls="", marker="x", ms=8, color="k",
                              label="estimated centre; its 95 % box (right)"))  # fmt: skip
    if s is not None and any(i.kind == "soft" for i in s.inclusions):
        handles.append(Line2D([], [], color=SOFT, lw=1.5, label="a soft inclusion (reported)"))
    if result.truth is not None:
        handles.append(Line2D([], [], color="w", ls="--", lw=1.2, marker="+", ms=8,
                              label="the true inclusion and centre (simulation)"))  # fmt: skip
    fig.legend(handles=handles, loc="outside lower center", ncol=4, fontsize=8, facecolor="0.75")


def _probes(ax: Any, result: SurveyResult) -> None:
    xy = np.array([[p.x, p.y] for p in result.probes]) / MM
    if xy.size == 0:
        return
    ax.plot(xy[:, 0], xy[:, 1], "-", color="w", lw=0.6, alpha=0.8)
    for k, p in enumerate(result.probes):
        colour = COLOURS.get(p.status, "k") if p.usable else COLOURS["none"]
        ax.plot(p.x / MM, p.y / MM, "x" if not p.usable else "o", ms=4, color=colour, mfc="w")
        ax.annotate(
            str(k + 1),
            (p.x / MM, p.y / MM),
            fontsize=6,
            xytext=(2, 2),
            textcoords="offset points",
            color="w",
        )
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")


def _truth(ax: Any, result: SurveyResult) -> None:
    if result.truth is None:
        return
    for t in (result.truth, *result.truth.others):
        centre = (t.centre[0] / MM, t.centre[1] / MM)
        ax.add_patch(Circle(centre, t.radius / MM, fill=False, ls="--", color="w", lw=1.2))
        ax.plot(*centre, "w+", ms=9)


def _others(axes: Any, others: Any) -> None:
    """The map's inclusions beyond its first: each disc on every panel (black stiff, cyan
    soft), its centre and its 95 % box on the right."""
    for inc in others:
        colour = "k" if inc.kind == "stiff" else SOFT
        centre = (inc.centre[0] / MM, inc.centre[1] / MM)
        for ax in axes:
            ax.add_patch(Circle(centre, inc.radius / MM, fill=False, color=colour, lw=1.5))
        (x0, x1), (y0, y1) = inc.centre_ci
        box = Rectangle((x0 / MM, y0 / MM), (x1 - x0) / MM, (y1 - y0) / MM, fill=False)
        box.set_edgecolor(colour)
        axes[2].add_patch(box)
        axes[2].plot(*centre, "x", color=colour, ms=9)


def _depths(ax: Any, inclusions: Any) -> None:
    """Each inclusion's depth beside it on the left panel: its centre's depth and the 95 %
    interval (mm), as the map read its sphere (``maps.depth``)."""
    for inc in inclusions:
        if inc.depth is None:
            continue
        d = inc.depth
        ax.annotate(
            f"{d.depth / MM:.1f} mm deep\n[{d.depth_ci[0] / MM:.1f}-{d.depth_ci[1] / MM:.1f}]",
            (inc.centre[0] / MM, inc.centre[1] / MM),
            xytext=(0, -(inc.radius / MM) * 9 - 10),
            textcoords="offset points",
            ha="center",
            va="top",
            fontsize=7,
            color="w",
        )


def _save(fig: Any, path: Path) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path

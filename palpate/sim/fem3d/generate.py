"""Regenerate the 3-D inclusion tables shipped with the package: ``python -m sim.fem3d.generate``.

The shipped problems are those of the shipped scenes' samples with inclusions
(``config/scenes/inclusions/``), found by reading the scenes, so a scene and its tables cannot
drift apart (tests/sim/test_fem3d_world.py checks that every such sample finds its table here).
Each is solved afresh and written to ``sim/fem3d/tables/``; tables no shipped scene names any
more are removed.
"""

from __future__ import annotations

import sys

from ...config import load, load_stack, resolve
from ...config.loader import CONFIG_DIR
from ...config.scene import SceneConfig
from ..sample_law import fe_world
from .offsets import OFFSET_NODES, MapWorld, node_problems
from .problem import InclusionProblem
from .table import SHIPPED_DIR, save_ratios, solve_ratios
from .world import InclusionWorld


def shipped_problems() -> dict[str, InclusionProblem]:
    """The 3-D problems of the shipped scenes' samples, by ``scene/sample``: a sample's own,
    or for a map's world (``fidelity.inclusion_offsets: interpolated``) one per solved
    distance (``scene/sample@offset``), each in the frame its solve uses."""
    out: dict[str, InclusionProblem] = {}
    for path in sorted((CONFIG_DIR / "scenes").rglob("*.yaml")):
        scene = load(SceneConfig, path)
        tip = load_stack(resolve(scene.robot)).sensor.tip_radius
        for sample in scene.samples:
            world = fe_world(sample, scene.fidelity, tip)
            if isinstance(world, InclusionWorld):
                out[f"{scene.name}/{sample.name}"] = world.solid.canonical_problem()
            elif isinstance(world, MapWorld):
                for node, problem in zip(OFFSET_NODES, node_problems(world.solid), strict=True):
                    out[f"{scene.name}/{sample.name}@{node:g}R"] = problem.canonical_problem()
    return out


def main() -> int:
    wanted = set()
    for name, problem in shipped_problems().items():
        table = solve_ratios(problem)
        path = save_ratios(table, SHIPPED_DIR)
        wanted.add(path.name)
        print(f"{name:32s} {path.name}  {table.build_seconds:6.1f} s", flush=True)
    for stale in SHIPPED_DIR.glob("inclusion-*.npz"):
        if stale.name not in wanted:
            stale.unlink()
            print(f"removed {stale.name}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

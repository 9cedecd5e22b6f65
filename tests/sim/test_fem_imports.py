"""The world's tissue physics never calls the estimator's contact laws (docs/world.md)."""

from __future__ import annotations

import ast
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
SOURCES = [
    *sorted((ROOT / "sim" / "fem").glob("*.py")),
    *sorted((ROOT / "sim" / "fem3d").glob("*.py")),
    ROOT / "sim" / "viscoelastic.py",
]
# the world's FE path outside sim/fem: it may use estimation's beam mechanics, never its laws
WORLD = [
    ROOT / "sim" / n
    for n in ("sample_law.py", "contact_history.py", "contact_table.py", "world.py")
]
WORLD += sorted((ROOT / "sim" / "equilibrium").glob("*.py"))
LAWS = (
    "estimation.contact.hertz",
    "estimation.contact.law",
    "estimation.contact.sneddon",
    "estimation.contact.layer_table",
    "estimation.contact.layer_exact",
    "estimation.jointfit",
    "estimation.relaxation",
    "sim.tissue",
)


def ours(name: str) -> str:
    """An import's name within the stack: ``palpate.estimation.contact.hertz`` ->
    ``estimation.contact.hertz``
    (the layers are installed under ``palpate``)."""
    return name.removeprefix("palpate.")


def from_module(path: Path, node: ast.ImportFrom) -> str:
    """The absolute name (in the layers' terms) a ``from ... import`` names, its relative
    level resolved against the file's package (``from ..estimation import hertz`` in
    ``sim/world.py`` is ``estimation``; ``from .tissue import`` is ``sim.tissue``)."""
    if not node.level:
        return ours(node.module or "")
    package = path.relative_to(ROOT).with_suffix("").parts[:-1]
    anchor = package[: len(package) - (node.level - 1)]
    return ".".join([*anchor, node.module] if node.module else anchor)


def imported_modules(path: Path) -> set[str]:
    names: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(), filename=str(path))):
        if isinstance(node, ast.Import):
            names.update(ours(alias.name) for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = from_module(path, node)
            if base:
                names.add(base)
            names.update(f"{base}.{alias.name}".strip(".") for alias in node.names)
    return names


@pytest.mark.parametrize("path", SOURCES, ids=lambda p: p.name)
def test_no_estimator_contact_law_in_the_world(path: Path) -> None:
    bad = {
        name
        for name in imported_modules(path)
        if name == "estimation" or name.startswith("estimation.")
    }
    assert not bad, f"{path.relative_to(ROOT)} imports {sorted(bad)}"


@pytest.mark.parametrize("path", WORLD, ids=lambda p: p.name)
def test_the_worlds_fe_path_imports_no_contact_law_at_module_level(path: Path) -> None:
    """sim.sample_law imports sim.tissue (the closed forms) only inside the closed-form branch;
    the rest of the path never names the laws at all."""
    tree = ast.parse(path.read_text(), filename=str(path))
    top = [n for n in tree.body if isinstance(n, ast.Import | ast.ImportFrom)]
    names = {ours(a.name) for n in top if isinstance(n, ast.Import) for a in n.names}
    names |= {from_module(path, n) for n in top if isinstance(n, ast.ImportFrom)}
    assert not {n for n in names if n.startswith(LAWS)}, f"{path.name}: {sorted(names)}"


def test_the_scan_sees_the_package() -> None:
    assert len(SOURCES) >= 8
    assert "sim.fem.problem" in imported_modules(ROOT / "sim" / "fem" / "table.py")
    # relative imports resolved: sim.sample_law names sim.tissue (inside its closed-form branch)
    assert "sim.tissue" in imported_modules(ROOT / "sim" / "sample_law.py")


WORLD_PATH = """
import sys
import numpy as np
from palpate.config.sample import SampleConfig
from palpate.config.scene import FidelityConfig
from palpate.config import load_stack
from robot_free_section import section
from palpate.sim.contact_history import ViscoelasticContact
from palpate.sim.contact_table import GridPhysics, equilibrium_on_grid
from palpate.sim.equilibrium import ContactEffects
from palpate.sim.sample_law import relaxation, world_tissue
stack = load_stack()
sample = SampleConfig(name="S", modulus_kpa=500.0, material="neo-hookean",
                      relaxation_time_s=1.0, relaxed_ratio=0.8)
fidelity = FidelityConfig(tissue_model="fe", viscoelastic=True)
law = world_tissue(sample, fidelity, stack.sensor.tip_radius)
s = section(stack.sensor)
physics = GridPhysics(s.EI, s.EA, s.fiber_offset, stack.sensor.grating_length,
                      tuple(stack.sensor.grating_centres_from_tip()), law,
                      ContactEffects(imperfection=0.001))
equilibrium_on_grid(physics, tuple(np.linspace(0, 1.5e-3, 31).tolist()), 42e-3)
history = ViscoelasticContact(physics, relaxation(sample, fidelity))
for k in range(1, 20):
    history.at(0.01 * k, 5e-5 * k, 42e-3)
print(" ".join(sorted(m.removeprefix("palpate.") for m in sys.modules
                     if m.startswith("palpate.estimation"))))
"""

SECTION = """
from palpate.estimation.beam.section import composite_section
def section(sensor):
    return composite_section(sensor.fiber_radius, sensor.fiber_modulus, sensor.wire_radius,
                             sensor.wire_modulus, sensor.wire_count)
"""


def test_the_world_on_the_fe_level_never_loads_the_estimators_laws(tmp_path: Path) -> None:
    """The world's FE path (sample -> law -> tabulated and stepped equilibrium, grating strains)
    runs in a fresh interpreter without ever importing estimation.contact.hertz or .corrections:
    what
    is never loaded is never called. (The beam mechanics of estimation are allowed.)"""
    (tmp_path / "robot_free_section.py").write_text(SECTION)
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(tmp_path), str(ROOT)])}
    out = subprocess.run(
        [sys.executable, "-c", WORLD_PATH], capture_output=True, text=True, env=env, check=False
    )
    assert out.returncode == 0, out.stderr
    loaded = set(out.stdout.split())
    assert "estimation.beam.model" in loaded  # the scan sees the estimation modules that do load
    assert not loaded & set(LAWS)

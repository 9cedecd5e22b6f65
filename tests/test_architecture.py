"""The layers of docs/architecture.md, read from every module's imports (ast, so imports inside
functions count too): which package may import which, and no two packages importing each other.

wire, store (the cache of solved tables) and maps (probes and the map of them) import nothing
of ours; config only config; estimation only estimation, config and store; sensor_design (the
sensor's design search) estimation and config; sensor wire, estimation, config; robot wire, maps,
estimation, sensor, config; sim wire, store, estimation, config (never sensor, robot or palpate);
palpate, the application, anything. Every layer is a folder of ``palpate/`` (the card's ones
also linked at the root). Tests are not a layer.
"""

from __future__ import annotations

import ast
import functools
import itertools
from collections.abc import Iterator
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
ALLOWED: dict[str, frozenset[str]] = {
    "wire": frozenset({"wire"}),
    "store": frozenset({"store"}),
    "maps": frozenset({"maps"}),
    "config": frozenset({"config"}),
    "estimation": frozenset({"estimation", "config", "store"}),
    "sensor_design": frozenset({"sensor_design", "estimation", "config"}),
    "sensor": frozenset({"sensor", "wire", "estimation", "config"}),
    "robot": frozenset({"robot", "wire", "maps", "estimation", "sensor", "config"}),
    "sim": frozenset({"sim", "wire", "store", "estimation", "config"}),
    "palpate": frozenset(
        {"palpate", "wire", "store", "maps", "config", "estimation", "sensor_design", "sensor"}
        | {"robot", "sim"}
    ),
}
PACKAGES = frozenset(ALLOWED)


@functools.cache
def parsed(path: Path) -> ast.Module:
    """A module's syntax tree, parsed once for every check (the checks read the whole tree)."""
    return ast.parse(path.read_text(encoding="utf-8"), str(path))


LAYERS = frozenset(ALLOWED) - {"palpate"}


def module_name(path: Path, root: Path = ROOT) -> str:
    """A file's module in the layers' terms (``palpate/sim/world.py`` is ``sim.world``)."""
    parts = path.relative_to(root).with_suffix("").parts
    return layer_name(".".join(parts[:-1] if parts[-1] == "__init__" else parts))


def folder(package: str, root: Path = ROOT) -> Path:
    """Where a package's files are: a layer under ``palpate/``, the application at the root."""
    return root / "palpate" / package if package in LAYERS else root / package


def files_of(package: str, root: Path = ROOT) -> list[Path]:
    """The package's modules (the application's without its layers' folders)."""
    return sorted(
        path
        for path in folder(package, root).rglob("*.py")
        if package != "palpate" or path.relative_to(root / "palpate").parts[0] not in LAYERS
    )


def layer_name(name: str) -> str:
    """An import's name in the layers' terms: the layers are installed under ``palpate``
    (``palpate.sim.world`` is ``sim.world``; ``palpate.simulation`` stays the application's)."""
    parts = name.split(".")
    if len(parts) > 1 and parts[0] == "palpate" and parts[1] in LAYERS:
        return ".".join(parts[1:])
    return name


def imported_modules(path: Path, root: Path = ROOT) -> Iterator[tuple[int, str]]:
    """(line, absolute name) of every import in the file, relative ones resolved; ``from a
    import b`` gives ``a.b`` (``b`` may be a module or a name in ``a``); names in the layers'
    terms (:func:`layer_name`)."""
    tree = parsed(path)
    package = module_name(path, root)
    if path.name != "__init__.py":
        package = package.rpartition(".")[0]
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                yield node.lineno, layer_name(alias.name)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.split(".")[: len(package.split(".")) - (node.level - 1)]
                base = ".".join([*anchor, base]) if base else ".".join(anchor)
            for alias in node.names:  # a name may be a module: ``from sim.dynamixel import bus``
                yield node.lineno, layer_name(f"{base}.{alias.name}")


def our_imports(root: Path = ROOT) -> Iterator[tuple[str, str, str]]:
    """(importing package, imported package, "file:line module") for imports between ours."""
    for package in sorted(PACKAGES):
        for path in files_of(package, root):
            for line, name in imported_modules(path, root):
                top = name.partition(".")[0]
                if top in PACKAGES:
                    where = f"{path.relative_to(root)}:{line} {name}"
                    yield package, top, where


def package_graph(root: Path = ROOT) -> dict[str, set[str]]:
    graph: dict[str, set[str]] = {p: set() for p in PACKAGES}
    for source, target, _ in our_imports(root):
        if source != target:
            graph[source].add(target)
    return graph


def find_cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """A cycle of the directed graph as [a, b, ..., a], or None."""
    state: dict[str, int] = {}  # 1: on the current path, 2: done
    path: list[str] = []

    def visit(node: str) -> list[str] | None:
        state[node] = 1
        path.append(node)
        for nxt in sorted(graph.get(node, ())):
            if state.get(nxt) == 1:
                return [*path[path.index(nxt) :], nxt]
            if nxt not in state and (cycle := visit(nxt)) is not None:
                return cycle
        path.pop()
        state[node] = 2
        return None

    for node in sorted(graph):
        if node not in state and (cycle := visit(node)) is not None:
            return cycle
    return None


def subpackages(root: Path = ROOT) -> frozenset[str]:
    """Every package of ours, top-level and nested (a folder with an ``__init__.py``)."""
    return frozenset(
        module_name(init, root)
        for package in PACKAGES
        for init in folder(package, root).rglob("__init__.py")
    )


def package_of(name: str, packages: frozenset[str]) -> str:
    """The deepest package of ours that holds the module or name ``name``."""
    parts = name.split(".")
    for n in range(len(parts), 0, -1):
        if ".".join(parts[:n]) in packages:
            return ".".join(parts[:n])
    raise ValueError(f"{name} is not in one of our packages")


def subpackage_graph(root: Path = ROOT) -> dict[str, set[str]]:
    """Imports between packages at any depth, leaving out a package and its own subpackages
    (``sim`` and ``sim.dynamixel`` are one room)."""
    packages = subpackages(root)
    graph: dict[str, set[str]] = {p: set() for p in packages}
    for package in PACKAGES:
        for path in files_of(package, root):
            source = package_of(module_name(path, root), packages)
            for _, name in imported_modules(path, root):
                if name.partition(".")[0] not in PACKAGES:
                    continue
                target = package_of(name, packages)
                nested = f"{target}.".startswith(f"{source}.") or f"{source}.".startswith(
                    f"{target}."
                )
                if not nested:
                    graph[source].add(target)
    return graph


@pytest.mark.parametrize("package", sorted(PACKAGES))
def test_a_package_imports_only_the_layers_below_it(package: str) -> None:
    bad = [
        where
        for source, target, where in our_imports()
        if source == package and target not in ALLOWED[package]
    ]
    assert not bad, f"{package} may import only {sorted(ALLOWED[package])}:\n" + "\n".join(bad)


def test_no_two_packages_import_each_other() -> None:
    graph = package_graph()
    mutual = [
        (a, b)
        for a, b in itertools.combinations(sorted(graph), 2)
        if b in graph[a] and a in graph[b]
    ]
    assert not mutual
    assert find_cycle(graph) is None


@pytest.mark.slow
def test_no_two_subpackages_import_each_other() -> None:
    """Inside a layer too: e.g. palpate.faults may use palpate.reports.replay, but not a command
    module that imports palpate.faults back."""
    assert find_cycle(subpackage_graph()) is None


def test_the_check_sees_every_kind_of_import(tmp_path: Path) -> None:
    """Imports inside functions and relative imports are found; a cycle is found."""
    pkg = tmp_path / "palpate" / "robot" / "teleop"
    pkg.mkdir(parents=True)
    (tmp_path / "palpate" / "robot" / "__init__.py").write_text("", encoding="utf-8")
    (pkg / "__init__.py").write_text("from . import model\n", encoding="utf-8")
    (pkg / "model.py").write_text(
        "import math\n\ndef f():\n"
        "    from palpate.sim.world import World\n    from ..drive import x\n",
        encoding="utf-8",
    )
    found = {name for _, name in imported_modules(pkg / "model.py", tmp_path)}
    assert found == {"math", "sim.world.World", "robot.drive.x"}
    assert {name for _, name in imported_modules(pkg / "__init__.py", tmp_path)} == {
        "robot.teleop.model"
    }
    assert package_of("robot.teleop.model", subpackages(tmp_path)) == "robot.teleop"
    assert package_of("robot.drive.x", subpackages(tmp_path)) == "robot"
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]
    assert find_cycle({"a": {"b"}, "b": set()}) is None


MAX_MODULE_LINES = 400
MAX_FUNCTION_LINES = 60


def oversized(root: Path = ROOT) -> list[str]:
    """Modules over MAX_MODULE_LINES lines and functions over MAX_FUNCTION_LINES (issues 14 and
    24: every module fits on a few screens, every function on one)."""
    found = []
    for package in sorted(PACKAGES):
        for path in files_of(package, root):
            text = path.read_text(encoding="utf-8")
            where = path.relative_to(root)
            if text.count("\n") > MAX_MODULE_LINES:
                found.append(f"{where}: {text.count(chr(10))} lines")
            for node in ast.walk(parsed(path)):
                if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
                    length = (node.end_lineno or node.lineno) - node.lineno + 1
                    if length > MAX_FUNCTION_LINES:
                        found.append(f"{where}:{node.lineno} {node.name}: {length} lines")
    return found


def test_modules_and_functions_fit_on_a_screen() -> None:
    assert oversized() == []


def test_the_size_check_sees_a_long_function(tmp_path: Path) -> None:
    body = "\n".join(f"    x{i} = {i}" for i in range(MAX_FUNCTION_LINES + 1))
    (tmp_path / "palpate" / "wire").mkdir(parents=True)
    (tmp_path / "palpate" / "wire" / "big.py").write_text(
        f"def big() -> None:\n{body}\n", encoding="utf-8"
    )
    assert [f.split(" ")[1] for f in oversized(tmp_path)] == ["big:"]


# The rooms of the application (issue 24), from the bottom up: each may import the rooms named
# (and itself, and every layer below ``palpate``). ``palpate`` alone is its top-level modules:
# the CLI's command table and the helpers every room uses (argtypes, progress, calibration).
_BELOW_REPORTS = frozenset({"palpate", "palpate.simulation", "palpate.campaigns"})
PALPATE_ROOMS: dict[str, frozenset[str]] = {
    "palpate": frozenset(),
    "palpate.simulation": frozenset({"palpate"}),
    "palpate.lab": frozenset({"palpate"}),
    "palpate.campaigns": frozenset({"palpate", "palpate.simulation"}),
    "palpate.reports": _BELOW_REPORTS,
    "palpate.faults": _BELOW_REPORTS | {"palpate.reports"},
    # the work both front ends call (the command line, the Python API)
    "palpate.services": _BELOW_REPORTS | {"palpate.reports", "palpate.faults", "palpate.lab"},
    # the ROS 2 node: a front end beside the commands (its command, palpate ros, starts it)
    "palpate.ros": _BELOW_REPORTS
    | {"palpate.reports", "palpate.faults", "palpate.lab", "palpate.services"},
    "palpate.commands": _BELOW_REPORTS
    | {"palpate.reports", "palpate.faults", "palpate.lab", "palpate.services", "palpate.ros"},
    # the Python API (palpate/api.py): the other front end, beside the commands (never above
    # them: both call the rooms below, the services first)
    "palpate.api": _BELOW_REPORTS
    | {"palpate.reports", "palpate.faults", "palpate.lab", "palpate.services"},
}
FRONT_DOOR = "palpate/__init__.py"  # the installed name re-exports the API, and only that
MAX_PALPATE_TOP_MODULES = 6  # besides __init__, __main__, cli and api


def palpate_room(module: str) -> str:
    """The room of a module of ``palpate``: its first sub-package, or ``palpate`` at the top."""
    parts = module.split(".")
    room = ".".join(parts[:2])
    return room if room in PALPATE_ROOMS else "palpate"


def palpate_room_breaks(root: Path = ROOT) -> list[str]:
    """Imports from one room of ``palpate`` into a room it may not use ("file:line module")."""
    bad = []
    for path in files_of("palpate", root):
        source = palpate_room(module_name(path, root))
        front = path.relative_to(root).as_posix() == FRONT_DOOR
        for line, name in imported_modules(path, root):
            if name.partition(".")[0] != "palpate" or name == "palpate":
                continue
            target = palpate_room(name)
            if front and target == "palpate.api":
                continue
            if target != source and target not in PALPATE_ROOMS[source]:
                bad.append(f"{path.relative_to(root)}:{line} {name} ({source} -> {target})")
    return bad


def test_no_package_hides_a_name_of_the_api() -> None:
    """``palpate.<name>`` is the API's function: a sub-package of that name would replace it on
    the package once imported (``palpate.design`` did)."""
    import palpate

    folders = {init.parent.name for init in (ROOT / "palpate").glob("*/__init__.py")}
    modules = {p.stem for p in (ROOT / "palpate").glob("*.py")}
    assert not (folders | modules) & set(palpate.__all__)


def test_every_module_of_palpate_lives_in_a_known_room() -> None:
    rooms = {
        f"palpate.{init.parent.name}"
        for init in (ROOT / "palpate").glob("*/__init__.py")
        if init.parent.name not in LAYERS  # the layers' folders, linked in (pyproject.toml)
    }
    rooms.add("palpate.api")
    assert rooms <= set(PALPATE_ROOMS), "a new sub-package of palpate needs its PALPATE_ROOMS entry"
    top = sorted(
        p.stem
        for p in (ROOT / "palpate").glob("*.py")
        if p.stem not in {"__init__", "__main__", "cli", "api"}
    )
    assert len(top) <= MAX_PALPATE_TOP_MODULES, f"palpate/ top level: {top}"


def test_the_rooms_of_palpate_import_only_the_rooms_below() -> None:
    assert palpate_room_breaks() == []


def test_the_room_check_sees_an_arrow_running_back_up(tmp_path: Path) -> None:
    (tmp_path / "palpate" / "simulation").mkdir(parents=True)
    (tmp_path / "palpate" / "__init__.py").write_text("", encoding="utf-8")
    (tmp_path / "palpate" / "simulation" / "__init__.py").write_text("", encoding="utf-8")
    (tmp_path / "palpate" / "simulation" / "world.py").write_text(
        "def f():\n    from palpate.reports.plots import draw\n", encoding="utf-8"
    )
    (tmp_path / "palpate" / "argtypes.py").write_text(
        "from palpate.simulation import world\n", encoding="utf-8"
    )
    assert [b.rpartition(" (")[2] for b in palpate_room_breaks(tmp_path)] == [
        "palpate -> palpate.simulation)",
        "palpate.simulation -> palpate.reports)",
    ]


@pytest.mark.slow
def test_our_code_imports_the_layers_by_their_installed_names() -> None:
    """``from palpate.config import ...``, never ``from config import ...``: a bare name would
    be shadowed by a user's own config.py (or sim.py, robot.py, ...) beside their script."""
    bare = []
    for folder in sorted({*LAYERS, "palpate", "tests", "bench", "examples"}):
        for path in sorted((ROOT / folder).rglob("*.py")):
            tree = parsed(path)
            for node in ast.walk(tree):
                names = []
                if isinstance(node, ast.Import):
                    names = [a.name for a in node.names]
                elif isinstance(node, ast.ImportFrom) and not node.level and node.module:
                    names = [node.module]
                bare += [
                    f"{path.relative_to(ROOT)}:{node.lineno} {n}"
                    for n in names
                    if n.partition(".")[0] in LAYERS
                ]
    assert not bare, "\n".join(bare)


def test_the_product_never_imports_the_benchmarks() -> None:
    """``benchmarks/`` is not installed: a module of ``palpate`` that imported it would break
    in a wheel (``palpate bench`` finds it at run time, and says so when it is not there)."""
    found = [
        f"{path.relative_to(ROOT)}:{line} {name}"
        for path in sorted((ROOT / "palpate").rglob("*.py"))
        for line, name in imported_modules(path)
        if name.partition(".")[0] == "benchmarks"
    ]
    assert found == []

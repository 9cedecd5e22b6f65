"""One loader for every YAML file: mapping -> typed, validated dataclasses.

The schema is plain dataclasses (see :mod:`config.schema`). A field's YAML key is its name, so a
key carries its unit when the unit is not SI (``length_mm``); the dataclass exposes SI properties.
Range limits live in the field metadata (``ge``, ``gt``, ``le``, ``lt``), so the schema is data and
this module is the only code that checks it.

Every failure raises :class:`ConfigError` with the file and the dotted key path, e.g.
``config/robot.yaml: sensor.wire_count: expected an integer, got 'four'``.
"""

from __future__ import annotations

import dataclasses
import math
import operator
import re
import types
import typing
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any, Literal, TypeVar, get_args, get_origin

import yaml

T = TypeVar("T")

CONFIG_DIR = Path(__file__).resolve().parent


class _Loader(yaml.SafeLoader):
    """PyYAML's safe loader, reading ``1e9`` as the number it means: YAML 1.1 (PyYAML) wants a
    dot in a float (``1.0e9``) and took ``1e9`` for a string; YAML 1.2 and JSON do not."""


_Loader.add_implicit_resolver(
    "tag:yaml.org,2002:float",
    re.compile(r"^[-+]?(?:[0-9][0-9_]*)(?:\.[0-9_]*)?[eE][-+]?[0-9]+$"),
    list("-+0123456789"),
)


class InputError(ValueError):
    """What the user gave is wrong: a file, a key, an option, a log that fails its schema.
    The message names it. The command line reports it as bad input (exit 2); any other
    exception that reaches it is a bug (exit 1, ``internal error``)."""


class ConfigError(InputError):
    """A configuration file or value is wrong; the message names the file and the key."""

    def __init__(self, source: str, key: str, problem: str) -> None:
        self.source = source
        self.key = key
        self.problem = problem
        where = f"{source}: {key}" if key else source
        super().__init__(f"{where}: {problem}")


def limits(
    *,
    ge: float | None = None,
    gt: float | None = None,
    le: float | None = None,
    lt: float | None = None,
    doc: str = "",
) -> dict[str, Any]:
    """Field metadata for a numeric range check: ``field(default=1.0, metadata=limits(gt=0))``."""
    return {"ge": ge, "gt": gt, "le": le, "lt": lt, "doc": doc}


def _join(path: str, key: str | int) -> str:
    if isinstance(key, int):
        return f"{path}[{key}]"
    return f"{path}.{key}" if path else key


def _check_range(value: float, meta: Mapping[str, Any], source: str, path: str) -> None:
    bounds: tuple[tuple[str, Callable[[float, float], bool], str], ...] = (
        ("ge", operator.ge, ">="),
        ("gt", operator.gt, ">"),
        ("le", operator.le, "<="),
        ("lt", operator.lt, "<"),
    )
    for name, ok, sign in bounds:
        bound = meta.get(name)
        if bound is not None and not ok(value, bound):
            raise ConfigError(source, path, f"must be {sign} {bound}, got {value}")


def _convert(tp: Any, value: Any, source: str, path: str, meta: Mapping[str, Any]) -> Any:
    origin = get_origin(tp)
    if origin in (typing.Union, types.UnionType):
        return _convert_union(tp, value, source, path, meta)
    if origin is Literal:
        allowed = get_args(tp)
        if value not in allowed:
            raise ConfigError(source, path, f"must be one of {list(allowed)}, got {value!r}")
        return value
    if origin in (tuple, list):
        return _convert_sequence(tp, origin, value, source, path, meta)
    if origin is dict:
        if not isinstance(value, Mapping):
            raise ConfigError(source, path, f"expected a mapping, got {value!r}")
        _, val_tp = get_args(tp)
        return {
            str(k): _convert(val_tp, v, source, _join(path, str(k)), meta) for k, v in value.items()
        }
    if dataclasses.is_dataclass(tp) and isinstance(tp, type):
        return from_mapping(tp, value, source, path)
    return _convert_scalar(tp, value, source, path, meta)


def _convert_union(tp: Any, value: Any, source: str, path: str, meta: Mapping[str, Any]) -> Any:
    """The first option of ``X | Y | None`` that accepts ``value``. Else: an option whose shape
    fits but a key inside it is wrong gives that key's error (``assumed.poisson[1]: must be <=
    0.5``), otherwise every option's problem at ``path``."""
    options = get_args(tp)
    if value is None and type(None) in options:
        return None
    errors: list[ConfigError] = []
    for option in options:
        if option is type(None):
            continue
        try:
            return _convert(option, value, source, path, meta)
        except ConfigError as exc:
            errors.append(exc)
    deeper = [exc for exc in errors if exc.key != path]
    if deeper:
        raise deeper[0]
    raise ConfigError(source, path, " / ".join(exc.problem for exc in errors))


def _convert_sequence(
    tp: Any, origin: Any, value: Any, source: str, path: str, meta: Mapping[str, Any]
) -> Any:
    """A YAML list as ``list[X]``, ``tuple[X, ...]`` or a fixed-length ``tuple[X, Y]``."""
    args = get_args(tp)
    if not isinstance(value, list | tuple):
        raise ConfigError(source, path, f"expected a list, got {value!r}")
    item_tp = args[0] if args else Any
    items = [_convert(item_tp, v, source, _join(path, i), meta) for i, v in enumerate(value)]
    if origin is tuple and args and args[-1] is not Ellipsis and len(args) != len(items):
        raise ConfigError(source, path, f"expected {len(args)} items, got {len(items)}")
    return tuple(items) if origin is tuple else items


def _convert_scalar(tp: Any, value: Any, source: str, path: str, meta: Mapping[str, Any]) -> Any:
    """bool, int, float (finite, within the field's range), str or Any."""
    if tp is bool:
        if not isinstance(value, bool):
            raise ConfigError(source, path, f"expected true or false, got {value!r}")
        return value
    if tp is int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise ConfigError(source, path, f"expected an integer, got {value!r}")
        _check_range(value, meta, source, path)
        return value
    if tp is float:
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise ConfigError(source, path, f"expected a number, got {value!r}")
        if not math.isfinite(value):
            raise ConfigError(source, path, f"must be finite, got {value!r}")
        _check_range(float(value), meta, source, path)
        return float(value)
    if tp is str:
        if not isinstance(value, str):
            raise ConfigError(source, path, f"expected a string, got {value!r}")
        return value
    if tp is Any:
        return value
    raise TypeError(f"config schema uses an unsupported type {tp!r} at {path}")


def from_mapping(cls: type[T], data: Any, source: str = "<config>", path: str = "") -> T:
    """Build dataclass ``cls`` from a YAML mapping, rejecting unknown keys by name.

    Missing keys take the dataclass default; a key without a default is required.
    After construction, a ``validate()`` method on the dataclass (if any) checks cross-field rules
    and may raise ``ValueError``; that message is re-raised as a :class:`ConfigError` at ``path``.
    """
    if data is None:
        data = {}
    if not isinstance(data, Mapping):
        raise ConfigError(source, path, f"expected a mapping, got {data!r}")
    if not (dataclasses.is_dataclass(cls) and isinstance(cls, type)):
        raise TypeError(f"{cls!r} is not a dataclass")
    hints = typing.get_type_hints(cls)
    fields = {f.name: f for f in dataclasses.fields(cls) if f.init}
    unknown = sorted(str(k) for k in data if k not in fields)
    if unknown:
        raise ConfigError(
            source,
            _join(path, unknown[0]),
            f"unknown key (expected one of: {', '.join(sorted(fields))})",
        )
    kwargs: dict[str, Any] = {}
    for name, f in fields.items():
        key_path = _join(path, name)
        if name in data:
            kwargs[name] = _convert(hints[name], data[name], source, key_path, f.metadata)
        elif f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING:
            raise ConfigError(source, key_path, "missing required key")
    try:
        obj = cls(**kwargs)
        validate = getattr(obj, "validate", None)
        if callable(validate):
            validate()
    except ConfigError:
        raise
    except ValueError as exc:
        raise ConfigError(source, path or "<top>", str(exc)) from exc
    return obj


def read_yaml(path: str | Path) -> Any:
    """Parse a YAML file; a syntax error or a missing file becomes a :class:`ConfigError`."""
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ConfigError(str(p), "", "file not found") from None
    except OSError as exc:
        raise ConfigError(str(p), "", f"cannot read: {exc.strerror}") from None
    try:
        data = yaml.load(text, Loader=_Loader)  # a SafeLoader: no arbitrary objects
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f"line {mark.line + 1}, column {mark.column + 1}: " if mark else ""
        problem = getattr(exc, "problem", exc)
        raise ConfigError(str(p), "", f"malformed YAML: {where}{problem}") from None
    except RecursionError:
        raise ConfigError(str(p), "", "malformed YAML: nested too deeply") from None
    _check_size(data, str(p))
    return data


MAX_NODES = 100_000


def _check_size(data: Any, source: str) -> None:
    """Refuse a document whose aliases expand to more than ``MAX_NODES`` values (a "billion
    laughs" file would make every later walk over it take forever)."""
    stack, seen = [data], 0
    while stack:
        node = stack.pop()
        seen += 1
        if seen > MAX_NODES:
            raise ConfigError(source, "", f"too large: more than {MAX_NODES} values once expanded")
        if isinstance(node, dict):
            stack.extend(node.values())
        elif isinstance(node, list):
            stack.extend(node)


def load(cls: type[T], path: str | Path) -> T:
    """Load one YAML file into dataclass ``cls``."""
    return from_mapping(cls, read_yaml(path), str(path))


def resolve(name: str | Path) -> Path:
    """A path as given if it exists, else a file shipped in ``config/`` (``"robot.yaml"``)."""
    p = Path(name)
    if p.exists():
        return p
    shipped = CONFIG_DIR / p
    if shipped.exists():
        return shipped
    raise ConfigError(str(name), "", "file not found (neither as given nor in the shipped config/)")


def to_mapping(obj: Any) -> Any:
    """A configuration dataclass as the YAML mapping :func:`from_mapping` reads back (tuples as
    lists, nested dataclasses as mappings)."""
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        return {f.name: to_mapping(getattr(obj, f.name)) for f in dataclasses.fields(obj)}
    if isinstance(obj, tuple | list):
        return [to_mapping(v) for v in obj]
    if isinstance(obj, float) and math.isfinite(obj):
        return float(f"{obj:.12g}")  # 0.04, not the 0.039999999999999994 of a unit conversion
    return obj


def write_yaml(obj: Any, path: str | Path, comment: str = "") -> None:
    """Write a configuration dataclass to ``path`` as YAML (``comment`` lines first)."""
    head = "".join(f"# {line}\n" for line in comment.splitlines())
    text = yaml.safe_dump(to_mapping(obj), sort_keys=False, default_flow_style=None)
    Path(path).write_text(head + text, encoding="utf-8")

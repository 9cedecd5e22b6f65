"""Fuzz target for the configuration loader: random and mutated YAML trees and text through
:func:`config.loader.read_yaml` and :func:`config.loader.from_mapping` (robot and scene schemas);
only ``ConfigError`` may come out (:mod:`benchmarks.fuzztargets` lists every target).
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from palpate.config.loader import ConfigError, from_mapping, read_yaml
from palpate.config.scene import SceneConfig
from palpate.config.schema import StackConfig

Rng = np.random.Generator

SCHEMAS: tuple[type[Any], ...] = (StackConfig, SceneConfig)
_SCALARS: tuple[Any, ...] = (
    None, True, 0, -1, 1, 2.5, -1e9, 1e300, math.inf, math.nan, "", "x", "sim", "robot", [], {},
)  # fmt: skip


def default_mapping(cls: type[Any]) -> dict[str, Any]:
    """The schema's defaults as plain YAML data (tuples -> lists)."""
    data = dataclasses.asdict(cls())
    return yaml.safe_load(yaml.safe_dump(plain(data)))  # type: ignore[no-any-return]


def plain(value: Any) -> Any:
    """``value`` with every tuple made a list (what YAML can dump safely)."""
    if isinstance(value, dict):
        return {k: plain(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [plain(v) for v in value]
    return value


def mutate_mapping(data: Any, rng: Rng, depth: int = 0) -> Any:
    """Change a few values, keys and shapes of a YAML tree at random."""
    if isinstance(data, dict) and data:
        out = dict(data)
        keys = list(out)
        for _ in range(int(rng.integers(1, 3))):
            k = keys[int(rng.integers(len(keys)))]
            r = rng.random()
            if r < 0.15:
                out.pop(k, None)
            elif r < 0.25:
                out[k + "_typo"] = out.pop(k, None)
            elif r < 0.6 and depth < 4:
                out[k] = mutate_mapping(out.get(k), rng, depth + 1)
            else:
                out[k] = _SCALARS[int(rng.integers(len(_SCALARS)))]
        return out
    if isinstance(data, list) and data:
        out_list = list(data)
        i = int(rng.integers(len(out_list)))
        out_list[i] = mutate_mapping(out_list[i], rng, depth + 1)
        return out_list
    return _SCALARS[int(rng.integers(len(_SCALARS)))]


def config_mapping_case(cls: type[Any], data: Any) -> bool:
    """``from_mapping`` on any data: True if accepted, False on ConfigError, else it raises."""
    try:
        from_mapping(cls, data, "<fuzz>")
    except ConfigError:
        return False
    return True


def config_text_case(cls: type[Any], text: str, path: Path) -> bool:
    """Write ``text`` to ``path`` and load it like a config file (read_yaml + from_mapping)."""
    path.write_text(text, encoding="utf-8", errors="surrogatepass")
    try:
        from_mapping(cls, read_yaml(path), str(path))
    except ConfigError:
        return False
    return True


def mutate_text(text: str, rng: Rng) -> str:
    chars = list(text)
    alphabet = ":-[]{}#&*!|>'\"%@`,? \n\t0123456789abcxyz_.\\"
    for _ in range(int(rng.integers(1, 6))):
        if not chars:
            break
        i = int(rng.integers(len(chars)))
        r = rng.random()
        if r < 0.4:
            del chars[i]
        elif r < 0.8:
            chars.insert(i, alphabet[int(rng.integers(len(alphabet)))])
        else:
            chars[i] = alphabet[int(rng.integers(len(alphabet)))]
    return "".join(chars)

"""Benchmark-only replacements of shipped functions, always put back (a measurement's hooks).

A benchmark that needs to see inside a trial (time a boundary, tell the prober the true
surface) replaces a module's or a class's attribute for the duration of a ``with`` block and
restores the original on exit, even on error. Shipped code has no hooks for this.
"""

from __future__ import annotations

import contextlib
import functools
import importlib
from collections.abc import Callable, Iterator, Sequence
from typing import Any

_MISSING = object()


def owner_of(path: str) -> Any:
    """The object named ``"package.module"`` or ``"package.module:Class"``."""
    module, _, cls = path.partition(":")
    obj: Any = importlib.import_module(module)
    return getattr(obj, cls) if cls else obj


@contextlib.contextmanager
def patched(
    replacements: Sequence[tuple[str, str, Callable[[Any], Any]]],
) -> Iterator[None]:
    """For each ``(owner path, attribute, make)``: the attribute becomes ``make(original)``
    inside the block; every original is back on exit (a class's own entry as it was, an
    inherited one removed again)."""
    undo: list[Callable[[], None]] = []
    try:
        for path, attribute, make in replacements:
            owner = owner_of(path)
            own = owner.__dict__.get(attribute, _MISSING) if isinstance(owner, type) else _MISSING
            original = getattr(owner, attribute)
            setattr(owner, attribute, make(original))
            if isinstance(owner, type) and own is _MISSING:
                undo.append(functools.partial(delattr, owner, attribute))
            else:
                back = own if own is not _MISSING else original
                undo.append(functools.partial(setattr, owner, attribute, back))
        yield
    finally:
        for step in reversed(undo):
            step()

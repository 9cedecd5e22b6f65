"""Benchmark-only replacements of shipped functions, always put back (a measurement's hooks).

A benchmark that needs to see inside a trial (time a boundary, tell the prober the true
surface) replaces a module's or a class's attribute for the duration of a ``with`` block and
restores the original on exit, even on error. Shipped code has no hooks for this. The owners
are the real objects (``unittest.mock.patch.object``'s), never import paths as strings::

    from palpate.simulation import trial
    with patched([(trial, "prober_for", lambda original: my_factory)]):
        ...
"""

from __future__ import annotations

import contextlib
import functools
from collections.abc import Callable, Iterator, Sequence
from typing import Any

_MISSING = object()


@contextlib.contextmanager
def patched(
    replacements: Sequence[tuple[Any, str, Callable[[Any], Any]]],
) -> Iterator[None]:
    """For each ``(owner, attribute, make)`` (a module or a class): the attribute becomes
    ``make(original)`` inside the block; every original is back on exit (a class's own entry
    as it was, an inherited one removed again)."""
    undo: list[Callable[[], None]] = []
    try:
        for owner, attribute, make in replacements:
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

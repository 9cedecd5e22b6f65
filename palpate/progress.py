"""Progress bars on stderr, only where someone watches them.

A bar redraws itself with carriage returns, which turn a redirected stderr (a log file, CI output)
into noise: :func:`progress_bar` shows one only when stderr is a terminal and the ``palpate``
logger lets progress notes (INFO) through (``-q`` hides it).
"""

from __future__ import annotations

import logging
import sys
from typing import Any

from tqdm import tqdm


def progress_bar(total: int, desc: str, unit: str = "trial") -> tqdm[Any]:
    """A tqdm bar on stderr; disabled (every call a no-op) off a terminal or under ``-q``."""
    shown = sys.stderr.isatty() and logging.getLogger("palpate").isEnabledFor(logging.INFO)
    return tqdm(total=total, desc=desc, unit=unit, file=sys.stderr, disable=not shown)

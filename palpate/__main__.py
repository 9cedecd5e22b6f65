"""``python -m palpate``: the ``palpate`` console script."""

from __future__ import annotations

import sys

from palpate.cli import main

sys.exit(main())

"""``python -m palpate.faults JOB_FILE``: the child process of a killed fault trial."""

from __future__ import annotations

import sys

from palpate.faults.runner import child_main

sys.exit(child_main(sys.argv[1]))

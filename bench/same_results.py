"""Are two runs' results the same? Compares two ``palpate ... --json`` outputs field by field,
leaving out what depends on the clock or on where the run wrote (wall and CPU times, speed-ups,
run folders and log paths). Prints each difference and exits 1 when there is one.

    python3 bench/same_results.py BEFORE.json AFTER.json [--new-keys] [--rtol 1e-3]

``--new-keys``: a key only in AFTER is not a difference (a change that adds an output and
leaves every earlier one as it was). A key renamed since BEFORE was written
(:data:`RENAMED`: ``actual_kpa`` is ``true_kpa`` since the two moduli got one name each) is
compared under its new name. ``--rtol R``: numbers within R of each other (relative) are the
same; strings, booleans and verdicts must still be equal (the tolerance results may move
within, docs/speed.md).

Used to show that a restructure moved code only: run the seeded campaign on both commits (e.g.
``palpate sim --campaign paper --no-plots --json`` and ``palpate sim --faults --no-plots
--json``), then compare.
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path
from typing import Any

CLOCK_OR_PLACE = frozenset(
    {"wall_s", "speedup", "fit_ms_per_trial", "log", "log_dir", "run_dir", "cpu_s", "elapsed_s"}
)


# an output key's old name -> its name now
RENAMED = {"actual_kpa": "true_kpa", "actual": "against"}


def renamed(value: Any) -> Any:
    """``value`` with every key of :data:`RENAMED` under its new name."""
    if isinstance(value, dict):
        return {RENAMED.get(k, k): renamed(v) for k, v in value.items()}
    if isinstance(value, list):
        return [renamed(v) for v in value]
    return value


def differences(
    a: Any, b: Any, path: str = "", new_keys: bool = False, rtol: float = 0.0
) -> list[str]:
    """Every place where ``a`` and ``b`` differ, outside the clock's and the folders' fields
    (and, with ``new_keys``, the keys only ``b`` has)."""
    if isinstance(a, dict) and isinstance(b, dict):
        out: list[str] = []
        for key in sorted(set(a) | set(b)):
            if key in CLOCK_OR_PLACE:
                continue
            if new_keys and key not in a:
                continue
            if key not in a or key not in b:
                out.append(f"{path}/{key}: only in {'after' if key in b else 'before'}")
            else:
                out += differences(a[key], b[key], f"{path}/{key}", new_keys, rtol)
        return out
    if isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            return [f"{path}: {len(a)} items before, {len(b)} after"]
        return [
            d
            for i, (x, y) in enumerate(zip(a, b, strict=True))
            for d in differences(x, y, f"{path}[{i}]", new_keys, rtol)
        ]
    if a == b or (
        isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b)
    ):
        return []  # a NaN in both runs is the same result (NaN != NaN in Python)
    numbers = isinstance(a, int | float) and isinstance(b, int | float)
    plain = numbers and not isinstance(a, bool) and not isinstance(b, bool)
    if rtol and plain and math.isclose(a, b, rel_tol=rtol):
        return []
    return [f"{path}: {a!r} before, {b!r} after"]


def main(argv: list[str]) -> int:
    new_keys = "--new-keys" in argv
    rtol = 0.0
    if "--rtol" in argv:
        i = argv.index("--rtol")
        rtol = float(argv[i + 1])
        argv = argv[:i] + argv[i + 2 :]
    paths = [a for a in argv if a != "--new-keys"]
    if len(paths) != 2:
        print(__doc__, file=sys.stderr)
        return 2
    before, after = (json.loads(Path(p).read_text(encoding="utf-8")) for p in paths)
    found = differences(renamed(before), after, new_keys=new_keys, rtol=rtol)
    for line in found:
        print(line)
    print(f"{len(found)} differences" if found else "identical (clock and folder fields left out)")
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

"""The trial log's records as data: every record kind and the fields a reader relies on.

:data:`RECORDS` is the one place that lists them. Each kind maps field names to a
:class:`Field` (a check, and whether the field must be there); fields a record has beyond those
are tolerated, so a writer may add fields (and a reader ignore them) without a new log version.
A new record kind is one more entry. :func:`check_record` validates one record and raises
:class:`LogRecordError` naming the field (``end.marks.x_buckling: expected a number or null,
got 'abc'``); :mod:`robot.records.log` applies it to every line it reads.

The checks are the readers' needs: types, and ranges where the estimators have a domain (an
exposed length, a Poisson ratio, a section's stiffness). Floats that were NaN or infinite are
written as null, so a number a trial may not have measured accepts null.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

Check = Callable[[Any, str], None]
"""``check(value, key)``: raises :class:`LogRecordError` at ``key`` when ``value`` is wrong."""


class LogRecordError(ValueError):
    """A record of a trial log is not what its kind promises; ``key`` is the dotted field."""

    def __init__(self, key: str, problem: str) -> None:
        self.key = key
        self.problem = problem
        super().__init__(f"{key}: {problem}")


@dataclass(frozen=True)
class Field:
    check: Check
    required: bool = True


def logged_number(value: Any) -> float:
    """A number as a log holds it, NaN for its null (a value the tick did not measure, such as
    the advance of a tick whose servo read was missed)."""
    return math.nan if value is None else float(value)


def _fail(key: str, want: str, value: Any) -> LogRecordError:
    shown = repr(value)
    return LogRecordError(key, f"expected {want}, got {shown[:60]}")


def number(
    *, null: bool = False, gt: float | None = None, ge: float | None = None, le: float | None = None
) -> Check:
    """A finite JSON number (not a bool) within the bounds; ``null`` allows null."""

    def check(value: Any, key: str) -> None:
        if value is None and null:
            return
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise _fail(key, "a number or null" if null else "a number", value)
        if not math.isfinite(value):
            raise _fail(key, "a finite number", value)
        if gt is not None and not value > gt:
            raise LogRecordError(key, f"must be > {gt}, got {value}")
        if ge is not None and not value >= ge:
            raise LogRecordError(key, f"must be >= {ge}, got {value}")
        if le is not None and not value <= le:
            raise LogRecordError(key, f"must be <= {le}, got {value}")

    return check


def integer(*, ge: int | None = None) -> Check:
    def check(value: Any, key: str) -> None:
        if isinstance(value, bool) or not isinstance(value, int):
            raise _fail(key, "an integer", value)
        if ge is not None and value < ge:
            raise LogRecordError(key, f"must be >= {ge}, got {value}")

    return check


def string(*, null: bool = False) -> Check:
    def check(value: Any, key: str) -> None:
        if not (isinstance(value, str) or (value is None and null)):
            raise _fail(key, "a string", value)

    return check


def boolean(value: Any, key: str) -> None:
    if not isinstance(value, bool):
        raise _fail(key, "true or false", value)


def list_of(item: Check, what: str, *, null: bool = False) -> Check:
    """A list whose every item passes ``item`` (``what`` names them in the error; ``null``: the
    list may be null)."""

    def check(value: Any, key: str) -> None:
        if value is None and null:
            return
        if not isinstance(value, list):
            raise _fail(key, f"a list of {what}", value)
        for i, v in enumerate(value):
            item(v, f"{key}[{i}]")

    return check


def booleans(*, null: bool = False) -> Check:
    """A list of true/false (``null``: the list may be null)."""
    return list_of(boolean, "true/false", null=null)


def one_of(*allowed: str) -> Check:
    def check(value: Any, key: str) -> None:
        if value not in allowed:
            raise LogRecordError(key, f"must be one of {list(allowed)}, got {value!r:.60}")

    return check


def numbers(*, null_items: bool = False, null: bool = False) -> Check:
    """A list of numbers (``null_items``: an item may be null; ``null``: the list may be)."""
    return list_of(number(null=null_items), "numbers", null=null)


def mapping(fields: Mapping[str, Field], *, null: bool = False) -> Check:
    """A JSON object with ``fields`` (extra keys tolerated); ``null`` allows null."""

    def check(value: Any, key: str) -> None:
        if value is None and null:
            return
        if not isinstance(value, dict):
            raise _fail(key, "an object", value)
        check_fields(value, fields, key)

    return check


def anything(value: Any, key: str) -> None:
    """Any JSON value (a field kept for people, not read back)."""


def check_fields(record: Mapping[str, Any], fields: Mapping[str, Field], where: str) -> None:
    for name, f in fields.items():
        key = f"{where}.{name}"
        if name not in record:
            if f.required:
                raise LogRecordError(key, "missing")
            continue
        f.check(record[name], key)


def req(check: Check) -> Field:
    return Field(check)


def opt(check: Check) -> Field:
    return Field(check, required=False)


LENGTH = number(gt=0, le=1.0)  # m: a sensor length, a radius, a layer
POSITION = number(ge=-10.0, le=10.0)  # m: a stage position

SPEC = {
    "kind": req(one_of("bench", "robot")),
    "exposed_length": req(LENGTH),
    "tube": opt(string()),
}
SECTION = {
    "EI": req(number(gt=0)),
    "EA": req(number(gt=0)),
    "neutral_axis": req(number()),
    "fiber_offset": req(number()),
    "I_fiber": req(number(ge=0)),
    "I_wires": req(number(ge=0)),
}
ESTIMATOR = {  # estimation.trial.estimate.EstimatorInputs
    "kind": req(one_of("bench", "robot")),
    "exposed_length": req(LENGTH),
    "flush_translation": req(POSITION),
    "tip_radius": req(LENGTH),
    "poisson": req(number(ge=-1.0, le=0.5)),
    "thickness": req(number(null=True, gt=0)),
    "bonded": req(boolean),
    "encoder_resolution": req(number(gt=0, le=1e-2)),
    "misalignment": req(number(ge=0, le=math.pi)),
    # version 2 (beliefs, compliance, verdict limits); a version-1 header has none of them
    "poisson_range": opt(numbers(null=True)),
    "thickness_range": opt(numbers(null=True, null_items=True)),
    "bonded_options": opt(booleans(null=True)),
    "compliance": opt(numbers()),
    "compliance_calibrated": opt(boolean),
    "misalignment_tolerance": opt(number(null=True, ge=0, le=math.pi)),
    "motion_tolerance": opt(number(null=True, gt=0)),
    "travel_window": opt(number(null=True, gt=0)),
    "rigid": opt(boolean),
    "orientation_verified": opt(boolean),  # absent before issue 25: verified
    "misalignment_sigma": opt(number(null=True, ge=0, le=math.pi)),
    "designed_range": opt(numbers(null=True)),  # absent before issue 28: not stated
    "probe_reason": opt(string(null=True)),
    "surface_radius": opt(number(null=True, gt=0)),  # absent before: flat or unknown
    "version": opt(integer(ge=1)),
}
PROBE = {  # robot.probe_plan.ProbeResult: what probing found (robot trials that probe)
    "reachable": req(boolean),
    "reason": req(string()),
    "roll": req(number(null=True)),
    "contact_advance": req(number(null=True, ge=-10.0, le=10.0)),
    "misalignment": req(number(null=True, ge=0, le=math.pi)),  # null: no normal was fitted
    "normal_sigma": req(number(null=True, ge=0)),
}
MARKS = {  # robot.indentation.TrialMarks
    "x_contact": req(number(null=True, ge=-10.0, le=10.0)),
    "x_buckling": req(number(null=True, ge=-10.0, le=10.0)),
    "t_contact": opt(number(null=True)),
    "t_buckling": opt(number(null=True)),
    "strains_at_buckling": req(numbers(null=True)),
    "reason": opt(string()),
}

RECORDS: dict[str, dict[str, Field]] = {
    "header": {
        "trial": req(string()),
        "source": opt(string()),
        "spec": req(mapping(SPEC)),
        "plan": opt(anything),
        "section": req(mapping(SECTION)),
        "sensor": req(mapping({})),  # checked key by key by the config loader (SensorConfig)
        "tube": req(mapping({}, null=True)),  # the same (TubeConfig), on the robot
        "poisson": req(number(ge=-1.0, le=0.5)),
        "estimator": opt(mapping(ESTIMATOR)),
        "units": opt(string()),
    },
    "sample": {
        "t": req(number()),
        "state": req(string()),
        "advance": req(number(null=True)),
        "roll": req(number(null=True)),
        "strains": req(numbers(null_items=True)),
        "contact": req(boolean),
        "goal": opt(number(null=True)),
        "tip_force": opt(number(null=True)),
        "beat": opt(boolean),
    },
    "transition": {
        "t": req(number()),
        "from": req(string()),
        "to": req(string()),
        "reason": req(string()),
        "advance": req(number(null=True)),
        "strains": req(numbers(null_items=True)),
    },
    # a stale FBG stream the motion held through (robot.indentation), once frames came again
    "stream_gap": {
        "t": req(number()),
        "duration": req(number(ge=0)),
        "state": req(string()),
    },
    "estimate": {
        "success": req(boolean),
        "modulus": opt(number(null=True)),
        "delta": opt(number(null=True)),
        "force": opt(number(null=True)),
        "exposed_length": opt(number(null=True)),
        "message": req(string()),
        "joint": opt(mapping({"success": req(boolean), "message": req(string())})),
    },
    "probe": PROBE,
    # a simulated trial's world truth, which the controller never sees (for reports, --resume)
    "world": {
        "true_misalignment": opt(number(null=True, ge=0, le=math.pi)),
        "true_motion": opt(number(null=True, ge=0)),
    },
    "end": {
        "state": req(string()),
        "reason": req(string()),
        "marks": req(mapping(MARKS)),
        "ticks": req(integer(ge=0)),
        "duration": req(number(null=True)),
    },
}
"""Record kind -> its fields (the header's ``format`` and ``version`` are checked first)."""


def check_record(record: Any) -> str:
    """Validate one record (a parsed line); return its kind. Raises :class:`LogRecordError`."""
    if not isinstance(record, dict):
        raise _fail("record", "a JSON object", record)
    kind = record.get("kind")
    if not isinstance(kind, str) or kind not in RECORDS:
        raise LogRecordError("kind", f"unknown record kind {kind!r:.40}; known: {sorted(RECORDS)}")
    check_fields(record, RECORDS[kind], kind)
    return kind

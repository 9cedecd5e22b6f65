"""A trial's log records as ROS 2 messages: the definitions and the pure conversions.

Standard definitions where one exists, the project's own (``palpate_msgs``) where none does
(docs/recordings.md lists them). Each definition is the ``ros2msg`` text MCAP stores: the type's
fields, then each dependency after a line of ``=`` as ``MSG: pkg/Type``.

Channels, one message per log record of the kind (a ``sample`` gives two):

- ``/joint_states`` (``sensor_msgs/msg/JointState``): each sample's stage translation (m) and
  outer roll (rad);
- ``/fbg/strains`` (``palpate_msgs/msg/GratingStrains``): each sample's state, strains, contact
  event and goal;
- ``/palpate/transition`` (``palpate_msgs/msg/StateTransition``): each transition;
- ``/palpate/record`` (``palpate_msgs/msg/Record``): the ``probe``, ``world``, ``estimate`` and
  ``end`` records, as their JSON lines;
- ``/tip/wrench`` (``geometry_msgs/msg/WrenchStamped``): each sample, the tip force derived from
  its strains when the trial ends (NaN where it has none: strains incomplete, or the sensor not
  yet out of the tube);
- ``/tf`` (``tf2_msgs/msg/TFMessage``): on the robot, each sample's ``base`` -> ``tube_tip`` (the
  tube's forward kinematics at the sample's roll) and ``tube_tip`` -> ``sensor_tip`` (the exposed
  length along the tangent, the beam taken straight), written when the trial ends.

Times: a record's ``t`` (s, the rig's clock) as nanoseconds; a record without one (the estimate,
the end) takes the last time seen, so every channel's times never decrease.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence
from typing import Any

from ...config.schema import TubeConfig
from ..kinematics import tube_tip_in_bend_plane
from . import cdr
from .logschema import logged_number

SEP = "\n" + "=" * 80 + "\n"
TIME = "MSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n"
HEADER = "MSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\nstring frame_id\n"
VECTOR3 = "MSG: geometry_msgs/Vector3\nfloat64 x\nfloat64 y\nfloat64 z\n"
WRENCH = "MSG: geometry_msgs/Wrench\ngeometry_msgs/Vector3 force\ngeometry_msgs/Vector3 torque\n"
QUATERNION = "MSG: geometry_msgs/Quaternion\nfloat64 x\nfloat64 y\nfloat64 z\nfloat64 w\n"
TRANSFORM = (
    "MSG: geometry_msgs/Transform\ngeometry_msgs/Vector3 translation\n"
    "geometry_msgs/Quaternion rotation\n"
)
TRANSFORM_STAMPED = (
    "MSG: geometry_msgs/TransformStamped\nstd_msgs/Header header\nstring child_frame_id\n"
    "geometry_msgs/Transform transform\n"
)


def _definition(fields: str, *dependencies: str) -> str:
    return fields + "".join(SEP + d for d in dependencies)


SCHEMAS: dict[str, str] = {
    "sensor_msgs/msg/JointState": _definition(
        "std_msgs/Header header\nstring[] name\nfloat64[] position\nfloat64[] velocity\n"
        "float64[] effort\n",
        HEADER,
        TIME,
    ),
    "geometry_msgs/msg/WrenchStamped": _definition(
        "std_msgs/Header header\ngeometry_msgs/Wrench wrench\n", HEADER, WRENCH, VECTOR3, TIME
    ),
    "tf2_msgs/msg/TFMessage": _definition(
        "geometry_msgs/TransformStamped[] transforms\n",
        TRANSFORM_STAMPED,
        TRANSFORM,
        QUATERNION,
        VECTOR3,
        HEADER,
        TIME,
    ),
    "palpate_msgs/msg/GratingStrains": _definition(
        "# one control tick: the state machine's state after it, the used gratings' strains\n"
        "std_msgs/Header header\nstring state\nfloat64[] strain\nbool contact\nfloat64 goal\n",
        HEADER,
        TIME,
    ),
    "palpate_msgs/msg/StateTransition": _definition(
        "# a transition of the indentation state machine\n"
        "std_msgs/Header header\nstring from_state\nstring to_state\nstring reason\n"
        "float64 advance\nfloat64[] strain\n",
        HEADER,
        TIME,
    ),
    "palpate_msgs/msg/Record": _definition(
        "# a trial log record without a standard type: its kind and the record as JSON\n"
        "std_msgs/Header header\nstring kind\nstring json\n",
        HEADER,
        TIME,
    ),
}

TOPICS: dict[str, str] = {
    "/joint_states": "sensor_msgs/msg/JointState",
    "/fbg/strains": "palpate_msgs/msg/GratingStrains",
    "/palpate/transition": "palpate_msgs/msg/StateTransition",
    "/palpate/record": "palpate_msgs/msg/Record",
    "/tip/wrench": "geometry_msgs/msg/WrenchStamped",
    "/tf": "tf2_msgs/msg/TFMessage",
}
JOINTS = ["stage_translation", "outer_roll"]
Message = tuple[str, dict[str, Any]]  # (topic, message)


def nanoseconds(t: float) -> int:
    """Seconds as whole nanoseconds (>= 0: MCAP's times are unsigned)."""
    return max(round(t * 1e9), 0)


def header(stamp_ns: int, frame: str) -> dict[str, Any]:
    sec, nanosec = divmod(stamp_ns, 1_000_000_000)
    return {"stamp": {"sec": sec, "nanosec": nanosec}, "frame_id": frame}


def _numbers(values: Sequence[Any]) -> list[float]:
    return [logged_number(v) for v in values]


def sample_messages(record: dict[str, Any], stamp_ns: int) -> list[tuple[str, bytes]]:
    """A ``sample`` record's two messages, CDR-encoded (``robot.records.cdr``: they are written
    every control tick)."""
    joints = cdr.joint_state(
        stamp_ns, "stage", JOINTS, _numbers([record["advance"], record["roll"]])
    )
    strains = cdr.grating_strains(
        stamp_ns,
        "sensor",
        record["state"],
        _numbers(record["strains"]),
        bool(record["contact"]),
        logged_number(record.get("goal")),
    )
    return [("/joint_states", joints), ("/fbg/strains", strains)]


def messages(record: dict[str, Any], stamp_ns: int, line: str) -> list[Message]:
    """The messages of a log record that is neither the header (the recording's metadata) nor
    a sample (:func:`sample_messages`); ``line`` is the record as its log writes it (JSON, NaN
    as null)."""
    if record.get("kind") == "transition":
        return [
            (
                "/palpate/transition",
                {
                    "header": header(stamp_ns, "stage"),
                    "from_state": record["from"],
                    "to_state": record["to"],
                    "reason": record["reason"],
                    "advance": logged_number(record["advance"]),
                    "strain": _numbers(record["strains"]),
                },
            )
        ]
    kind = str(record.get("kind"))
    return [("/palpate/record", {"header": header(stamp_ns, ""), "kind": kind, "json": line})]


def wrench(stamp_ns: int, load: float) -> tuple[str, bytes]:
    """The tissue's push on the tip (N) along the sensor axis, in the tip's frame (+z into the
    tissue): ``-load``, the axial load the strains give (compression positive); CDR-encoded."""
    return (
        "/tip/wrench",
        cdr.wrench_stamped(stamp_ns, "sensor_tip", (0.0, 0.0, -load), (0.0,) * 3),
    )


@functools.lru_cache(maxsize=64)
def _tip_in_bend_plane(tube: TubeConfig) -> tuple[float, float, float]:
    """The tube tip's position at roll 0 (``robot.kinematics.tube_tip_in_bend_plane``), once a
    tube: a recording's ``/tf`` asks for it at every sample."""
    p0, _ = tube_tip_in_bend_plane(tube)
    return float(p0[0]), float(p0[1]), float(p0[2])


def tip_transforms(tube: TubeConfig, roll: float, advance: float) -> list[cdr.Transform] | None:
    """A robot sample's ``/tf`` transforms: ``base`` -> ``tube_tip`` -> ``sensor_tip`` (None
    where the encoders gave no number); as ``robot.kinematics.forward``, the rotation composed as
    quaternions (roll about x, then the tube's tip angle about y)."""
    if not (math.isfinite(roll) and math.isfinite(advance)):
        return None
    x0, y0, z0 = _tip_in_bend_plane(tube)
    c, s = math.cos(roll), math.sin(roll)
    tip = (x0, c * y0 - s * z0, s * y0 + c * z0)
    w1, x1 = math.cos(roll / 2), math.sin(roll / 2)
    w2, y2 = math.cos(tube.tip_angle / 2), math.sin(tube.tip_angle / 2)
    quaternion = (x1 * w2, w1 * y2, x1 * y2, w1 * w2)  # (x, y, z, w) of q_x(roll) q_y(angle)
    exposed = advance - tube.flush_translation
    return [
        ("base", "tube_tip", tip, quaternion),
        ("tube_tip", "sensor_tip", (exposed, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0)),
    ]

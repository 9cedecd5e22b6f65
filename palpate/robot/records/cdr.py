"""A small CDR (XCDR1, little endian) encoder for the messages every control tick records.

``mcap-ros2-support``'s encoder reads the message definition at run time and costs 8-40 us a
message; a trial records three a tick (the wrench when it ends), which made the recording a
fifth of a simulated trial's CPU. These messages have fixed layouts, so they are packed here
directly (2 us; alignment relative to the payload after the 4-byte encapsulation header, as CDR
has it). Tests hold them byte for byte to ``mcap-ros2-support``'s encoder, and decode the
recordings with its decoder, against the definitions in ``robot.records.ros2``.
"""

from __future__ import annotations

import functools
import struct
from collections.abc import Sequence

ENCAPSULATION = b"\x00\x01\x00\x00"  # CDR, little endian


class _Buffer:
    def __init__(self) -> None:
        self.data = bytearray()

    def align(self, n: int) -> None:
        pad = -len(self.data) % n
        if pad:
            self.data += b"\x00" * pad

    def u32(self, value: int) -> None:
        self.align(4)
        self.data += struct.pack("<I", value)

    def header(self, stamp_ns: int, frame: str) -> None:
        sec, nanosec = divmod(stamp_ns, 1_000_000_000)
        self.align(4)
        self.data += struct.pack("<iI", sec, nanosec)
        self.string(frame)

    def string(self, text: str) -> None:
        raw = text.encode() + b"\x00"
        self.u32(len(raw))
        self.data += raw

    def strings(self, texts: Sequence[str]) -> None:
        self.u32(len(texts))
        for text in texts:
            self.string(text)

    def doubles(self, values: Sequence[float]) -> None:
        self.u32(len(values))
        if values:
            self.align(8)
            self.data += struct.pack(f"<{len(values)}d", *values)

    def double(self, value: float) -> None:
        self.align(8)
        self.data += struct.pack("<d", value)

    def boolean(self, value: bool) -> None:
        self.data += b"\x01" if value else b"\x00"

    def payload(self) -> bytes:
        return ENCAPSULATION + bytes(self.data)


def _stamp(stamp_ns: int) -> bytes:
    return _STAMP.pack(*divmod(stamp_ns, 1_000_000_000))


_STAMP = struct.Struct("<iI")


@functools.lru_cache(maxsize=64)
def _joint_layout(frame: str, names: tuple[str, ...], n: int) -> tuple[bytes, struct.Struct]:
    """A JointState of ``n`` > 0 positions as (the bytes between the stamp and the positions,
    the positions' and the empty arrays' struct): every offset is fixed by the frame, the
    names and n, so a tick's message is two packs (the messages are written every tick)."""
    b = _Buffer()
    b.header(0, frame)
    b.strings(names)
    b.u32(n)
    b.align(8)
    return bytes(b.data[_STAMP.size :]), struct.Struct(f"<{n}d2I")  # velocity, effort: empty


@functools.lru_cache(maxsize=64)
def _strains_layout(frame: str, state: str, n: int) -> tuple[bytes, struct.Struct]:
    """A GratingStrains of ``n`` > 0 strains, as :func:`_joint_layout`: the strains end on an
    8-byte boundary, so the flag is followed by 7 bytes of padding and the goal."""
    b = _Buffer()
    b.header(0, frame)
    b.string(state)
    b.u32(n)
    b.align(8)
    return bytes(b.data[_STAMP.size :]), struct.Struct(f"<{n}d?7xd")


def joint_state(
    stamp_ns: int, frame: str, names: Sequence[str], positions: Sequence[float]
) -> bytes:
    """``sensor_msgs/msg/JointState`` with positions only (no velocity, no effort)."""
    if positions:
        middle, values = _joint_layout(frame, tuple(names), len(positions))
        return ENCAPSULATION + _stamp(stamp_ns) + middle + values.pack(*positions, 0, 0)
    b = _Buffer()
    b.header(stamp_ns, frame)
    b.strings(names)
    b.doubles(positions)
    b.doubles(())
    b.doubles(())
    return b.payload()


def grating_strains(
    stamp_ns: int, frame: str, state: str, strain: Sequence[float], contact: bool, goal: float
) -> bytes:
    """``palpate_msgs/msg/GratingStrains``."""
    if strain:
        middle, values = _strains_layout(frame, state, len(strain))
        return ENCAPSULATION + _stamp(stamp_ns) + middle + values.pack(*strain, contact, goal)
    b = _Buffer()
    b.header(stamp_ns, frame)
    b.string(state)
    b.doubles(strain)
    b.boolean(contact)
    b.double(goal)
    return b.payload()


def wrench_stamped(
    stamp_ns: int, frame: str, force: Sequence[float], torque: Sequence[float]
) -> bytes:
    """``geometry_msgs/msg/WrenchStamped``."""
    b = _Buffer()
    b.header(stamp_ns, frame)
    b.align(8)
    b.data += struct.pack("<6d", *force, *torque)
    return b.payload()


Transform = tuple[str, str, Sequence[float], Sequence[float]]  # parent, child, xyz, quaternion xyzw


def tf_message(stamp_ns: int, transforms: Sequence[Transform]) -> bytes:
    """``tf2_msgs/msg/TFMessage``: each transform stamped ``stamp_ns``."""
    b = _Buffer()
    b.u32(len(transforms))
    for parent, child, xyz, quaternion in transforms:
        b.header(stamp_ns, parent)
        b.string(child)
        b.align(8)
        b.data += struct.pack("<7d", *xyz, *quaternion)
    return b.payload()

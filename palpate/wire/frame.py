"""The acquisition board's binary frame: a table-driven layout and pure encode/decode functions.

The wire format is specified for firmware authors in ``docs/frame-protocol.md``; this module is
its executable form. Everything here is pure (bytes in, values out) and depends only on the
standard library and numpy, because the frame is a *wire protocol* shared by two sides:
``sensor/`` reads it and the board emulator in ``sim/board.py`` writes it. Like everything in
``wire/``, it imports nothing of the project.

Layout (little-endian, ``N`` peaks, optional reference and force fields)::

    off  size  field          type   meaning
    0    2     sync           u8[2]  0xA5 0x5A
    2    1     version        u8     1
    3    1     n_peaks        u8     N, 1..32
    4    1     options        u8     bit0 reference, bit1 force, bit2 tip grating present
    5    1     length         u8     payload bytes = 18 + 4 N (+4 reference) (+4 force) (+4 tip)
    6    4     seq            u32    sample counter, +1 per sample, wraps at 2**32
    10   8     timestamp_us   u64    board time of the sample, microseconds
    18   4     encoder        i32    stage encoder count
    22   2     flags          u16    :class:`Status` bits
    24   4N    peak_fm        u32[N] peak (Bragg) wavelengths, femtometres
    ..   4     reference_fm   u32    strain-free reference grating, femtometres (optional)
    ..   4     force_un       i32    force reading, micronewtons (optional)
    ..   4     tip_fm         u32    tip force grating, femtometres (optional, revision 1.1)
    ..   4     crc            u32    CRC-32/ISO-HDLC (zlib.crc32) of every preceding byte

Raw fields keep their wire units in their names (``peak_fm``, ``force_un``); the properties
``time``, ``wavelengths`` and ``force`` convert to SI at this boundary.

Blocks of many frames as arrays (recorded streams, benchmarks) are in :mod:`wire.frameblock`.
"""

from __future__ import annotations

import struct
import zlib
from dataclasses import dataclass
from enum import IntFlag
from functools import cached_property, lru_cache
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

SYNC = b"\xa5\x5a"
VERSION = 1
MARKER = SYNC + bytes([VERSION])
"""Sync word and version: the three bytes a receiver hunts for."""
HEADER_SIZE = 6
CRC_SIZE = 4
MAX_PEAKS = 32
OPTION_REFERENCE = 0x01
OPTION_FORCE = 0x02
OPTION_TIP = 0x04
"""Revision 1.1: a tip force grating's peak follows every other field. A frame without the bit is
byte for byte a revision 1.0 frame; a 1.0 receiver rejects a frame with it (a bad header),
never misreads it."""
OPTIONS = OPTION_REFERENCE | OPTION_FORCE | OPTION_TIP

FM = 1e-15
"""One femtometre in metres (wavelength unit on the wire)."""
UN = 1e-6
"""One micronewton in newtons (force unit on the wire)."""
US = 1e-6
"""One microsecond in seconds (timestamp unit on the wire)."""


class Status(IntFlag):
    """Status bits of the ``flags`` field (bits 8-15 are reserved and sent as 0)."""

    PEAK_LOST = 1 << 0
    """The interrogator lost at least one peak; a lost peak is sent as 0 fm."""
    FORCE_VALID = 1 << 1
    """The force field holds a fresh reading (only meaningful when force is present)."""
    ENCODER_FAULT = 1 << 2
    """The encoder reported an error; the count is the last good one."""
    OVERRUN = 1 << 3
    """The board's transmit buffer overflowed; samples were dropped (seq shows how many)."""
    PEAKS_REPEATED = 1 << 4
    """No new spectrum since the previous sample; the peaks are repeated."""
    CONTACT_EVENT = 1 << 5
    """The rig's contact trigger is active (force-scale threshold or camera event input)."""
    BREATH_HOLD = 1 << 6
    """The ventilator's breath-hold gate input is active (the patient's breath is held)."""
    CARDIAC_TRIGGER = 1 << 7
    """The ECG monitor's sync output is active: a pulse at each R wave (each heartbeat)."""


@dataclass(frozen=True)
class FieldSpec:
    """One field of the frame: name, struct code (little-endian), count, wire unit, meaning."""

    name: str
    code: str
    count: int = 1
    unit: str = ""
    doc: str = ""

    @property
    def size(self) -> int:
        return struct.calcsize("<" + self.code) * self.count


HEADER: tuple[FieldSpec, ...] = (
    FieldSpec("sync0", "B", doc="0xA5"),
    FieldSpec("sync1", "B", doc="0x5A"),
    FieldSpec("version", "B", doc="protocol version, 1"),
    FieldSpec("n_peaks", "B", doc="number of peak wavelengths N, 1..32"),
    FieldSpec("options", "B", doc="bit0: reference, bit1: force, bit2: tip grating; others 0"),
    FieldSpec("length", "B", doc="payload bytes between the header and the CRC"),
)
FIXED_PAYLOAD: tuple[FieldSpec, ...] = (
    FieldSpec("seq", "I", unit="1", doc="sample counter, +1 per sample, wraps at 2**32"),
    FieldSpec("timestamp_us", "Q", unit="us", doc="board time of the sample"),
    FieldSpec("encoder", "i", unit="count", doc="stage encoder count"),
    FieldSpec("flags", "H", unit="bits", doc="Status bits"),
)
REFERENCE_FIELD = FieldSpec("reference_fm", "I", unit="fm", doc="strain-free reference grating")
FORCE_FIELD = FieldSpec("force_un", "i", unit="uN", doc="force reading")
TIP_FIELD = FieldSpec("tip_fm", "I", unit="fm", doc="tip force grating (revision 1.1)")
CRC_FIELD = FieldSpec("crc", "I", doc="CRC-32/ISO-HDLC of all preceding bytes")

U32_MAX = 2**32 - 1
I32_MIN, I32_MAX = -(2**31), 2**31 - 1
U64_MAX = 2**64 - 1


class FrameError(ValueError):
    """Bytes that are not a valid frame; ``reason`` is one of ``REASONS``."""

    REASONS = ("short", "sync", "header", "crc")

    def __init__(self, reason: str, detail: str) -> None:
        self.reason = reason
        super().__init__(f"{reason}: {detail}")


@dataclass(frozen=True)
class FrameLayout:
    """Which optional fields a stream carries; fixes the frame size and the constant header."""

    n_peaks: int
    has_reference: bool = False
    has_force: bool = False
    has_tip: bool = False

    def __post_init__(self) -> None:
        if not 1 <= self.n_peaks <= MAX_PEAKS:
            raise ValueError(f"n_peaks must be in 1..{MAX_PEAKS}, got {self.n_peaks}")

    @property
    def options(self) -> int:
        return (
            (OPTION_REFERENCE if self.has_reference else 0)
            | (OPTION_FORCE if self.has_force else 0)
            | (OPTION_TIP if self.has_tip else 0)
        )

    @cached_property
    def fields(self) -> tuple[FieldSpec, ...]:
        """Every field in wire order, header to CRC."""
        peaks = FieldSpec("peak_fm", "I", self.n_peaks, "fm", "peak wavelengths")
        optional = (
            (REFERENCE_FIELD,) * self.has_reference
            + (FORCE_FIELD,) * self.has_force
            + (TIP_FIELD,) * self.has_tip
        )
        return (*HEADER, *FIXED_PAYLOAD, peaks, *optional, CRC_FIELD)

    @property
    def payload_size(self) -> int:
        return self.size - HEADER_SIZE - CRC_SIZE

    @cached_property
    def size(self) -> int:
        return sum(f.size for f in self.fields)

    @cached_property
    def header(self) -> bytes:
        """The six constant header bytes of every frame of this layout."""
        return MARKER + bytes([self.n_peaks, self.options, self.payload_size])

    @cached_property
    def struct(self) -> struct.Struct:
        """The whole frame, header to CRC, as one ``struct.Struct``."""
        return struct.Struct("<" + "".join(f"{f.count}{f.code}" for f in self.fields))

    @cached_property
    def dtype(self) -> np.dtype[np.void]:
        """The whole frame as a packed numpy structured dtype (same order as ``fields``)."""
        items: list[tuple[str, str] | tuple[str, str, tuple[int]]] = []
        for f in self.fields:
            base = "<" + {"B": "u1", "H": "u2", "I": "u4", "i": "i4", "Q": "u8"}[f.code]
            items.append((f.name, base, (f.count,)) if f.count > 1 else (f.name, base))
        return np.dtype(items)


@lru_cache(maxsize=256)
def layout_of(
    n_peaks: int, has_reference: bool = False, has_force: bool = False, has_tip: bool = False
) -> FrameLayout:
    """The shared :class:`FrameLayout` instance for these fields, so its cached ``struct`` and
    ``dtype`` are built once per layout rather than once per frame (a frame's ``layout`` is
    asked for on every encode and decode)."""
    return FrameLayout(n_peaks, has_reference, has_force, has_tip)


def parse_header(header: bytes) -> FrameLayout:
    """The layout announced by six header bytes; :class:`FrameError` if impossible."""
    if len(header) < HEADER_SIZE:
        raise FrameError("short", f"need {HEADER_SIZE} header bytes, got {len(header)}")
    if header[:3] != MARKER:
        raise FrameError("sync", f"expected {MARKER.hex()}, got {header[:3].hex()}")
    n, options, length = header[3], header[4], header[5]
    if not 1 <= n <= MAX_PEAKS or options & ~OPTIONS:
        raise FrameError("header", f"n_peaks {n} or options {options:#04x} out of range")
    layout = layout_of(
        n,
        bool(options & OPTION_REFERENCE),
        bool(options & OPTION_FORCE),
        bool(options & OPTION_TIP),
    )
    if length != layout.payload_size:
        raise FrameError("header", f"length {length} impossible for {layout}")
    return layout


class Frame(NamedTuple):
    """One decoded frame, in wire units (see the module docstring); SI via the properties."""

    seq: int
    timestamp_us: int
    encoder: int
    flags: int
    peak_fm: tuple[int, ...]
    reference_fm: int | None = None
    force_un: int | None = None
    tip_fm: int | None = None

    @property
    def layout(self) -> FrameLayout:
        return layout_of(
            len(self.peak_fm),
            self.reference_fm is not None,
            self.force_un is not None,
            self.tip_fm is not None,
        )

    @property
    def time(self) -> float:
        """Board timestamp in s."""
        return self.timestamp_us * US

    @property
    def wavelengths(self) -> NDArray[np.float64]:
        """Peak wavelengths in m, shape (N,)."""
        return np.asarray(self.peak_fm, dtype=np.float64) * FM

    @property
    def reference(self) -> float | None:
        """Reference grating wavelength in m, or None."""
        return None if self.reference_fm is None else self.reference_fm * FM

    @property
    def force(self) -> float | None:
        """Force in N, or None."""
        return None if self.force_un is None else self.force_un * UN

    @property
    def tip(self) -> float | None:
        """Tip force grating's wavelength in m, or None."""
        return None if self.tip_fm is None else self.tip_fm * FM

    @property
    def status(self) -> Status:
        return Status(self.flags)


def to_fm(wavelength: float) -> int:
    """A wavelength in m as the wire's femtometre count (rounded); ValueError if out of u32."""
    fm = round(wavelength / FM)
    if not 0 <= fm <= U32_MAX:
        raise ValueError(f"wavelength {wavelength} m is outside 0..{U32_MAX} fm")
    return fm


def to_un(force: float) -> int:
    """A force in N as the wire's micronewton count (rounded); ValueError if out of i32."""
    un = round(force / UN)
    if not I32_MIN <= un <= I32_MAX:
        raise ValueError(f"force {force} N is outside the i32 micronewton range")
    return un


def frame_from_si(
    seq: int,
    time: float,
    encoder: int,
    wavelengths: NDArray[np.float64] | tuple[float, ...] | list[float],
    *,
    reference: float | None = None,
    force: float | None = None,
    flags: int = 0,
    tip: float | None = None,
) -> Frame:
    """Build a frame from SI values (time in s, wavelengths in m, force in N)."""
    return Frame(
        seq=seq % (U32_MAX + 1),
        timestamp_us=round(time / US),
        encoder=int(encoder),
        flags=int(flags),
        peak_fm=tuple(to_fm(float(w)) for w in wavelengths),
        reference_fm=None if reference is None else to_fm(reference),
        force_un=None if force is None else to_un(force),
        tip_fm=None if tip is None else to_fm(tip),
    )


def check_ranges(frame: Frame) -> None:
    """ValueError if a field of ``frame`` does not fit its type (what :func:`encode` checks)."""
    checks = (
        ("seq", frame.seq, 0, U32_MAX),
        ("timestamp_us", frame.timestamp_us, 0, U64_MAX),
        ("encoder", frame.encoder, I32_MIN, I32_MAX),
        ("flags", frame.flags, 0, 0xFFFF),
        ("reference_fm", frame.reference_fm or 0, 0, U32_MAX),
        ("force_un", frame.force_un or 0, I32_MIN, I32_MAX),
        ("tip_fm", frame.tip_fm or 0, 0, U32_MAX),
        *(("peak_fm", p, 0, U32_MAX) for p in frame.peak_fm),
    )
    for name, value, lo, hi in checks:
        if not lo <= value <= hi:
            raise ValueError(f"{name} = {value} is outside {lo}..{hi}")


def encode(frame: Frame) -> bytes:
    """The bytes of one frame, CRC included; ValueError if a field does not fit its type."""
    layout = frame.layout
    check_ranges(frame)
    optional = (
        (frame.reference_fm,) * layout.has_reference
        + (frame.force_un,) * layout.has_force
        + (frame.tip_fm,) * layout.has_tip
    )
    body = layout.struct.pack(
        *layout.header,
        frame.seq,
        frame.timestamp_us,
        frame.encoder,
        frame.flags,
        *frame.peak_fm,
        *optional,
        0,
    )[:-CRC_SIZE]
    return body + zlib.crc32(body).to_bytes(CRC_SIZE, "little")


def unpack(layout: FrameLayout, values: tuple[int, ...]) -> Frame:
    """A :class:`Frame` from the flat tuple ``layout.struct.unpack`` returns."""
    n = layout.n_peaks
    end = 10 + n
    ref = values[end] if layout.has_reference else None
    force = values[end + layout.has_reference] if layout.has_force else None
    tip = values[end + layout.has_reference + layout.has_force] if layout.has_tip else None
    return Frame(values[6], values[7], values[8], values[9], values[10:end], ref, force, tip)


def decode(data: bytes | bytearray | memoryview, layout: FrameLayout | None = None) -> Frame:
    """Decode one frame starting at ``data[0]``; trailing bytes are ignored.

    With ``layout`` given, a frame of another layout is rejected (reason ``"header"``).
    Raises :class:`FrameError` (a ``ValueError``) naming the first check that failed.
    """
    found = parse_header(bytes(data[:HEADER_SIZE]))
    if layout is not None and found != layout:
        raise FrameError("header", f"frame has {found}, expected {layout}")
    if len(data) < found.size:
        raise FrameError("short", f"need {found.size} bytes, got {len(data)}")
    values = found.struct.unpack_from(data, 0)
    crc = zlib.crc32(data[: found.size - CRC_SIZE])
    if crc != values[-1]:
        raise FrameError("crc", f"computed {crc:#010x}, frame says {values[-1]:#010x}")
    return unpack(found, values)


# ---------------------------------------------------------------------------------------------
# Vectorised blocks

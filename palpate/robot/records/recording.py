"""MCAP recordings of trials, beside the JSON Lines log (which stays the replay source).

A :class:`McapRecorder` takes every record its trial log writes (``robot.records.log``) and
writes its ROS 2 messages (``robot.records.ros2``) to ``<log>.mcap`` as the trial runs. The file
is chunked and indexed, as rosbag2 writes MCAP, so tools that read by index (Rerun, rosbag2's
MCAP storage, Foxglove) open it: each chunk zstd-compressed with its message indexes behind
it, and MCAP's summary (chunk indexes, statistics, channels) at the close. A chunk ends when
the log flushes (every record that is not a sample, every 0.1 s of samples), so a crash keeps
what the JSON log keeps: a killed trial's file reads up to its last whole chunk. The header's
fields are the recording's metadata ``palpate.trial`` (its keys, values as JSON). When
the trial ends the tip force is derived from every sample's strains (the estimator's beam
states, ``estimation.trial.states``) and written as ``/tip/wrench``, and on the robot each sample's
tip pose as ``/tf``.

:func:`robot.records.export.export` converts an existing log; :func:`read_recording` reads one
back without ROS,
through ``mcap``'s stream reader and ``mcap-ros2-support``'s CDR decoder, up to where a killed
trial's file ends.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, Any, NamedTuple

from mcap.exceptions import EndOfFile, McapError  # type: ignore[import-untyped,unused-ignore]
from mcap.records import Channel, Message, Schema  # type: ignore[import-untyped,unused-ignore]
from mcap.stream_reader import StreamReader  # type: ignore[import-untyped,unused-ignore]
from mcap.well_known import MessageEncoding, SchemaEncoding  # type: ignore[import-untyped,unused-ignore]
from mcap.writer import CompressionType, Writer  # type: ignore[import-untyped,unused-ignore]
from mcap_ros2._dynamic import serialize_dynamic  # type: ignore[import-untyped,unused-ignore]
from mcap_ros2.decoder import DecoderFactory  # type: ignore[import-untyped,unused-ignore]

from ...config.loader import from_mapping
from ...config.schema import TubeConfig
from . import cdr
from .ros2 import (
    SCHEMAS,
    TOPICS,
    messages,
    nanoseconds,
    sample_messages,
    tip_transforms,
    wrench,
)

LIBRARY = "palpate"
CHUNK_BYTES = 1 << 20  # a chunk's most (uncompressed): the log's flushes end chunks long before


class Sample(NamedTuple):
    """A sample as the recorder keeps it for what it derives when the trial ends: its stamp
    (ns), stage advance (m) and roll (rad) (NaN where not measured), its strains, and the tip
    grating's load (N; NaN without one)."""

    stamp: int
    advance: float
    roll: float
    strains: list[Any]
    tip_force: float = math.nan


class McapRecorder:
    """One trial's MCAP recording (see the module docstring): ``write`` each log record with
    its JSON line, ``close`` at the end (idempotent)."""

    def __init__(self, path: str | Path, header: dict[str, Any]) -> None:
        self.path = Path(path)
        self._fh: IO[bytes] | None = open(self.path, "wb")  # noqa: SIM115
        self._writer = Writer(self._fh, chunk_size=CHUNK_BYTES, compression=CompressionType.ZSTD)
        self._writer.start(profile="ros2", library=LIBRARY)
        self._writer.add_metadata("palpate.trial", _metadata(header))
        self._channels: dict[str, int] = {}
        self._encoders: dict[str, Callable[[Any], bytes]] = {}
        self._last_ns = 0
        self.samples: list[Sample] = []  # what the tip force and pose are derived from
        self.header = header

    def write(self, record: dict[str, Any], line: str) -> None:
        if self._fh is None:
            raise ValueError(f"recording {self.path} is closed")
        if record.get("kind") == "header":
            return
        t = record.get("t")
        if isinstance(t, int | float) and math.isfinite(t):
            self._last_ns = max(self._last_ns, nanoseconds(float(t)))
        if record.get("kind") == "sample":
            for topic, data in sample_messages(record, self._last_ns):
                self._raw(topic, data, self._last_ns)
            advance, roll = _float(record.get("advance")), _float(record.get("roll"))
            strains, tip = record.get("strains") or [], _float(record.get("tip_force"))
            self.samples.append(Sample(self._last_ns, advance, roll, strains, tip))
            return
        for topic, message in messages(record, self._last_ns, line):
            self._raw(topic, self._encoder(topic)(message), self._last_ns)

    def _channel(self, topic: str) -> int:
        channel = self._channels.get(topic)
        if channel is None:
            name = TOPICS[topic]
            schema = self._writer.register_schema(name, SchemaEncoding.ROS2, SCHEMAS[name].encode())
            channel = self._writer.register_channel(topic, MessageEncoding.CDR, schema)
            self._channels[topic] = channel
        return channel

    def _encoder(self, topic: str) -> Callable[[Any], bytes]:
        """The definition-driven CDR encoder of ``topic``'s type (``mcap-ros2-support``)."""
        encoder = self._encoders.get(topic)
        if encoder is None:
            name = TOPICS[topic]
            encoder = self._encoders[topic] = serialize_dynamic(name, SCHEMAS[name])[name]
        return encoder

    def _raw(self, topic: str, data: bytes, stamp: int) -> None:
        """Write one encoded message, logged and published at ``stamp`` (ns)."""
        self._writer.add_message(
            self._channel(topic), log_time=stamp, data=data, publish_time=stamp
        )

    def flush(self) -> None:
        """End the chunk in progress and hand it to the OS (the log calls it when it flushes)."""
        if self._fh is not None:
            self._writer.flush()  # type: ignore[no-untyped-call,unused-ignore]

    def close(self, loads: Callable[[McapRecorder], list[float] | None] | None = None) -> None:
        """Write the derived tip force (``loads``: the axial load per sample, N; None or a
        failure writes none), then MCAP's summary and footer."""
        if self._fh is None:
            return
        try:
            forces = loads(self) if loads is not None else None
            if forces is not None:
                for sample, load in zip(self.samples, forces, strict=True):
                    self._raw(*wrench(sample.stamp, load), sample.stamp)
            self._transforms()
        finally:  # whatever the derived channels did, the file ends with its summary
            self._writer.finish()  # type: ignore[no-untyped-call,unused-ignore]
            self._fh.close()
            self._fh = None

    def _transforms(self) -> None:
        """``/tf`` of every sample of a robot trial (its header names the tube)."""
        tube = _tube(self.header)
        if tube is None:
            return
        for sample in self.samples:
            found = tip_transforms(tube, sample.roll, sample.advance)
            if found is not None:
                self._raw("/tf", cdr.tf_message(sample.stamp, found), sample.stamp)


def _float(value: Any) -> float:
    return float(value) if isinstance(value, int | float) else math.nan


def _tube(header: dict[str, Any]) -> TubeConfig | None:
    """The robot trial's tube from its log header (None on the bench stage or unreadable)."""
    raw = header.get("tube")
    if not isinstance(raw, dict):
        return None
    try:
        return from_mapping(TubeConfig, raw, "<log>", "tube")
    except (TypeError, ValueError):
        return None


def _metadata(header: dict[str, Any]) -> dict[str, str]:
    return {str(k): json.dumps(v, separators=(",", ":"), default=str) for k, v in header.items()}


@dataclass
class Recording:
    """A recording read back: its metadata, each topic's type and decoded messages (with their
    log times, ns), and whether the file was closed (``complete``) or ends mid-way."""

    metadata: dict[str, dict[str, str]] = field(default_factory=dict)
    types: dict[str, str] = field(default_factory=dict)
    schemas: dict[str, str] = field(default_factory=dict)  # type -> its definition text
    messages: dict[str, list[tuple[int, Any]]] = field(default_factory=dict)
    complete: bool = False

    def count(self, topic: str) -> int:
        return len(self.messages.get(topic, []))


def read_recording(path: str | Path) -> Recording:
    """Every message of an MCAP file, decoded without ROS, in file order; a file cut short (a
    killed trial) reads up to its last whole record (``complete`` False)."""
    out = Recording()
    schemas: dict[int, Schema] = {}
    channels: dict[int, Channel] = {}
    decoders: dict[int, Callable[[bytes], Any]] = {}
    factory = DecoderFactory()
    with open(path, "rb") as fh:
        try:
            for record in StreamReader(fh, skip_magic=False).records:
                _take(record, out, schemas, channels, decoders, factory)
        except EndOfFile:  # a file cut short: read up to its last whole record
            out.complete = False
    return out


def _take(
    record: Any,
    out: Recording,
    schemas: dict[int, Schema],
    channels: dict[int, Channel],
    decoders: dict[int, Callable[[bytes], Any]],
    factory: DecoderFactory,
) -> None:
    kind = type(record).__name__
    if isinstance(record, Schema):
        schemas[record.id] = record
        out.schemas[record.name] = record.data.decode()
    elif isinstance(record, Channel):
        channels[record.id] = record
        out.types[record.topic] = schemas[record.schema_id].name
        decoder = factory.decoder_for(record.message_encoding, schemas[record.schema_id])
        if decoder is None:
            raise McapError(f"no decoder for channel {record.topic}")
        decoders[record.id] = decoder
    elif isinstance(record, Message):
        topic = channels[record.channel_id].topic
        out.messages.setdefault(topic, []).append(
            (record.log_time, decoders[record.channel_id](record.data))
        )
    elif kind == "Metadata":
        out.metadata[record.name] = dict(record.metadata)
    elif kind == "Footer":
        out.complete = True

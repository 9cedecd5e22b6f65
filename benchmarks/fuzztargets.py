"""Fuzzing: every parser of outside bytes or text, fed random and mutated inputs.

Targets, each a function of one input that raises :class:`FuzzFailureError` (or anything else) when
the code under test misbehaves:

- ``frame parser``: :class:`sensor.parser.FrameParser` on valid frames mixed with garbage, bit
  flips and cuts, fed in random chunks; it must never raise, must find every intact frame, and
  must account for every byte (``bytes_received == frames * size + discarded + pending``);
  :func:`wire.frame.decode` on the same bytes raises only ``FrameError``;
- ``servo packets``: :meth:`sim.dynamixel.bus.EmulatedBus.handle` on random and mutated
  Protocol 2.0 packets; it must never raise, and every reply must be a well-formed status packet;
- ``driver replies``: :class:`robot.dynamixel.driver.DynamixelBus` (the real dynamixel-sdk)
  over the in-process port, its replies replaced by random, mutated or well-formed but wrong
  status packets; every call returns or raises ``ServoTransportError`` / ``ServoFaultError``;
- ``config``: random and mutated YAML text through :func:`config.loader.read_yaml` and
  :func:`config.loader.from_mapping` (robot and scene schemas); only ``ConfigError`` comes out.

The config target lives in :mod:`benchmarks.fuzzconfig`; :func:`targets` gathers all four.
The tests in ``tests/fuzz`` drive the same targets from Hypothesis (seeded, bounded); the bench
section :mod:`benchmarks.fuzz` runs them long on a seeded numpy generator.
"""

from __future__ import annotations

import contextlib
import itertools
import math
from collections.abc import Callable
from pathlib import Path

import numpy as np
import yaml

from benchmarks.fuzzconfig import (
    SCHEMAS,
    config_mapping_case,
    config_text_case,
    default_mapping,
    mutate_mapping,
    mutate_text,
    plain,
)
from palpate.robot.dynamixel.driver import DynamixelBus
from palpate.robot.dynamixel.roster import Motor
from palpate.robot.motors import ServoFaultError, ServoTransportError
from palpate.sensor.parser import FrameParser
from palpate.sim.dynamixel import protocol
from palpate.sim.dynamixel.faults import FaultyBus
from palpate.sim.dynamixel.servo import EmulatedServo
from palpate.sim.inprocess import InProcessPort
from palpate.wire.frame import Frame, FrameError, FrameLayout, decode, encode, layout_of

Rng = np.random.Generator


class FuzzFailureError(AssertionError):
    """The code under test broke an invariant on a fuzz input."""


def _require(ok: bool, what: str) -> None:
    if not ok:
        raise FuzzFailureError(what)


# -- frame parser ----------------------------------------------------------------------------

LAYOUTS: tuple[FrameLayout, ...] = (layout_of(3), layout_of(5, True, True), layout_of(1))


def sample_frame(layout: FrameLayout, seq: int, rng: Rng) -> bytes:
    n = layout.n_peaks
    frame = Frame(
        seq % 2**32,
        int(rng.integers(0, 2**63)),
        int(rng.integers(-(2**31), 2**31)),
        int(rng.integers(0, 2**16)),
        tuple(int(x) for x in rng.integers(0, 2**32, size=n)),
        int(rng.integers(0, 2**32)) if layout.has_reference else None,
        int(rng.integers(-(2**31), 2**31)) if layout.has_force else None,
    )
    return encode(frame)


def frame_stream(rng: Rng, layout: FrameLayout, frames: int) -> tuple[bytes, int]:
    """Frames with garbage, bit flips and cuts between them; returns (bytes, intact frames)."""
    out = bytearray()
    intact = 0
    for seq in range(frames):
        data = bytearray(sample_frame(layout, seq, rng))
        r = rng.random()
        if r < 0.15:
            out += rng.integers(0, 256, size=int(rng.integers(1, 40)), dtype=np.uint8).tobytes()
        r = rng.random()
        if r < 0.1:
            bit = int(rng.integers(len(data) * 8))
            data[bit // 8] ^= 1 << (bit % 8)
        elif r < 0.2:
            del data[int(rng.integers(1, len(data))) :]
        else:
            intact += 1
        out += data
    return bytes(out), intact


def split(data: bytes, rng: Rng, pieces: int) -> list[bytes]:
    cuts = sorted(int(x) for x in rng.integers(0, len(data) + 1, size=max(0, pieces - 1)))
    bounds = [0, *cuts, len(data)]
    return [data[a:b] for a, b in itertools.pairwise(bounds)]


def frame_parser_case(layout: FrameLayout, chunks: list[bytes], at_least: int = 0) -> int:
    """Feed ``chunks``; check byte accounting, CRCs, and that at least ``at_least`` frames came
    out (intact frames can only be lost when garbage just before them forms a sync prefix, so
    callers pass a lower bound). Also decodes each chunk with the one-shot codec. Returns the
    number of frames found."""
    parser = FrameParser(layout)
    found: list[Frame] = []
    for chunk in chunks:
        found += parser.feed(chunk)
        with contextlib.suppress(FrameError):
            decode(chunk, layout)
    c = parser.counters
    _require(
        c.bytes_received == c.frames * layout.size + c.bytes_discarded + parser.pending,
        f"byte accounting broken: {c.as_dict()} pending {parser.pending}",
    )
    _require(c.frames == len(found), "frame counter differs from frames returned")
    for f in found:
        _require(f.layout == layout, "frame of another layout")
        _require(decode(encode(f), layout) == f, "a returned frame does not round-trip")
    _require(len(found) >= at_least, f"found {len(found)} frames, expected >= {at_least}")
    return len(found)


def _frame_input(rng: Rng) -> tuple[FrameLayout, list[bytes], int]:
    layout = LAYOUTS[int(rng.integers(len(LAYOUTS)))]
    if rng.random() < 0.2:  # pure noise
        data = rng.integers(0, 256, size=int(rng.integers(0, 400)), dtype=np.uint8).tobytes()
        return layout, split(data, rng, int(rng.integers(1, 5))), 0
    data, _ = frame_stream(rng, layout, int(rng.integers(1, 8)))
    return layout, split(data, rng, int(rng.integers(1, 6))), 0


# -- servo emulator packets ------------------------------------------------------------------

_INSTRUCTIONS = (
    protocol.INST_PING, protocol.INST_READ, protocol.INST_WRITE, protocol.INST_REG_WRITE,
    protocol.INST_ACTION, protocol.INST_FACTORY_RESET, protocol.INST_REBOOT, protocol.INST_CLEAR,
    protocol.INST_SYNC_READ, protocol.INST_SYNC_WRITE, protocol.INST_BULK_READ,
    protocol.INST_BULK_WRITE, protocol.INST_FAST_SYNC_READ, protocol.INST_STATUS,
)  # fmt: skip


def servo_bus() -> FaultyBus:
    """A fresh bus of three servos (ids 1-3) with no clock (it runs on wall time)."""
    return FaultyBus([EmulatedServo(1), EmulatedServo(2), EmulatedServo(3, "XL430-W250")])


def servo_packet_case(bus: FaultyBus, data: bytes) -> int:
    """Feed ``data``; every reply must split into well-formed status packets. Returns their
    number."""
    reply = bus.handle(data)
    reader = protocol.PacketReader()
    packets = reader.feed(reply)
    consumed = sum(len(protocol.encode_status(p.servo_id, p.error, p.params))
                   for p in packets if isinstance(p, protocol.Packet))  # fmt: skip
    for p in packets:
        _require(isinstance(p, protocol.Packet), f"reply with a bad CRC: {reply.hex()}")
        _require(isinstance(p, protocol.Packet) and p.is_status, "reply is not a status packet")
    _require(consumed == len(reply), f"reply has stray bytes: {reply.hex()}")
    return len(packets)


def random_packet(rng: Rng) -> bytes:
    """A well-framed packet with a random id, instruction and parameters, maybe mutated."""
    servo_id = int(rng.choice([1, 2, 3, 0xFE, int(rng.integers(0, 256))]))
    inst = int(rng.choice(_INSTRUCTIONS)) if rng.random() < 0.9 else int(rng.integers(0, 256))
    n = int(rng.integers(0, 16))
    params = bytearray(rng.integers(0, 256, size=n, dtype=np.uint8).tobytes())
    if n >= 2 and rng.random() < 0.7:  # plausible addresses and lengths
        params[0] = int(rng.integers(0, 150))
        params[1] = 0
    if n >= 4 and rng.random() < 0.5:
        params[2] = int(rng.integers(0, 10))
        params[3] = 0
    raw = bytearray(protocol.encode(servo_id, inst, bytes(params)))
    r = rng.random()
    if r < 0.1:
        raw[int(rng.integers(len(raw)))] ^= int(rng.integers(1, 256))
    elif r < 0.15:
        del raw[int(rng.integers(1, len(raw))) :]
    return bytes(raw)


def _servo_input(rng: Rng) -> bytes:
    if rng.random() < 0.1:
        return rng.integers(0, 256, size=int(rng.integers(0, 64)), dtype=np.uint8).tobytes()
    return b"".join(random_packet(rng) for _ in range(int(rng.integers(1, 4))))


# -- driver reply handling -------------------------------------------------------------------

DRIVER_OPS: tuple[str, ...] = (
    "read_state", "write_goals", "ping", "read_item", "write_item", "hardware_error",
    "set_torque", "reboot",
)  # fmt: skip


def connected_driver() -> tuple[DynamixelBus, FaultyBus]:
    """A driver on the in-process port of a fresh emulated bus, connected, torque on."""
    bus = servo_bus()
    port = InProcessPort(bus)
    port.reply_timeout_ms = 0.0  # a missing reply is known at once in-process
    motors = [Motor("a", 1, "XM430-W350"), Motor("b", 2, "XM430-W350"),
              Motor("c", 3, "XL430-W250")]  # fmt: skip
    driver = DynamixelBus(port, motors, retries=1)
    driver.connect()
    driver.set_torque(True)
    return driver, bus


def driver_reply_case(
    driver: DynamixelBus, bus: FaultyBus, op: str, replies: Callable[[bytes], bytes]
) -> str:
    """Run one driver operation with the servos' replies replaced by ``replies(real)``.
    Returns "ok", "transport" or "fault"; anything else propagates (a failure)."""
    bus.reply_filter = replies
    try:
        if op == "read_state":
            state = driver.read_state()
            for s in state.values():
                _require(math.isfinite(s.position), "non-finite position")
        elif op == "write_goals":
            driver.write_goals({"a": 0.01, "c": -0.01})
        elif op == "ping":
            driver.ping("b")
        elif op == "read_item":
            driver.read_item("c", "Present_Position")
        elif op == "write_item":
            driver.write_item("a", "Profile_Velocity", 100)
        elif op == "hardware_error":
            driver.read_hardware_error("a")
        elif op == "set_torque":
            driver.set_torque(True)
        elif op == "reboot":
            driver.reboot("b")
        else:
            raise ValueError(f"unknown driver op {op!r}")
    except ServoTransportError:
        return "transport"
    except ServoFaultError:
        return "fault"
    except RuntimeError as exc:  # write_goals before torque: a usage error, not a reply one
        if "torque on" not in str(exc):
            raise
        return "fault"
    finally:
        bus.reply_filter = None
    return "ok"


def reply_mutator(rng: Rng) -> Callable[[bytes], bytes]:
    """Replace a reply by noise, a mutated copy, or well-formed status packets with random
    ids, error bytes and parameters (CRC valid: the hardest for the driver)."""
    kind = rng.random()
    seed = int(rng.integers(2**32))

    def mutate(real: bytes) -> bytes:
        r = np.random.default_rng(seed)
        if kind < 0.2:
            return r.integers(0, 256, size=int(r.integers(0, 40)), dtype=np.uint8).tobytes()
        if kind < 0.5 and real:
            raw = bytearray(real)
            for _ in range(int(r.integers(1, 4))):
                raw[int(r.integers(len(raw)))] ^= int(r.integers(1, 256))
            return bytes(raw)
        out = b""
        for _ in range(int(r.integers(0, 4))):
            sid = int(r.choice([1, 2, 3, int(r.integers(0, 256))]))
            err = int(r.choice([0, 0, 0x80, int(r.integers(0, 256))]))
            params = r.integers(0, 256, size=int(r.integers(0, 16)), dtype=np.uint8).tobytes()
            out += protocol.encode_status(sid, err, params)
        return out

    return mutate


def targets(tmp: Path) -> dict[str, Callable[[Rng], object]]:
    """One callable per parser: draws an input from the generator and checks it."""
    bus = servo_bus()
    driver, dbus = connected_driver()
    cfg_path = tmp / "fuzz.yaml"
    texts = [yaml.safe_dump(plain(default_mapping(c))) for c in SCHEMAS]
    mappings = [default_mapping(c) for c in SCHEMAS]

    def frames(rng: Rng) -> object:
        return frame_parser_case(*_frame_input(rng))

    def servo(rng: Rng) -> object:
        return servo_packet_case(bus, _servo_input(rng))

    def replies(rng: Rng) -> object:
        op = DRIVER_OPS[int(rng.integers(len(DRIVER_OPS)))]
        return driver_reply_case(driver, dbus, op, reply_mutator(rng))

    def config(rng: Rng) -> object:
        i = int(rng.integers(len(SCHEMAS)))
        if rng.random() < 0.5:
            return config_mapping_case(SCHEMAS[i], mutate_mapping(mappings[i], rng))
        return config_text_case(SCHEMAS[i], mutate_text(texts[i], rng), cfg_path)

    return {
        "frame parser": frames,
        "servo packets": servo,
        "driver replies": replies,
        "config loader": config,
    }

"""Fault injection on the emulators and the ground truth the judge reads.

:class:`FaultInjector` satisfies ``palpate.simulation.trial.EmulatorHook``: it builds the trial's
servo bus (a :class:`sim.dynamixel.faults.FaultyBus`), moves the tissue when a case says it is
closer than planned, fires the case's faults on the virtual clock (at the start or at first touch,
after a delay), and records what the emulators and the world saw (:class:`GroundTruth`), never what
the controller believes. For a killed case it writes that truth to a black box and SIGKILLs its own
process.
"""

from __future__ import annotations

import dataclasses
import json
import math
import os
import signal
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from palpate.config.faults import FaultCase
from palpate.config.schema import ServoBusConfig
from palpate.robot.records.log import TrialLogWriter
from palpate.sim.board import BoardEmulator, BoardFaults
from palpate.sim.clock import VirtualClock
from palpate.sim.dynamixel.bus import EmulatedBus
from palpate.sim.dynamixel.faults import FaultyBus, PacketFaults
from palpate.sim.world import Surface, World
from palpate.wire import dynamixel as tables

HARDWARE_ERROR_BITS: dict[str, int] = {
    "input_voltage": tables.HW_INPUT_VOLTAGE,
    "overheating": tables.HW_OVERHEATING,
    "encoder": tables.HW_ENCODER,
    "electrical_shock": tables.HW_ELECTRICAL_SHOCK,
    "overload": tables.HW_OVERLOAD,
}
_SERVO_FIELDS = ("outer_roll", "inner_roll", "translation")


def servo_id(cfg: ServoBusConfig, name: str) -> int:
    return int(getattr(cfg, name).id)


@dataclass
class ServoSnapshot:
    torque: bool
    velocity: float  # ticks/s
    remaining_ticks: int  # |goal - present|
    hardware_error: int


@dataclass
class GroundTruth:
    """What the emulators saw, independent of the controller."""

    fired_at: float | None = None
    contact_at: float | None = None
    max_strain: float = 0.0
    max_past_contact: float = -math.inf
    end_past_contact: float = -math.inf
    end_force: float = 0.0
    servos: dict[str, ServoSnapshot] = field(default_factory=dict)
    translation_blocked: str = ""  # why the stage could not move at the end, if it could not
    link: dict[str, int] = field(default_factory=dict)
    board: dict[str, Any] = field(default_factory=dict)
    records_written: int | None = None  # log lines flushed before a kill


def _snapshot(bus: EmulatedBus, cfg: ServoBusConfig) -> dict[str, ServoSnapshot]:
    out = {}
    for name in _SERVO_FIELDS:
        s = bus.servo(servo_id(cfg, name))
        out[name] = ServoSnapshot(
            torque=s.torque_enabled,
            velocity=s.velocity_ticks_per_s,
            remaining_ticks=abs(s.item("Goal_Position") - s.position_ticks),
            hardware_error=s.hardware_error,
        )
    return out


class FaultInjector:
    """Satisfies ``palpate.simulation.trial.EmulatorHook``: schedules one case's faults on the
    virtual clock and records the ground truth the checks use."""

    def __init__(
        self,
        case: FaultCase,
        servos: ServoBusConfig,
        *,
        seed: int,
        board_faults: BoardFaults | None = None,
        blackbox: Path | None = None,
        ready_after_records: int | None = None,
        ready_fd: int | None = None,
    ) -> None:
        self.case = case
        self.cfg = servos
        self.seed = seed
        self._board_faults = board_faults
        self.blackbox = blackbox
        self.ready_after_records = ready_after_records
        self.ready_fd = ready_fd
        self.truth = GroundTruth()
        self._trigger_at: float | None = None
        self._attached = False
        self._bus: FaultyBus | None = None
        self._board: BoardEmulator | None = None
        self._world: World | None = None
        self._clock: VirtualClock | None = None
        self._log: TrialLogWriter | None = None
        self._muted_until = -math.inf

    # -- EmulatorHook ---------------------------------------------------------------------------
    @property
    def board_faults(self) -> BoardFaults | None:
        return self._board_faults

    def make_bus(self, cfg: ServoBusConfig, clock: VirtualClock) -> EmulatedBus:
        self._bus = FaultyBus.from_config(cfg, clock=clock)
        return self._bus

    def attach(
        self, clock: VirtualClock, bus: EmulatedBus, board: BoardEmulator, world: World
    ) -> None:
        self._clock, self._board, self._world = clock, board, world
        early = self.case.early_contact
        if early:  # the tissue is closer than the plan expects
            s = world.surface
            world.surface = Surface(point=s.point + early * s.normal, normal=s.normal)
        self._attached = True
        if self.case.trigger == "start":
            self._trigger_at = clock.now() + self.case.delay_s
        clock.on_advance(self._on_advance)

    def log_opened(self, log: TrialLogWriter) -> None:
        self._log = log

    def detach(self) -> None:
        """Final ground truth, after the control stack closed its ports."""
        self._attached = False
        if self._bus is None or self._world is None or self._clock is None:
            return
        t = self._clock.now()
        st = self._world.state(t)
        self.truth.end_past_contact = st.past_contact
        self.truth.end_force = st.P
        self.truth.servos = _snapshot(self._bus, self.cfg)
        self.truth.translation_blocked = self._blocked(t)
        self.truth.link = dataclasses.asdict(self._bus.link_stats)
        if self._board is not None:
            stats = dataclasses.asdict(self._board.stats)
            stats.pop("log", None)
            self.truth.board = stats

    # -- the schedule --------------------------------------------------------------------------
    def _on_advance(self, t: float) -> None:
        if not self._attached or self._world is None:
            return
        st = self._world.state(t)
        tr = self.truth
        tr.max_strain = max(tr.max_strain, max((abs(x) for x in st.strains), default=0.0))
        tr.max_past_contact = max(tr.max_past_contact, st.past_contact)
        if tr.contact_at is None and st.past_contact > 0.0:
            tr.contact_at = t
            if self.case.trigger == "contact":
                self._trigger_at = t + self.case.delay_s
        if tr.fired_at is None and self._trigger_at is not None and t >= self._trigger_at:
            tr.fired_at = t
            self._fire(t)
        log = self._log
        ready = self.ready_after_records
        fd = self.ready_fd
        if ready is not None and log is not None and fd is not None and log.records >= ready:
            os.write(fd, b"R")
            self.ready_fd = None

    def _fire(self, t: float) -> None:
        c = self.case
        bus = self._bus
        assert bus is not None  # make_bus ran before attach
        sid = servo_id(self.cfg, c.servo)
        servo = bus.servo(sid)
        if c.servo_timeout_s is not None:
            self._muted_until = t + c.servo_timeout_s
            bus.mute(sid, self._muted_until)
        if c.corrupt_replies:
            servo.corrupt_replies(c.corrupt_replies)
        if c.packet_loss or c.corrupt_probability:
            bus.set_packet_faults(PacketFaults(c.packet_loss, c.corrupt_probability), self.seed)
        bits = 0
        for name in c.hardware_error:
            bits |= HARDWARE_ERROR_BITS[name]
        if bits:
            servo.raise_hardware_error(bits)
        if c.stall:
            servo.set_stalled(True)
        if c.stream_stops and self._board is not None:
            self._board.disconnect()
        if c.kill:
            self._die(t)

    def _blocked(self, t: float) -> str:
        """Why the translation stage cannot move now, from the emulator ('' if it can)."""
        c = self.case
        assert self._bus is not None
        s = self._bus.servo(servo_id(self.cfg, "translation"))
        if c.stall and c.servo == "translation":
            return "stalled"
        if s.hardware_error & s.item("Shutdown"):
            return "shut down by a hardware error"
        if c.servo == "translation" and t < self._muted_until:
            return "not answering"
        return ""

    def _die(self, t: float) -> None:
        """SIGKILL this process, first writing what the emulators know (the black box)."""
        assert self._bus is not None
        assert self._world is not None
        if self.blackbox is not None:
            tr = self.truth
            box = {
                "t": t,
                "records_written": None if self._log is None else self._log.records,
                "max_strain": tr.max_strain,
                "max_past_contact": tr.max_past_contact,
                "servos": {
                    k: dataclasses.asdict(v) for k, v in _snapshot(self._bus, self.cfg).items()
                },
            }
            self.blackbox.write_text(json.dumps(box), encoding="utf-8")
        os.kill(os.getpid(), signal.SIGKILL)

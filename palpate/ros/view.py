"""The node's topics: what a trial's ticks and a survey's maps publish (``palpate.live.View``, the
interface the live view has too), built as ROS 2 messages with rclpy's generated types.

A trial publishes every tick its state when it changes, and at ``rate`` per second of the
trial's clock the joints, the tip's pose and wrench, the strains and the simulator's ``/clock``;
its diagnostics once a second. Stamps are the trial's clock, each trial's starting after the
last one's end, so the node's time never runs back (a simulated trial's clock starts at 0)::

    view = RosView(node, stack, rate=50.0, sim_time=True)
    publish = view.trial(Stage.on(tube, 0.0))     # one trial's publisher
    publish(observation, State.INDENTING)          # each tick (palpate.simulation.trial)
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from builtin_interfaces.msg import Time
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from geometry_msgs.msg import PoseStamped, WrenchStamped
from numpy.typing import NDArray
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState, PointCloud2, PointField
from std_msgs.msg import Float64MultiArray, MultiArrayDimension, String
from transforms3d.quaternions import rotate_vector

from palpate.config.schema import StackConfig
from palpate.estimation.beam.section import sensor_section
from palpate.estimation.beam.stage import Stage
from palpate.live import Publisher, beam_reading
from palpate.robot.guards import Observation
from palpate.robot.indentation import State
from palpate.robot.records.ros2 import JOINTS, nanoseconds, tip_transforms
from palpate.wire.frame import Frame

from .names import grating_labels, peak_labels

DEPTH = 100  # the streams' history: a subscriber a little behind the simulator loses nothing
DIAGNOSTICS_PERIOD = 1.0  # s of the trial's clock
LATCHED = QoSProfile(depth=10, durability=DurabilityPolicy.TRANSIENT_LOCAL)


def stamp(t: float) -> Time:
    """Seconds (>= 0) as a ``builtin_interfaces/Time``."""
    sec, nanosec = divmod(nanoseconds(t), 1_000_000_000)
    return Time(sec=sec, nanosec=nanosec)


class RosView:
    """The node's publishers, and the publisher of each trial (:meth:`trial`) and map
    (:meth:`cloud`) on them."""

    def __init__(
        self,
        node: Node,
        stack: StackConfig,
        *,
        rate: float,
        sim_time: bool,
        pace: float | None = None,
    ) -> None:
        if not rate > 0:
            raise ValueError(f"rate must be > 0, got {rate}")
        if pace is not None and not pace > 0:
            raise ValueError(f"pace must be > 0, got {pace}")
        self.node, self.stack, self.period = node, stack, 1.0 / rate
        self.pace = pace  # trial seconds per wall second; None: as fast as the trial computes
        self.section = sensor_section(stack.sensor)
        self.elapsed = 0.0  # s: the last stamp published (the next trial starts after it)
        make = node.create_publisher
        self.joints = make(JointState, "measured_js", DEPTH)
        self.pose = make(PoseStamped, "measured_cp", DEPTH)
        self.wrench = make(WrenchStamped, "measured_cf", DEPTH)
        self.strains = make(Float64MultiArray, "fbg/strains", DEPTH)
        self.wavelengths = make(Float64MultiArray, "fbg/wavelengths", DEPTH)
        self.state = make(String, "trial/state", LATCHED)
        self.result = make(String, "trial/result", LATCHED)
        self.diagnostics = make(DiagnosticArray, "/diagnostics", 10)
        self.clock = make(Clock, "/clock", DEPTH) if sim_time else None
        self.clouds = {
            "/map/probes": make(PointCloud2, "map/probes", LATCHED),
            "/map/grid": make(PointCloud2, "map/grid", LATCHED),
        }

    def trial(self, stage: Stage) -> Publisher:
        """The publisher of one trial on ``stage`` (its clock's 0 placed after the last stamp)."""
        return _Feed(self, stage, self.elapsed + self.period).publish

    def cloud(
        self,
        topic: str,
        stamp_ns: int,
        names: Sequence[str],
        columns: Sequence[NDArray[np.float64]],
    ) -> None:
        """A survey's map or probes as a ``sensor_msgs/PointCloud2`` of float64 fields (x and y
        first, m) in the patch's frame ``sample``, stamped ``stamp_ns`` (the lab's time)."""
        data = np.column_stack(columns).astype("<f8")
        fields = [
            PointField(name=n, offset=8 * k, datatype=PointField.FLOAT64, count=1)
            for k, n in enumerate(names)
        ]
        message = PointCloud2(height=1, width=len(data), fields=fields, is_bigendian=False)
        message.header.stamp = stamp(self.elapsed + stamp_ns * 1e-9)
        message.header.frame_id = "sample"
        message.point_step = 8 * len(names)
        message.row_step = message.point_step * len(data)
        message.data = data.tobytes()
        message.is_dense = bool(np.isfinite(data).all())
        self.clouds[topic].publish(message)

    def finished(self, row: str) -> None:
        """A trial's row (JSON) on ``trial/result``."""
        self.result.publish(String(data=row))


@dataclass
class _Feed:
    view: RosView
    stage: Stage
    base: float  # s added to the trial's clock
    state: State | None = None
    due: float = -math.inf  # the trial's clock: the streams' next message
    diagnostics_due: float = -math.inf
    wall_start: float | None = None  # monotonic s at the trial's 0, when paced

    def publish(self, obs: Observation, state: State) -> None:
        v = self.view
        t = self.base + obs.t
        if v.pace is not None:
            self._keep_pace(obs.t, v.pace)
        v.elapsed = max(v.elapsed, t)
        if state is not self.state:
            self.state = state
            v.state.publish(String(data=state.value))
        if obs.t >= self.diagnostics_due:
            self.diagnostics_due = obs.t + DIAGNOSTICS_PERIOD
            v.diagnostics.publish(_diagnostics(obs, t))
        if obs.t < self.due:
            return
        # the next one a period on (the average rate is the rate, whatever the control rate)
        gap = obs.t - self.due
        self.due = (self.due if gap < v.period else obs.t) + v.period
        self._streams(obs, t)

    def _keep_pace(self, t: float, pace: float) -> None:
        """Wait until the wall clock has caught up with the trial's ``t`` (s) at ``pace``."""
        now = time.monotonic()
        if self.wall_start is None:
            self.wall_start = now - t / pace
        ahead = self.wall_start + t / pace - now
        if ahead > 0.0:
            time.sleep(ahead)

    def _streams(self, obs: Observation, t: float) -> None:
        v, now = self.view, stamp(t)
        if v.clock is not None:
            v.clock.publish(Clock(clock=now))
        joints = JointState(name=list(JOINTS), position=[obs.advance, obs.roll])
        joints.header.stamp, joints.header.frame_id = now, "stage"
        v.joints.publish(joints)
        v.strains.publish(_array([float(s) for s in obs.strains], grating_labels(len(obs.strains))))
        if obs.frame is not None:
            v.wavelengths.publish(_wavelengths(obs.frame))
        if not (math.isfinite(obs.advance) and math.isfinite(obs.roll)):
            return
        length = self.stage.exposed_length(obs.advance)
        load, _ = beam_reading(v.stack.sensor, v.section, obs.strains, length)
        if obs.tip_force is not None:  # a tip force grating reads the load itself
            load = obs.tip_force
        wrench = WrenchStamped()
        wrench.header.stamp, wrench.header.frame_id = now, "sensor_tip"
        wrench.wrench.force.z = -load if math.isfinite(load) else math.nan
        v.wrench.publish(wrench)
        v.pose.publish(self._pose(obs, length, now))

    def _pose(self, obs: Observation, length: float, now: Time) -> PoseStamped:
        """The sensor tip: on a tube its forward kinematics with the beam straight along the
        tip's tangent; on the bench stage, ``length`` along the stage's axis."""
        pose = PoseStamped()
        pose.header.stamp = now
        tube = self.stage.tube
        known = None if tube is None else tip_transforms(tube, obs.roll, obs.advance)
        if known is None:
            pose.header.frame_id = "stage"
            pose.pose.position.x = length
            pose.pose.orientation.w = 1.0
            return pose
        (_, _, tip, (x, y, z, w)), (_, _, along, _) = known
        at = np.asarray(tip) + rotate_vector(np.asarray(along, dtype=float), (w, x, y, z))
        pose.header.frame_id = "base"
        p, q = pose.pose.position, pose.pose.orientation
        p.x, p.y, p.z = (float(c) for c in at)
        q.x, q.y, q.z, q.w = x, y, z, w
        return pose


def _array(data: list[float], labels: list[str]) -> Float64MultiArray:
    """A one-dimensional array whose dimension's label lists its entries' names."""
    message = Float64MultiArray(data=data)
    n = len(data)
    message.layout.dim = [MultiArrayDimension(label=",".join(labels), size=n, stride=n)]
    return message


def _wavelengths(frame: Frame) -> Float64MultiArray:
    """A frame's peak wavelengths (m), every grating the board reports, its reference last."""
    peaks = [float(w) for w in frame.wavelengths]
    labels = peak_labels(len(peaks))
    if frame.reference is not None:
        peaks.append(frame.reference)
        labels.append("reference")
    return _array(peaks, labels)


def _diagnostics(obs: Observation, t: float) -> DiagnosticArray:
    """The servo bus's and the FBG stream's health at one tick."""
    ok, warn, error = DiagnosticStatus.OK, DiagnosticStatus.WARN, DiagnosticStatus.ERROR
    if obs.servo_fault is not None:
        bus = (error, f"servo fault: {obs.servo_fault}")
    elif obs.bus_lost:
        bus = (error, "servo bus lost")
    else:
        bus = (ok, "replying")
    stream_age = float(obs.stream_age)
    stream = (ok, "streaming") if stream_age < 0.05 else (warn, f"no frame for {stream_age:.3f} s")
    array = DiagnosticArray()
    array.header.stamp = stamp(t)
    array.status = [
        _status("palpate: servo bus", bus, {"joints_age_s": f"{obs.joints_age:.4f}"}),
        _status("palpate: FBG stream", stream, {"stream_age_s": f"{stream_age:.4f}"}),
    ]
    return array


def _status(name: str, level: tuple[bytes, str], values: dict[str, str]) -> DiagnosticStatus:
    return DiagnosticStatus(
        level=level[0],
        name=name,
        message=level[1],
        hardware_id="palpate",
        values=[KeyValue(key=k, value=v) for k, v in values.items()],
    )


__all__ = ["RosView", "stamp"]

"""The live view: a trial's channels on a local Foxglove websocket while the robot moves.

``--live [PORT]`` on ``palpate sim`` (one trial at a time), ``palpate trial`` and ``palpate
teleop`` starts ``foxglove-sdk``'s websocket server on 127.0.0.1 (only: the bench's data does
not leave the machine) and PORT (8765 by default; 0 takes a free one, printed); Foxglove
connects to ``ws://127.0.0.1:PORT``. Off unless asked; the server stops when the command ends.

Channels, published at most ``PUBLISH_HZ`` (the geometry ``SCENE_HZ``) times a second of wall
time (the simulator runs faster than real time; a person watches at the screen's pace), and
only while a client listens:

- ``/joint_states`` and ``/fbg/strains`` (JSON): the stage translation and roll, the state, the
  used gratings' strains, the contact event, the ventilator's breath hold (frame status bit 6);
- ``/tip/force`` (JSON): the axial load and the beam's end shortening from the strains (the
  estimator's beam state of that tick, ``estimation.beam.states``); the load is the tip force
  grating's where the sensor has one;
- ``/tf`` (``foxglove.FrameTransforms``): ``base`` -> ``tube_tip`` -> ``sensor_tip`` from the
  tube's forward kinematics (``robot.kinematics``);
- ``/scene`` (``foxglove.SceneUpdate``): the tube's centreline (straight part and arc) and the
  sensor beam, bent as the elastica at the tick's end shortening (``estimation.beam.elastica``), in
  the tube's bend plane (the gratings' own plane is not measured: a drawing, not a fit);
- on ``palpate map --live``, after each probe: ``/map/grid`` and ``/map/probes``
  (``foxglove.PointCloud``, frame ``sample``): the map over the patch (modulus, sd of log E,
  P(above)) and the probes so far, the fields docs/maps.md lists for the recording.
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import logging
import math
import time
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np
from numpy.typing import NDArray

from palpate.argtypes import port_number
from palpate.config.loader import InputError
from palpate.config.schema import SensorConfig, StackConfig, TubeConfig
from palpate.estimation.beam.elastica import post_buckling
from palpate.estimation.beam.section import Section, grating_intervals, sensor_section
from palpate.estimation.beam.stage import Stage
from palpate.estimation.beam.states import infer_states
from palpate.robot.guards import Observation
from palpate.robot.indentation import State
from palpate.robot.kinematics import forward
from palpate.robot.records.cdr import Transform
from palpate.robot.records.ros2 import tip_transforms

log = logging.getLogger(__name__)

DEFAULT_PORT = 8765
HOST = "127.0.0.1"
PUBLISH_HZ = 15.0  # the plain channels (joints, strains, force)
SCENE_HZ = 5.0  # the geometry (transforms, the tube and the bent beam: an elastica each)
BEAM_POINTS = 24
TOPICS = ("/joint_states", "/fbg/strains", "/tip/force", "/tf", "/scene")
Publisher = Callable[[Observation, State], None]
FloatArray = NDArray[np.float64]


class View(Protocol):
    """What a trial publishes its ticks to: the live view here, or the ROS 2 node's topics
    (``palpate.ros``)."""

    def trial(self, stage: Stage) -> Publisher:
        """The publisher of one trial on ``stage``."""
        ...

    def cloud(
        self, topic: str, stamp: int, names: Sequence[str], columns: Sequence[FloatArray]
    ) -> None:
        """A map's point cloud (columns x, y first, m) at ``stamp`` (ns)."""
        ...


def beam_reading(
    sensor: SensorConfig, section: Section, strains: Sequence[float], length: float
) -> tuple[float, float]:
    """(axial load N, end shortening m) of one tick's strains at exposed ``length`` (the
    estimator's beam state, ``estimation.beam.states``), NaN when they do not fit."""
    if length <= 0 or len(strains) != len(sensor.used_gratings):
        return math.nan, math.nan
    rows = np.asarray([strains], dtype=float)
    if not np.isfinite(rows).all():
        return math.nan, math.nan
    if not np.any(rows):  # exactly at rest (an ideal emulator): no load, no shortening
        return 0.0, 0.0
    intervals = grating_intervals(sensor, length)
    with np.errstate(invalid="ignore", divide="ignore"):
        try:
            s = infer_states(rows, intervals, length, section.EA, section.fiber_offset, 1e-6)
        except ValueError:  # the strains fit no beam state (the elastica refuses them)
            return math.nan, math.nan
    return float(s.P[0]), float(s.e[0])


def add_live_argument(parser: argparse.ArgumentParser, what: str) -> None:
    """``--live [PORT]`` on a command (``what``: what it shows)."""
    parser.add_argument(
        "--live",
        nargs="?",
        const=DEFAULT_PORT,
        type=port_number,
        metavar="PORT",
        help=f"serve {what} to Foxglove on ws://{HOST}:PORT (default {DEFAULT_PORT}; 0: any "
        "free port) while it runs (docs/recordings.md)",
    )


@contextlib.contextmanager
def live_view(port: int | None, stack: StackConfig) -> Iterator[LiveView | None]:
    """The live view on ``port`` for ``stack``'s sensor while the block runs (None without a
    port: off); its address is logged."""
    if port is None:
        yield None
        return
    with LiveView(port, stack.sensor, sensor_section(stack.sensor)) as view:
        log.warning("live view: ws://%s:%d (open it in Foxglove)", HOST, view.port)
        yield view


def _schema(properties: dict[str, str]) -> dict[str, Any]:
    kinds: dict[str, dict[str, Any]] = {
        "number": {"type": "number"},
        "string": {"type": "string"},
        "boolean": {"type": "boolean"},
        "numbers": {"type": "array", "items": {"type": "number"}},
        "gate": {"type": ["boolean", "null"]},  # null: no frame yet
    }
    return {"type": "object", "properties": {k: kinds[v] for k, v in properties.items()}}


class LiveView:
    """The server and its channels (see the module docstring); :meth:`trial` gives each trial
    its publisher, :meth:`close` stops the server (idempotent)."""

    def __init__(self, port: int, sensor: SensorConfig, section: Section) -> None:
        try:  # the live view's own dependency (the [live] extra), loaded only when asked for
            import foxglove
            from foxglove.channels import FrameTransformsChannel, SceneUpdateChannel
        except ImportError:
            raise InputError(
                "--live needs foxglove-sdk: python3 -m pip install -e '.[live]'"
            ) from None

        self._fg = foxglove
        self.context = foxglove.Context()
        try:
            self.server = foxglove.start_server(host=HOST, port=port, context=self.context)
        except Exception as exc:  # the SDK raises its own error for a port it cannot bind
            raise InputError(f"--live: cannot serve on {HOST}:{port}: {exc}") from None
        self.port = int(self.server.port)
        self.sensor, self.section = sensor, section
        ctx = self.context
        self.joints = foxglove.Channel(
            "/joint_states",
            schema=_schema({"stage_translation": "number", "outer_roll": "number"}),
            context=ctx,
        )
        self.strains = foxglove.Channel(
            "/fbg/strains",
            schema=_schema(
                {
                    "state": "string",
                    "strain": "numbers",
                    "contact": "boolean",
                    "breath_hold": "gate",
                }
            ),
            context=ctx,
        )
        self.force = foxglove.Channel(
            "/tip/force",
            schema=_schema({"axial_load": "number", "end_shortening": "number"}),
            context=ctx,
        )
        self.tf = FrameTransformsChannel("/tf", context=ctx)
        self.scene = SceneUpdateChannel("/scene", context=ctx)
        self._clouds: dict[str, Any] = {}  # a map's channels, opened by its first frame
        self._closed = False

    def trial(self, stage: Stage) -> Publisher:
        """The publisher of one trial on ``stage`` (``palpate.estimation.beam.stage``): on the
        bench its
        exposed length is fixed, on a tube it follows the translation."""
        feed = _Feed(self, stage.tube, stage)
        return feed.publish

    def cloud(
        self, topic: str, stamp: int, names: Sequence[str], columns: Sequence[FloatArray]
    ) -> None:
        """Float64 ``columns`` named ``names`` (x and y first, m) as a ``foxglove.PointCloud``
        on ``topic`` at ``stamp`` (ns): ``palpate map --live``'s map and probes, in the
        patch's frame ``sample``."""
        from foxglove.channels import PointCloudChannel
        from foxglove.messages import (
            PackedElementField,
            PackedElementFieldNumericType,
            PointCloud,
            Pose,
            Quaternion,
            Timestamp,
            Vector3,
        )

        channel = self._clouds.get(topic)
        if channel is None:
            channel = self._clouds[topic] = PointCloudChannel(topic, context=self.context)
        f64 = PackedElementFieldNumericType.Float64
        fields = [PackedElementField(name=n, offset=8 * k, type=f64) for k, n in enumerate(names)]
        data = np.column_stack(columns).astype("<f8")
        channel.log(
            PointCloud(
                timestamp=Timestamp(*divmod(stamp, 1_000_000_000)),
                frame_id="sample",
                pose=Pose(
                    position=Vector3(x=0.0, y=0.0, z=0.0),
                    orientation=Quaternion(x=0.0, y=0.0, z=0.0, w=1.0),
                ),
                point_stride=8 * len(names),
                fields=fields,
                data=data.tobytes(),
            )
        )

    def close(self) -> None:
        if not self._closed:
            self._closed = True
            self.server.stop()

    def __enter__(self) -> LiveView:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


@dataclass
class _Feed:
    view: LiveView
    tube: TubeConfig | None
    stage: Stage
    _last: float = -math.inf
    _last_scene: float = -math.inf

    def publish(self, obs: Observation, state: State) -> None:
        now = time.monotonic()
        if now - self._last < 1.0 / PUBLISH_HZ:
            return
        self._last = now
        v = self.view
        stamp = max(round(obs.t * 1e9), 0)
        if v.joints.has_sinks():
            v.joints.log({"stage_translation": obs.advance, "outer_roll": obs.roll}, log_time=stamp)
        if v.strains.has_sinks():
            message = {
                "state": state.value,
                "strain": list(obs.strains),
                "contact": obs.contact,
                "breath_hold": obs.gate,
            }
            v.strains.log(message, log_time=stamp)
        wanted = v.force.has_sinks() or v.tf.has_sinks() or v.scene.has_sinks()
        if not wanted or not all(math.isfinite(x) for x in (obs.advance, obs.roll)):
            return
        length = self._length(obs.advance)
        load, shortening = beam_reading(v.sensor, v.section, obs.strains, length)
        if obs.tip_force is not None:  # a tip force grating reads the load itself
            load = obs.tip_force
        if v.force.has_sinks():
            v.force.log({"axial_load": load, "end_shortening": shortening}, log_time=stamp)
        if now - self._last_scene >= 1.0 / SCENE_HZ:
            self._last_scene = now
            self._geometry(obs, length, shortening, stamp)

    def _length(self, advance: float) -> float:
        return self.stage.exposed_length(advance)

    def _geometry(self, obs: Observation, length: float, shortening: float, stamp: int) -> None:
        from foxglove.messages import FrameTransforms, SceneEntity, SceneUpdate, Timestamp

        v = self.view
        ts = Timestamp(*divmod(stamp, 1_000_000_000))
        tube_points, tip, rotation = _tube(self.tube, obs.roll, obs.advance)
        beam = _beam_points(length, shortening)  # in the tube tip's frame (x along the tangent)
        if v.tf.has_sinks():
            # the recording's transforms (robot.records.ros2), the sensor tip at the bent beam's end
            known = None if self.tube is None else tip_transforms(self.tube, obs.roll, obs.advance)
            identity = (0.0, 0.0, 0.0, 1.0)
            to_tip: Transform = known[0] if known else ("base", "tube_tip", (0, 0, 0), identity)
            end = tuple(float(x) for x in beam[-1])
            frames = [_frame(ts, to_tip), _frame(ts, ("tube_tip", "sensor_tip", end, identity))]
            v.tf.log(FrameTransforms(transforms=frames), log_time=stamp)
        if v.scene.has_sinks():
            world_beam = [tip + rotation @ p for p in beam]
            lines = [
                _line(tube_points, (0.6, 0.6, 0.6), 2.0),
                _line(world_beam, (0.9, 0.3, 0.1), 3.0),
            ]
            entity = SceneEntity(timestamp=ts, frame_id="base", id="robot", lines=lines)
            v.scene.log(SceneUpdate(entities=[entity]), log_time=stamp)


def _frame(ts: Any, transform: Transform) -> Any:
    """A foxglove transform of the recording's (parent, child, xyz, quaternion xyzw)."""
    from foxglove.messages import FrameTransform, Quaternion, Vector3

    parent, child, at, (x, y, z, w) = transform
    return FrameTransform(
        timestamp=ts,
        parent_frame_id=parent,
        child_frame_id=child,
        translation=Vector3(x=float(at[0]), y=float(at[1]), z=float(at[2])),
        rotation=Quaternion(x=x, y=y, z=z, w=w),
    )


def _line(points: list[FloatArray], rgb: tuple[float, float, float], thickness: float) -> Any:
    from foxglove.messages import Color, LinePrimitive, LinePrimitiveLineType, Point3

    return LinePrimitive(
        type=LinePrimitiveLineType.LineStrip,
        thickness=thickness,
        scale_invariant=True,
        color=Color(r=rgb[0], g=rgb[1], b=rgb[2], a=1.0),
        points=[Point3(x=float(p[0]), y=float(p[1]), z=float(p[2])) for p in points],
    )


def _tube(
    tube: TubeConfig | None, roll: float, advance: float
) -> tuple[list[FloatArray], FloatArray, FloatArray]:
    """The tube's centreline points, its tip and its tip frame's rotation in ``base`` (m): the
    forward kinematics of the tube cut short along its arc; on the bench stage (no tube) no
    centreline, the clamp at the origin."""
    if tube is None:
        return [np.zeros(3)], np.zeros(3), np.eye(3)
    points = [np.zeros(3)]
    for u in np.linspace(0.0, 1.0, 12):
        partial = dataclasses.replace(
            tube, tip_angle_deg=u * tube.tip_angle_deg, arc_length_mm=u * tube.arc_length_mm
        )
        points.append(forward(partial, roll, advance).tube_tip)
    pose = forward(tube, roll, advance)
    return points, pose.tube_tip, pose.rotation


def _beam_points(length: float, shortening: float) -> list[FloatArray]:
    """The sensor's centreline in the tube tip's frame (x along the tangent): the elastica at
    e/L (straight below buckling or where the state did not fit)."""
    s = np.linspace(0.0, 1.0, BEAM_POINTS)
    ratio = shortening / length if length > 0 and math.isfinite(shortening) else 0.0
    if not 1e-9 < ratio < 0.5:
        return [np.array([length * u, 0.0, 0.0]) for u in s]
    x, y = post_buckling(np.array([ratio]), "accurate").xy(s)
    return [np.array([length * a, 0.0, length * b]) for a, b in zip(x, y, strict=True)]

"""A survey's map as an MCAP recording (``map.mcap`` in its run folder): the map after every
probe, in ROS 2 messages that Foxglove and RViz draw without a plugin.

Channels, each message stamped with the lab time (s) at which its probe finished:

- ``/map/grid`` (``sensor_msgs/msg/PointCloud2``): the map over the patch once it has
  ``MIN_PROBES`` usable probes: one point per cell of the summary's 41 x 41 grid, fields
  ``x``, ``y``, ``z`` (m; z = 0, the sample's surface), ``modulus_kpa`` (the posterior median),
  ``sd`` (of log E) and ``p_above`` (of the threshold as the map had it then);
- ``/map/probes`` (``sensor_msgs/msg/PointCloud2``): the probes so far, fields ``x``, ``y``,
  ``z``, ``modulus_kpa`` (NaN without a number) and ``order`` (1, 2, ...);
- ``/tf`` (``tf2_msgs/msg/TFMessage``), a map through the robot only, at each probe: ``world``
  -> ``base`` (where the positioner or the bench's gantry put the robot for that probe) and, in
  simulation, ``world`` -> ``sample`` (the patch's plane in the robot's base frame at stage
  zero, so the clouds stand where the tissue is); the trials' own recordings carry ``base`` ->
  ``tube_tip`` -> ``sensor_tip``.

Why point clouds: a standard message every ROS 2 viewer colours by any of its fields (the
modulus, its uncertainty or the probability, chosen in the viewer), on any cell spacing;
``nav_msgs/OccupancyGrid`` would carry one int8 channel on square cells only. Written with the
``mcap`` writer and ``mcap-ros2-support``'s encoder, as the trial recordings are; read back with
``robot.records.recording.read_recording``::

    write_map_recording(result, run_dir / "map.mcap")
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from mcap.well_known import MessageEncoding, SchemaEncoding  # type: ignore[import-untyped,unused-ignore]
from mcap.writer import CompressionType, Writer  # type: ignore[import-untyped,unused-ignore]
from mcap_ros2._dynamic import serialize_dynamic  # type: ignore[import-untyped,unused-ignore]

from palpate.campaigns.survey import SurveyResult
from palpate.maps.region import GRID_FIELDS, PROBE_FIELDS, grid_frame, probe_frame
from palpate.robot.records.cdr import tf_message
from palpate.robot.records.ros2 import HEADER, SCHEMAS, SEP, TIME, TOPICS, header, nanoseconds

CLOUD = "sensor_msgs/msg/PointCloud2"
POINT_FIELD = (
    "MSG: sensor_msgs/PointField\nuint8 INT8=1\nuint8 UINT8=2\nuint8 INT16=3\nuint8 UINT16=4\n"
    "uint8 INT32=5\nuint8 UINT32=6\nuint8 FLOAT32=7\nuint8 FLOAT64=8\nstring name\n"
    "uint32 offset\nuint8 datatype\nuint32 count\n"
)
CLOUD_SCHEMA = (
    "std_msgs/Header header\nuint32 height\nuint32 width\nsensor_msgs/PointField[] fields\n"
    "bool is_bigendian\nuint32 point_step\nuint32 row_step\nuint8[] data\nbool is_dense\n"
    + SEP
    + POINT_FIELD
    + SEP
    + HEADER
    + SEP
    + TIME
)
FLOAT64 = 8
FRAME = "sample"  # the patch's frame: x, y on the sample's surface from where a trial indents


def cloud(stamp_ns: int, names: Sequence[str], columns: Sequence[np.ndarray]) -> dict[str, Any]:
    """A PointCloud2 of float64 fields ``names``, one point per row of ``columns``."""
    data = np.column_stack(columns).astype("<f8")
    step = 8 * len(names)
    fields = [
        {"name": n, "offset": 8 * k, "datatype": FLOAT64, "count": 1} for k, n in enumerate(names)
    ]
    return {
        "header": header(stamp_ns, FRAME),
        "height": 1,
        "width": int(data.shape[0]),
        "fields": fields,
        "is_bigendian": False,
        "point_step": step,
        "row_step": step * int(data.shape[0]),
        "data": data.tobytes(),
        "is_dense": True,
    }


def write_map_recording(result: SurveyResult, path: Path, threshold: float | None = None) -> Path:
    """The survey's map after each probe (module docstring) as MCAP at ``path``."""
    encode = serialize_dynamic(CLOUD, CLOUD_SCHEMA)[CLOUD]
    with open(path, "wb") as fh:
        writer = Writer(fh, compression=CompressionType.ZSTD)
        writer.start(profile="ros2", library="palpate")
        schema = writer.register_schema(CLOUD, SchemaEncoding.ROS2, CLOUD_SCHEMA.encode())
        grid = writer.register_channel("/map/grid", MessageEncoding.CDR, schema)
        probes = writer.register_channel("/map/probes", MessageEncoding.CDR, schema)
        tf = None
        if result.reach is not None:
            name = TOPICS["/tf"]
            tf_schema = writer.register_schema(name, SchemaEncoding.ROS2, SCHEMAS[name].encode())
            tf = writer.register_channel("/tf", MessageEncoding.CDR, tf_schema)
        lab = 0.0
        for k, probe in enumerate(result.probes, start=1):
            lab += probe.lab_time
            stamp = nanoseconds(lab)
            if tf is not None and result.reach is not None:
                data = tf_message(stamp, result.reach.frames((probe.x, probe.y)))
                writer.add_message(tf, log_time=stamp, data=data, publish_time=stamp)
            so_far = result.probes[:k]
            data = encode(cloud(stamp, PROBE_FIELDS, probe_frame(so_far)))
            writer.add_message(probes, log_time=stamp, data=data, publish_time=stamp)
            columns = grid_frame(
                so_far, result.patch, threshold=threshold, length_scale_max=result.length_scale_max
            )
            if columns is not None:
                data = encode(cloud(stamp, GRID_FIELDS, columns))
                writer.add_message(grid, log_time=stamp, data=data, publish_time=stamp)
        writer.finish()  # type: ignore[no-untyped-call,unused-ignore]
    return path

"""The ROS 2 node's names: its topics, services and parameters, with their types (docs/ros2.md
lists the same; a test holds the two equal, and another the names a running node advertises).

Relative names live under the node's namespace (``/palpate`` by default): ``measured_js`` is
``/palpate/measured_js``. The motion and force topics follow the CRTK convention the dVRK and
Raven use (``measured_js``, ``measured_cp``, ``measured_cf``); ``/clock`` and ``/diagnostics``
are ROS's own, absolute.
"""

from __future__ import annotations

TOPICS: dict[str, tuple[str, str]] = {
    "measured_js": (
        "sensor_msgs/msg/JointState",
        "the stage translation (m) and the outer roll (rad), at --rate",
    ),
    "measured_cp": (
        "geometry_msgs/msg/PoseStamped",
        "the sensor tip's pose in `base` (the tube's kinematics; on the bench stage, `stage`)",
    ),
    "measured_cf": (
        "geometry_msgs/msg/WrenchStamped",
        "the tissue's push on the tip in `sensor_tip` (+z into the tissue: minus the axial load "
        "the strains give, N)",
    ),
    "fbg/strains": (
        "std_msgs/msg/Float64MultiArray",
        "the used gratings' strains (zeroed at rest), one dimension labelled by grating",
    ),
    "fbg/wavelengths": (
        "std_msgs/msg/Float64MultiArray",
        "the peak wavelengths (m) of the board's newest frame: every grating, the reference last",
    ),
    "trial/state": ("std_msgs/msg/String", "the trial's state on each change (latched)"),
    "trial/result": (
        "std_msgs/msg/String",
        "each finished trial's row as JSON (the fields of `palpate sim --json`'s trials; latched)",
    ),
    "map/probes": (
        "sensor_msgs/msg/PointCloud2",
        "after each probe of a survey: x, y (m), the modulus (Pa) and its sd of log E",
    ),
    "map/grid": (
        "sensor_msgs/msg/PointCloud2",
        "after each probe of a survey: the map over the patch (modulus, sd, P(above))",
    ),
    "/diagnostics": (
        "diagnostic_msgs/msg/DiagnosticArray",
        "the servo bus's and the FBG stream's health, once a second of the trial's clock",
    ),
    "/clock": (
        "rosgraph_msgs/msg/Clock",
        "simulation only: the simulator's virtual clock (nodes with use_sim_time follow it)",
    ),
}

SIMULATION_ONLY = frozenset({"/clock"})  # not published on the bench

SUBSCRIPTIONS: dict[str, tuple[str, str]] = {
    "joy": (
        "sensor_msgs/msg/Joy",
        "a gamepad (the `joy` node, remapped here): left stick up/down advances/retracts, "
        "left/right rolls; A the emergency stop, B re-arms",
    ),
    "servo_jp": (
        "sensor_msgs/msg/JointState",
        "CRTK joint goal: `stage_translation` (m) and/or `outer_roll` (rad) by name, met within "
        "a jog step of where the robot is (stream it); the teleop's guards",
    ),
}

SERVICES: dict[str, tuple[str, str]] = {
    "run_trial": (
        "std_srvs/srv/Trigger",
        "run the next trial (or the one the `trial` parameter names); answers with its row as "
        "JSON in `message`",
    ),
    "run_survey": (
        "std_srvs/srv/Trigger",
        "a map scene's survey; answers with the map's summary as JSON in `message`",
    ),
    "stop": (
        "std_srvs/srv/Trigger",
        "stop the running trial: it retracts at its next control tick and ends `aborted` (while "
        "jogging: the emergency stop)",
    ),
    "zero": (
        "std_srvs/srv/Trigger",
        "re-zero the FBG strains now, the sensor free and still (opens a jog session if none is "
        "open); answers with the zero's wavelengths as JSON. Every trial zeroes at its start too",
    ),
}

PARAMETERS: dict[str, tuple[str, str]] = {
    "trial": (
        "string",
        "the trial `run_trial` runs next: a trial id, an index of the campaign or, on the "
        "bench, a stored target's name ('' the next in order)",
    ),
    "max_probes": (
        "integer",
        "the probes `run_survey` takes at most (0: the scene's `max_probes`)",
    ),
}


def grating_labels(strains: int) -> list[str]:
    """The strains topic's dimension labels: the gratings in the order the frames give them."""
    return [f"grating_{k + 1}" for k in range(strains)]


def peak_labels(peaks: int) -> list[str]:
    """The wavelengths topic's labels: the board's peaks in the order its frames give them."""
    return [f"peak_{k + 1}" for k in range(peaks)]


__all__ = [
    "PARAMETERS",
    "SERVICES",
    "SIMULATION_ONLY",
    "SUBSCRIPTIONS",
    "TOPICS",
    "grating_labels",
    "peak_labels",
]

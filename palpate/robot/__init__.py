"""Robot stack: tube kinematics, roller-gear drive, Dynamixel driver, indentation state machine.

The constant-curvature kinematics, e.g. where the sensor's tip is on the 15 degree tube, rolled
0, with 10 mm of sensor out of it (m, in the robot's base frame)::

    >>> from palpate.config import load_stack
    >>> from palpate.robot.kinematics import forward
    >>> tube = load_stack("robot.yaml").tubes[1]
    >>> pose = forward(tube, roll=0.0, translation=0.01)
    >>> tube.name, [round(float(v), 4) for v in pose.sensor_tip]
    ('bent15', [0.0892, 0.0, -0.0078])
"""

"""The stack as a ROS 2 node (``palpate ros``, docs/ros2.md): :mod:`.names` its topics and
services, :mod:`.view` the messages a trial publishes, :mod:`.runner` what it runs,
:mod:`.node` the node. Needs rclpy (the ``ros`` extra); nothing else of the stack imports it.
"""

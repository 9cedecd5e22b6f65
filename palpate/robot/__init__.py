"""Robot stack: tube kinematics, roller-gear drive, Dynamixel driver, indentation state machine."""

"""What crosses a cable, as data and pure encode/decode: the Dynamixel control table
(:mod:`wire.dynamixel`) and the FBG board's frame codec (:mod:`wire.frame`, :mod:`wire.frameblock`).

The lowest layer: robot/, sensor/ and sim/ import it, and it imports nothing of the project.
"""

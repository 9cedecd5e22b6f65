"""What crosses a cable, as data and pure encode/decode: the Dynamixel control table
(:mod:`wire.dynamixel`) and the FBG board's frame codec (:mod:`wire.frame`, :mod:`wire.frameblock`).

The lowest layer: robot/, sensor/ and sim/ import it, and it imports nothing of the project.
A board frame, to bytes and back::

    >>> from palpate.wire.frame import decode, encode, frame_from_si
    >>> frame = frame_from_si(7, 0.5, 1234, [1530e-9, 1535e-9])
    >>> back = decode(encode(frame))
    >>> back.seq, back.encoder, [round(float(w) * 1e9, 3) for w in back.wavelengths]
    (7, 1234, [1530.0, 1535.0])
"""

"""The bench's wiring: the real servo bus and acquisition board, and scripted trials on them.

- :mod:`.hardware`: open the bench's real interfaces on the ports named.
- :mod:`.plan`: the bench file's trial list and the stored targets as trial plans.
- :mod:`.trial`: stored poses -> trial plans -> the same trial loop as the simulator.

May import: ``robot``, ``sensor``, ``estimation``, ``config``, ``wire`` and the top-level helpers
of ``palpate``; never ``sim`` or ``palpate.simulation`` (the bench runs without a world).
Imported by the commands (``palpate trial``, ``palpate teleop``).
"""

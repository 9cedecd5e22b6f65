"""The FBG acquisition board emulated on a pseudo-terminal, with fault injection.

``with BoardEmulator(source, layout, clock=clock) as board:`` gives ``board.port``, a path a
reader opens with pyserial as it would open the real board; every sample comes from
``source(t) -> BoardSample`` and goes out as a frame of :mod:`wire.frame` (the codec shared
with the reader in ``sensor/``; ``sim/`` imports ``wire/``, never ``sensor/``).

Modules: :mod:`.source` (:class:`BoardSample`, the sample source), :mod:`.faults`
(:class:`BoardFaults`, :class:`BoardStats` and the per-sample fault draws), :mod:`.emulator`
(:class:`BoardEmulator`: the clock, the frames, the pty and its writer thread).
"""

from .emulator import BoardEmulator, ByteSink
from .faults import SYNC_BYTE, BoardFaults, BoardStats
from .source import BoardSample, SampleSource, constant_source

__all__ = [
    "SYNC_BYTE",
    "BoardEmulator",
    "BoardFaults",
    "BoardSample",
    "BoardStats",
    "ByteSink",
    "SampleSource",
    "constant_source",
]

"""A free sensor's record through a scene's temperature change, as raw board frames: what a lab
records with ``cat /dev/ttyACM0 > insertion.bin`` while the sensor enters the body (or with
``palpate emulate --scene ...`` on the printed board port), for ``palpate calibrate --thermal``.

The emulated bench (:class:`palpate.simulation.twin.SimulatedBench`) at its power-up pose (the
sensor retracted, touching nothing), its board's frames (``BoardEmulator.frame_of``) taken on
the virtual clock: the scene's ``fidelity.temperature`` and drift, each grating's true thermal
shift, the interrogator's noise.

Usage::

    data = insertion_frames(load_stack("robot-lung-invivo.yaml"),
                            load_scene("scenes/invivo/temperature.yaml"), seconds=30)
    Path("insertion.bin").write_bytes(data)
"""

from __future__ import annotations

from palpate.config.scene import SceneConfig
from palpate.config.schema import StackConfig
from palpate.simulation.twin import SimulatedBench
from palpate.wire.frame import encode


def insertion_frames(
    stack: StackConfig, scene: SceneConfig, *, seconds: float, rate_hz: float = 250.0, seed: int = 0
) -> bytes:
    """``seconds`` of frames at ``rate_hz`` from the free sensor of ``stack`` in ``scene``."""
    board = SimulatedBench(stack, scene, wire=False, seed=seed).board
    return b"".join(encode(board.frame_of(k, k / rate_hz)) for k in range(round(seconds * rate_hz)))

"""What the equilibrium solver returns: :class:`ContactState`, with one table of status texts."""

from __future__ import annotations

from dataclasses import dataclass

from .law import BoolArray, FloatArray

STATUS_MESSAGES: dict[int, str] = {
    0: "converged",
    1: "iteration limit reached before the tolerance",
    2: "stage advance beyond the modelled range of the beam (e > max_shortening or past the "
    "load maximum)",
}


@dataclass(frozen=True)
class ContactState:
    """Equilibrium after contact; arrays are shaped like the stage advance ``u``.

    Attributes:
        delta: tissue indentation (m).
        e: beam end shortening (m).
        P: axial load (N), equal to the tissue force.
        R: lateral reaction at the pin (N).
        buckled: ``e`` beyond the straight-compression range ``P_cr L / EA``.
        converged: per element, the residual of ``u = delta + e + P/k`` is below tolerance.
        success: all elements converged.
        status: key of ``STATUS_MESSAGES`` for the worst element (0 when ``success``).
        message: the status text, with the count of failing elements.
        iterations: iterations of the longer of the two stages.
    """

    delta: FloatArray
    e: FloatArray
    P: FloatArray
    R: FloatArray
    buckled: BoolArray
    converged: BoolArray
    success: bool
    status: int
    message: str
    iterations: int


def status_message(status: int, failed: int, total: int) -> str:
    """The text of ``status``, with the count of failing stage positions when there are any."""
    message = STATUS_MESSAGES[status]
    if failed:
        message = f"{message} ({failed} of {total} stage positions)"
    return message

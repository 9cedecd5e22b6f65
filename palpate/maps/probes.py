"""A map's probes: where each indentation was and what the estimator said of it.

A probe carries the joint fit's modulus and interval and the verdict; the map (``gp``) turns the
interval into the probe's own noise on log E (its half-width over the interval's z), inflates a
``suspect`` probe's variance (:data:`SUSPECT_INFLATION`) and leaves out a probe without a number,
keeping its reason. A probe suspect only because its measured tilt to the normal is not verified
within the campaign's tolerance, and that tilt (with its doubt) is under :data:`SMALL_TILT`,
keeps its interval: its number stands (a map through the robot, issue 58)::

    probe = Probe(x=2e-3, y=-1e-3, modulus=3.4e5, ci=(3.2e5, 3.6e5), status="ok")
    probe.log_sigma()   # ~0.03: the sd of log E the interval implies
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

Z95 = 1.959963984540054  # the joint fit's intervals are 95 %
SUSPECT_INFLATION = 4.0  # a suspect probe's variance on log E, times its interval's
MM = 1e-3
SIGMA_FLOOR = 0.01  # sd of log E below which no probe is believed (1 %: the world's own scatter)
# A measured tilt this small costs the joint fit little (docs/accuracy.md: 0.9 % square on, 16 %
# at 25 deg; about 1.5 % at 5), so a probe suspect for that alone keeps its interval.
SMALL_TILT = math.radians(5.0)
TILT_REASON = "misalignment "  # how the verdict's reasons of a measured tilt begin (verdict.py)


@dataclass(frozen=True)
class Probe:
    """One indentation of a map.

    Attributes:
        x, y: where it indented on the patch (m).
        modulus: the joint fit's E (Pa), None without a number.
        ci: its 95 % interval (Pa), None without one.
        status: the verdict's ``ok``, ``suspect`` or ``none``; reasons: its reasons.
        lab_time: simulated or bench seconds it took, the stage's travel to it included.
        contact_radius: the tip's contact radius at its deepest (m; sqrt(R delta), Hertz's),
            None if unknown: how wide the probe reads the tissue (``extent``).
        normal_error: the angle between the sensor's axis and the surface's normal where it
            indented (rad; a map through the robot), None where nothing turned it (the bench
            column over a level patch).
        tilt: the largest tilt to the normal the trial's own touches allow (rad: the measured
            misalignment and two of its sigmas), None where no normal was measured.
    """

    x: float
    y: float
    modulus: float | None
    ci: tuple[float, float] | None
    status: str
    reasons: tuple[str, ...] = field(default=())
    lab_time: float = 0.0
    contact_radius: float | None = None
    normal_error: float | None = None
    tilt: float | None = None

    @property
    def usable(self) -> bool:
        """A number with a finite, positive interval around it."""
        if self.modulus is None or self.ci is None or not self.modulus > 0:
            return False
        lo, hi = self.ci
        return self.status != "none" and 0 < lo <= self.modulus <= hi and math.isfinite(hi)

    def log_sigma(self) -> float:
        """The sd of log E its interval implies (half the log-width over the 95 % z), at least
        :data:`SIGMA_FLOOR`, widened for a ``suspect`` verdict. ValueError if not usable."""
        if not self.usable or self.ci is None:
            raise ValueError(f"probe at ({self.x:.4g}, {self.y:.4g}) m has no usable interval")
        lo, hi = self.ci
        sigma = max(math.log(hi / lo) / (2.0 * Z95), SIGMA_FLOOR)
        if self.status == "suspect" and not self.only_a_small_tilt:
            sigma *= math.sqrt(SUSPECT_INFLATION)
        return sigma

    @property
    def only_a_small_tilt(self) -> bool:
        """Suspect for a measured tilt alone, and that tilt under :data:`SMALL_TILT`."""
        small = self.tilt is not None and self.tilt <= SMALL_TILT
        return small and bool(self.reasons) and all(r.startswith(TILT_REASON) for r in self.reasons)

    def why_left_out(self) -> str | None:
        """Why the map does not use it (None: it does)."""
        if self.usable:
            return None
        if self.status == "none" or self.modulus is None:
            return "; ".join(self.reasons) or "no number"
        return "no finite interval"

    @classmethod
    def from_record(cls, d: dict[str, Any]) -> Probe:
        """The probe :meth:`record` wrote (a survey's ``probes.jsonl`` line, read back): the
        same floats, bit for bit, so a resumed survey is the survey it resumes. A line in the
        older form (millimetres and kPa, as :meth:`as_dict`) is read too."""
        if "x_m" not in d:
            return cls._from_display(d)
        ci = d["ci_pa"]
        return cls(
            float(d["x_m"]),
            float(d["y_m"]),
            None if d["modulus_pa"] is None else float(d["modulus_pa"]),
            None if ci is None else (float(ci[0]), float(ci[1])),
            d["status"],
            tuple(d["reasons"]),
            float(d["lab_time_s"]),
            None if d["contact_radius_m"] is None else float(d["contact_radius_m"]),
            None if d.get("normal_error_rad") is None else float(d["normal_error_rad"]),
            None if d.get("tilt_rad") is None else float(d["tilt_rad"]),
        )

    @classmethod
    def _from_display(cls, d: dict[str, Any]) -> Probe:
        ci = d["ci_kpa"]
        return cls(
            d["x_mm"] * MM,
            d["y_mm"] * MM,
            None if d["modulus_kpa"] is None else d["modulus_kpa"] * 1e3,
            None if ci is None else (ci[0] * 1e3, ci[1] * 1e3),
            d["status"],
            tuple(d["reasons"]),
            d["lab_time_s"],
            None if d.get("contact_radius_mm") is None else d["contact_radius_mm"] * MM,
        )

    def record(self) -> dict[str, object]:
        """The probe for a file that is read back (SI units: JSON writes a float at ``repr``
        precision, so :meth:`from_record` gets the same probe)."""
        return {
            "x_m": self.x,
            "y_m": self.y,
            "modulus_pa": self.modulus,
            "ci_pa": None if self.ci is None else list(self.ci),
            "status": self.status,
            "reasons": list(self.reasons),
            "lab_time_s": self.lab_time,
            "contact_radius_m": self.contact_radius,
            **({} if self.normal_error is None else {"normal_error_rad": self.normal_error}),
            **({} if self.tilt is None else {"tilt_rad": self.tilt}),
        }

    def as_dict(self) -> dict[str, object]:
        """What a person reads (``--json``: millimetres and kPa); a file read back holds
        :meth:`record` instead."""
        return {
            "x_mm": self.x * 1e3,
            "y_mm": self.y * 1e3,
            "modulus_kpa": None if self.modulus is None else self.modulus / 1e3,
            "ci_kpa": None if self.ci is None else [self.ci[0] / 1e3, self.ci[1] / 1e3],
            "status": self.status,
            "reasons": list(self.reasons),
            "lab_time_s": self.lab_time,
            "contact_radius_mm": None if self.contact_radius is None else self.contact_radius / MM,
            **(
                {}
                if self.normal_error is None
                else {"normal_error_deg": math.degrees(self.normal_error)}
            ),
            **({} if self.tilt is None else {"tilt_deg": math.degrees(self.tilt)}),
        }


NORMAL_TOLERANCE = math.radians(2.0)  # square on: the orthogonality tolerance
OFF_NORMAL_WORDS = ("misalign", "oblique", "orientation unverified")  # a verdict that says so


def normal_scores(probes: list[Probe], tolerance: float = NORMAL_TOLERANCE) -> dict[str, object]:
    """How square on the probes pressed (those with a known normal error): the largest error
    (deg), how many were off the normal by more than ``tolerance`` (rad), and how many of those
    pressed without a verdict that says so (a reason naming misalignment, an oblique press or
    an unverified orientation); empty when no probe knows its normal error."""
    known = [p for p in probes if p.normal_error is not None]
    if not known:
        return {}
    off = [p for p in known if p.normal_error is not None and p.normal_error > tolerance]
    silent = [
        p
        for p in off
        if p.modulus is not None and not any(w in r for r in p.reasons for w in OFF_NORMAL_WORDS)
    ]
    return {
        "normal_error_max_deg": max(math.degrees(p.normal_error or 0.0) for p in known),
        "probes_off_normal": len(off),
        "off_normal_unflagged": len(silent),
    }

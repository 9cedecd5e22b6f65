"""The simulated world of one trial: where the sensor is, what it presses on, what the fiber sees.

Each board sample asks the world for its state at time ``t``. The world reads the servos' present
positions (through injected callables, so ``sim/`` never imports the control code), places the
sensor with the injected forward kinematics, and solves the quasi-static contact along the sensor
axis (:mod:`sim.equilibrium`) with the tissue's own force law (:mod:`sim.sample_law`: the
sample's finite-element table, or the closed forms where a scene picks them), tabulated along
the trial's path (:mod:`sim.contact_table`, which also turns the beam state into grating
strains); a viscoelastic sample is instead stepped on the clock (:mod:`sim.contact_history`).
From the beam state it makes what the hardware would send: peak wavelengths (Eq. 1 with Eq. 3
and Eq. 12, plus noise and temperature drift), the force scale reading and the contact event.
Gratings still inside the tube read 0.

Only what the scene switches on is computed (:class:`config.scene.FidelityConfig`).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from config.scene import FidelityConfig
from config.schema import FbgConfig, SensorConfig
from estimation.section import Section
from sim.board import BoardSample
from sim.contact_history import ViscoelasticContact
from sim.contact_table import ContactTable, GridPhysics, Vector, equilibrium_on_grid
from sim.equilibrium import ContactEffects, TissueLaw
from sim.viscoelastic import StandardLinearSolid
from wire.frame import Status

# (roll rad, translation m) -> (tube tip point, unit tangent, exposed length m)
PoseFn = Callable[[float, float], tuple[Vector, Vector, float]]
JointsFn = Callable[[], tuple[float, float, int]]  # -> (roll rad, translation m, encoder count)

CONTACT_EVENT = Status.CONTACT_EVENT
_CONTACT_FLAG = int(Status.CONTACT_EVENT)  # int() of an IntFlag costs ~0.3 us per sample
_FORCE_FLAG = int(Status.FORCE_VALID)


@dataclass(frozen=True)
class Surface:
    """The tissue's surface plane: a point on it and its outward unit normal (base frame, m)."""

    point: Vector
    normal: Vector


class WorldState(NamedTuple):
    """The world at one board sample (SI). A NamedTuple, not a frozen dataclass: one is built
    at every sample, and a NamedTuple builds in ~0.5 us instead of ~1.8 us."""

    t: float
    roll: float
    translation: float
    exposed_length: float
    past_contact: float  # advance along the sensor axis past first touch (m), <= 0 when free
    delta: float
    e: float
    P: float
    R: float
    strains: tuple[float, ...]
    contact_event: bool
    encoder: int = 0  # the stage encoder count the board reports with this state


# The physics at one pose: exposed length, advance past contact, delta, e, P, R, strains.
_Physics = tuple[float, float, float, float, float, float, tuple[float, ...]]


class World:
    """One trial's world. ``sample(t)`` is the board emulator's source.

    The servos rest for about a third of the board samples (the board and the control loop
    both run at 250 Hz, and the stage waits at the zero and between moves), so the physics of
    the last joint reading is kept and the pose and contact lookup run only when the servos
    moved or the surface was replaced. Per sample, the rest is plain-float arithmetic on a few
    values: numpy's ~1 us per call would cost more than the arithmetic itself.
    """

    def __init__(
        self,
        *,
        section: Section,
        sensor: SensorConfig,
        fbg: FbgConfig,
        fidelity: FidelityConfig,
        tissue: TissueLaw,
        surface: Surface,
        pose: PoseFn,
        joints: JointsFn,
        rng: np.random.Generator,
        has_force: bool = True,
        length_grows: bool = True,
        encoder_step: float | None = None,
        relaxation: StandardLinearSolid | None = None,
    ) -> None:
        """``encoder_step``: the stage advance per encoder count (m). The stage stops only on
        whole counts, so every sample in contact lies on that lattice; the contact table is
        then solved on it and needs no interpolation in the advance (None: a 5 um grid).
        ``relaxation``: the tissue is viscoelastic (``tissue`` is its instantaneous law), so
        the contact is stepped at every sample instead of tabulated."""
        self.section = section
        self.sensor = sensor
        self.fbg = fbg
        self.fidelity = fidelity
        self.tissue = tissue
        self.pose = pose
        self.joints = joints
        self.rng = rng
        self.has_force = has_force
        k_tube = fidelity.tube_tip_stiffness_n_per_mm
        self.effects = ContactEffects(
            tube_stiffness=None if k_tube is None else k_tube * 1e3,
            imperfection=fidelity.imperfection_w0_over_l,
        )
        sd = fidelity.contact_uncertainty_mm * 1e-3
        self.contact_offset = float(rng.normal(0.0, sd)) if sd > 0 else 0.0
        self._centres = tuple(sensor.grating_centres_from_tip())
        self._base = tuple(fbg.base_wavelengths_nm[g - 1] * 1e-9 for g in sensor.used_gratings)
        self._noise = fidelity.fbg_noise_pm * 1e-12
        ref_nm = fbg.reference_wavelength_nm
        self._reference = None if ref_nm is None else ref_nm * 1e-9
        # peak noises, then the reference's, drawn in one call (the same stream as separate ones)
        self._draws = (len(self._base) + (ref_nm is not None)) if self._noise > 0 else 0
        self._strain_coefficient = fbg.strain_coefficient
        self._temperature_coefficient = fbg.temperature_coefficient
        self._tip_radius = sensor.tip_radius
        self._free = (0.0,) * len(self._centres)
        self.length_grows = length_grows
        self.encoder_step = encoder_step
        self._table: ContactTable | None = None
        self._history = (
            None if relaxation is None else ViscoelasticContact(self._grid(), relaxation)
        )
        self._now = 0.0  # the time of the sample being computed
        self._surface = surface
        self._joints: tuple[float, float, int] | None = None  # the reading _physics belongs to
        self._physics: _Physics = (0.0, -math.inf, 0.0, 0.0, 0.0, 0.0, self._free)
        self.last: WorldState | None = None

    @property
    def surface(self) -> Surface:
        return self._surface

    @surface.setter
    def surface(self, surface: Surface) -> None:
        self._surface = surface
        self._joints = None  # the kept physics belonged to the old surface

    # -- physics ------------------------------------------------------------------------------
    def state(self, t: float) -> WorldState:
        joints = self.joints()
        if joints != self._joints or self._history is not None:  # a history moves with time
            self._now = t
            self._physics = self._physics_at(joints[0], joints[1])
            self._joints = joints
        roll, translation, encoder = joints
        length, past, delta, e, P, R, strains = self._physics
        event = past > self.contact_offset
        st = WorldState(t, roll, translation, length, past, delta, e, P, R, strains, event, encoder)
        self.last = st
        return st

    def _physics_at(self, roll: float, translation: float) -> _Physics:
        tip, tangent, length = self.pose(roll, translation)
        n = self._surface.normal
        cos_a = -float(tangent @ n)  # 1 when the sensor points straight into the surface
        centre_height = float((tip - self._surface.point) @ n) - length * cos_a
        past = (self._tip_radius - centre_height) / cos_a if cos_a > 0.05 else -math.inf
        strains = self._free
        delta = e = P = R = 0.0
        if past > 0.0 and length > 0.0 and self._history is not None:
            delta, e, P, R, strains = self._history.at(self._now, past, length)
        elif past > 0.0 and length > 0.0:
            if self._table is None:
                self._table = ContactTable(
                    self, length - past, self.length_grows, lattice=self._lattice(past)
                )
            delta, e, P, R, strains = self._table.at(past)
        elif self._history is not None:
            self._history.release(self._now)
        return length, past, delta, e, P, R, strains

    def _lattice(self, past: float) -> tuple[float, float] | None:
        """(step, origin) of the encoder lattice in the advance past contact, from the first
        sample in contact; None without an encoder step."""
        if self.encoder_step is None:
            return None
        return self.encoder_step, past % self.encoder_step

    def solve_on_grid(self, u: Vector, length: float) -> tuple[Vector, ...]:
        """Equilibrium at advances ``u`` (M,) for one exposed length: delta, e, P, |R|, strains
        (M, G) (see :func:`equilibrium_on_grid`, which caches it)."""
        grid = tuple(np.asarray(u, dtype=np.float64).tolist())
        return equilibrium_on_grid(self._grid(), grid, length)

    def _grid(self) -> GridPhysics:
        return GridPhysics(
            self.section.EI,
            self.section.EA,
            self.section.fiber_offset,
            self.sensor.grating_length,
            self._centres,
            self.tissue,
            self.effects,
        )

    # -- what the board sends ----------------------------------------------------------------
    def sample(self, t: float) -> BoardSample:
        st = self.state(t)
        drift = self.fidelity.temperature_drift_degc_per_s * t
        noise = self.rng.normal(0.0, self._noise, size=self._draws).tolist() if self._draws else []
        reference = None
        if self._reference is not None:
            reference = self._reference
            reference += self._temperature_coefficient * drift
            if noise:
                reference += noise[-1]
        flags = _CONTACT_FLAG if st.contact_event else 0
        force = None
        if self.has_force:
            force = st.P
            flags |= _FORCE_FLAG
        return BoardSample(
            wavelengths=self._peaks(st.strains, drift, noise),
            encoder=st.encoder,
            reference=reference,
            force=force,
            flags=flags,
        )

    def _peaks(
        self, strains: tuple[float, ...], drift: float, noise: list[float]
    ) -> tuple[float, ...]:
        """Peak wavelengths (m): base + S_eps eps (+ S_T dT) (+ noise). Plain floats, with the
        same IEEE operations in the same order as the array expression they replace, so the
        same bits."""
        k = self._strain_coefficient
        shift = [k * x for x in strains]
        if drift:
            offset = self._temperature_coefficient * drift
            shift = [x + offset for x in shift]
        wl = [b + x for b, x in zip(self._base, shift, strict=True)]
        if noise:
            wl = [w + n for w, n in zip(wl, noise[: len(wl)], strict=True)]
        return tuple(wl)

"""The simulated world of one trial: where the sensor is, what it presses on, what the fiber sees.

Each board sample asks the world for its state at time ``t``. The world reads the servos' present
positions (through injected callables, so ``sim/`` never imports the control code), places the
sensor with the injected forward kinematics, and solves the quasi-static contact along the sensor
axis (:mod:`sim.equilibrium`) with the tissue's own force law (:mod:`sim.tissue`), which is not the
estimator's Hertz model, tabulated along the trial's path (:mod:`sim.contact_table`, which
also turns the beam state into grating strains). From the beam state it makes what the hardware
would send: peak wavelengths (Eq. 1 with Eq. 3 and Eq. 12, plus noise and the temperature:
:mod:`sim.readout`), the force scale reading, the contact event, the ventilator's breath-hold
gate. Gratings still inside the tube read 0. With ``breathing`` the surface moves along its
normal on the clock (:mod:`sim.breathing`), so the contact is looked up at every sample.

Only what the scene switches on is computed (:class:`config.scene.FidelityConfig`). The tissue's
force law is the sample's own (:mod:`sim.sample_law`: its finite-element table, or the closed
forms where a scene picks them); a viscoelastic sample's contact is stepped on the clock
(:mod:`sim.contact_history`) instead of tabulated.

The surface is a plane or a convex sphere (:class:`Surface`). Each roll the sensor touches the
tissue at has its own contact (a probing robot touches at several): its own table, solved with
the tissue law as the sensor axis sees it at that contact (:mod:`sim.oblique`: the angle to the
local normal, the sample's friction, the surface's curvature) and, with ``gravity``, the beam's
pre-bend from its own weight (:mod:`sim.gravity`). :attr:`World.contacts` keeps what each was.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from ..config.scene import FidelityConfig
from ..config.schema import FbgConfig, SensorConfig
from ..estimation.beam.section import Section
from ..estimation.pose.surface import SurfaceGeometry
from ..wire.frame import Status
from .board import BoardSample
from .breathing import Breath
from .contact_history import ViscoelasticContact
from .contact_table import ContactGrid, ContactTable, GridPhysics, Vector, equilibrium_on_grid
from .equilibrium import ContactEffects, TissueLaw
from .gravity import BeamWeight, offset_to_mode, sensing_axis
from .oblique import ObliqueContact
from .readout import BoardReadout, grating_ends
from .viscoelastic import Relaxation

# (roll rad, translation m) -> (tube tip point, unit tangent, exposed length m)
PoseFn = Callable[[float, float], tuple[Vector, Vector, float]]
JointsFn = Callable[[], tuple[float, float, int]]  # -> (roll rad, translation m, encoder count)

CONTACT_EVENT = Status.CONTACT_EVENT
_CONTACT_FLAG = int(Status.CONTACT_EVENT)  # int() of an IntFlag costs ~0.3 us per sample
_FORCE_FLAG = int(Status.FORCE_VALID)
_HOLD_FLAG = int(Status.BREATH_HOLD)
_BEAT_FLAG = int(Status.CARDIAC_TRIGGER)


COARSE_BIN_STEPS = 50  # grid steps in a bin of a coarse contact grid at a fixed length
ALIGNED = 1e-6  # rad: a misalignment below this is the aligned contact, bit for bit


@dataclass(frozen=True)
class Surface:
    """The tissue's surface: a point on it and its outward unit normal there (base frame, m);
    ``radius`` (m) makes it a convex sphere through the point, None a plane."""

    point: Vector
    normal: Vector
    radius: float | None = None


@dataclass(frozen=True)
class Contact:
    """One contact of a trial: the roll it was made at, the angle between the sensor axis and
    the inward normal where the tip first touched (rad), whether the friction held the tip, and
    the pre-bend imperfection the beam carried (w0, m, signed: negative buckles the other way)."""

    roll: float
    misalignment: float
    sticks: bool
    imperfection: float


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
        friction: float = 0.5,
        poisson: float = 0.45,
        weight: BeamWeight | None = None,
        relaxation: Relaxation | None = None,
    ) -> None:
        """``encoder_step``: the stage advance per encoder count (m). The stage stops only on
        whole counts, so every sample in contact lies on that lattice; the contact table is
        then solved on it and needs no interpolation in the advance (None: a 5 um grid).
        ``friction`` and ``poisson``: the sample's, for oblique contacts; ``weight``: the
        sensor's weight when the scene models gravity (None: it does not). ``relaxation``: the
        tissue is viscoelastic (``tissue`` is its instantaneous law), so each contact is stepped
        at every sample instead of tabulated."""
        self.section = section
        self.sensor = sensor
        self.fbg = fbg
        self.fidelity = fidelity
        self.tissue = tissue
        self.pose = pose
        self.joints = joints
        self.rng = rng
        self.has_force = has_force
        self.effects, self.contact_offset = _contact_effects(fidelity, rng, sensor)
        self._centres = tuple(sensor.grating_centres_from_tip())
        self.readout = BoardReadout(sensor, fbg, fidelity)
        self._tip_radius = sensor.tip_radius
        self._free = (0.0,) * len(self._centres)
        self.length_grows = length_grows
        self.encoder_step = encoder_step
        self.friction, self.poisson, self.weight = friction, poisson, weight
        self._from_tip = grating_ends(self._centres, sensor.grating_length)  # gravity's sag
        self._tables: dict[float, ContactTable] = {}
        self.relaxation, self.breath = relaxation, Breath.of(fidelity.breathing, rng)
        self._moving, self._lift = relaxation is not None or self.breath is not None, 0.0
        self.moved: tuple[float, float] | None = None  # the surface's lift range in contact (m)
        self._histories: dict[float, ViscoelasticContact] = {}
        self._now = 0.0  # the time of the sample being computed
        self._contact_at: dict[float, Contact] = {}
        self.contacts: list[Contact] = []
        self.indentation: Contact | None = None  # the contact that went deepest
        self._deepest = 0.0
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
        if joints != self._joints or self._moving:  # a history or the breath moves with time
            self._now = t
            self._lift = 0.0 if self.breath is None else self.breath.lift(t)
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
        past, normal = self._past(tip, tangent, length)
        strains = self._free if self.weight is None else self._sag(roll, tangent, length)
        delta = e = P = R = 0.0
        if past > 0.0 and length > 0.0:
            lo, hi = self.moved or (self._lift, self._lift)
            self.moved = (min(lo, self._lift), max(hi, self._lift))
            table = self._tables.get(roll)
            if table is None:
                table = self._new_table(roll, tangent, length, past, normal)
            if self.relaxation is None:
                delta, e, P, R, bent = table.at(past)
            else:
                delta, e, P, R, bent = self._histories[roll].at(self._now, past, length)
            if past > self._deepest:
                self._deepest = past
                self.indentation = self._contact_at[roll]
            strains = (
                bent
                if self.weight is None
                else tuple(a + b for a, b in zip(strains, bent, strict=True))
            )
        else:
            for history in self._histories.values():  # the surface recovers while the tip is away
                history.release(self._now)
        return length, past, delta, e, P, R, strains

    def _past(self, tip: Vector, tangent: Vector, length: float) -> tuple[float, Vector]:
        """How far (m) the tip sphere's centre is past first touch along the axis (-inf when
        the axis does not meet the surface within 87 deg), and the outward normal where the
        tip first touches."""
        n = self._surface.normal
        if self._surface.radius is None:
            cos_a = -float(tangent @ n)  # 1 when the sensor points straight into the surface
            centre_height = float((tip - self._surface.point) @ n) - self._lift - length * cos_a
            past = (self._tip_radius - centre_height) / cos_a if cos_a > 0.05 else -math.inf
            return past, n
        s = self._surface
        offset = SurfaceGeometry(s.point + self._lift * n, n, s.radius).offset(self._tip_radius)
        centre = tip + length * tangent
        ahead = offset.ray_hit(centre, tangent)
        if not math.isfinite(ahead):
            return -math.inf, n
        local = offset.normal_at(centre + ahead * tangent)
        return (-ahead if -float(tangent @ local) > 0.05 else -math.inf), local

    def _sag(self, roll: float, tangent: Vector, length: float) -> tuple[float, ...]:
        """The free beam's strains under its own weight (gravity on)."""
        assert self.weight is not None
        across = self.weight.across(sensing_axis(tangent, roll))
        sec = self.section
        return across.sag_strains(sec.EI, sec.fiber_offset, length, self._from_tip)

    def _new_table(
        self, roll: float, tangent: Vector, length: float, past: float, normal: Vector
    ) -> ContactTable:
        """The contact table of a first touch at ``roll``: the tissue as this axis sees it."""
        cos_a = min(1.0, -float(tangent @ normal))
        psi = math.acos(cos_a)
        curvature = 1.0
        if self._surface.radius is not None:
            curvature = math.sqrt(self._surface.radius / (self._surface.radius + self._tip_radius))
        contact_length = length - past
        tissue: TissueLaw = self.tissue
        if psi > ALIGNED or curvature != 1.0:
            tissue = ObliqueContact(
                self.tissue,
                psi,
                self.friction,
                self.poisson,
                curvature,
                self._slip_share(roll, tangent, normal, psi),
            )
        effects, sign, w0 = self._pre_bend(roll, tangent, contact_length)
        sec = self.section
        physics = GridPhysics(
            sec.EI,
            sec.EA,
            sec.fiber_offset,
            self.sensor.grating_length,
            self._centres,
            tissue,
            effects,
            sign,
        )
        lattice = self._lattice(past)
        # at a fixed length a bin's width changes no value (every lookup is a lattice point
        # of one length, or between two neighbours of it): wide bins pay the ~1-4 ms per
        # vectorised call less often; a coarse grid's bins hold as many steps as 1 mm of
        # 20 um ones
        wide = 1e-3 if lattice is None else max(1e-3, COARSE_BIN_STEPS * lattice[0])
        table = ContactTable(
            ContactGrid(physics),
            contact_length,
            self.length_grows,
            lattice=lattice,
            bin_width=0.25e-3 if self.length_grows else wide,
        )
        self._tables[roll] = table
        if self.relaxation is not None:
            self._histories[roll] = ViscoelasticContact(physics, self.relaxation)
        sticks = not isinstance(tissue, ObliqueContact) or tissue.sticks
        self.contacts.append(Contact(roll, psi, sticks, w0))
        self._contact_at[roll] = self.contacts[-1]
        return table

    def _slip_share(self, roll: float, tangent: Vector, normal: Vector, psi: float) -> float:
        """cos of the angle between a slip's lateral load (b = sin psi n + cos psi m) and the
        fiber's bending plane."""
        if psi <= ALIGNED:
            return 0.0
        along = (tangent + math.cos(psi) * normal) / math.sin(psi)  # m, the way t leans
        lateral = math.sin(psi) * normal + math.cos(psi) * along
        return float(lateral @ sensing_axis(tangent, roll))

    def _pre_bend(
        self, roll: float, tangent: Vector, length: float
    ) -> tuple[ContactEffects, float, float]:
        """(effects, bending sign, signed imperfection w0 m) of a contact: the scene's
        imperfection, plus the first-mode equivalent of the weight's pin offset (gravity on)."""
        w0 = self.fidelity.imperfection_w0_over_l * length
        if self.weight is None:
            return self.effects, 1.0, w0
        across = self.weight.across(sensing_axis(tangent, roll))
        w0 += offset_to_mode() * across.pin_offset(self.section.EI, length)
        effects = ContactEffects(self.effects.tube_stiffness, abs(w0) / length)
        return effects, (1.0 if w0 >= 0 else -1.0), w0

    def _lattice(self, past: float) -> tuple[float, float] | None:
        """(step, origin) of the encoder lattice in the advance past contact, from the first
        sample in contact (every ``fidelity.contact_grid_um`` of it when that is set); None
        without an encoder step or a grid."""
        grid = self.fidelity.contact_grid_um
        if self.encoder_step is None:
            return None if grid is None else (grid * 1e-6, 0.0)
        step = self.encoder_step
        if grid is not None:  # a coarser grid of whole counts: lookups between its points
            step *= max(1, round(grid * 1e-6 / step))
        return step, past % self.encoder_step

    def solve_on_grid(self, u: Vector, length: float) -> tuple[Vector, ...]:
        """Equilibrium at advances ``u`` (M,) for one exposed length: delta, e, P, |R|, strains
        (M, G) (see :func:`equilibrium_on_grid`, which caches it)."""
        physics = GridPhysics(
            self.section.EI,
            self.section.EA,
            self.section.fiber_offset,
            self.sensor.grating_length,
            self._centres,
            self.tissue,
            self.effects,
        )
        return equilibrium_on_grid(physics, tuple(np.asarray(u, dtype=np.float64).tolist()), length)

    # -- what the board sends ----------------------------------------------------------------
    def sample(self, t: float) -> BoardSample:
        st = self.state(t)
        wavelengths, reference, tip = self.readout.read(st.strains, st.P, t, self.rng)
        flags = _CONTACT_FLAG if st.contact_event else 0
        if self.breath is not None:
            if self.breath.config.gate and self.breath.holding(t):
                flags |= _HOLD_FLAG
            if self.breath.beat(t):
                flags |= _BEAT_FLAG
        force = None
        if self.has_force:
            force = st.P
            flags |= _FORCE_FLAG
        return BoardSample(
            wavelengths=wavelengths,
            encoder=st.encoder,
            reference=reference,
            force=force,
            flags=flags,
            tip=tip,
        )


def _contact_effects(
    fidelity: FidelityConfig, rng: np.random.Generator, sensor: SensorConfig
) -> tuple[ContactEffects, float]:
    """What the scene and the sensor add at the contact (a compliant tube tip and a tip grating's
    element in series, the beam's bow) and this trial's contact-event error (m, drawn once)."""
    k_tube = fidelity.tube_tip_stiffness_n_per_mm
    stiffness = None if k_tube is None else k_tube * 1e3
    tip = sensor.tip_grating
    if tip is not None and tip.compliance > 0:  # in series with the tube
        stiffness = 1.0 / (tip.compliance + (0.0 if stiffness is None else 1.0 / stiffness))
    effects = ContactEffects(
        tube_stiffness=stiffness,
        imperfection=fidelity.imperfection_w0_over_l,
    )
    sd = fidelity.contact_uncertainty
    return effects, float(rng.normal(0.0, sd)) if sd > 0 else 0.0

"""The simulated world of one trial: where the sensor is, what it presses on, what the fiber sees.

Each board sample asks the world for its state at time ``t``. The world reads the servos' present
positions (through injected callables, so ``sim/`` never imports the control code), places the
sensor with the injected forward kinematics, and solves the quasi-static contact along the sensor
axis (:mod:`sim.equilibrium`) with the tissue's own force law (:mod:`sim.tissue`), which is not the
estimator's Hertz model. From the beam state it makes what the hardware would send: peak
wavelengths (Eq. 1 with Eq. 3 and Eq. 12, plus noise and temperature drift), the force scale
reading and the contact event.

Only what the scene switches on is computed (:class:`config.scene.FidelityConfig`).

Grating strains. The bending strain of a grating follows the beam's lateral pin reaction ``R``:
for the perfect beam this is the elastica at the solved shortening; for an imperfect beam the
contact solver gives ``R`` of the amplified imperfection, and the strains are those of the
perfect elastica with the same ``R`` (bending moments scale with ``R`` in the first mode). The
fiber also feels the uniform axial compression ``-P/EA``. Gratings still inside the tube read 0.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from config.scene import FidelityConfig
from config.schema import FbgConfig, SensorConfig
from estimation.beam import Beam
from estimation.elastica import post_buckling
from estimation.section import Section
from sim.board import BoardSample
from sim.equilibrium import ContactEffects, solve_contact
from sim.tissue import TissueModel
from wire.frame import Status

Vector = NDArray[np.float64]
# (roll rad, translation m) -> (tube tip point, unit tangent, exposed length m)
PoseFn = Callable[[float, float], tuple[Vector, Vector, float]]
JointsFn = Callable[[], tuple[float, float, int]]  # -> (roll rad, translation m, encoder count)

CONTACT_EVENT = Status.CONTACT_EVENT
_CONTACT_FLAG = int(Status.CONTACT_EVENT)  # int() of an IntFlag costs ~0.3 us per sample
_FORCE_FLAG = int(Status.FORCE_VALID)


@functools.lru_cache(maxsize=1)
def _r_table() -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """log(r) and log(e/L) of the perfect elastica on a dense grid, to invert r -> e/L."""
    e_over_l = np.logspace(-12, -1, 600)
    r = np.abs(np.asarray(post_buckling(e_over_l, method="fast").r, dtype=float))
    if not np.all(np.diff(r) > 0):
        raise RuntimeError("elastica reaction r(e/L) is not increasing on the inversion grid")
    return np.log(r), np.log(e_over_l)


def shortening_for_reaction(r: NDArray[np.float64]) -> NDArray[np.float64]:
    """e/L of the perfect elastica whose dimensionless pin reaction is ``r`` (0 where r <= 0)."""
    log_r, log_e = _r_table()
    safe = np.maximum(r, 1e-300)
    return np.where(r > 0.0, np.exp(np.interp(np.log(safe), log_r, log_e)), 0.0)


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


class GridPhysics(NamedTuple):
    """Everything a table of contact equilibria depends on besides the grid and the length."""

    EI: float
    EA: float
    fiber_offset: float
    grating_length: float
    centres_from_tip: tuple[float, ...]
    tissue: TissueModel
    effects: ContactEffects


@functools.lru_cache(maxsize=256, typed=True)
def equilibrium_on_grid(
    physics: GridPhysics, u: tuple[float, ...], length: float
) -> tuple[Vector, Vector, Vector, Vector, Vector]:
    """Equilibrium at advances ``u`` (M,) for one exposed length: delta, e, P, |R| (M,) and the
    grating strains (M, G); read-only arrays.

    Cached per process: a pure function of its arguments, and a campaign solves the same table
    again whenever a trial repeats a sample, tube length and contact geometry (the robot
    campaign's straight and bent tubes meet the tissue at the same exposed length to the last
    bit), which saves its ~5 ms per call. Raises RuntimeError naming the failure if the contact
    solver does not converge."""
    beam = Beam(physics.EI, physics.EA, physics.fiber_offset, length)
    sol = solve_contact(np.asarray(u, dtype=np.float64), beam, physics.tissue, physics.effects)
    if not sol.success:
        raise RuntimeError(f"contact equilibrium failed at L = {length:.6g} m: {sol.message}")
    R = np.abs(sol.R)
    r = R * length**2 / physics.EI
    g = shortening_for_reaction(r)  # e_g/L of the shape that carries this pin reaction
    half = 0.5 * physics.grating_length
    centres = length - np.asarray(physics.centres_from_tip)
    intervals = np.stack([centres - half, np.minimum(centres + half, length)], axis=-1)
    eps = beam.bending_strains(g, intervals)
    eps = eps - (sol.P / physics.EA)[:, None]
    out = (sol.delta, sol.e, sol.P, R, eps)
    for a in out:
        a.flags.writeable = False  # shared by every caller of the cache
    return out


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
        tissue: TissueModel,
        surface: Surface,
        pose: PoseFn,
        joints: JointsFn,
        rng: np.random.Generator,
        has_force: bool = True,
        length_grows: bool = True,
        encoder_step: float | None = None,
    ) -> None:
        """``encoder_step``: the stage advance per encoder count (m). The stage stops only on
        whole counts, so every sample in contact lies on that lattice; the contact table is
        then solved on it and needs no interpolation in the advance (None: a 5 um grid)."""
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
        if joints != self._joints:
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
        if past > 0.0 and length > 0.0:
            if self._table is None:
                self._table = ContactTable(
                    self, length - past, self.length_grows, lattice=self._lattice(past)
                )
            delta, e, P, R, strains = self._table.at(past)
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


def _lerp(a: list[float], b: list[float], w: float) -> list[float]:
    """``a (1 - w) + b w`` elementwise in plain floats: the same IEEE operations as numpy's
    ``a * (1 - w) + b * w`` on rows of 7 values, at a third of its cost."""
    c = 1 - w
    return [x * c + y * w for x, y in zip(a, b, strict=True)]


class _Bin(NamedTuple):
    u: list[float]  # the bin's u grid (n,)
    rows: list[list[list[float]]]  # per edge length: rows [delta, e, P, |R|, strains...] (n, 4 + G)


class ContactTable:
    """Equilibrium tabulated over the advance past contact ``u``, solved lazily in bins.

    A trial visits one path through (u, L): L = L_contact + u on the robot (the sensor slides
    out of the tube), L fixed on the bench. The grid in u is the encoder lattice when the world
    knows it (``lattice`` = (step, origin): every sample in contact is at origin + j step, so a
    lookup lands on a solved point and the linear interpolation in u is exact; it was not on a
    fixed 5 um grid, whose strains near the buckling knee were off by up to 2.4 ue, about one
    noise sd). Each bin of about ``bin_width`` (a whole number of steps) is solved in one
    vectorised call per bin edge length, and values are interpolated linearly in L between the
    edges (error O(dL^2 / L^2) ~ 4e-5 for 0.25 mm bins at L = 42 mm). Why bins: a vectorised
    solve costs ~4 ms of numpy call overhead plus ~30 us per point (2 points: 4.0 ms, 51: 5.6
    ms, 101: 6.8 ms), so one call per sample would make a trial take a minute. A trial touches
    3-5 bins and visits most of each but the last (~140 samples per bin at 0.5 mm/s and 250 Hz),
    so solving part of a bin would save little; 0.5 mm bins (half the calls, 101 points) saved
    ~15 % on the bench and nothing on the robot. The tables are kept as plain floats: a lookup
    is ~20 float operations.
    """

    def __init__(
        self,
        world: World,
        contact_length: float,
        grows: bool,
        *,
        lattice: tuple[float, float] | None = None,
        bin_width: float = 0.25e-3,
    ) -> None:
        self.world = world
        self.contact_length = contact_length
        self.grows = grows
        self.step, self.origin = lattice if lattice is not None else (5e-6, 0.0)
        self.n = max(2, round(bin_width / self.step))  # grid intervals per bin
        self.bin_width = self.n * self.step
        self._bins: dict[int, _Bin] = {}

    def _bin(self, k: int) -> _Bin:
        """Bin ``k``: its u grid (lattice points k n .. (k + 1) n) and, per edge length, the
        rows on that grid."""
        if k not in self._bins:
            j = np.arange(k * self.n, (k + 1) * self.n + 1, dtype=np.float64)
            u = self.origin + j * self.step  # the same value for a point two bins share
            edges = (u[0], u[-1]) if self.grows else (0.0,)
            rows = [
                np.column_stack(self.world.solve_on_grid(u, self.contact_length + edge)).tolist()
                for edge in edges
            ]
            self._bins[k] = _Bin(u.tolist(), rows)
        return self._bins[k]

    def at(self, u: float) -> tuple[float, float, float, float, tuple[float, ...]]:
        """(delta, e, P, |R|, strains) at advance ``u`` past contact."""
        pos = (u - self.origin) / self.step  # lattice index, whole on the lattice
        k = max(0, int(pos // self.n))
        local = pos - k * self.n
        i = min(max(int(local), 0), self.n - 1)
        w_u = local - i
        grid, rows = self._bin(k)
        row = _lerp(rows[0][i], rows[0][i + 1], w_u)
        if self.grows:
            w_l = (u - grid[0]) / (grid[-1] - grid[0])
            row = _lerp(row, _lerp(rows[1][i], rows[1][i + 1], w_u), w_l)
        return row[0], row[1], row[2], row[3], tuple(row[4:])

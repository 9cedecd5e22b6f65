"""The simulated world of one trial: where the sensor is, what it presses on, what the fiber sees.

Each board sample asks the world for its state at time ``t``. The world reads the servos' present
positions (through injected callables, so ``sim/`` never imports the control code), places the
sensor with the injected forward kinematics, and solves the quasi-static contact along the sensor
axis (:mod:`sim.contact`) with the tissue's own force law (:mod:`sim.tissue`), which is not the
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

import numpy as np
from numpy.typing import NDArray

from config.scene import FidelityConfig
from config.schema import FbgConfig, SensorConfig
from estimation.beam import Beam
from estimation.elastica import post_buckling
from estimation.section import Section
from sensor.frame import Status
from sim.board import BoardSample
from sim.contact import ContactEffects, solve_contact
from sim.tissue import TissueModel

Vector = NDArray[np.float64]
# (roll rad, translation m) -> (tube tip point, unit tangent, exposed length m)
PoseFn = Callable[[float, float], tuple[Vector, Vector, float]]
JointsFn = Callable[[], tuple[float, float, int]]  # -> (roll rad, translation m, encoder count)

CONTACT_EVENT = Status.CONTACT_EVENT


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


@dataclass(frozen=True)
class WorldState:
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


class World:
    """One trial's world. ``sample(t)`` is the board emulator's source."""

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
    ) -> None:
        self.section = section
        self.sensor = sensor
        self.fbg = fbg
        self.fidelity = fidelity
        self.tissue = tissue
        self.surface = surface
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
        self._centres = np.asarray(sensor.grating_centres_from_tip())
        self._base = np.asarray(
            [fbg.base_wavelengths_nm[g - 1] * 1e-9 for g in sensor.used_gratings]
        )
        self._noise = fidelity.fbg_noise_pm * 1e-12
        self.length_grows = length_grows
        self._table: ContactTable | None = None
        self.last: WorldState | None = None

    # -- physics ------------------------------------------------------------------------------
    def state(self, t: float) -> WorldState:
        roll, translation, encoder = self.joints()
        tip, tangent, length = self.pose(roll, translation)
        r_tip = self.sensor.tip_radius
        n = self.surface.normal
        cos_a = -float(tangent @ n)  # 1 when the sensor points straight into the surface
        centre_height = float((tip - self.surface.point) @ n) - length * cos_a
        past = (r_tip - centre_height) / cos_a if cos_a > 0.05 else -math.inf
        strains: tuple[float, ...] = (0.0,) * len(self._centres)
        delta = e = P = R = 0.0
        if past > 0.0 and length > 0.0:
            if self._table is None:
                self._table = ContactTable(self, length - past, self.length_grows)
            delta, e, P, R, eps = self._table.at(past)
            strains = tuple(float(x) for x in eps)
        event = past > self.contact_offset
        st = WorldState(t, roll, translation, length, past, delta, e, P, R, strains, event, encoder)
        self.last = st
        return st

    def solve_on_grid(self, u: Vector, length: float) -> tuple[Vector, ...]:
        """Equilibrium at advances ``u`` (M,) for one exposed length: delta, e, P, |R|, strains
        (M, G). Raises RuntimeError naming the failure if the contact solver does not converge."""
        beam = Beam(self.section.EI, self.section.EA, self.section.fiber_offset, length)
        sol = solve_contact(u, beam, self.tissue, self.effects)
        if not sol.success:
            raise RuntimeError(f"contact equilibrium failed at L = {length:.6g} m: {sol.message}")
        R = np.abs(sol.R)
        r = R * length**2 / self.section.EI
        g = shortening_for_reaction(r)  # e_g/L of the shape that carries this pin reaction
        half = 0.5 * self.sensor.grating_length
        centres = length - self._centres
        intervals = np.stack([centres - half, np.minimum(centres + half, length)], axis=-1)
        eps = beam.bending_strains(g, intervals)
        eps = eps - (sol.P / self.section.EA)[:, None]
        return sol.delta, sol.e, sol.P, R, eps

    # -- what the board sends ----------------------------------------------------------------
    def sample(self, t: float) -> BoardSample:
        st = self.state(t)
        encoder = st.encoder
        shift = self.fbg.strain_coefficient * np.asarray(st.strains)
        drift = self.fidelity.temperature_drift_degc_per_s * t
        if drift:
            shift = shift + self.fbg.temperature_coefficient * drift
        wl = self._base + shift
        if self._noise > 0:
            wl = wl + self.rng.normal(0.0, self._noise, size=wl.shape)
        reference = None
        if self.fbg.reference_wavelength_nm is not None:
            reference = self.fbg.reference_wavelength_nm * 1e-9
            reference += self.fbg.temperature_coefficient * drift
            if self._noise > 0:
                reference += float(self.rng.normal(0.0, self._noise))
        flags = int(CONTACT_EVENT) if st.contact_event else 0
        force = None
        if self.has_force:
            force = st.P
            flags |= int(Status.FORCE_VALID)
        return BoardSample(
            wavelengths=wl, encoder=encoder, reference=reference, force=force, flags=flags
        )


class ContactTable:
    """Equilibrium tabulated over the advance past contact ``u``, solved lazily in bins.

    A trial visits one path through (u, L): L = L_contact + u on the robot (the sensor slides
    out of the tube), L fixed on the bench. Each bin of ``bin_width`` in u is solved in one
    vectorised call per bin edge length, and values are interpolated linearly in u on a
    ``step`` grid and linearly in L between the edges (error O(dL^2 / L^2) ~ 4e-5 for 0.25 mm
    bins at L = 42 mm). Why: the elastica and contact laws cost ~1 ms per call whatever the
    array size, so one call per sample would make a trial take a minute; a trial touches 2-4
    bins.
    """

    def __init__(
        self,
        world: World,
        contact_length: float,
        grows: bool,
        *,
        bin_width: float = 0.25e-3,
        step: float = 5e-6,
    ) -> None:
        self.world = world
        self.contact_length = contact_length
        self.grows = grows
        self.bin_width = bin_width
        self.n = max(2, round(bin_width / step)) + 1
        self._bins: dict[int, tuple[Vector, list[Vector]]] = {}

    def _bin(self, k: int) -> tuple[Vector, list[Vector]]:
        """Bin ``k``: its u grid (n,) and, per edge length, the rows ``[delta, e, P, |R|,
        strains...]`` on that grid, shape (n, 4 + G)."""
        if k not in self._bins:
            u = np.linspace(k * self.bin_width, (k + 1) * self.bin_width, self.n)
            edges = (k, k + 1) if self.grows else (k,)
            values = [
                np.column_stack(
                    self.world.solve_on_grid(
                        u, self.contact_length + j * self.bin_width * self.grows
                    )
                )
                for j in edges
            ]
            self._bins[k] = (u, values)
        return self._bins[k]

    def at(self, u: float) -> tuple[float, float, float, float, Vector]:
        k = int(u // self.bin_width)
        grid, values = self._bin(k)
        i = min(int((u - grid[0]) / (grid[1] - grid[0])), self.n - 2)
        w_u = (u - grid[i]) / (grid[i + 1] - grid[i])
        row = values[0][i] * (1 - w_u) + values[0][i + 1] * w_u
        if self.grows:
            w_l = (u - grid[0]) / self.bin_width
            hi = values[1][i] * (1 - w_u) + values[1][i + 1] * w_u
            row = row * (1 - w_l) + hi * w_l
        delta, e, P, R = row[:4].tolist()
        return delta, e, P, R, row[4:]

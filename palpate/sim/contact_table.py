"""The contact equilibrium tabulated for a trial: solved on grids, looked up per sample.

:func:`equilibrium_on_grid` solves the beam-tissue equilibrium (:mod:`sim.equilibrium`) at a
grid of advances past contact for one exposed length and turns it into grating strains (cached
per process); :class:`ContactTable` solves it lazily in bins along the trial's path and looks a
sample up in plain floats.

Grating strains. The bending strain of a grating follows the beam's lateral pin reaction ``R``:
for the perfect beam this is the elastica at the solved shortening; for an imperfect beam the
contact solver gives ``R`` of the amplified imperfection, and the strains are those of the
perfect elastica with the same ``R`` (bending moments scale with ``R`` in the first mode)
(:func:`shortening_for_reaction`). The fiber also feels the uniform axial compression
``-P/EA``.
"""

from __future__ import annotations

import functools
from typing import NamedTuple, Protocol

import numpy as np
from numpy.typing import NDArray

from ..estimation.beam.elastica import post_buckling
from ..estimation.beam.model import Beam
from .equilibrium import ContactEffects, TissueLaw, solve_contact
from .oblique import ObliqueContact, slip_law, slip_strains

Vector = NDArray[np.float64]


class GridSolver(Protocol):
    """What a :class:`ContactTable` solves its bins with (``sim.world.World``)."""

    def solve_on_grid(self, u: Vector, length: float) -> tuple[Vector, ...]: ...


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


class GridPhysics(NamedTuple):
    """Everything a table of contact equilibria depends on besides the grid and the length."""

    EI: float
    EA: float
    fiber_offset: float
    grating_length: float
    centres_from_tip: tuple[float, ...]
    tissue: TissueLaw
    effects: ContactEffects
    bending_sign: float = 1.0  # -1: the beam buckles toward the other side (a pre-bend's)


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
    solver does not converge.

    A slipping oblique contact (:mod:`sim.oblique`) replaces the pinned beam by the clamped-free
    beam-column its lateral load makes of it, strains included."""
    beam = Beam(physics.EI, physics.EA, physics.fiber_offset, length)
    tissue = physics.tissue
    oblique = tissue if isinstance(tissue, ObliqueContact) else None
    slip = None if oblique is None else slip_law(oblique, beam.EI, beam.EA, length)
    uu = np.asarray(u, dtype=np.float64)
    sol = solve_contact(uu, beam if slip is None else slip, tissue, physics.effects)
    if not sol.success:
        raise RuntimeError(f"contact equilibrium failed at L = {length:.6g} m: {sol.message}")
    R = np.abs(sol.R)
    if slip is not None and oblique is not None:
        half = 0.5 * physics.grating_length
        from_tip = np.asarray(physics.centres_from_tip)[:, None] + np.array([-half, half])
        bend = slip_strains(oblique, sol.P, beam.EI, physics.fiber_offset, length, from_tip)
        eps = bend - (sol.P / physics.EA)[:, None]
    else:
        eps = grating_strains(physics, beam, sol.P, R)
    out = (sol.delta, sol.e, sol.P, R, eps)
    for a in out:
        a.flags.writeable = False  # shared by every caller of the cache
    return out


class ContactGrid(NamedTuple):
    """The grid solver of one contact's physics (a :class:`GridSolver`)."""

    physics: GridPhysics

    def solve_on_grid(self, u: Vector, length: float) -> tuple[Vector, ...]:
        grid = tuple(np.asarray(u, dtype=np.float64).tolist())
        return equilibrium_on_grid(self.physics, grid, length)


def grating_strains(
    physics: GridPhysics, beam: Beam, P: NDArray[np.float64], R: NDArray[np.float64]
) -> NDArray[np.float64]:
    """The gratings' mean strains (M, G) of the beam carrying axial load ``P`` and pin reaction
    magnitude ``R`` (M,): the bending of the shape with that reaction, minus ``P / EA``."""
    r = R * beam.length**2 / physics.EI
    g = shortening_for_reaction(r)  # e_g/L of the shape that carries this pin reaction
    half = 0.5 * physics.grating_length
    centres = beam.length - np.asarray(physics.centres_from_tip)
    intervals = np.stack([centres - half, np.minimum(centres + half, beam.length)], axis=-1)
    bend = beam.bending_strains(g, intervals)
    if physics.bending_sign < 0:  # the beam buckles toward the other side (a pre-bend's)
        bend = -bend
    return bend - (P / physics.EA)[:, None]


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
        world: GridSolver,
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

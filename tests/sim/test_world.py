"""The simulated world: its fast paths give the very bits of the computation they replace."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from palpate.config import load_stack
from palpate.config.scene import FidelityConfig
from palpate.estimation.beam.model import Beam
from palpate.estimation.beam.section import sensor_section
from palpate.sim.contact_table import ContactTable, equilibrium_on_grid
from palpate.sim.equilibrium import solve_contact
from palpate.sim.tissue import TissueModel
from palpate.sim.world import Surface, World

STACK = load_stack()
SENSOR = STACK.sensor
SECTION = sensor_section(SENSOR)
L = SENSOR.exposed_length
DOWN = np.array([0.0, 0.0, -1.0])
TOUCH = 1e-3  # stage translation (m) at which the tip touches the surface
TISSUE = TissueModel(
    modulus=3.1e5,
    poisson=0.45,
    thickness=10e-3,
    tip_radius=SENSOR.tip_radius,
    large_indentation=True,
)
FIDELITY = FidelityConfig(
    fbg_noise_pm=1.0, imperfection_w0_over_l=0.002, temperature_drift_degc_per_s=0.05
)


def surface() -> Surface:
    """A horizontal surface the sensor (pointing down, tip at -translation) meets at TOUCH."""
    return Surface(point=np.array([0.0, 0.0, -(TOUCH + L + SENSOR.tip_radius)]), normal=-DOWN)


class Stage:
    """Scripted joints and a counting bench pose: the tube tip moves down with the stage."""

    def __init__(self, translations: list[float]) -> None:
        self.translations = translations
        self.k = 0
        self.poses = 0

    def joints(self) -> tuple[float, float, int]:
        x = self.translations[min(self.k, len(self.translations) - 1)]
        self.k += 1
        return 0.0, x, round(x * 1e6)

    def pose(self, roll: float, translation: float) -> tuple[np.ndarray, np.ndarray, float]:
        self.poses += 1
        return translation * DOWN, DOWN, L


def world(stage: Stage, *, seed: int = 0, grows: bool = True, fbg_reference: bool = True) -> World:
    fbg = STACK.fbg
    if fbg_reference:
        fbg = dataclasses.replace(fbg, reference_wavelength_nm=1560.0)
    return World(
        section=SECTION,
        sensor=SENSOR,
        fbg=fbg,
        fidelity=FIDELITY,
        tissue=TISSUE,
        surface=surface(),
        pose=stage.pose,
        joints=stage.joints,
        rng=np.random.default_rng(seed),
        length_grows=grows,
    )


# A stage path that rests (repeated readings) before and after contact and indents ~0.6 mm.
PATH = [0.0, 0.0, 0.5e-3, 0.5e-3, 0.5e-3, *np.linspace(0.9e-3, 1.6e-3, 40).tolist(), 1.6e-3]


def test_resting_servos_reuse_the_last_physics() -> None:
    stage = Stage([1.2e-3, 1.2e-3, 1.2e-3])
    w = world(stage)
    a, b = w.state(0.1), w.state(0.2)
    assert stage.poses == 1
    assert a._replace(t=0.2) == b
    assert b.past_contact > 0
    assert b.P > 0
    w.surface = surface()  # a replaced surface: the kept physics no longer holds
    w.state(0.3)
    assert stage.poses == 2


@pytest.mark.parametrize("grows", [True, False])
def test_kept_physics_is_what_a_fresh_evaluation_gives(grows: bool) -> None:
    kept, fresh = Stage(PATH), Stage(PATH)
    wk, wf = world(kept, grows=grows), world(fresh, grows=grows)
    for k in range(len(PATH)):
        wf.surface = wf.surface  # forget the kept physics: evaluate every sample afresh
        assert wk.state(k * 4e-3) == wf.state(k * 4e-3)
    assert kept.poses < fresh.poses == len(PATH)


@pytest.mark.parametrize("grows", [True, False])
def test_table_lookup_is_the_array_interpolation(grows: bool) -> None:
    w = world(Stage(PATH))
    table = ContactTable(w, L, grows)
    step = table.step
    for u in np.random.default_rng(3).uniform(0.0, 0.6e-3, 25).tolist():
        # the lookup as numpy rows, which the plain-float lookup replaces
        k = int(u // table.bin_width)
        grid = table.origin + np.arange(k * table.n, (k + 1) * table.n + 1) * step
        edges = (grid[0], grid[-1]) if grows else (0.0,)
        values = [np.column_stack(w.solve_on_grid(grid, L + edge)) for edge in edges]
        local = u / step - k * table.n
        i = min(int(local), table.n - 1)
        w_u = local - i
        row = values[0][i] * (1 - w_u) + values[0][i + 1] * w_u
        if grows:
            w_l = (u - grid[0]) / (grid[-1] - grid[0])
            row = row * (1 - w_l) + (values[1][i] * (1 - w_u) + values[1][i + 1] * w_u) * w_l
        delta, e, P, R, strains = table.at(u)
        assert (delta, e, P, R) == tuple(row[:4].tolist())
        assert strains == tuple(row[4:].tolist())


def test_on_the_encoder_lattice_a_lookup_is_the_solved_equilibrium() -> None:
    """With the encoder step known, samples in contact (whole counts from the first) land on
    solved points: no interpolation error in the advance, even at the buckling knee where a
    fixed 5 um grid was off by ~2 ue."""
    step = 20e-3 / 4096
    w = world(Stage(PATH), grows=False)
    w.encoder_step = step
    first = 0.7 * step
    table = ContactTable(w, L, False, lattice=w._lattice(first))
    assert table.origin == pytest.approx(first)
    us = first + np.arange(0, 130, 3) * step  # across the knee (P_cr at ~0.3 mm here)
    exact = np.column_stack(w.solve_on_grid(us, L))
    looked_up = np.array([[*table.at(u)[:4], *table.at(u)[4]] for u in us.tolist()])
    assert np.allclose(looked_up, exact, rtol=1e-9, atol=1e-15)
    off = ContactTable(w, L, False)  # the fixed 5 um grid, for contrast
    off_grid = np.array([[*off.at(u)[:4], *off.at(u)[4]] for u in us.tolist()])
    assert np.max(np.abs(off_grid[:, 4:] - exact[:, 4:])) > 1e-8


def test_a_coarse_contact_grid_is_exact_on_its_points_and_close_between() -> None:
    """``fidelity.contact_grid_um``: the table solves every k-th encoder count (whole counts
    from the first sample in contact) and interpolates between them; its points are the
    lattice table's, the counts between are off by the interpolation, a few ue at most."""
    step = 20e-3 / 4096
    w = world(Stage(PATH), grows=False)
    w.encoder_step = step
    first = 0.7 * step
    w.fidelity = dataclasses.replace(FIDELITY, contact_grid_um=40.0)
    k = round(40e-6 / step)
    coarse = w._lattice(first)
    assert coarse is not None
    assert coarse[0] == pytest.approx(k * step)
    assert coarse[1] == pytest.approx(first)
    table = ContactTable(w, L, False, lattice=coarse)
    us = first + np.arange(0, 130) * step  # every count across the knee
    exact = np.column_stack(w.solve_on_grid(us, L))
    looked_up = np.array([[*table.at(u)[:4], *table.at(u)[4]] for u in us.tolist()])
    on_points = slice(0, None, k)
    assert np.allclose(looked_up[on_points], exact[on_points], rtol=1e-9, atol=1e-15)
    strain_error = np.abs(looked_up[:, 4:] - exact[:, 4:])
    assert np.max(strain_error) > 1e-9  # between the points it is an interpolation
    assert np.max(strain_error) < 20e-6
    load_error = np.abs(looked_up[:, 2] - exact[:, 2])
    assert np.max(load_error) < 0.005 * np.max(exact[:, 2])  # P: within 0.5 % of the range


def test_peaks_are_the_array_expression_with_the_same_noise() -> None:
    stage = Stage(PATH)
    w = world(stage, seed=7)
    twin = np.random.default_rng(7)
    fbg = w.fbg
    assert fbg.reference_wavelength_nm is not None
    base = np.asarray([fbg.base_wavelengths_nm[g - 1] * 1e-9 for g in SENSOR.used_gratings])
    noise = FIDELITY.fbg_noise_pm * 1e-12
    for k in range(len(PATH)):
        t = k * 4e-3
        s = w.sample(t)
        st = w.last
        assert st is not None
        # the array expression and the separate draws the plain-float path replaces
        drift = FIDELITY.temperature_drift_degc_per_s * t
        shift = (
            fbg.strain_coefficient * np.asarray(st.strains) + fbg.temperature_coefficient * drift
        )
        wl = base + shift + twin.normal(0.0, noise, size=base.shape)
        ref = fbg.reference_wavelength_nm * 1e-9
        ref += fbg.temperature_coefficient * drift
        ref += float(twin.normal(0.0, noise))
        assert tuple(s.wavelengths) == tuple(wl.tolist())
        assert s.reference == ref
        assert s.force == st.P
        assert s.encoder == st.encoder


@pytest.mark.parametrize("seed", range(5))
def test_one_draw_of_n_plus_1_is_n_then_1(seed: int) -> None:
    a, b = np.random.default_rng(seed), np.random.default_rng(seed)
    separate = [*a.normal(0.0, 1e-12, size=3).tolist(), float(a.normal(0.0, 1e-12))]
    assert b.normal(0.0, 1e-12, size=4).tolist() == separate
    assert a.random() == b.random()  # and the streams go on in step


def test_tables_are_cached_read_only_and_the_solved_equilibrium() -> None:
    w = world(Stage(PATH))
    u = np.linspace(0.0, 0.25e-3, 51)
    equilibrium_on_grid.cache_clear()
    first = w.solve_on_grid(u, L)
    again = world(Stage(PATH)).solve_on_grid(u.copy(), L)  # another trial, same physics
    assert equilibrium_on_grid.cache_info().hits == 1
    assert all(x is y for x, y in zip(first, again, strict=True))
    assert not any(a.flags.writeable for a in first)
    sol = solve_contact(u, Beam(SECTION.EI, SECTION.EA, SECTION.fiber_offset, L), TISSUE, w.effects)
    assert first[0].tolist() == sol.delta.tolist()
    assert first[2].tolist() == sol.P.tolist()
    assert first[3].tolist() == np.abs(sol.R).tolist()
    other = dataclasses.replace(TISSUE, modulus=2 * TISSUE.modulus)
    w.tissue = other
    assert w.solve_on_grid(u, L)[2].tolist() != first[2].tolist()  # the key holds the tissue

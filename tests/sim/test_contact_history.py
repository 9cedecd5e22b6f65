"""The viscoelastic contact stepped on the clock: the QLV force history, speed, relaxation."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from palpate.config import load_stack
from palpate.config.sample import SampleConfig
from palpate.config.scene import FidelityConfig
from palpate.estimation.beam.section import sensor_section
from palpate.sim.contact_history import ViscoelasticContact, step_law
from palpate.sim.contact_table import GridPhysics, equilibrium_on_grid
from palpate.sim.equilibrium import ContactEffects, TissueLaw
from palpate.sim.sample_law import world_tissue
from palpate.sim.viscoelastic import StandardLinearSolid, ViscoelasticState, force_history
from palpate.sim.world import Surface, World

STACK = load_stack()
SENSOR = STACK.sensor
SECTION = sensor_section(SENSOR)
L = 42e-3
LAW = world_tissue(SampleConfig(name="S", modulus_kpa=400.0), FidelityConfig(), SENSOR.tip_radius)
SLS = StandardLinearSolid(tau=0.5, ratio=0.6)


def physics(law: TissueLaw = LAW, *, rigid_beam: bool = False) -> GridPhysics:
    scale = 1e6 if rigid_beam else 1.0  # a beam that neither shortens nor buckles: u = delta
    return GridPhysics(
        SECTION.EI * scale,
        SECTION.EA * scale,
        SECTION.fiber_offset,
        SENSOR.grating_length,
        tuple(SENSOR.grating_centres_from_tip()),
        law,
        ContactEffects(),
    )


def ramp(contact: ViscoelasticContact, speed: float, depth: float, dt: float = 4e-3) -> list[float]:
    """Forces along a ramp of the advance at ``speed`` (m/s) to ``depth`` (m), touching at 0."""
    contact.release(0.0)
    n = round(depth / speed / dt)
    return [contact.at(k * dt, speed * k * dt, L)[2] for k in range(1, n + 1)]


def test_on_a_rigid_beam_the_force_is_the_qlv_history() -> None:
    """With u = delta, the stepped contact gives sim.viscoelastic's force history exactly."""
    contact = ViscoelasticContact(physics(rigid_beam=True), SLS)
    dt, speed = 4e-3, 0.5e-3
    forces = ramp(contact, speed, 0.6e-3, dt)
    times = dt * np.arange(1, len(forces) + 1)
    expected = force_history(SLS, LAW, np.concatenate([[0.0], times]), np.r_[0.0, speed * times])
    assert forces == pytest.approx(expected[1:].tolist(), rel=1e-6)


def test_an_elastic_ratio_is_the_tabulated_elastic_contact() -> None:
    contact = ViscoelasticContact(physics(), StandardLinearSolid(tau=0.5, ratio=1.0))
    contact.release(0.0)
    u = [k * 2e-5 for k in range(1, 80)]
    stepped = [contact.at(0.01 * k, x, L) for k, x in enumerate(u, start=1)]
    delta, _, P, _, eps = equilibrium_on_grid(physics(), tuple(u), L)
    assert [s[0] for s in stepped] == pytest.approx(delta.tolist(), rel=1e-9, abs=1e-15)
    assert [s[2] for s in stepped] == pytest.approx(P.tolist(), rel=1e-9)
    flat = [x for s in stepped for x in s[4]]
    assert flat == pytest.approx(eps.ravel().tolist(), rel=1e-6, abs=1e-12)


def test_speed_matters_between_the_relaxed_and_instantaneous_laws() -> None:
    """A fast ramp meets E_0, a slow one E_inf (the elastic law is E_0's)."""
    depth = 0.4e-3
    fast = ramp(ViscoelasticContact(physics(rigid_beam=True), SLS), 50e-3, depth, 1e-4)[-1]
    slow = ramp(ViscoelasticContact(physics(rigid_beam=True), SLS), 2e-6, depth, 1.0)[-1]
    elastic = LAW.force_and_stiffness_at(depth)[0]
    assert fast == pytest.approx(elastic, rel=0.01)
    assert slow == pytest.approx(SLS.ratio * elastic, rel=0.01)


def test_a_held_advance_relaxes_and_a_released_tip_lets_the_tissue_recover() -> None:
    contact = ViscoelasticContact(physics(), SLS)
    loaded = ramp(contact, 0.5e-3, 0.8e-3)[-1]
    t0 = 1.6
    held = [contact.at(t0 + 0.1 * k, 0.8e-3, L)[2] for k in range(1, 40)]
    assert held[0] < loaded
    assert all(b < a for a, b in itertools.pairwise(held))
    # 4 s = 8 tau later the tissue has relaxed to E_inf (before buckling delta ~ u)
    assert held[-1] == pytest.approx(SLS.ratio * LAW.force_and_stiffness_at(0.8e-3)[0], rel=0.02)
    for k in range(1, 200):
        contact.release(t0 + 4.0 + 0.1 * k)
    assert contact.state == ViscoelasticState()


def test_the_step_law_is_affine_with_a_gap_and_its_own_inverse() -> None:
    state = ViscoelasticState(elastic_force=0.5, memory=(0.2,))
    law = step_law(SLS, LAW, state, 0.01)
    assert law.b < 0  # the memory is below the last elastic force: the surface lags behind
    gap = law.inverse_at(0.0)
    assert gap > 0
    assert law.force_and_stiffness_at(0.5 * gap) == (0.0, 0.0)
    for force in (0.1, 0.7, 1.3):
        depth = law.inverse_at(force)
        assert law.force_and_stiffness_at(depth)[0] == pytest.approx(force, rel=1e-10)
        assert float(law.inverse(force)) == pytest.approx(depth, rel=1e-12)
    f, k = law.force_and_stiffness(np.array([0.5 * gap, 2 * gap]))
    assert f[0] == 0.0
    assert k[1] > 0


def test_the_world_steps_a_viscoelastic_sample_at_every_sample() -> None:
    """Resting servos: the elastic world keeps its physics, the viscoelastic one relaxes."""
    down = np.array([0.0, 0.0, -1.0])
    touch = 1e-3
    surface = Surface(point=np.array([0.0, 0.0, -(touch + L + SENSOR.tip_radius)]), normal=-down)
    # out of contact, touching, then 0.1 s later 0.5 mm in, where the stage rests
    path = [touch - 1e-4, touch + 1e-9, *[touch + 0.5e-3] * 30]

    def world(relaxation: StandardLinearSolid | None) -> World:
        readings = iter(path)
        return World(
            section=SECTION,
            sensor=SENSOR,
            fbg=STACK.fbg,
            fidelity=FidelityConfig(fbg_noise_pm=0.0),
            tissue=LAW,
            surface=surface,
            pose=lambda roll, x: (x * down, down, L),
            joints=lambda: (0.0, next(readings), 0),
            rng=np.random.default_rng(0),
            length_grows=False,
            relaxation=relaxation,
        )

    elastic, ve = world(None), world(SLS)
    p_elastic = [elastic.state(0.1 * k).P for k in range(len(path))]
    p_ve = [ve.state(0.1 * k).P for k in range(len(path))]
    assert p_elastic[0] == p_ve[0] == 0.0
    assert len(set(p_elastic[2:])) == 1
    assert SLS.ratio * p_elastic[2] < p_ve[2] < p_elastic[2]  # 0.1 s = tau / 5 of relaxation
    assert all(b < a for a, b in itertools.pairwise(p_ve[2:]))
    assert p_ve[-1] == pytest.approx(SLS.ratio * p_elastic[-1], rel=0.02)  # 2.9 s ~ 6 tau

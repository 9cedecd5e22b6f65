"""Oblique contact in the world: a tilted surface changes the force and the buckling load as the
contact model says (sim.oblique), and gravity pre-bends the beam by orientation (sim.gravity)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from palpate.config import load_stack
from palpate.config.scene import FidelityConfig
from palpate.estimation.beam.section import sensor_section
from palpate.sim.contact_table import GridPhysics, equilibrium_on_grid
from palpate.sim.equilibrium import ContactEffects
from palpate.sim.gravity import BeamWeight, offset_to_mode, sensing_axis
from palpate.sim.oblique import ObliqueContact, tangential_ratio
from palpate.sim.tissue import TissueModel
from palpate.sim.world import Surface, World

STACK = load_stack()
SENSOR = STACK.sensor
SECTION = sensor_section(SENSOR)
L = 42e-3
TISSUE = TissueModel(3.1e5, 0.45, 10e-3, True, SENSOR.tip_radius, True, True)
P_PINNED = 20.19 * SECTION.EI / L**2  # clamped-pinned onset
P_FREE = math.pi**2 * SECTION.EI / (4 * L**2)  # clamped-free
U = tuple(np.linspace(0.0, 2.5e-3, 26).tolist())


def _solve(tissue: TissueModel | ObliqueContact) -> tuple[np.ndarray, ...]:
    physics = GridPhysics(
        SECTION.EI, SECTION.EA, SECTION.fiber_offset, SENSOR.grating_length,
        SENSOR.grating_centres_from_tip(), tissue, ContactEffects(None, 0.0),
    )  # fmt: skip
    return equilibrium_on_grid(physics, U, L)


def test_a_sticking_oblique_contact_maps_the_normal_law_onto_the_axis() -> None:
    psi = math.radians(20.0)
    contact = ObliqueContact(TISSUE, psi, friction=0.8, poisson=0.45)
    assert contact.sticks
    assert contact.lean == 0.0
    travel = math.cos(psi) + math.sin(psi) * math.tan(psi) / tangential_ratio(0.45)
    a = np.array([1e-4, 4e-4, 1e-3])
    P, k = contact.force_and_stiffness(a)
    f, kn = TISSUE.force_and_stiffness(a / travel)
    assert np.allclose(P * math.cos(psi), f)  # the normal force is the axial one's share
    assert np.allclose(k, kn / (travel * math.cos(psi)))
    assert np.allclose(contact.inverse(P), a)
    assert contact.force_and_stiffness_at(4e-4) == pytest.approx((P[1], k[1]))
    assert contact.inverse_at(float(P[2])) == pytest.approx(1e-3)


def test_a_tilt_in_stick_keeps_the_buckling_load_and_takes_the_normal_force_with_it() -> None:
    _, _, p0, _, _eps0 = _solve(TISSUE)
    psi = math.radians(20.0)
    _, _, p20, _, _eps20 = _solve(ObliqueContact(TISSUE, psi, 0.8, 0.45))
    # the pinned beam still buckles at P_cr along its axis...
    assert p0[-1] == pytest.approx(p20[-1], rel=0.01)
    assert P_PINNED < p20[-1] < 1.05 * P_PINNED
    # ...while the tissue carries only cos(psi) of it normally: the estimator's force is high
    normal_at_buckling = p20[-1] * math.cos(psi)
    assert normal_at_buckling == pytest.approx(P_PINNED * math.cos(psi), rel=0.05)
    # the tip has to travel further along the axis before buckling at the same axial load
    reach = int(np.argmax(p0 > 0.5 * P_PINNED)), int(np.argmax(p20 > 0.5 * P_PINNED))
    assert reach[1] >= reach[0]


def test_a_slipping_contact_bends_the_beam_at_once_and_lowers_its_capacity() -> None:
    psi = math.radians(25.0)
    slip = ObliqueContact(TISSUE, psi, friction=0.2, poisson=0.45, sensed=1.0)
    assert not slip.sticks
    assert slip.lean == pytest.approx(psi - math.atan(0.2))
    _, _, P, R, eps = _solve(slip)
    assert np.all(P < P_FREE)  # clamped-free capacity, an eighth of the pinned one
    assert P[-1] < 0.5 * P_PINNED
    assert np.allclose(R, P * math.tan(slip.lean))  # the lateral load the beam carries
    bending = eps + (P / SECTION.EA)[:, None]
    assert np.all(np.abs(bending[1:]).max(axis=1) > 0)  # bent from the first touch
    assert np.all(np.diff(np.abs(bending[:, 0])) > 0)


def _world(surface: Surface, roll: float, *, weight: BeamWeight | None = None) -> World:
    tip = np.array([0.08, 0.0, 0.0])
    tangent = np.array([1.0, 0.0, 0.0])
    x = [0.0]

    def pose(r: float, translation: float) -> tuple[np.ndarray, np.ndarray, float]:
        return tip, tangent, translation

    def joints() -> tuple[float, float, int]:
        return roll, x[0], round(x[0] * 1e6)

    w = World(
        section=SECTION, sensor=SENSOR, fbg=STACK.fbg,
        fidelity=FidelityConfig(fbg_noise_pm=0.0, imperfection_w0_over_l=0.002),
        tissue=TISSUE, surface=surface, pose=pose, joints=joints,
        rng=np.random.default_rng(0), encoder_step=1e-6, friction=0.8, weight=weight,
    )  # fmt: skip
    for translation in (L - 1e-3, L + 0.5e-3):
        x[0] = translation
        w.state(0.0)
    return w


def test_the_world_meets_a_tilted_plane_at_its_tilt_and_a_sphere_where_the_axis_hits_it() -> None:
    contact = np.array([0.08 + L + SENSOR.tip_radius, 0.0, 0.0])
    tilt = math.radians(12.0)
    normal = np.array([-math.cos(tilt), 0.0, math.sin(tilt)])
    plane = _world(Surface(point=contact, normal=normal), 0.0)
    assert plane.contacts[0].misalignment == pytest.approx(tilt)
    assert plane.contacts[0].sticks
    # a sphere whose apex faces the axis 5 mm off: the local normal there leans asin(5/40)
    centre = contact + np.array([40e-3, 5e-3, 0.0])
    point = centre + 40e-3 * np.array([-1.0, 0.0, 0.0])
    sphere = _world(Surface(point=point, normal=np.array([-1.0, 0.0, 0.0]), radius=40e-3), 0.0)
    offset = 40e-3 + SENSOR.tip_radius
    assert sphere.contacts[0].misalignment == pytest.approx(math.asin(5e-3 / offset), rel=1e-6)


def test_gravity_pre_bends_the_beam_by_orientation() -> None:
    assert offset_to_mode() == pytest.approx(-0.1385, abs=5e-4)
    weight = BeamWeight.of(SENSOR.tip_mass, SENSOR.linear_mass)
    contact = np.array([0.08 + L + SENSOR.tip_radius, 0.0, 0.0])
    flat = Surface(point=contact, normal=np.array([-1.0, 0.0, 0.0]))
    w0 = {
        name: _world(flat, roll, weight=weight).contacts[0].imperfection
        for name, roll in (("downward", 0.0), ("sideways", math.pi / 2), ("upward", math.pi))
    }
    scene = 0.002 * L
    # the fiber bends in the tube's bend plane: vertical at roll 0 and pi, horizontal sideways
    assert w0["sideways"] == pytest.approx(scene, rel=1e-9)
    sag = weight.across(sensing_axis(np.array([1.0, 0, 0]), 0.0)).pin_offset(SECTION.EI, L)
    assert sag < 0  # the tip hangs below the axis, away from the fiber's side at roll 0
    assert w0["downward"] == pytest.approx(scene + offset_to_mode() * sag, rel=1e-3)
    assert w0["upward"] == pytest.approx(scene - offset_to_mode() * sag, rel=1e-3)
    assert w0["downward"] > scene > w0["upward"]

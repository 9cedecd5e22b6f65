"""Tube kinematics: closed-form geometry, the straight limit, and IK/FK properties."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given
from hypothesis import strategies as st

from palpate.config.schema import DEFAULT_TUBES, TubeConfig
from palpate.robot.kinematics import best_roll, forward, inverse, solve_for_tube, tangent

R_TIP = 3.5e-3
LIMITS = (0.0, 0.08)
BENT = TubeConfig(name="bent50", tip_angle_deg=50.0, straight_length_mm=40, arc_length_mm=40)
STRAIGHT = TubeConfig(name="straight")

tubes = st.sampled_from(DEFAULT_TUBES)
rolls = st.floats(-math.pi, math.pi)
unit_vectors = (
    st.tuples(st.floats(-1, 1), st.floats(-1, 1), st.floats(-1, 1))
    .map(np.array)
    .filter(lambda v: float(np.linalg.norm(v)) > 0.1)
    .map(lambda v: v / np.linalg.norm(v))
)


def _angle(a: np.ndarray, b: np.ndarray) -> float:
    c = float(a @ b) / float(np.linalg.norm(a) * np.linalg.norm(b))
    return math.acos(max(-1.0, min(1.0, c)))


def test_straight_tube() -> None:
    pose = forward(STRAIGHT, 1.234, 0.042)
    np.testing.assert_allclose(pose.tube_tip, [0.08, 0, 0], atol=1e-15)
    np.testing.assert_allclose(pose.tangent, [1, 0, 0], atol=1e-15)
    assert pose.exposed_length == pytest.approx(0.042)
    np.testing.assert_allclose(pose.sensor_tip, [0.122, 0, 0], atol=1e-15)


def test_bent_tube_matches_the_arc_formula() -> None:
    a = math.radians(50.0)
    r = 0.04 / a
    pose = forward(BENT, 0.0, 0.0)
    np.testing.assert_allclose(pose.tube_tip, [0.04 + r * math.sin(a), 0, -r * (1 - math.cos(a))])
    np.testing.assert_allclose(pose.tangent, [math.cos(a), 0, -math.sin(a)])


@pytest.mark.parametrize(
    ("roll", "direction"),
    [(0.0, (0, 0, -1)), (math.pi / 2, (0, 1, 0)), (math.pi, (0, 0, 1))],
    ids=["downward", "sideways(+y)", "upward"],
)
def test_roll_conventions(roll: float, direction: tuple[int, int, int]) -> None:
    pose = forward(BENT, roll, 0.0)
    lateral = pose.tube_tip - np.array([pose.tube_tip[0], 0, 0])
    np.testing.assert_allclose(lateral / np.linalg.norm(lateral), direction, atol=1e-12)


@given(st.floats(0.0, 1e-6), rolls)
def test_stable_as_curvature_goes_to_zero(angle_deg: float, roll: float) -> None:
    tube = TubeConfig(name="almost", tip_angle_deg=angle_deg)
    near, straight = forward(tube, roll, 0.03), forward(STRAIGHT, roll, 0.03)
    assert np.all(np.isfinite(near.tube_tip))
    np.testing.assert_allclose(near.sensor_tip, straight.sensor_tip, atol=1e-9)


@given(tubes, rolls, st.floats(0.0, 0.08))
def test_frame_is_a_rotation_and_the_sensor_leaves_along_it(
    tube: TubeConfig, roll: float, x: float
) -> None:
    pose = forward(tube, roll, x)
    np.testing.assert_allclose(pose.rotation @ pose.rotation.T, np.eye(3), atol=1e-12)
    assert np.linalg.det(pose.rotation) == pytest.approx(1.0)
    np.testing.assert_allclose(pose.tangent, tangent(tube, roll), atol=1e-12)
    np.testing.assert_allclose(
        pose.sensor_tip, pose.tube_tip + pose.exposed_length * pose.tangent, atol=1e-15
    )
    h = pose.transform()
    np.testing.assert_allclose(h[:3, 3], pose.tube_tip)


@given(tubes, unit_vectors)
def test_fk_after_ik_hits_the_direction_within_the_residual(
    tube: TubeConfig, normal: np.ndarray
) -> None:
    roll, residual = best_roll(tube, normal)
    t = forward(tube, roll, 0.0).tangent
    assert _angle(t, -normal) == pytest.approx(residual, abs=1e-7)
    # no other roll does better
    for other in np.linspace(-math.pi, math.pi, 37):
        assert _angle(tangent(tube, float(other)), -normal) >= residual - 1e-9


@given(tubes, rolls, st.floats(0.01, 0.07))
def test_reachable_normals_give_exact_orthogonality(
    tube: TubeConfig, roll: float, advance: float
) -> None:
    assume(tube.tip_angle > 0 or roll == 0.0)
    pose = forward(tube, roll, advance)
    normal = -pose.tangent
    target = pose.sensor_tip - R_TIP * normal  # where the sphere would touch
    sol = solve_for_tube(tube, target, normal, tip_radius=R_TIP, translation_limits=LIMITS)
    assert sol.reachable, sol.reason
    assert sol.residual == pytest.approx(0.0, abs=2e-7)
    fk = forward(tube, sol.roll, sol.advance)
    np.testing.assert_allclose(fk.tangent, -normal, atol=1e-12)
    assert sol.advance == pytest.approx(advance, abs=1e-12)
    assert float(normal @ (fk.sensor_tip - target)) == pytest.approx(R_TIP, abs=1e-12)
    assert sol.miss == pytest.approx(0.0, abs=1e-9)


@given(tubes, unit_vectors, st.floats(-0.05, 0.05), st.floats(-0.05, 0.05))
def test_the_sphere_touches_the_plane_at_the_advance(
    tube: TubeConfig, normal: np.ndarray, y: float, z: float
) -> None:
    target = np.array([0.15, y, z])
    sol = solve_for_tube(tube, target, normal, tip_radius=R_TIP, translation_limits=(-1, 1))
    assume(sol.status in (0, 3))
    fk = forward(tube, sol.roll, sol.advance)
    assert float(normal @ (fk.sensor_tip - target)) == pytest.approx(R_TIP, abs=1e-12)
    np.testing.assert_allclose(sol.contact_point, fk.sensor_tip - R_TIP * normal, atol=1e-15)


@pytest.mark.parametrize("roll", [0.0, math.pi / 2, math.pi], ids=["down", "side", "up"])
@pytest.mark.parametrize("tube", DEFAULT_TUBES[1:], ids=lambda t: t.name)
def test_canonical_trial_orientations_come_out(tube: TubeConfig, roll: float) -> None:
    pose = forward(tube, roll, 0.04)
    sol = inverse(
        DEFAULT_TUBES,
        pose.sensor_tip + R_TIP * pose.tangent,
        -pose.tangent,
        tip_radius=R_TIP,
        translation_limits=LIMITS,
    )
    assert sol.tube == tube.name
    assert sol.roll == pytest.approx(roll, abs=1e-12)
    assert sol.residual == pytest.approx(0.0, abs=1e-7)
    assert sol.reachable


def test_inverse_prefers_the_tube_with_the_smallest_residual() -> None:
    normal = -np.array([math.cos(math.radians(35)), 0.0, -math.sin(math.radians(35))])
    sol = inverse(
        DEFAULT_TUBES,
        np.array([0.2, 0, -0.05]),
        normal,
        tip_radius=R_TIP,
        translation_limits=(0.0, 1.0),
    )
    assert sol.tube == "bent30"
    assert sol.roll == pytest.approx(0.0)
    assert math.degrees(sol.residual) == pytest.approx(5.0)


def test_unreachable_targets_say_why() -> None:
    down = np.array([0.0, 0.0, 1.0])
    facing_away = solve_for_tube(
        STRAIGHT,
        np.array([0.1, 0, 0]),
        np.array([1.0, 0, 0]),
        tip_radius=R_TIP,
        translation_limits=LIMITS,
    )
    assert (facing_away.status, facing_away.reachable) == (1, False)
    assert "away" in facing_away.reason or "into" in facing_away.reason
    too_far = solve_for_tube(
        STRAIGHT,
        np.array([0.5, 0, 0]),
        np.array([-1.0, 0, 0]),
        tip_radius=R_TIP,
        translation_limits=LIMITS,
    )
    assert too_far.status == 3
    behind = solve_for_tube(
        STRAIGHT,
        np.array([0.05, 0, 0]),
        np.array([-1.0, 0, 0]),
        tip_radius=R_TIP,
        translation_limits=LIMITS,
    )
    assert behind.status == 2
    rolled = solve_for_tube(
        BENT,
        np.array([0.1, 0, 0.1]),
        -down,
        tip_radius=R_TIP,
        translation_limits=LIMITS,
        roll_limits=(-1.0, 1.0),
    )
    assert rolled.status == 4
    best = inverse(
        [STRAIGHT],
        np.array([0.5, 0, 0]),
        np.array([-1.0, 0, 0]),
        tip_radius=R_TIP,
        translation_limits=LIMITS,
    )
    assert not best.reachable


def test_bad_input_raises() -> None:
    with pytest.raises(ValueError, match="non-zero"):
        best_roll(BENT, np.zeros(3))
    with pytest.raises(ValueError, match="tip_radius"):
        solve_for_tube(
            BENT, np.zeros(3), np.array([0, 0, 1.0]), tip_radius=-1.0, translation_limits=LIMITS
        )
    with pytest.raises(ValueError, match="at least one"):
        inverse([], np.zeros(3), np.array([0, 0, 1.0]), tip_radius=R_TIP, translation_limits=LIMITS)

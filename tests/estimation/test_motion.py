"""The surface's motion along the axis from a trial's tip-grating record (issue 42): the advance
at one small load on the way in against the way out; and the verdict that says how far it
moved."""

from __future__ import annotations

import numpy as np
import pytest

from palpate.estimation.jointfit import JointFit
from palpate.estimation.pose.motion import surface_motion
from palpate.estimation.verdict import MOTION_SHARE, TrialFacts, judge

K = 30.0  # N/m^1.5: a soft layer's Hertz-like law
TICK = 4e-3


def record(
    drift: float, noise: float = 0.05e-3, seed: int = 0, retract: float = 5e-3
) -> tuple[list[str], np.ndarray, list[float | None], np.ndarray]:
    """A trial against a surface at 10 mm drifting ``drift`` m/s toward the sensor: approach
    at 1 mm/s from 8 mm, indent at 0.5 mm/s to 12 mm, retract at ``retract`` m/s."""
    rng = np.random.default_rng(seed)
    u_in = np.arange(8e-3, 12e-3, 1e-3 * TICK)
    states = ["approach" if u < 10e-3 else "indenting" for u in u_in]
    u_out = np.arange(12e-3, 8e-3, -retract * TICK)
    u = np.concatenate([u_in, u_out])
    states += ["retracting"] * u_out.size
    t = np.arange(u.size) * TICK
    surface = 10e-3 - drift * t
    depth = np.clip(u - surface, 0.0, None)
    loads = K * depth**1.5 + rng.normal(0.0, noise, u.size)
    return states, u, loads.tolist(), t


def test_a_still_surface_does_not_move() -> None:
    states, u, f, t = record(0.0)
    motion = surface_motion(states, u, f, t)
    assert motion is not None
    assert motion.moved == pytest.approx(0.0, abs=40e-6)  # the band's lines' noise


def test_a_drifting_surface_moves_by_its_drift_between_touch_and_release() -> None:
    states, u, f, t = record(0.2e-3)  # 0.2 mm/s toward the sensor
    motion = surface_motion(states, u, f, t)
    assert motion is not None
    assert motion.release > motion.touch
    assert motion.moved == pytest.approx(0.2e-3 * (motion.release - motion.touch), abs=40e-6)
    assert motion.velocity == pytest.approx(0.2e-3, rel=0.15)
    away = surface_motion(*record(-0.2e-3))
    assert away is not None
    assert away.moved < -50e-6


def test_a_retraction_too_fast_for_the_small_loads_is_read_through_a_wider_band() -> None:
    # at 80 mm/s the way out crosses the small loads in one or two records
    states, u, f, t = record(0.2e-3, retract=80e-3)
    motion = surface_motion(states, u, f, t)
    assert motion is not None
    assert motion.moved == pytest.approx(0.2e-3 * (motion.release - motion.touch), abs=40e-6)


def test_no_motion_without_an_approach_or_a_release() -> None:
    states, u, f, t = record(0.0)
    assert surface_motion(["indenting"] * len(states), u, f, t) is None
    n = states.index("retracting")
    assert surface_motion(states[:n], u[:n], f[:n], t[:n]) is None
    assert surface_motion(states, u, [None] * len(f), t) is None


def fit(depth: float) -> JointFit:
    return JointFit(True, "ok", modulus=2e3, ci_low=1.9e3, ci_high=2.1e3, max_depth=depth)


def test_the_verdict_says_how_far_the_surface_moved() -> None:
    facts = TrialFacts(motion=0.3e-3, motion_tolerance=0.2e-3)
    verdict = judge(fit(2e-3), facts, 10e-3)
    assert verdict.status == "suspect"
    assert verdict.reasons[-1].startswith("moved: the surface moved 0.30 mm toward the sensor")
    # within the tolerance but past MOTION_SHARE of a shallow indentation
    shallow = TrialFacts(motion=-0.05e-3, motion_tolerance=0.2e-3)
    reasons = judge(fit(1e-3), shallow, 10e-3).reasons
    assert any(f"{MOTION_SHARE:.0%} of the 1.00 mm indentation" in r for r in reasons)
    assert "away from the sensor" in reasons[-1]
    assert (
        judge(fit(2e-3), TrialFacts(motion=0.05e-3, motion_tolerance=0.2e-3), 10e-3).status == "ok"
    )
    assert (
        judge(fit(2e-3), TrialFacts(motion=5e-3), 10e-3).status == "ok"
    )  # no tolerance: unchecked


def test_a_campaign_expecting_motion_cannot_vouch_for_a_trial_whose_motion_was_not_seen() -> None:
    # a relaxing lung trial in a breath hold (invivo/lumen-2.8-relaxing.yaml, seed 0): its
    # surface moved 0.42 mm, its release could not be matched to its touch, and it read `ok`
    facts = TrialFacts(motion=None, motion_tolerance=0.2e-3)
    verdict = judge(fit(2e-3), facts, 10e-3)
    assert verdict.status == "suspect"
    assert verdict.reasons[-1].startswith("motion not measured")
    assert "0.2 mm tolerance" in verdict.reasons[-1]
    assert judge(fit(2e-3), TrialFacts(motion=None), 10e-3).status == "ok"  # nothing expected

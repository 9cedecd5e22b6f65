"""Sensor design for a modulus range: Hertz inverse, checks, search, and how it fails."""

from __future__ import annotations

import math

import numpy as np
import pytest

from palpate.estimation.beam.elastica import fast
from palpate.estimation.beam.elastica.constants import MODE_REACTION, MODE_SHORTENING
from palpate.estimation.beam.section import composite_section, euler_load
from palpate.estimation.contact.hertz import hertz_force
from palpate.sensor_design import (
    CHECKS,
    DesignConstraints,
    DesignSpace,
    SensorDesign,
    design_sensor,
    evaluate_design,
    hertz_depth,
    imperfection_state,
)

KPA = 1e3
PAPER = SensorDesign(
    fiber_radius=0.115e-3,
    fiber_modulus=67e9,
    wire_count=4,
    wire_radius=0.1e-3,
    wire_modulus=55e9,
    tip_radius=3.5e-3,
    exposed_length=42e-3,
)
# a smaller grid than the default (fewer tips and a coarser length step) keeps the tests quick
SMALL = DesignSpace(
    fiber_radii=(40e-6, 62.5e-6),
    wire_diameters=(25e-6, 50e-6, 100e-6, 200e-6),
    tip_radii=tuple(r * 1e-3 for r in (2.0, 3.0, 4.0, 5.0, 6.0, 8.0)),
    length_step=1e-3,
)


def test_hertz_depth_inverts_hertz_force() -> None:
    E = np.array([1e3, 6e3, 300e3])
    depth = hertz_depth(2e-3, E, 4e-3, 0.45)
    np.testing.assert_allclose(hertz_force(E, depth, 4e-3, 0.45), 2e-3, rtol=1e-12)
    with pytest.raises(ValueError, match="modulus"):
        hertz_depth(1e-3, 0.0, 4e-3, 0.45)


def test_first_mode_constants_match_the_elastica_at_onset() -> None:
    """The mode constants are consistent with the elastica: near onset |r| = MODE_REACTION A/L
    and e/L = MODE_SHORTENING (A/L)**2, so |r| / sqrt(e/L) = MODE_REACTION / sqrt(c)."""
    g = 1e-10
    slope = float(abs(fast.reaction(np.array(g)))) / math.sqrt(g)
    assert slope == pytest.approx(MODE_REACTION / math.sqrt(MODE_SHORTENING), rel=1e-4)
    assert pytest.approx(2.581572061251422, rel=1e-14) == MODE_SHORTENING  # mpmath, 40 digits
    assert pytest.approx(14.439365739198137, rel=1e-14) == MODE_REACTION


def test_bow_shortening_is_the_first_modes() -> None:
    w0, x = 1e-3, 0.9
    e_equiv, e_imp = imperfection_state(w0, x)
    assert e_imp == pytest.approx(MODE_SHORTENING * w0**2 * ((1 - x) ** -2 - 1), rel=1e-14)
    assert e_equiv == pytest.approx(MODE_SHORTENING * (w0 * x / (1 - x)) ** 2, rel=1e-14)
    assert imperfection_state(0.0, x) == (0.0, 0.0)


def test_paper_sensor_on_the_papers_range_is_outside_hertz() -> None:
    c = DesignConstraints(thickness=10e-3)  # the simulated phantoms' 10 mm layers
    ev = evaluate_design(PAPER, (300 * KPA, 1100 * KPA), c)
    section = composite_section(0.115e-3, 67e9, 0.1e-3, 55e9, 4)
    assert ev.critical_load == pytest.approx(euler_load(section.EI, 42e-3), rel=1e-12)
    assert ev.critical_load == pytest.approx(1.353, abs=1e-3)
    # the Hertz sphere carries P_cr at both ends; depths scale as E**(-2/3)
    for E, delta in ((300 * KPA, ev.delta_soft), (1100 * KPA, ev.delta_stiff)):
        assert float(hertz_force(E, delta, 3.5e-3, 0.45)) == pytest.approx(ev.critical_load)
    assert ev.delta_soft / ev.delta_stiff == pytest.approx((1100 / 300) ** (2 / 3))
    assert ev.delta_soft == pytest.approx(1.276e-3, rel=1e-3)
    checks = {ch.name: ch for ch in ev.checks}
    assert list(checks) == [c for c in CHECKS if c not in ("force", "weight")]  # opt-in checks
    # within the exact law's trusted domain (Hertz's a/h = 0.21 and delta/R = 0.36 were not)
    assert checks["depth"].value == pytest.approx(0.3647, rel=1e-3)
    assert checks["depth"].ok
    assert checks["thickness"].value == pytest.approx(0.1276, rel=1e-3)  # delta/h
    assert checks["thickness"].ok
    assert checks["resolution"].ok  # 0.54 mm is 110 encoder counts
    assert checks["detection"].ok


def test_a_design_for_the_papers_range_is_hertz_valid() -> None:
    result = design_sensor((300 * KPA, 1100 * KPA), DesignConstraints(thickness=10e-3), SMALL)
    assert result.success, result.message
    ev = result.evaluation
    assert ev is not None
    assert ev.depth_ratio <= 0.5
    assert ev.contact_ratio <= 0.2


def test_a_feasible_soft_tissue_design() -> None:
    c = DesignConstraints(imperfection=5e-4)
    result = design_sensor((1 * KPA, 10 * KPA), c, SMALL)
    assert result.success, result.message
    ev = result.evaluation
    assert ev is not None
    assert result.design == ev.design
    assert ev.ok
    assert all(ch.margin >= 1.0 for ch in ev.checks)
    d = ev.design
    assert d.wire_count >= 1  # a bare fiber has no offset from the neutral axis: no signal
    # buckling is Hertz-valid at the soft end and measurable at the stiff end
    assert ev.depth_ratio <= 0.5
    assert ev.delta_soft <= 0.2 * 20e-3
    assert ev.delta_stiff >= 20 * 20e-3 / 4096
    assert float(hertz_force(1 * KPA, ev.delta_soft, d.tip_radius, 0.45)) == pytest.approx(
        ev.critical_load
    )
    # tens of millinewtons: two orders of magnitude below the paper's sensor
    assert 1e-4 < ev.critical_load < 1e-1
    assert ev.threshold is not None
    assert ev.detection_floor < ev.detection_strain
    assert 0 < ev.bow_strain <= ev.threshold  # a bowed beam must not trip it before 0.9 P_cr
    assert ev.threshold >= math.sqrt(ev.detection_floor * ev.detection_strain)
    assert result.length_window is not None
    lo, hi = result.length_window
    assert lo <= d.exposed_length <= hi
    # the window is where that hardware passes: just outside it, something fails
    for L in (lo - SMALL.length_step, hi + SMALL.length_step):
        if SMALL.length_range[0] <= L <= SMALL.length_range[1] and L > 27.5e-3:
            outside = SensorDesign(**{**d.__dict__, "exposed_length": L})
            assert not evaluate_design(outside, (1 * KPA, 10 * KPA), c).ok


def test_softer_tissue_gets_a_more_flexible_sensor() -> None:
    loads = []
    for lo in (1.0, 10.0, 100.0):
        result = design_sensor((lo * KPA, 3 * lo * KPA), space=SMALL)
        assert result.success, result.message
        assert result.evaluation is not None
        loads.append(result.evaluation.critical_load)
    assert loads[0] < loads[1] < loads[2]
    # P_cr tracks the modulus: a decade softer, roughly a decade lower buckling load
    assert 2 < loads[1] / loads[0] < 30
    assert 2 < loads[2] / loads[1] < 30


def test_a_range_too_wide_for_any_sensor_says_why() -> None:
    result = design_sensor((1 * KPA, 1000 * KPA), space=SMALL)
    assert not result.success
    assert result.design is None
    assert result.length_window is None
    assert "too wide for any sensor" in result.message
    assert "100" in result.message  # (E_max / E_min)**(2/3), the depth ratio it needs
    assert result.evaluation is not None
    assert not result.evaluation.ok
    assert result.feasible == 0
    assert result.failures["depth"] > 0


def test_a_bowed_sensor_is_rejected_by_the_bias_check() -> None:
    result = design_sensor((1 * KPA, 10 * KPA), DesignConstraints(imperfection=5e-3), SMALL)
    assert not result.success
    assert "too wide" not in result.message  # the depth window alone would allow it
    assert "delta_bias" in result.message


def test_a_bare_fiber_cannot_see_buckling() -> None:
    space = DesignSpace(fiber_radii=(40e-6,), wire_counts=(0,), length_step=1e-3)
    result = design_sensor((1 * KPA, 10 * KPA), space=space)
    assert not result.success
    assert "detection" in result.message
    assert result.evaluation is not None
    assert result.evaluation.detection_strain < result.evaluation.detection_floor
    assert result.evaluation.threshold is None


def test_bad_inputs_raise() -> None:
    with pytest.raises(ValueError, match="modulus range"):
        design_sensor((10 * KPA, 1 * KPA), space=SMALL)
    with pytest.raises(ValueError, match="wire_counts"):
        DesignSpace(wire_counts=(-1,))
    with pytest.raises(ValueError, match="poisson"):
        DesignConstraints(poisson=0.7)
    short = SensorDesign(**{**PAPER.__dict__, "exposed_length": 20e-3})
    with pytest.raises(ValueError, match="gratings inside the tube"):
        evaluate_design(short, (1 * KPA, 10 * KPA))


def test_the_tip_grating_is_the_most_sensitive_whose_range_carries_twice_p_cr() -> None:
    from palpate.sensor_design.tipgrating import choose_tip_grating

    lung = choose_tip_grating(18e-3, 1.0)  # the 1-20 kPa design: P_cr 18 mN, 1 pm of noise
    assert lung.sensitivity_pm_per_mn == 8.0
    assert lung.range_mn >= 2 * 18.0
    assert lung.resolution_mn == pytest.approx(0.125)
    assert lung.compliance_mm_per_n == pytest.approx(3e-3 * 8.0 / 1.2 * 1e-6 * 1e6)  # L s / k
    stiff = choose_tip_grating(0.6, 1.0)  # 1.2 N in a 2 nm window: the coarsest element
    assert stiff.sensitivity_pm_per_mn == 1.0
    with pytest.raises(ValueError, match="carries"):
        choose_tip_grating(1.35, 1.0)  # the paper's sensor: 2.7 N needs a stiffer element


def test_the_weight_check_is_the_cantilevers_sag_and_its_tip_budget() -> None:
    from palpate.estimation.beam.section import composite_section
    from palpate.sensor_design.weight import SAG_LIMIT, STANDARD_GRAVITY, weight_check

    EI = composite_section(40e-6, 67e9, 25e-6, 55e9, 2).EI  # the 1-20 kPa design's beam
    L = 28.5e-3
    check = weight_check(0.05e-3, 0.0, EI, L)
    assert check.sag == pytest.approx(0.05e-3 * STANDARD_GRAVITY * L**3 / (3 * EI))
    p_cr = 20.19 * EI / L**2
    assert check.sag_over_length == pytest.approx(20.19 / 3 * 0.05e-3 * 9.80665 / p_cr, 1e-3)
    assert not check.ok
    at_limit = weight_check(check.tip_mass_limit, 0.0, EI, L)
    assert at_limit.sag_over_length == pytest.approx(SAG_LIMIT)
    with pytest.raises(ValueError, match="EI"):
        weight_check(1e-4, 0.0, 0.0, L)


def test_a_beam_softer_across_the_fibers_plane_fails_the_plane_check() -> None:
    """A beam buckles about its softest axis: the gratings see only their own plane's bending."""
    from palpate.estimation.beam.section import across_rigidity, composite_section

    paper = composite_section(115e-6, 67e9, 100e-6, 55e9, 4)
    assert across_rigidity(115e-6, 67e9, 100e-6, 55e9, 4) / paper.EI == pytest.approx(
        3.15, abs=0.01
    )
    bare = across_rigidity(40e-6, 67e9, 25e-6, 55e9, 0)
    assert bare == pytest.approx(67e9 * math.pi * (40e-6) ** 4 / 4)
    thin = SensorDesign(40e-6, 67e9, 2, 25e-6, 55e9, 10e-3, 28.5e-3)  # the first 1-20 kPa proposal
    plane = next(c for c in evaluate_design(thin, (1e3, 20e3)).checks if c.name == "plane")
    assert plane.value == pytest.approx(0.42, abs=0.01)
    assert not plane.ok
    wide = SensorDesign(40e-6, 67e9, 4, 37.5e-6, 55e9, 10e-3, 45e-3)  # the design it proposes now
    assert next(c for c in evaluate_design(wide, (1e3, 20e3)).checks if c.name == "plane").ok

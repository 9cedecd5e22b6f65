"""A sensor through a working channel: what passes, the force-resolution check and the span
of a modulus range one sensor cannot cover (``design.lumen``)."""

from __future__ import annotations

import math

import pytest

from palpate.sensor_design import DesignConstraints, DesignSpace, design_sensor
from palpate.sensor_design.lumen import Lumen, bundle, span_range
from palpate.sensor_design.tipgrating import tip_grating_for_resolution

KPA = 1e3
# a coarse grid of hardware keeps each search short; the lumen adds its largest tip
SPACE = DesignSpace(wire_diameters=(25e-6, 50e-6, 75e-6), length_step=2e-3)


def test_only_what_passes_the_channel_is_searched() -> None:
    lumen = Lumen(2.8e-3)
    assert lumen.passage == pytest.approx(2.6e-3)
    assert lumen.largest_tip() == pytest.approx(1.3e-3)
    space = lumen.space(DesignSpace())
    assert max(space.tip_radii) == pytest.approx(1.3e-3)
    assert all(2 * r <= lumen.passage * (1 + 1e-12) for r in space.tip_radii)
    # a row of four 200 um wires under a 230 um fiber is 0.9 mm across: it passes 2.8 mm
    assert bundle(115e-6, 4, 200e-6) == pytest.approx(math.hypot(0.8e-3, 0.43e-3))
    assert space.wire_diameters == DesignSpace().wire_diameters
    # through 0.4 mm a row of four 75 um wires under the 230 um fiber (0.43 mm) does not pass
    narrow = Lumen(0.5e-3, clearance=0.1e-3).space(DesignSpace())
    assert max(narrow.wire_diameters) == pytest.approx(50e-6)
    assert narrow.tip_radii == (0.2e-3,)
    with pytest.raises(ValueError, match="no tip sphere passes"):
        Lumen(0.08e-3, clearance=0.0).space(DesignSpace())
    with pytest.raises(ValueError, match="clearance"):
        Lumen(2e-3, clearance=2e-3)


def test_the_force_check_bounds_p_cr_by_the_tip_gratings_resolution() -> None:
    c = DesignConstraints(tip_force_resolution=0.25e-3)
    # the contact at 5 sigma (1.25 mN) may sink the tip half its depth at buckling: P_cr >=
    # 1.25 mN / 0.5**1.5
    assert c.smallest_critical_load == pytest.approx(5 * 0.25e-3 / 0.5**1.5)
    assert DesignConstraints().smallest_critical_load == 0.0
    space = Lumen(2.8e-3).space(SPACE)
    fine = design_sensor((5 * KPA, 20 * KPA), DesignConstraints(max_depth_ratio=1.0), space)
    assert fine.success
    assert fine.evaluation is not None
    assert "force" not in {ch.name for ch in fine.evaluation.checks}
    # a grating too coarse for this beam: the closest candidate fails the force check
    coarse = DesignConstraints(max_depth_ratio=1.0, tip_force_resolution=5e-3)
    refused = design_sensor((5 * KPA, 20 * KPA), coarse, space)
    assert not refused.success
    assert refused.evaluation is not None
    assert "force" in {ch.name for ch in refused.evaluation.failed}
    with pytest.raises(ValueError, match="tip_force_resolution"):
        DesignConstraints(tip_force_resolution=0.0)


def test_a_range_one_sensor_cannot_span_is_split_where_the_limits_bind() -> None:
    c = DesignConstraints(max_depth_ratio=1.0, tip_force_resolution=0.05e-3)
    space = Lumen(2.8e-3).space(SPACE)
    span = span_range((1 * KPA, 20 * KPA), c, space)
    assert not span.one_sensor
    assert span.ranges
    assert span.designs
    assert len(span.ranges) == len(span.designs)
    lo, hi = span.ranges[0]
    # below lo no sensor through the channel works: its softest beam sinks the tip past
    # delta/R = 1 (the beam cannot be softer and still buckle in the gratings' plane)
    assert 1 * KPA < lo < 5 * KPA
    assert "depth" in span.lowest_blocked
    assert not design_sensor((lo / 1.05, lo / 1.05), c, space).success
    first = span.designs[0]
    assert first.success
    assert first.evaluation is not None
    assert first.evaluation.modulus_range == (lo, hi)
    assert first.evaluation.depth_ratio <= 1.0 + 1e-9
    assert 2 * first.evaluation.design.tip_radius <= 2.6e-3 + 1e-12
    # the ranges follow one another up to what they cover
    assert all(a[1] == b[0] for a, b in zip(span.ranges, span.ranges[1:], strict=False))
    assert span.covered is not None
    assert span.covered[0] == lo


def test_a_range_one_sensor_spans_is_one_range() -> None:
    c = DesignConstraints(max_depth_ratio=1.0, tip_force_resolution=0.05e-3)
    span = span_range((8 * KPA, 16 * KPA), c, Lumen(2.8e-3).space(SPACE))
    assert span.one_sensor
    assert span.ranges == ((8 * KPA, 16 * KPA),)
    assert span.lowest_blocked == ()
    assert span.top_blocked == ()


def test_a_published_resolution_sets_the_tip_gratings_sensitivity() -> None:
    tip = tip_grating_for_resolution(4e-3, 1.0, 0.05e-3)
    assert tip.sensitivity_pm_per_mn == pytest.approx(20.0)
    assert tip.resolution_mn == pytest.approx(0.05)
    assert tip.range_mn == pytest.approx(100.0)
    assert tip.resolution_share == pytest.approx(0.05 / 4.0)
    with pytest.raises(ValueError, match="less than"):
        tip_grating_for_resolution(4e-3, 1.0, 0.001e-3)  # 1000 pm/mN reaches 2 mN


def test_the_binding_checks_are_those_whose_relaxing_alone_lets_a_candidate_pass() -> None:
    from palpate.sensor_design.search import binding_checks

    c = DesignConstraints(max_depth_ratio=1.0, tip_force_resolution=0.05e-3)
    space = Lumen(2.8e-3).space(SPACE)
    assert binding_checks((8 * KPA, 16 * KPA), c, space) == ()
    binding = binding_checks((1 * KPA, 1 * KPA), c, space)
    assert "depth" in binding
    for name in binding:  # relaxing that one check alone lets a sensor reach 1 kPa
        relaxed = DesignConstraints(max_depth_ratio=1e6 if name == "depth" else 1.0,
                                    plane_margin=1e-6 if name == "plane" else 2.0,
                                    tip_force_resolution=0.05e-3)  # fmt: skip
        if name in ("depth", "plane"):
            assert design_sensor((1 * KPA, 1 * KPA), relaxed, space).success


def test_held_across_a_sensor_must_carry_its_own_weight() -> None:
    from palpate.sensor_design import evaluate_design
    from palpate.sensor_design.weight import SAG_LIMIT, weight_check

    c = DesignConstraints(max_depth_ratio=1.0, held_across=True)
    space = Lumen(2.8e-3).space(SPACE)
    found = design_sensor((20 * KPA, 20 * KPA), c, space)
    assert found.success
    assert found.evaluation is not None
    weight = {ch.name: ch for ch in found.evaluation.checks}["weight"]
    d = found.evaluation.design
    tip_mass = c.tip_density * 4 / 3 * math.pi * d.tip_radius**3
    sag = weight_check(tip_mass, d.linear_mass(), d.section().EI, d.exposed_length)
    assert weight.value == pytest.approx(sag.sag_over_length)
    assert weight.value <= SAG_LIMIT
    # the 100 mm beam that reaches 1.42 kPa held vertically sags a quarter of its length
    soft = span_range((1 * KPA, 20 * KPA), DesignConstraints(max_depth_ratio=1.0), space)
    ev = evaluate_design(soft.designs[0].evaluation.design, soft.ranges[0], c)  # type: ignore[union-attr]
    assert not {ch.name: ch for ch in ev.checks}["weight"].ok
    assert not design_sensor((1 * KPA, 20 * KPA), c, space).success

"""The dimensional beam: load against shortening, inverses, lateral force, grating strains."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from palpate.estimation.beam.elastica import E_OVER_L_MAX, E_OVER_L_PEAK, post_buckling
from palpate.estimation.beam.model import Beam
from palpate.estimation.beam.section import composite_section, euler_load

SECTION = composite_section(0.115e-3, 67e9, 0.1e-3, 55e9, 4)
L = 0.042
BEAM = Beam.from_section(SECTION, L)
# Paper gratings: 3 mm, centred 10, 18, 26 mm from the tip.
GRATINGS = np.array([[L - d - 1.5e-3, L - d + 1.5e-3] for d in (10e-3, 18e-3, 26e-3)])


def test_scalars() -> None:
    assert BEAM.critical_load() == pytest.approx(euler_load(SECTION.EI, L), rel=1e-15)
    assert BEAM.critical_shortening() == pytest.approx(BEAM.critical_load() * L / SECTION.EA)
    assert BEAM.peak_load() == pytest.approx(23.0096 * SECTION.EI / L**2, rel=1e-5)
    assert BEAM.max_shortening() == pytest.approx(E_OVER_L_MAX * L)


def test_force_is_continuous_at_onset_and_follows_both_regimes() -> None:
    e_cr = BEAM.critical_shortening()
    e = e_cr * np.array([0.0, 0.5, 1.0 - 1e-12, 1.0, 1.0 + 1e-12])
    P = BEAM.force(e)
    np.testing.assert_allclose(P[:3], SECTION.EA * e[:3] / L, rtol=1e-15)
    np.testing.assert_allclose(P[2:], BEAM.critical_load(), rtol=1e-10)
    # After buckling: e = P L / EA + e_g with P from the elastica at e_g.
    e_g = np.array([1e-8, 1e-4, 0.01, 0.3, E_OVER_L_PEAK, 0.7]) * L
    p = post_buckling(e_g / L).p * SECTION.EI / L**2
    np.testing.assert_allclose(BEAM.force(p * L / SECTION.EA + e_g), p, rtol=1e-9)
    np.testing.assert_allclose(
        BEAM.geometric_shortening(p * L / SECTION.EA + e_g), e_g / L, rtol=1e-9, atol=1e-15
    )


def test_lateral_force() -> None:
    assert float(BEAM.lateral_force(0.5 * BEAM.critical_shortening())) == 0.0
    e_g = 0.01
    sol = post_buckling(e_g)
    e = float(sol.p) * BEAM.slenderness_ratio * L + e_g * L
    assert float(BEAM.lateral_force(e)) == pytest.approx(float(sol.r) * SECTION.EI / L**2, rel=1e-9)


@given(frac=st.floats(0.0, 1.0))
def test_shortening_inverts_force_on_the_rising_branch(frac: float) -> None:
    e = frac * (E_OVER_L_PEAK + BEAM.slenderness_ratio * 23.0) * L * 0.999
    P = BEAM.force(e)
    assert float(BEAM.shortening(P)) == pytest.approx(e, rel=1e-7, abs=1e-12 * L)


@given(frac=st.floats(0.0, 1.0), branch=st.sampled_from(["rising", "falling"]))
def test_force_inverts_shortening_on_both_branches(frac: float, branch: str) -> None:
    P = frac * BEAM.peak_load()
    e = BEAM.shortening(P, branch=branch)  # type: ignore[arg-type]
    assert float(BEAM.force(e)) == pytest.approx(P, rel=1e-9, abs=1e-12 * BEAM.peak_load())


def test_branches_differ_below_the_peak() -> None:
    P = BEAM.critical_load()
    assert float(BEAM.shortening(P, "rising")) == pytest.approx(BEAM.critical_shortening())
    assert float(BEAM.shortening(P, "falling")) > 0.5 * L
    assert float(BEAM.shortening(0.0, "falling")) == pytest.approx(BEAM.max_shortening(), rel=1e-9)


def test_grating_strains_follow_eq_3_and_12() -> None:
    e = np.array([0.0, 0.9 * BEAM.critical_shortening(), 1e-3, 1e-2])
    strains = BEAM.grating_strains(e, GRATINGS)
    assert strains.shape == (4, 3)
    assert np.all(strains[:2] == 0.0)  # no bending before buckling
    g = BEAM.geometric_shortening(e[2:])
    ref = post_buckling(g[:, None]).mean_curvature(GRATINGS[:, 0] / L, GRATINGS[:, 1] / L)
    np.testing.assert_allclose(strains[2:], SECTION.fiber_offset * ref / L, rtol=1e-9)
    assert np.all(strains[2:] > 0)  # main lobe, fiber_offset > 0
    axial = BEAM.grating_strains(e, GRATINGS, include_axial=True) - strains
    expected = np.broadcast_to(-(BEAM.force(e) / SECTION.EA)[:, None], axial.shape)
    np.testing.assert_allclose(axial, expected, rtol=1e-12)


def test_grating_partly_inside_the_tube_is_straight_there() -> None:
    e = 5e-3
    inside = BEAM.grating_strains(e, np.array([[-1e-3, 2e-3]]))
    exposed = BEAM.grating_strains(e, np.array([[0.0, 2e-3]]))
    assert float(inside[0]) == pytest.approx(float(exposed[0]) * 2 / 3, rel=1e-12)
    assert float(BEAM.grating_strains(e, np.array([[-3e-3, -1e-3]]))[0]) == 0.0


@pytest.mark.parametrize("length", [5e-3, 1.0])
def test_very_short_and_very_long_beams(length: float) -> None:
    beam = Beam.from_section(SECTION, length)
    e_cr = beam.critical_shortening()
    e = np.array([0.5 * e_cr, e_cr, 1.001 * e_cr, 2.0 * e_cr, 0.3 * beam.max_shortening()])
    P = beam.force(e)
    assert np.all(np.diff(P) > 0)
    np.testing.assert_allclose(beam.shortening(P), e, rtol=1e-7)
    assert float(beam.force(beam.max_shortening())) == pytest.approx(0.0, abs=1e-9 * P[-1])


def test_bad_input() -> None:
    with pytest.raises(ValueError, match=r"^e "):
        BEAM.force(-1e-6)
    with pytest.raises(ValueError, match=r"^e "):
        BEAM.force(math.nan)
    with pytest.raises(ValueError, match=r"^e "):
        BEAM.force(BEAM.max_shortening() * 1.01)
    with pytest.raises(ValueError, match=r"^P "):
        BEAM.shortening(BEAM.peak_load() * 1.01)
    with pytest.raises(ValueError, match=r"^branch "):
        BEAM.shortening(1.0, "sideways")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match=r"^length "):
        Beam(EI=1.0, EA=1.0, fiber_offset=0.0, length=0.0)
    with pytest.raises(ValueError, match=r"too short"):
        Beam.from_section(SECTION, 2e-4)
    with pytest.raises(ValueError, match=r"^intervals"):
        BEAM.grating_strains(1e-3, np.array([[0.01, 0.005]]))
    with pytest.raises(ValueError, match=r"^intervals"):
        BEAM.grating_strains(1e-3, np.array([[0.04, 0.05]]))

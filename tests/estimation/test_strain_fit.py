"""fit_strains: recovers the state from noise-free strains; straight beams and bad input."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from palpate.estimation.beam.elastica import E_OVER_L_MAX
from palpate.estimation.beam.model import Beam
from palpate.estimation.beam.section import composite_section
from palpate.estimation.fits.strain_fit import fit_strains

SECTION = composite_section(0.115e-3, 67e9, 0.1e-3, 55e9, 4)
L = 0.042
BEAM = Beam.from_section(SECTION, L)
GRATINGS = np.array([[L - d - 1.5e-3, L - d + 1.5e-3] for d in (10e-3, 18e-3, 26e-3)])


@given(
    log_e=st.floats(-7.0, np.log10(0.9 * E_OVER_L_MAX * L)),
    sign=st.sampled_from([1.0, -1.0]),
    axial=st.booleans(),
)
def test_fit_recovers_e_from_noise_free_strains(log_e: float, sign: float, axial: bool) -> None:
    beam = Beam(SECTION.EI, SECTION.EA, sign * SECTION.fiber_offset, L)  # either dy_fbg sign
    e = max(10.0**log_e, 1.001 * beam.critical_shortening())
    strains = beam.grating_strains(e, GRATINGS, include_axial=axial)
    fit = fit_strains(beam, strains, GRATINGS, include_axial=axial)
    assert fit.success, fit.message
    assert fit.buckled, fit.message
    assert fit.direction == 1
    assert fit.e == pytest.approx(e, rel=1e-6)
    assert pytest.approx(float(beam.force(e)), rel=1e-8) == fit.P
    assert fit.residual < 1e-9 * np.abs(strains).max()


def test_mirror_image_is_detected() -> None:
    e = 2e-3
    fit = fit_strains(BEAM, -BEAM.grating_strains(e, GRATINGS), GRATINGS)
    assert fit.direction == -1
    assert fit.e == pytest.approx(e, rel=1e-8)


def test_weights_and_noise() -> None:
    rng = np.random.default_rng(1)
    e = 3e-3
    clean = BEAM.grating_strains(e, GRATINGS)
    noisy = clean + rng.normal(0, 5e-6, 3)
    fit = fit_strains(BEAM, noisy, GRATINGS, sigma=np.full(3, 5e-6))
    assert fit.success
    assert fit.e == pytest.approx(e, rel=0.05)
    assert 0 < fit.residual < 2e-5


def test_all_zero_strains_are_a_straight_beam() -> None:
    fit = fit_strains(BEAM, np.zeros(3), GRATINGS)
    assert fit.success
    assert not fit.buckled
    assert BEAM.critical_load() == fit.P
    assert fit.e == BEAM.critical_shortening()
    assert "only bounded" in fit.message


def test_straight_beam_with_axial_strain() -> None:
    e = 0.5 * BEAM.critical_shortening()
    strains = BEAM.grating_strains(e, GRATINGS, include_axial=True)
    fit = fit_strains(BEAM, strains, GRATINGS, include_axial=True)
    assert not fit.buckled
    assert fit.e == pytest.approx(e, rel=1e-12)
    assert pytest.approx(float(BEAM.force(e)), rel=1e-12) == fit.P


def test_bad_input() -> None:
    with pytest.raises(ValueError, match=r"^strains"):
        fit_strains(BEAM, np.zeros(1), GRATINGS[:1])
    with pytest.raises(ValueError, match=r"^strains"):
        fit_strains(BEAM, np.zeros(2), GRATINGS)
    with pytest.raises(ValueError, match=r"^strains"):
        fit_strains(BEAM, np.array([0.0, np.nan, 0.0]), GRATINGS)
    with pytest.raises(ValueError, match=r"^sigma"):
        fit_strains(BEAM, np.zeros(3), GRATINGS, sigma=0.0)
    with pytest.raises(ValueError, match=r"^fiber_offset"):
        fit_strains(Beam(SECTION.EI, SECTION.EA, 0.0, L), np.zeros(3), GRATINGS)

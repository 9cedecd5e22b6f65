"""Axial load and shortening from grating strains with a free axial load
(estimation.beam.states)."""

from __future__ import annotations

import numpy as np
import pytest

from palpate.estimation.beam.model import Beam
from palpate.estimation.beam.section import composite_section
from palpate.estimation.beam.states import infer_states

SECTION = composite_section(0.115e-3, 67e9, 0.1e-3, 55e9, 4)
CENTRES_FROM_TIP = np.array([10e-3, 18e-3, 26e-3])


def intervals(L: float) -> np.ndarray:
    c = L - CENTRES_FROM_TIP
    return np.stack([c - 1.5e-3, c + 1.5e-3], axis=1)


def test_recovers_load_and_shortening_before_and_after_buckling() -> None:
    L = 44e-3
    beam = Beam.from_section(SECTION, L)
    e = np.concatenate(
        [np.linspace(0.0, 0.99, 5) * beam.critical_shortening(), np.geomspace(1e-6, 5e-4, 12)]
    )
    eps = beam.grating_strains(e, intervals(L), include_axial=True)
    st = infer_states(eps, intervals(L), L, SECTION.EA, SECTION.fiber_offset, 2.4e-6)
    assert st.converged.all()
    np.testing.assert_allclose(st.P, beam.force(e), rtol=1e-7, atol=1e-9)
    np.testing.assert_allclose(st.e, e, rtol=1e-6, atol=1e-10)
    assert np.all(st.residual < 1e-12)


def test_the_load_is_free_of_the_bending_an_imperfect_beam_bows_before_p_cr() -> None:
    # bending of a state past the onset, but a load of 0.8 P_cr: the perfect elastica would say
    # P >= P_cr, the free axial load reads 0.8 P_cr
    L = 44e-3
    beam = Beam.from_section(SECTION, L)
    P = 0.8 * beam.critical_load()
    bend = beam.grating_strains(np.array([2e-5]), intervals(L))
    eps = bend - P / SECTION.EA
    st = infer_states(eps, intervals(L), L, SECTION.EA, SECTION.fiber_offset, 2.4e-6)
    assert st.P[0] == pytest.approx(P, rel=1e-7)


def test_lengths_per_sample_and_sigmas_scale_with_the_noise() -> None:
    lengths = np.array([42e-3, 43e-3, 44e-3])
    e = np.array([1e-4, 2e-4, 3e-4])
    arcs = np.stack([intervals(L) for L in lengths])
    eps = np.stack(
        [
            Beam.from_section(SECTION, L).grating_strains(x, intervals(L), include_axial=True)
            for L, x in zip(lengths, e, strict=True)
        ]
    )
    a = infer_states(eps, arcs, lengths, SECTION.EA, SECTION.fiber_offset, 1e-6)
    b = infer_states(eps, arcs, lengths, SECTION.EA, SECTION.fiber_offset, 2e-6)
    np.testing.assert_allclose(a.e, e, rtol=1e-6)
    np.testing.assert_allclose(b.sigma_P, 2 * a.sigma_P, rtol=1e-12)
    assert np.all(a.sigma_e > 0)


def test_noise_statistics_match_the_stated_sigma() -> None:
    rng = np.random.default_rng(7)
    L = 44e-3
    beam = Beam.from_section(SECTION, L)
    e = np.full(2000, 2e-4)
    clean = beam.grating_strains(e, intervals(L), include_axial=True)
    sigma = 2.4e-6
    st = infer_states(
        clean + rng.normal(0, sigma, clean.shape),
        intervals(L),
        L,
        SECTION.EA,
        SECTION.fiber_offset,
        sigma,
    )
    z = (st.P - beam.force(e)) / st.sigma_P
    assert abs(float(np.mean(z))) < 0.1
    assert 0.9 < float(np.std(z)) < 1.1


def test_bad_input() -> None:
    with pytest.raises(ValueError, match="G >= 3"):
        infer_states(np.zeros((4, 2)), np.zeros((2, 2)), 0.04, 1e4, 1e-4, 1e-6)
    with pytest.raises(ValueError, match="finite"):
        infer_states(np.full((1, 3), np.nan), intervals(0.044), 0.044, 1e4, 1e-4, 1e-6)
    with pytest.raises(ValueError, match="s0 < s1"):
        infer_states(np.zeros((1, 3)), intervals(0.044)[:, ::-1], 0.044, 1e4, 1e-4, 1e-6)
    with pytest.raises(ValueError, match="sigma_strain"):
        infer_states(np.zeros((1, 3)), intervals(0.044), 0.044, 1e4, 1e-4, 0.0)

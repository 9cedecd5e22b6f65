"""Beam-tissue-tube equilibrium after contact: u = delta + e + P/k, F(delta) = P(e)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from palpate.estimation.beam.elastica.constants import MODE_REACTION, MODE_SHORTENING, P_CRIT
from palpate.sim.equilibrium import (
    DEFAULT_MAX_E_OVER_L,
    AxialLaw,
    ContactEffects,
    ContactState,
    solve_contact,
)
from palpate.sim.equilibrium.sides import Recall
from palpate.sim.tissue import TissueModel

EI = 1.18e-4
EA = 9.7e3


def stand_in(length: float | np.ndarray = 0.045, slope: float = 0.5) -> AxialLaw:
    """A perfect beam: EA e / L, then P_cr (1 + slope (e - e_cr)/L) and R ~ sqrt(e - e_cr)."""
    L = np.asarray(length, dtype=np.float64)
    p_cr = P_CRIT * EI / L**2
    e_cr = p_cr * L / EA

    def force(e: np.ndarray) -> np.ndarray:
        return np.where(e <= e_cr, EA * e / L, p_cr * (1.0 + slope * (e - e_cr) / L))

    def lateral(e: np.ndarray) -> np.ndarray:
        x = np.maximum(e - e_cr, 0.0) / L
        return EI / L**2 * MODE_REACTION * np.sqrt(x / MODE_SHORTENING)

    return AxialLaw(force, p_cr, L, EA, lateral)


def residual(u: np.ndarray, s: ContactState, k: float | None = None) -> np.ndarray:
    return u - (s.delta + s.e + (0.0 if k is None else s.P / k))


U = np.linspace(0.0, 3e-3, 1000)
TISSUES = [
    TissueModel(modulus=5e5),
    TissueModel(modulus=3e5, poisson=0.5, thickness=4e-3, large_indentation=True),
    TissueModel(modulus=1.1e6, thickness=2e-3, bonded=False),
]
EFFECTS = [
    ContactEffects(),
    ContactEffects(tube_stiffness=1500.0),
    ContactEffects(imperfection=2e-3),
    ContactEffects(tube_stiffness=800.0, imperfection=5e-3),
]


@pytest.mark.parametrize("tissue", TISSUES)
@pytest.mark.parametrize("fx", EFFECTS)
def test_equilibrium_holds_over_a_trial(tissue: TissueModel, fx: ContactEffects) -> None:
    law = stand_in()
    s = solve_contact(U, law, tissue, fx)
    assert s.success
    assert s.status == 0
    assert s.message == "converged"
    assert np.all(s.converged)
    np.testing.assert_allclose(residual(U, s, fx.tube_stiffness), 0.0, atol=1e-12)
    np.testing.assert_allclose(tissue.force(s.delta), s.P, rtol=1e-10, atol=1e-15)
    for arr in (s.delta, s.e, s.P, s.R):
        assert arr.shape == U.shape
        assert np.all(np.isfinite(arr))
        assert np.all(arr >= 0)
    # Monotone loading path.
    assert np.all(np.diff(s.e) >= 0)
    assert np.all(np.diff(s.P) >= -1e-12)
    assert np.all(np.diff(s.delta) >= -1e-15)
    # Buckled exactly beyond the straight range; 3 mm of travel buckles these tissues.
    e_cr = float(law.onset_shortening)
    np.testing.assert_array_equal(s.buckled, s.e > e_cr)
    assert s.buckled[-1]
    assert not s.buckled[1]


def test_pre_buckling_matches_closed_form_split() -> None:
    # Straight beam on Hertz tissue: pick delta, then u = delta + F(delta) (L/EA + 1/k).
    tissue = TissueModel(modulus=8e5, poisson=0.5)
    law = stand_in()
    k = 3000.0
    delta = np.linspace(0.0, 0.9, 11) * float(tissue.inverse(law.critical_load))
    F = tissue.force(delta)
    u = delta + F * (0.045 / EA + 1.0 / k)
    s = solve_contact(u, law, tissue, ContactEffects(tube_stiffness=k))
    np.testing.assert_allclose(s.delta, delta, rtol=0, atol=1e-13)  # atol of the solver
    np.testing.assert_allclose(s.P, F, rtol=1e-9)
    assert not np.any(s.buckled)
    assert np.all(s.R == 0.0)


def test_flat_plateau_puts_all_further_advance_into_the_beam() -> None:
    tissue = TissueModel(modulus=5e5)
    law = stand_in(slope=0.0)
    d_cr = float(tissue.inverse(law.critical_load))
    u = d_cr + np.array([1e-4, 1e-3, 2e-3])
    s = solve_contact(u, law, tissue)
    np.testing.assert_allclose(s.delta, d_cr, rtol=1e-12)
    np.testing.assert_allclose(s.e, u - d_cr, rtol=1e-12)
    assert np.all(s.buckled)


def test_zero_imperfection_is_exactly_the_perfect_model() -> None:
    tissue = TISSUES[1]
    law = stand_in()
    perfect = solve_contact(U, law, tissue)
    zero = solve_contact(U, law, tissue, ContactEffects(imperfection=0.0))
    for name in ("delta", "e", "P", "R", "buckled"):
        np.testing.assert_array_equal(getattr(zero, name), getattr(perfect, name))
    # And w0 -> 0 converges to it: the load deficit scales like w0 / amplitude.
    deficits = [
        np.max(perfect.P - solve_contact(U, law, tissue, ContactEffects(imperfection=w)).P)
        for w in (1e-5, 1e-6, 1e-7)
    ]
    assert deficits[0] > 5 * deficits[1] > 25 * deficits[2] > 0


def test_imperfection_smooths_the_onset_and_converges_to_the_elastica() -> None:
    tissue = TissueModel(modulus=5e5)
    law = stand_in()
    p_cr = float(law.critical_load)
    u = np.linspace(0.0, 3e-3, 3001)
    perfect = solve_contact(u, law, tissue)
    imperfect = solve_contact(u, law, tissue, ContactEffects(imperfection=3e-3))
    assert imperfect.success
    assert np.all(imperfect.P <= perfect.P + 1e-12)
    # Before the perfect onset the imperfect beam already bends: R > 0, more shortening.
    early = (~perfect.buckled) & (u > 0)
    assert np.all(imperfect.R[early] > 0)
    assert np.all(imperfect.e[early] > perfect.e[early])
    # Smooth: the load's slope along u has no jump where the perfect one has a kink.
    jump_perfect = np.max(np.abs(np.diff(perfect.P, 2)))
    jump_imperfect = np.max(np.abs(np.diff(imperfect.P, 2)))
    assert jump_imperfect < 0.1 * jump_perfect
    # Past the onset the deficit shrinks like w0 / A ~ sqrt(c w0^2 / (L e)) (Southwell-like).
    post = perfect.buckled
    deficit = (perfect.P - imperfect.P)[post] / p_cr
    assert np.all(np.diff(deficit) <= 1e-12)
    g = MODE_SHORTENING * 3e-3**2 * 0.045
    assert deficit[-1] <= 1.5 * math.sqrt(g / imperfect.e[-1])
    assert imperfect.P[-1] > p_cr


def test_stiff_tube_tends_to_rigid_clamp() -> None:
    tissue = TissueModel(modulus=5e5)
    law = stand_in()
    rigid = solve_contact(U, law, tissue)
    stiff = solve_contact(U, law, tissue, ContactEffects(tube_stiffness=1e12))
    np.testing.assert_allclose(stiff.delta, rigid.delta, rtol=1e-6, atol=1e-15)
    soft = solve_contact(U, law, tissue, ContactEffects(tube_stiffness=500.0))
    assert soft.delta[-1] < rigid.delta[-1] + 1e-15
    assert soft.e[-1] < rigid.e[-1]


def test_soft_tissue_never_buckles_and_stiff_tissue_buckles_at_once() -> None:
    law = stand_in()
    soft = solve_contact(U, law, TissueModel(modulus=2e3, large_indentation=True))
    assert soft.success
    assert not np.any(soft.buckled)
    np.testing.assert_allclose(residual(U, soft), 0.0, atol=1e-12)
    stiff = solve_contact(U, law, TissueModel(modulus=5e7))
    assert stiff.success
    assert stiff.buckled[U > 1e-4].all()
    assert stiff.delta.max() < 1e-4
    np.testing.assert_allclose(residual(U, stiff), 0.0, atol=1e-12)


def test_onset_neighbourhood_is_resolved() -> None:
    tissue = TissueModel(modulus=5e5)
    law = stand_in()
    p_cr = float(law.critical_load)
    u_cr = float(tissue.inverse(p_cr)) + float(law.onset_shortening)
    u = u_cr * (1.0 + np.array([-1e-12, -1e-15, 0.0, 1e-15, 1e-12, 1e-9]))
    s = solve_contact(u, law, tissue)
    assert s.success
    np.testing.assert_allclose(s.P, p_cr, rtol=1e-8)
    np.testing.assert_allclose(residual(u, s), 0.0, atol=1e-13)


def test_per_position_lengths_solve_in_one_call() -> None:
    tissue = TissueModel(modulus=7e5)
    u = np.linspace(0.0, 2e-3, 7)
    lengths = 0.042 + u  # the sensor keeps leaving the tube while it indents
    together = solve_contact(u, stand_in(lengths), tissue)
    for i, (ui, Li) in enumerate(zip(u, lengths, strict=True)):
        alone = solve_contact(ui, stand_in(float(Li)), tissue)
        assert float(alone.P) == pytest.approx(float(together.P[i]), rel=1e-12)
        assert float(alone.e) == pytest.approx(float(together.e[i]), rel=1e-9, abs=1e-15)


def test_scalar_in_scalar_out() -> None:
    s = solve_contact(1e-3, stand_in(), TissueModel(modulus=5e5))
    assert s.delta.shape == ()
    assert s.success
    assert bool(s.buckled)


def test_beyond_modelled_range_is_reported_not_nan() -> None:
    law = stand_in()
    u = np.array([1e-3, 0.5])  # 0.5 m of travel: e would exceed DEFAULT_MAX_E_OVER_L * L
    s = solve_contact(u, law, TissueModel(modulus=5e5))
    assert not s.success
    assert s.status == 2
    assert "1 of 2" in s.message
    assert s.converged.tolist() == [True, False]
    assert np.all(np.isfinite(s.e))
    assert s.e[1] <= DEFAULT_MAX_E_OVER_L * 0.045 + 1e-15


def test_iteration_limit_is_reported_not_nan() -> None:
    tissue = TissueModel(modulus=5e5, thickness=3e-3, large_indentation=True)
    s = solve_contact(U, stand_in(), tissue, ContactEffects(imperfection=3e-3), maxiter=1)
    assert not s.success
    assert s.status == 1
    assert "iteration limit" in s.message
    assert np.all(np.isfinite(s.P))
    assert np.all(np.isfinite(s.delta))


@pytest.mark.parametrize("bad", [-1e-6, math.nan, math.inf])
def test_bad_advance_raises(bad: float) -> None:
    with pytest.raises(ValueError, match="stage advance"):
        solve_contact(np.array([0.0, bad]), stand_in(), TissueModel(modulus=5e5))


def test_bad_effects_raise() -> None:
    with pytest.raises(ValueError, match="tube_stiffness"):
        ContactEffects(tube_stiffness=0.0)
    with pytest.raises(ValueError, match="imperfection"):
        ContactEffects(imperfection=-1e-3)


@given(
    E=st.floats(1e3, 5e7),
    u=st.floats(0.0, 5e-3),
    fx=st.sampled_from(EFFECTS),
    layered=st.booleans(),
)
def test_equilibrium_property(E: float, u: float, fx: ContactEffects, layered: bool) -> None:
    tissue = TissueModel(modulus=E, thickness=3e-3 if layered else math.inf)
    s = solve_contact(u, stand_in(), tissue, fx)
    assert s.success, s.message
    assert abs(float(residual(np.asarray(u), s, fx.tube_stiffness))) <= 1e-12
    assert float(tissue.force(s.delta)) == pytest.approx(float(s.P), rel=1e-9, abs=1e-14)


def test_with_the_real_beam() -> None:
    beam_mod = pytest.importorskip("palpate.estimation.beam.model")
    beam = beam_mod.Beam(EI=EI, EA=EA, fiber_offset=1.5e-4, length=0.045)
    tissue = TissueModel(modulus=5e5)
    s = solve_contact(U, beam, tissue)
    assert s.success, s.message
    np.testing.assert_allclose(residual(U, s), 0.0, atol=1e-12)
    np.testing.assert_allclose(beam.force(s.e), s.P, rtol=1e-9, atol=1e-12)
    assert s.buckled[-1]
    imperfect = solve_contact(U, beam, tissue, ContactEffects(imperfection=2e-3))
    assert imperfect.success, imperfect.message
    # Beam reports R <= 0 (paper Eq. 7's sign); the imperfect reaction keeps that sign.
    assert np.all(s.R <= 0)
    assert np.all(imperfect.R <= 0)
    assert np.all(np.abs(imperfect.R) >= np.abs(s.R) - 1e-12)
    fx = ContactEffects(imperfection=2e-3)
    one = solve_contact(1.5e-3, beam, tissue, fx)
    pair = solve_contact(np.array([1.5e-3, 2e-3]), beam, tissue, fx)
    assert float(one.P) == pytest.approx(pair.P[0], rel=1e-9)
    assert float(one.R) == pytest.approx(pair.R[0], rel=1e-6)
    assert float(one.R) <= 0


@pytest.mark.parametrize("tissue", TISSUES)
@pytest.mark.parametrize("fx", EFFECTS)
def test_scalar_path_agrees_with_array_path(tissue: TissueModel, fx: ContactEffects) -> None:
    law = stand_in()
    u = np.array([0.0, 1e-5, 2e-4, 6e-4, 1.5e-3, 3e-3])
    arr = solve_contact(u, law, tissue, fx)
    for i, ui in enumerate(u):
        one = solve_contact(ui, law, tissue, fx)
        assert one.success, one.message
        assert one.delta.shape == ()
        assert float(one.delta) == pytest.approx(arr.delta[i], rel=1e-9, abs=1e-13)
        assert float(one.e) == pytest.approx(arr.e[i], rel=1e-9, abs=1e-13)
        assert float(one.P) == pytest.approx(arr.P[i], rel=1e-9, abs=1e-12)
        assert float(one.R) == pytest.approx(arr.R[i], rel=1e-6, abs=1e-12)
        assert bool(one.buckled) == bool(arr.buckled[i])
        k = fx.tube_stiffness
        assert abs(float(residual(np.asarray(ui), one, k))) <= 1e-12
    # A one-element array takes the scalar path and keeps its shape.
    assert solve_contact(u[3:4], law, tissue, fx).P.shape == (1,)


def test_scalar_path_reports_failures() -> None:
    law = stand_in()
    far = solve_contact(0.5, law, TissueModel(modulus=5e5))
    assert not far.success
    assert far.status == 2
    assert np.isfinite(far.e)
    tissue = TissueModel(modulus=5e5, thickness=3e-3, large_indentation=True)
    short = solve_contact(2e-3, law, tissue, ContactEffects(imperfection=3e-3), maxiter=1)
    assert not short.success
    assert short.status == 1
    assert np.isfinite(short.P)


GRIDS = {
    "pre-onset": np.linspace(0.0, 2e-5, 51),
    "mixed": np.linspace(0.0, 2.5e-4, 51),
    "post-onset": np.linspace(5e-4, 7.5e-4, 51),
}


@pytest.mark.parametrize("grid", list(GRIDS))
@pytest.mark.parametrize("fx", EFFECTS)
def test_recalled_evaluations_change_no_bit(
    grid: str, fx: ContactEffects, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The solver recalls its last law evaluations for its outputs; evaluating every call
    afresh must give the same arrays bit for bit (pre-onset, mixed and post-onset grids)."""
    beam_mod = pytest.importorskip("palpate.estimation.beam.model")
    beam = beam_mod.Beam(EI=EI, EA=EA, fiber_offset=1.5e-4, length=0.042)
    tissue = TISSUES[1]
    u = GRIDS[grid]
    recalled = solve_contact(u, beam, tissue, fx)
    calls = []

    def evaluate(self: Recall[object], x: np.ndarray) -> object:
        calls.append(1)
        return self._fn(x)

    monkeypatch.setattr(Recall, "__call__", evaluate)
    fresh = solve_contact(u, beam, tissue, fx)
    assert calls
    assert recalled.success, recalled.message
    for name in ("delta", "e", "P", "R", "buckled", "converged"):
        assert getattr(recalled, name).tobytes() == getattr(fresh, name).tobytes(), name


def test_recall_returns_the_last_result_only_for_the_same_bits() -> None:
    seen: list[np.ndarray] = []

    def law(x: np.ndarray) -> np.ndarray:
        seen.append(x)
        return 2.0 * x

    f = Recall(law)
    x = np.array([1.0, 2.0])
    first = f(x)
    assert f(x.copy()) is first
    assert len(seen) == 1
    f(np.array([1.0, -0.0 + 2.0 * 1.0000000000000002]))  # one ulp away: evaluated
    f(np.array([[1.0, 2.0]]))  # same bytes, another shape: evaluated
    assert len(seen) == 3

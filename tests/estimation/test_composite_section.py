"""Composite section: the paper's 4-wire formulas, a bare fiber, and the Euler load."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from palpate.estimation.beam.elastica import P_CRIT
from palpate.estimation.beam.elastica.constants import X1
from palpate.estimation.beam.section import composite_section, euler_load

PAPER = {
    "fiber_radius": 0.115e-3,
    "fiber_modulus": 67e9,
    "wire_radius": 0.1e-3,
    "wire_modulus": 55e9,
    "wire_count": 4,
}


def test_paper_four_wire_formulas() -> None:
    sec = composite_section(**PAPER)
    r_f, r_w = PAPER["fiber_radius"], PAPER["wire_radius"]
    dy_f = sec.fiber_offset
    dy_w = -sec.neutral_axis
    assert sec.I_fiber == pytest.approx(math.pi * r_f**2 * (r_f**2 / 4 + dy_f**2), rel=1e-14)
    assert sec.I_wires == pytest.approx(math.pi * r_w**2 * (r_w**2 + 4 * dy_w**2), rel=1e-14)
    assert pytest.approx(67e9 * sec.I_fiber + 55e9 * sec.I_wires, rel=1e-14) == sec.EI
    # dy_fbg "about 0.15 mm" (the paper's sensor); fiber centre 0.215 mm above the row.
    assert sec.fiber_offset == pytest.approx(0.15327e-3, rel=1e-4)
    assert sec.neutral_axis + sec.fiber_offset == pytest.approx(r_w + r_f, rel=1e-14)


def test_bare_fiber_bends_about_its_own_axis() -> None:
    sec = composite_section(0.115e-3, 67e9, 0.1e-3, 55e9, 0)
    assert sec.fiber_offset == 0.0
    assert sec.I_wires == 0.0
    assert pytest.approx(67e9 * math.pi * 0.115e-3**4 / 4, rel=1e-14) == sec.EI
    assert pytest.approx(67e9 * math.pi * 0.115e-3**2, rel=1e-14) == sec.EA


@given(
    r_f=st.floats(1e-5, 1e-3),
    r_w=st.floats(1e-5, 1e-3),
    e_f=st.floats(1e9, 500e9),
    e_w=st.floats(1e9, 500e9),
    n=st.integers(0, 32),
)
def test_neutral_axis_minimises_the_bending_stiffness(
    r_f: float, r_w: float, e_f: float, e_w: float, n: int
) -> None:
    """Parallel-axis theorem: EI about any axis y = EI_na + EA (y - y_na)**2."""
    sec = composite_section(r_f, e_f, r_w, e_w, n)
    y_f = r_w + r_f

    def ei_about(y: float) -> float:
        fiber = e_f * math.pi * r_f**2 * (r_f**2 / 4 + (y_f - y) ** 2)
        wires = n * e_w * math.pi * r_w**2 * (r_w**2 / 4 + y**2)
        return fiber + wires

    assert ei_about(sec.neutral_axis) == pytest.approx(sec.EI, rel=1e-12)
    for y in (0.0, y_f, -r_w):
        expected = sec.EI + sec.EA * (y - sec.neutral_axis) ** 2
        assert ei_about(y) == pytest.approx(expected, rel=1e-10)


def test_euler_load_constant() -> None:
    assert math.tan(X1) == pytest.approx(X1, rel=1e-13)
    assert pytest.approx(20.190728556426, abs=1e-11) == P_CRIT
    assert euler_load(2.0, 0.5) == pytest.approx(P_CRIT * 2.0 / 0.25, rel=1e-15)
    assert euler_load(1.0, 1.0) == pytest.approx(20.1907, abs=1e-4)


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"EI": -1.0, "L": 1.0}, "EI"),
        ({"EI": 1.0, "L": 0.0}, "L"),
        ({"EI": 1.0, "L": math.nan}, "L"),
    ],
)
def test_euler_load_rejects_bad_input(kwargs: dict[str, float], name: str) -> None:
    with pytest.raises(ValueError, match=rf"^{name} "):
        euler_load(**kwargs)


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("fiber_radius", 0.0),
        ("fiber_modulus", -1.0),
        ("wire_radius", math.inf),
        ("wire_modulus", math.nan),
        ("wire_count", -1),
        ("wire_count", 2.5),
    ],
)
def test_composite_section_rejects_bad_input(field: str, value: float) -> None:
    kwargs = dict(PAPER)
    kwargs[field] = value
    with pytest.raises(ValueError, match=rf"^{field} "):
        composite_section(**kwargs)  # type: ignore[arg-type]


def test_more_wires_stiffen_and_move_the_neutral_axis_down() -> None:
    secs = [composite_section(0.115e-3, 67e9, 0.1e-3, 55e9, n) for n in range(6)]
    assert np.all(np.diff([s.EI for s in secs]) > 0)
    assert np.all(np.diff([s.neutral_axis for s in secs]) < 0)

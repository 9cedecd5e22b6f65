"""The stiffness map's parts on synthetic probes (unit tests of the map's arithmetic, not
evidence of accuracy: docs/maps.md judges it on the finite-element world through whole trials)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from palpate.maps import (
    Active,
    MapError,
    Patch,
    Probe,
    StiffnessMap,
    plan_for,
    raster_points,
    summarise,
)
from palpate.maps.probes import SIGMA_FLOOR, SUSPECT_INFLATION, Z95
from palpate.maps.region import log_threshold

PATCH = Patch.from_mm((-10.0, -10.0, 10.0, 10.0))
E0 = 314e3


def probe(x: float, y: float, e: float, sd: float = 0.04, status: str = "ok") -> Probe:
    return Probe(x, y, e, (e * math.exp(-Z95 * sd), e * math.exp(Z95 * sd)), status)


def bump(x: float, y: float, centre: tuple[float, float], rise: float = 0.45) -> float:
    r2 = (x - centre[0]) ** 2 + (y - centre[1]) ** 2
    return E0 * (1.0 + rise * math.exp(-r2 / (2 * 2.5e-3**2)))


def survey(strategy: str, centre: tuple[float, float], rise: float, seed: int) -> list[Probe]:
    rng = np.random.default_rng(seed)
    plan = plan_for(strategy, PATCH, 30, seed=seed)
    probes: list[Probe] = []
    while (point := plan.next(probes)) is not None:
        e = bump(*point, centre, rise) * math.exp(rng.normal(0.0, 0.04))
        probes.append(probe(*point, e))
    return probes


def test_a_probe_s_noise_is_its_interval_and_a_suspect_one_counts_less() -> None:
    p = probe(0.0, 0.0, 3e5, sd=0.05)
    assert p.log_sigma() == pytest.approx(0.05)
    s = probe(0.0, 0.0, 3e5, sd=0.05, status="suspect")
    assert s.log_sigma() == pytest.approx(0.05 * math.sqrt(SUSPECT_INFLATION))
    assert probe(0.0, 0.0, 3e5, sd=1e-5).log_sigma() == SIGMA_FLOOR
    none = Probe(0.0, 0.0, None, None, "none", ("no buckling",))
    assert not none.usable
    assert none.why_left_out() == "no buckling"
    with pytest.raises(ValueError, match="no usable interval"):
        none.log_sigma()


def test_a_map_needs_three_numbers_and_says_which_probes_it_left_out() -> None:
    few = [probe(0.0, 0.0, E0), Probe(1e-3, 0.0, None, None, "none", ("tip slid",))]
    with pytest.raises(MapError, match="1 usable probes"):
        StiffnessMap.fit(few)
    m = StiffnessMap.fit([*few, probe(2e-3, 0.0, E0), probe(0.0, 2e-3, E0)])
    assert len(m.used) == 3
    assert m.left_out[0][1] == "tip slid"
    assert math.exp(m.background) == pytest.approx(E0)


def test_the_threshold_from_the_data_never_sits_below_the_floor() -> None:
    m = StiffnessMap.fit([probe(x * 1e-3, 0.0, E0) for x in range(-5, 6, 2)])
    flat = np.full(4, m.background)
    assert log_threshold(m, flat, None) == pytest.approx(m.background + math.log(1.1))
    peaked = np.array([m.background, m.background + 1.0])
    assert log_threshold(m, peaked, None) == pytest.approx(m.background + 0.5)
    assert log_threshold(m, peaked, 4e5) == math.log(4e5)


def test_an_active_survey_finds_a_bump_and_a_flat_patch_gives_no_alarm() -> None:
    centre = (3e-3, -2e-3)
    found = summarise(StiffnessMap.fit(survey("active", centre, 0.45, 1)), PATCH)
    assert found.found
    assert found.centre is not None
    assert found.centre_ci is not None
    assert math.hypot(found.centre[0] - centre[0], found.centre[1] - centre[1]) < 1e-3
    (x0, x1), (y0, y1) = found.centre_ci
    assert x0 <= found.centre[0] <= x1
    assert y0 <= found.centre[1] <= y1
    flat = summarise(StiffnessMap.fit(survey("active", centre, 0.0, 1)), PATCH)
    assert not flat.found
    assert flat.centre is None
    assert flat.evidence.startswith("no inclusion found")


def test_the_raster_is_a_serpentine_of_cell_centres() -> None:
    points = raster_points(PATCH, 10)  # 3 x 3: the largest square within 10
    assert len(points) == 9
    xs = [round(p[0] * 1e3, 6) for p in points]
    assert xs[:3] == sorted(xs[:3])
    assert xs[3:6] == sorted(xs[3:6], reverse=True)
    assert min(p[0] for p in points) > PATCH.x_min
    assert max(p[1] for p in points) < PATCH.y_max


def test_the_active_plan_starts_on_a_raster_and_keeps_its_distance() -> None:
    plan = Active(PATCH, 14, min_spacing=1.5e-3)
    probes: list[Probe] = []
    while (point := plan.next(probes)) is not None:
        near = [math.hypot(point[0] - p.x, point[1] - p.y) for p in probes]
        assert not near or min(near) >= 1.5e-3 - 1e-12
        probes.append(probe(*point, bump(*point, (0.0, 0.0))))
    assert [(p.x, p.y) for p in probes[:9]] == raster_points(PATCH, 9)
    assert len(probes) == 14  # the budget


def test_an_unknown_strategy_is_refused() -> None:
    with pytest.raises(ValueError, match="strategy must be one of"):
        plan_for("spiral", PATCH, 10)

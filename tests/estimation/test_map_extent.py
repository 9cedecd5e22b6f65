"""The inclusion's extent, a disc seen through the tip's contact (``maps.extent``), on
synthetic probes: unit tests of its arithmetic. Its accuracy on the finite-element world, where
the disc errs outward, is judged through whole surveys in docs/maps.md."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from palpate.maps import Patch, Probe, StiffnessMap, plan_for, summarise
from palpate.maps.extent import ExtentError, contact_points, fit_extent, overlap
from palpate.maps.probes import Z95

PATCH = Patch.from_mm((-10.0, -10.0, 10.0, 10.0))
E0 = 314e3
A = 1.8e-3  # the probes' contact radius (m)


def seen(x: float, y: float, centre: tuple[float, float], r: float, rise: float) -> float:
    """E a probe at (x, y) reads of a disc (the extent's own model: arithmetic, not physics)."""
    share = overlap(np.array([x]), np.array([y]), np.array([A]), centre, r)[0]
    return E0 * math.exp(rise * share)


def probes_of(centre: tuple[float, float], r: float, rise: float, seed: int) -> list[Probe]:
    rng = np.random.default_rng(seed)
    plan = plan_for("active", PATCH, 30, seed=seed)
    out: list[Probe] = []
    while (point := plan.next(out)) is not None:
        e = seen(*point, centre, r, rise) * math.exp(rng.normal(0.0, 0.02))
        ci = (e * math.exp(-Z95 * 0.02), e * math.exp(Z95 * 0.02))
        out.append(Probe(point[0], point[1], e, ci, "ok", contact_radius=A))
    return out


def test_the_contact_s_pressure_sums_to_one_and_its_share_over_a_disc_is_a_fraction() -> None:
    x, y, w = contact_points(A)
    assert w.sum() == pytest.approx(1.0)
    assert np.all(np.hypot(x, y) < A)
    px, py, a = np.array([0.0, 20e-3, 5e-3]), np.zeros(3), np.full(3, A)
    share = overlap(px, py, a, (0.0, 0.0), 5e-3)
    assert share[0] == pytest.approx(1.0, abs=1e-6)  # the contact well inside the disc
    assert share[1] == pytest.approx(0.0, abs=1e-6)  # far outside
    assert 0.4 < share[2] < 0.5  # on the edge: half, less the curved edge's share


def test_the_fit_finds_the_disc_the_probes_were_drawn_from() -> None:
    centre, r = (3e-3, -2e-3), 2.5e-3
    probes = probes_of(centre, r, 0.5, seed=1)
    ext = fit_extent(probes, (2e-3, -1e-3), 2e-3)
    assert math.hypot(ext.centre[0] - centre[0], ext.centre[1] - centre[1]) < 0.2e-3
    assert ext.radius == pytest.approx(r, abs=0.2e-3)
    assert 0.0 < ext.radius_se < 0.3e-3
    assert abs(ext.radius - r) < 3.0 * ext.radius_se + 0.05e-3
    assert ext.rise == pytest.approx(0.5, abs=0.1)


def test_the_fit_refuses_probes_without_a_contact_radius_or_too_few() -> None:
    probes = probes_of((0.0, 0.0), 2.5e-3, 0.5, seed=2)
    bare = [Probe(p.x, p.y, p.modulus, p.ci, p.status) for p in probes]
    with pytest.raises(ExtentError, match="contact radius"):
        fit_extent(bare, (0.0, 0.0), 2e-3)
    with pytest.raises(ExtentError, match="6 probes"):
        fit_extent(probes[:5], (0.0, 0.0), 2e-3)


def test_the_summary_reports_the_disc_and_spans_its_radius_from_the_region_to_it() -> None:
    centre = (3e-3, -2e-3)
    probes = probes_of(centre, 2.5e-3, 0.5, seed=3)
    s = summarise(StiffnessMap.fit(probes), PATCH)
    assert s.found
    assert s.extent is not None
    assert s.radius_ci is not None
    assert s.apparent_radius is not None
    assert s.radius == s.extent.radius
    assert s.radius_ci[0] <= min(s.radius, s.apparent_radius)
    assert s.radius_ci[1] == pytest.approx(s.extent.radius + Z95 * s.extent.radius_se)
    xx, yy = np.meshgrid(s.x, s.y)
    inside = s.inside(xx, yy)
    c = s.extent.centre
    assert np.array_equal(inside, np.hypot(xx - c[0], yy - c[1]) <= s.extent.radius)
    d = s.as_dict()
    assert d["extent"]["radius_mm"] == pytest.approx(s.extent.radius * 1e3)  # type: ignore[index]
    # without contact radii (an older run's probes): the region is the boundary, as before
    bare = summarise(
        StiffnessMap.fit([Probe(p.x, p.y, p.modulus, p.ci, "ok") for p in probes]), PATCH
    )
    assert bare.extent is None
    assert bare.radius == bare.apparent_radius
    assert np.array_equal(bare.inside(xx, yy), bare.p_above > 0.5)


def test_a_probe_read_back_from_its_line_is_the_probe_written() -> None:
    # the contact radius that a millimetre round trip changed in its last bit (numpy 2.4)
    p = Probe(1e-3 / 3, -2e-3, 3e5 / 7, (2.9e5 / 3, 3.1e5), "ok", ("r",), 12.1, 0.00179131145500078)
    assert Probe.from_record(json.loads(json.dumps(p.record()))) == p
    assert Probe.from_record(json.loads(json.dumps(Probe(0.0, 0.0, None, None, "none").record())))


def test_an_older_probes_line_in_millimetres_still_reads() -> None:
    p = Probe(1e-3, -2e-3, 3e5, (2.9e5, 3.1e5), "ok", contact_radius=A)
    back = Probe.from_record(p.as_dict())
    assert back.contact_radius == pytest.approx(A)
    assert back.modulus == pytest.approx(3e5)
    old = p.as_dict()
    del old["contact_radius_mm"]
    assert Probe.from_record(old).contact_radius is None

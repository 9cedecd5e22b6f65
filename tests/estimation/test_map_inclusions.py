"""Every inclusion a map reads (maps.inclusions) on synthetic probes: two stiff bumps and a
soft dip, each found where it is and of its kind; a flat patch gives none (unit tests of the
arithmetic; docs/maps.md judges it through whole trials on the patch world)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from palpate.campaigns.surveyloop import Truth, inclusion_scores
from palpate.maps import Patch, StiffnessMap, raster_points, summarise
from palpate.maps.inclusions import find_inclusions
from palpate.maps.probes import Z95, Probe

PATCH = Patch.from_mm((-10.0, -10.0, 10.0, 10.0))
E0 = 314e3
STIFF_A, STIFF_B, SOFT = (4e-3, -4e-3), (-5e-3, 4e-3), (-4.5e-3, -5e-3)


def _modulus(x: float, y: float) -> float:
    def bump(c: tuple[float, float], rise: float) -> float:
        return rise * math.exp(-((x - c[0]) ** 2 + (y - c[1]) ** 2) / (2 * 2.2e-3**2))

    return E0 * (1.0 + bump(STIFF_A, 0.45) + bump(STIFF_B, 0.3)) * (1.0 - bump(SOFT, 0.3))


def _probes(field, seed: int = 0) -> list[Probe]:
    rng = np.random.default_rng(seed)
    out = []
    for x, y in raster_points(PATCH, 121):
        e = field(x, y) * math.exp(rng.normal(0.0, 0.02))
        out.append(Probe(x, y, e, (e * math.exp(-Z95 * 0.02), e * math.exp(Z95 * 0.02)), "ok"))
    return out


def _read(field):
    m = StiffnessMap.fit(_probes(field))
    summary = summarise(m, PATCH)
    return summary, find_inclusions(m, PATCH, summary)


def test_two_stiff_bumps_and_a_soft_dip_are_each_found_of_their_kind() -> None:
    summary, found = _read(_modulus)
    assert [f.kind for f in found].count("stiff") == 2
    assert [f.kind for f in found].count("soft") == 1
    assert found[0].centre == summary.centre  # the summary's inclusion comes first
    for truth, kind in ((STIFF_A, "stiff"), (STIFF_B, "stiff"), (SOFT, "soft")):
        near = min(
            (f for f in found if f.kind == kind),
            key=lambda f: math.hypot(f.centre[0] - truth[0], f.centre[1] - truth[1]),
        )
        assert math.hypot(near.centre[0] - truth[0], near.centre[1] - truth[1]) < 0.5e-3
        (x0, x1), (y0, y1) = near.centre_ci
        assert x0 <= truth[0] <= x1
        assert y0 <= truth[1] <= y1
    assert found[0].as_dict()["depth_mm"] is None  # probes without a contact radius: not read


def test_the_summary_reads_the_highest_of_two_bumps_not_between_them() -> None:
    summary, _ = _read(_modulus)
    assert summary.centre is not None
    assert math.hypot(summary.centre[0] - STIFF_A[0], summary.centre[1] - STIFF_A[1]) < 0.5e-3


def test_a_flat_patch_holds_no_inclusion() -> None:
    _, found = _read(lambda x, y: E0)
    assert found == []


def test_scores_match_each_truth_to_its_own_kind_and_count_the_rest_as_false() -> None:
    _, found = _read(_modulus)
    truths = [Truth(STIFF_A, 2.5e-3, 3.5e-3, 5.0), Truth(SOFT, 3e-3, 4e-3, 0.3)]
    scores = inclusion_scores(found, truths)
    assert scores["inclusions_found"] == 2
    assert scores["false_inclusions"] == 1  # the second bump, not in this truth
    assert [r["kind"] for r in scores["per_inclusion"]] == ["stiff", "soft"]
    missed = inclusion_scores([], truths)
    assert missed["inclusions_found"] == 0
    assert not missed["per_inclusion"][0]["found"]
    assert Truth(SOFT, 3e-3, 4e-3, 0.3).kind == "soft"
    assert pytest.approx(4.0) == Truth(STIFF_A, 2.5e-3, 3.5e-3, 5.0).one()["center_mm"][0]


def test_active_all_finds_the_weaker_bump_and_the_dip_that_active_leaves() -> None:
    from palpate.maps import plan_for

    def surveyed(strategy: str) -> list:
        rng = np.random.default_rng(3)
        plan = plan_for(strategy, PATCH, 40, seed=3)
        probes: list[Probe] = []
        while (point := plan.next(probes)) is not None:
            e = _modulus(*point) * math.exp(rng.normal(0.0, 0.02))
            sd = 0.02
            probes.append(Probe(*point, e, (e * math.exp(-Z95 * sd), e * math.exp(Z95 * sd)), "ok"))
        m = StiffnessMap.fit(probes)
        return find_inclusions(m, PATCH, summarise(m, PATCH))

    every = surveyed("active-all")
    truths = [
        Truth(STIFF_A, 2.5e-3, 3.5e-3, 5.0),
        Truth(STIFF_B, 2.5e-3, 3.5e-3, 5.0),
        Truth(SOFT, 3e-3, 4e-3, 0.3),
    ]
    scores = inclusion_scores(every, truths)
    assert scores["inclusions_found"] == 3
    assert scores["false_inclusions"] == 0
    assert inclusion_scores(surveyed("active"), truths)["inclusions_found"] < 3


def test_two_nodules_whose_blurred_footprints_touch_are_two() -> None:
    a, b = (-4e-3, 0.0), (4e-3, 0.0)  # 8 mm apart: one region at the 10 % level

    def two(x: float, y: float) -> float:
        def bump(c: tuple[float, float]) -> float:
            return 0.4 * math.exp(-((x - c[0]) ** 2 + (y - c[1]) ** 2) / (2 * 2.2e-3**2))

        return E0 * (1.0 + bump(a) + bump(b))

    _, found = _read(two)
    truths = [Truth(a, 2.5e-3, 3.5e-3, 5.0), Truth(b, 2.5e-3, 3.5e-3, 5.0)]
    scores = inclusion_scores(found, truths)
    assert scores["inclusions_found"] == 2
    assert scores["false_inclusions"] == 0


def test_a_region_the_probes_about_it_do_not_bear_out_is_dropped_but_the_summary_s() -> None:
    from palpate.maps.inclusions import Inclusion, with_depths

    rng = np.random.default_rng(2)
    probes = []
    for x, y in raster_points(PATCH, 81):  # 2.5 mm apart, every contact 1.8 mm wide
        e = E0 * math.exp(rng.normal(0.0, 0.02))
        ci = (e * math.exp(-Z95 * 0.02), e * math.exp(Z95 * 0.02))
        probes.append(Probe(x, y, e, ci, "ok", contact_radius=1.8e-3))
    m = StiffnessMap.fit(probes)

    def region(kind: str, centre: tuple[float, float]) -> Inclusion:
        box = ((centre[0] - 1e-3, centre[0] + 1e-3), (centre[1] - 1e-3, centre[1] + 1e-3))
        return Inclusion(kind, centre, box, 2e-3, (1e-3, 3e-3), 0.9 * E0, 0.99)

    flat = [region("stiff", (0.0, 0.0)), region("soft", (5e-3, 5e-3))]
    kept = with_depths(flat, m, keep_first=True)
    assert [f.kind for f in kept] == ["stiff"]  # the summary's own stays, read as not needed
    assert kept[0].depth is not None
    assert not kept[0].depth.needed
    assert with_depths(flat, m, keep_first=False) == []
    # a corner 30 mm off the patch: no probe within 4.5 contact radii, so none bears it out
    assert with_depths([region("soft", (30e-3, 30e-3))], m, keep_first=False) == []
    # probes without their contact radii cannot judge: the region stays, unread
    bare = StiffnessMap.fit([Probe(p.x, p.y, p.modulus, p.ci, p.status) for p in probes])
    assert [f.depth for f in with_depths(flat, bare, keep_first=False)] == [None, None]


def test_the_scores_carry_the_depth_where_the_map_read_it_and_a_study_sums_them() -> None:
    from dataclasses import replace

    from palpate.campaigns.mapstudy import whole_lines
    from palpate.maps.depth import DepthReading

    _, found = _read(_modulus)
    truths = [Truth(STIFF_A, 2.5e-3, 3.5e-3, 5.0), Truth(SOFT, 3e-3, 4e-3, 0.3)]
    stiff = min(
        (f for f in found if f.kind == "stiff"),
        key=lambda f: math.dist(f.centre, STIFF_A),
    )
    reading = DepthReading(
        3.1e-3, (2.5e-3, 5e-3), 0.8e-3, (0.2e-3, 1.5e-3), 2.3e-3, (1e-3, 4e-3), 4.0, (2, 50), 20, 30
    )
    read = [replace(f, depth=reading) if f is stiff else f for f in found]
    rows = inclusion_scores(read, truths)["per_inclusion"]
    assert rows[0]["depth_error_mm"] == pytest.approx(0.4)
    assert rows[0]["depth_in_ci"]
    assert "depth_error_mm" not in rows[1]  # the soft one: no reading, no depth score
    summary = whole_lines([inclusion_scores(read, truths)])
    assert summary["depth_read"] == 1
    assert summary["depth_in_ci"] == 1
    assert summary["depth_error_mm_median"] == pytest.approx(0.4)
    assert stiff.as_dict()["depth_mm"] is None
    assert replace(stiff, depth=reading).as_dict()["depth_mm"] == pytest.approx(3.1)

"""An inclusion's depth, sphere and contrast from the probes about it (maps.depth): the share
of the tip's energy a sphere holds against its integral written out, and the fit placing a
sphere from probes of that model (unit tests of the arithmetic: docs/maps.md judges the depth
through whole surveys on the finite-element patch world, bench/map_depth.py)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate

from palpate.maps.depth import (
    KAPPA,
    _unit_ball,
    energy_share,
    modulus_factor,
    read_depth,
)
from palpate.maps.probes import Z95, Probe

A = 1.8e-3  # the paper's sensor's contact radius at its deepest, about
E0 = 314e3


def _on_axis(top: float, radius: float, a: float) -> float:
    """The share on the sphere's axis, the disc's integral over rho in closed form, then z."""
    b = KAPPA * a

    def disc(z: float) -> float:
        zz = z + b
        rim = radius**2 - (z - top - radius) ** 2
        return math.pi * zz**2 * (1.0 / (2.0 * zz**4) - 1.0 / (2.0 * (rim + zz**2) ** 2))

    total, _ = integrate.quad(disc, top, top + 2 * radius, epsabs=0.0, epsrel=1e-10)
    return total / (math.pi / (2.0 * b))


@pytest.mark.parametrize(("top", "radius"), [(0.5, 2.0), (1.0, 1.0), (2.0, 3.0), (0.2, 1.5)])
def test_the_share_on_the_axis_is_the_integral_written_out(top: float, radius: float) -> None:
    share = energy_share(np.array([0.0]), np.array([1.0]), np.array([top]), radius)[0, 0]
    assert share == pytest.approx(_on_axis(top, radius, 1.0), rel=0.02)


def test_the_share_off_the_axis_agrees_with_a_finer_quadrature_and_falls_away() -> None:
    offsets = np.array([0.0, 1.0, 2.0, 4.0])
    coarse = energy_share(offsets, np.ones(4), np.array([0.7]), 1.8)[0]
    from palpate.maps import depth

    fine_ball = _unit_ball(24, 600)
    saved = depth.BALL, depth.BALL_WEIGHTS
    depth.BALL, depth.BALL_WEIGHTS = fine_ball
    try:
        fine = energy_share(offsets, np.ones(4), np.array([0.7]), 1.8)[0]
    finally:
        depth.BALL, depth.BALL_WEIGHTS = saved
    assert coarse == pytest.approx(fine, rel=0.02)
    assert np.all(np.diff(coarse) < 0.0)  # a probe further off feels less of it
    deeper = energy_share(offsets, np.ones(4), np.array([1.5]), 1.8)[0]
    assert deeper[0] < coarse[0]


def test_a_stiff_sphere_raises_the_modulus_and_a_soft_one_lowers_it() -> None:
    share = np.array([0.0, 0.1, 0.3])
    assert modulus_factor(share, 5.0)[0] == 1.0
    assert np.all(np.diff(modulus_factor(share, 5.0)) > 0.0)
    assert np.all(np.diff(modulus_factor(share, 0.3)) < 0.0)
    # Eshelby's concentration saturates: ten times stiffer is not twice the rise of five
    rise5, rise10 = modulus_factor(share, 5.0)[2] - 1.0, modulus_factor(share, 10.0)[2] - 1.0
    assert rise5 < rise10 < 2.0 * rise5


def _probes(top: float, radius: float, contrast: float, seed: int = 0) -> list[Probe]:
    """A 9 x 9 raster of probes 1.25 mm apart about a sphere at the origin, each reading the
    model's modulus with 2 % noise; every contact A wide (the model's own data)."""
    rng = np.random.default_rng(seed)
    out = []
    for x in np.arange(-4, 5) * 1.25e-3:
        for y in np.arange(-4, 5) * 1.25e-3:
            offset = np.array([math.hypot(x, y) / A])
            share = energy_share(offset, np.ones(1), np.array([top / A]), radius / A)
            e = E0 * float(modulus_factor(share, contrast)[0, 0]) * math.exp(rng.normal(0, 0.02))
            ci = (e * math.exp(-Z95 * 0.02), e * math.exp(Z95 * 0.02))
            out.append(Probe(x, y, e, ci, "ok", contact_radius=A))
    return out


@pytest.mark.parametrize(("top", "radius", "contrast"), [(0.8e-3, 2.5e-3, 5.0), (2e-3, 3e-3, 8.0)])
def test_a_sphere_is_placed_in_depth_from_the_probes_about_it(
    top: float, radius: float, contrast: float
) -> None:
    reading = read_depth(_probes(top, radius, contrast), (0.0, 0.0), math.log(E0), "stiff")
    assert reading is not None
    assert reading.depth_ci[0] <= top + radius <= reading.depth_ci[1]
    assert reading.top_ci[0] <= top <= reading.top_ci[1]
    assert reading.radius_ci[0] <= radius <= reading.radius_ci[1]
    assert reading.contrast_ci[0] <= contrast <= reading.contrast_ci[1]
    assert reading.depth_ci[0] <= reading.depth <= reading.depth_ci[1]
    assert reading.as_dict()["depth_mm"] == pytest.approx(reading.depth * 1e3)


def test_a_deeper_sphere_reads_deeper_and_a_soft_one_reads_soft() -> None:
    shallow = read_depth(_probes(0.5e-3, 2.5e-3, 5.0), (0.0, 0.0), math.log(E0), "stiff")
    deep = read_depth(_probes(2.5e-3, 2.5e-3, 5.0), (0.0, 0.0), math.log(E0), "stiff")
    assert shallow is not None
    assert deep is not None
    # the same footprint from deeper down: the deep sphere's interval reaches far deeper, the
    # shallow one's is bounded near its truth
    assert deep.depth_ci[1] > shallow.depth_ci[1] + 3e-3
    assert shallow.depth_ci[1] - shallow.depth_ci[0] < 1.5e-3
    assert abs(shallow.depth - 3e-3) < 0.5e-3
    cyst = read_depth(_probes(1e-3, 3e-3, 0.3), (0.0, 0.0), math.log(E0), "soft")
    assert cyst is not None
    assert cyst.contrast < 1.0
    assert cyst.top_ci[0] <= 1e-3 <= cyst.top_ci[1]


def test_probes_nearer_another_inclusion_are_left_to_it_and_too_few_give_none() -> None:
    probes = _probes(1e-3, 2.5e-3, 5.0)
    # another inclusion 2.5 mm to the side takes the probes nearer it
    split = read_depth(probes, (0.0, 0.0), math.log(E0), "stiff", others=[(2.5e-3, 0.0)])
    alone = read_depth(probes, (0.0, 0.0), math.log(E0), "stiff")
    assert split is not None
    assert alone is not None
    assert split.probes < alone.probes
    no_contact = [Probe(p.x, p.y, p.modulus, p.ci, p.status) for p in probes]
    assert read_depth(no_contact, (0.0, 0.0), math.log(E0), "stiff") is None
    assert read_depth(probes[:4], (0.0, 0.0), math.log(E0), "stiff") is None
    with pytest.raises(ValueError, match="kind"):
        read_depth(probes, (0.0, 0.0), math.log(E0), "hard")


def test_probes_a_shifted_background_explains_do_not_need_a_sphere() -> None:
    rng = np.random.default_rng(5)
    flat = []
    for x in np.arange(-4, 5) * 1.25e-3:
        for y in np.arange(-4, 5) * 1.25e-3:
            e = 0.9 * E0 * math.exp(rng.normal(0.0, 0.02))  # 10 % under the map's background
            ci = (e * math.exp(-Z95 * 0.02), e * math.exp(Z95 * 0.02))
            flat.append(Probe(x, y, e, ci, "ok", contact_radius=A))
    unneeded = read_depth(flat, (0.0, 0.0), math.log(E0), "soft")
    assert unneeded is not None
    assert not unneeded.needed
    cyst = read_depth(_probes(1e-3, 3e-3, 0.3), (0.0, 0.0), math.log(E0), "soft")
    assert cyst is not None
    assert cyst.needed
    assert cyst.support > 10 * unneeded.support + 10

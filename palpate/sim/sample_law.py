"""The world's force law for a scene's sample: the tissue fidelity levels and how a sample's
keys map onto them (the one place that does).

``fidelity.tissue_model`` picks the level:

- ``"fe"`` (the default): the sample's own finite-element table (:mod:`sim.fem`): a rigid
  sphere on a layer of the sample's thickness and lateral radius on a rigid base, ``bonded`` or
  sliding, ``material`` linear or neo-Hookean, the tip-surface ``friction`` mapped to the FE's
  contact condition by :func:`contact_condition`. Independent of the estimator: nothing on this
  path imports ``estimation.contact.hertz`` or ``estimation.contact.law``
  (tests/sim/test_fem_imports.py).
  A half-space (``thickness_mm: null``, or ``finite_thickness: false``) is a block 200 R deep
  and 200 R wide (within 0.4 % of Sneddon's half-space to delta = R, docs/tissue-fe.md). The
  FE is always a sphere at finite depth, so ``large_indentation`` does not apply to it.
  A sample with ``inclusions`` takes that table times the inclusions' factor on the force from
  a three-dimensional solve (:func:`fe_world`, :mod:`sim.fem3d`, docs/inclusions.md).
- ``"closed-form"``: :class:`sim.tissue.TissueModel`, Sneddon's sphere times the Dimitriadis
  series: the estimator's own family of laws, cheap; a scene that picks it judges the estimator
  on its own model. Linear, frictionless only (``material`` and ``friction`` are ignored).

``rigid: true`` on either level: a steel block (:class:`RigidBlock`).

Viscoelasticity (``fidelity.viscoelastic`` and a sample's ``relaxation_time_s``): the elastic
law above becomes the instantaneous one of a standard linear solid (:func:`relaxation`);
``modulus_kpa`` is the *relaxed* modulus E_inf, what a quasi-static test measures, so an
elastic and a viscoelastic sample mean the same by it, and E_0 = E_inf / ``relaxed_ratio``. The
world steps it on the virtual clock (``sim.contact_history``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ..config.sample import SampleConfig
from ..config.scene import FidelityConfig
from .equilibrium import TissueLaw
from .equilibrium.law import FloatArray
from .fem import FeTissueLaw, LayerProblem, table_key
from .fem.problem import significant
from .fem.table import solved_table
from .fem3d import Inclusion, InclusionProblem, InclusionWorld
from .fem3d.offsets import MapWorld, on_axis
from .fem3d.patch import PatchProblem, PatchWorld
from .viscoelastic import PowerLawSolid, Relaxation, StandardLinearSolid

HALF_SPACE_RATIO = 200.0
"""Depth and lateral radius / R of the block that stands in for a half-space on the FE level."""
SOLID_LIMIT_RATIO = 40.0
"""Largest depth and half-width / R of the 3-D model of a layer with inclusions."""

STEEL_MODULUS = 200e9  # Pa
STEEL_POISSON = 0.3


def contact_condition(friction: float, poisson: float) -> str:
    """The FE contact condition for a Coulomb ``friction`` coefficient between tip and surface.

    The FE has the two limits of Coulomb friction: frictionless, and full stick (a surface node
    that touches stays on the sphere's point it reached). Spence (1975, J. Elasticity 5:297)
    showed that a Hertzian indentation with friction mu has a central stick zone whose size
    depends only on beta / mu, with beta = (1 - 2 nu) / (2 (1 - nu)) the mismatch of the rigid
    sphere and the layer: the stick zone vanishes as mu -> 0 and covers the contact when mu is
    large against beta. The sample gets the nearer limit: full stick when ``mu >= beta``,
    frictionless below (always frictionless at mu = 0; any mu > 0 sticks an incompressible
    layer, where friction changes nothing). The two limits differ by 0.1-0.2 % in force at
    nu = 0.45 and by 5-6 % at nu = 0 (docs/tissue-fe.md)."""
    if friction <= 0.0:
        return "frictionless"
    beta = (1.0 - 2.0 * poisson) / (2.0 * (1.0 - poisson))
    return "stick" if friction >= beta else "frictionless"


def fe_problem(sample: SampleConfig, fidelity: FidelityConfig, tip_radius: float) -> LayerProblem:
    """The dimensionless FE problem of ``sample`` (ValueError naming the sample if it has none)."""
    options: dict[str, Any] = {
        "poisson": sample.poisson,
        "material": sample.material,
        "base": "bonded" if sample.bonded else "sliding",
        "contact": contact_condition(sample.friction, sample.poisson),
    }
    thickness = sample.thickness if fidelity.finite_thickness else None
    if thickness is None:
        side = HALF_SPACE_RATIO * tip_radius
        return LayerProblem.from_dimensions(tip_radius, side, side, **options)
    if sample.lateral_radius <= tip_radius:
        raise ValueError(
            f"sample {sample.name}: lateral_radius_mm must exceed the tip radius "
            f"({tip_radius * 1e3:g} mm) for the finite-element tissue"
        )
    return LayerProblem.from_dimensions(tip_radius, thickness, sample.lateral_radius, **options)


def fe_world(
    sample: SampleConfig,
    fidelity: FidelityConfig,
    tip_radius: float,
    at: tuple[float, float] = (0.0, 0.0),
) -> LayerProblem | InclusionWorld | MapWorld | PatchWorld:
    """The FE tissue of ``sample`` under a tip pressing at ``at`` (x, y in m on its surface,
    from the sample's origin, where a single trial indents): its layer's problem, or with
    inclusions the layer and its 3-D problem as seen from that point
    (:class:`sim.fem3d.InclusionWorld`; the 3-D model is cut at ``SOLID_LIMIT_RATIO`` R deep
    and wide, which the inclusions' factor does not feel). Points at the same distance from a
    single inclusion share one 3-D table. With ``fidelity.inclusion_offsets: interpolated`` the
    factor is read between solves at fixed distances (:class:`sim.fem3d.offsets.MapWorld`); with
    ``patch``, the whole of ``fidelity.inclusion_patch_mm`` is factorised once with every
    inclusion and the tip presses anywhere on it (:class:`sim.fem3d.patch.PatchWorld`)."""
    layer = fe_problem(sample, fidelity, tip_radius)
    if not sample.inclusions:
        return layer
    inclusions = tuple(
        Inclusion(
            x=significant(inc.center[0] / tip_radius),
            y=significant(inc.center[1] / tip_radius),
            depth=significant(inc.center[2] / tip_radius),
            radius=significant(inc.radius / tip_radius),
            contrast=significant(inc.modulus / sample.modulus),
            poisson=inc.poisson,
        )
        for inc in sample.inclusions
    )
    solid = InclusionProblem(
        thickness_ratio=min(layer.thickness_ratio, SOLID_LIMIT_RATIO),
        radius_ratio=min(layer.radius_ratio, SOLID_LIMIT_RATIO),
        poisson=layer.poisson,
        base=layer.base,
        inclusions=inclusions,
        depth_max=layer.depth_max,
        n_depths=layer.n_depths,
    )
    x, y = at
    if fidelity.inclusion_offsets == "patch":
        patch = tuple(significant(v * 1e-3 / tip_radius) for v in fidelity.inclusion_patch_mm)
        where = (significant(x / tip_radius), significant(y / tip_radius))
        return PatchWorld(layer, PatchProblem(solid, patch), where)  # type: ignore[arg-type]
    if x or y:
        solid = solid.seen_from(significant(x / tip_radius), significant(y / tip_radius))
    if fidelity.inclusion_offsets == "interpolated":
        return MapWorld(layer, on_axis(solid), solid.inclusions[0].offset)
    return InclusionWorld(layer, solid)


def relaxation(sample: SampleConfig, fidelity: FidelityConfig) -> Relaxation | None:
    """The sample's relaxation (``relaxation``: a standard linear solid or a power law) when the
    scene switches viscoelasticity on and the sample has a relaxation time; None: elastic."""
    if not fidelity.viscoelastic or sample.relaxation_time_s is None or sample.rigid:
        return None
    if sample.relaxation == "power-law":
        return PowerLawSolid(
            sample.relaxation_time_s, sample.relaxed_ratio, sample.relaxation_exponent
        )
    return StandardLinearSolid(sample.relaxation_time_s, sample.relaxed_ratio)


def world_tissue(
    sample: SampleConfig,
    fidelity: FidelityConfig,
    tip_radius: float,
    at: tuple[float, float] = (0.0, 0.0),
) -> TissueLaw:
    """The world's (elastic, instantaneous when viscoelastic) force law of ``sample`` under a
    tip pressing at ``at`` (m, :func:`fe_world`; a sample without inclusions is the same
    everywhere)."""
    if sample.rigid:
        return RigidBlock(tip_radius)
    sls = relaxation(sample, fidelity)
    modulus = sample.modulus / (1.0 if sls is None else sls.ratio)
    if fidelity.tissue_model == "fe":
        return FeTissueLaw(fe_world(sample, fidelity, tip_radius, at), modulus, tip_radius)
    from .tissue import TissueModel  # the estimator's family: only on this level

    return TissueModel(
        modulus=modulus,
        poisson=sample.poisson,
        thickness=(
            sample.thickness if (sample.thickness and fidelity.finite_thickness) else math.inf
        ),
        bonded=sample.bonded,
        tip_radius=tip_radius,
        finite_thickness=fidelity.finite_thickness,
        large_indentation=fidelity.large_indentation,
    )


def describe(sample: SampleConfig, fidelity: FidelityConfig, tip_radius: float) -> dict[str, Any]:
    """What the world's tissue of ``sample`` is, for results (``tissue_model`` in ``--json``)."""
    sls = relaxation(sample, fidelity)
    out: dict[str, Any] = {"level": "rigid" if sample.rigid else fidelity.tissue_model}
    if sample.rigid:
        out["law"] = "steel block (Hertz, E = 200 GPa)"
    elif fidelity.tissue_model == "fe":
        world = fe_world(sample, fidelity, tip_radius)
        problem = world if isinstance(world, LayerProblem) else world.layer
        out.update(
            law="finite elements (sim.fem)",
            material=problem.material,
            base=problem.base,
            contact=problem.contact,
            thickness_over_r=problem.thickness_ratio,
            lateral_radius_over_r=problem.radius_ratio,
            poisson=problem.poisson,
            table=table_key(problem),
        )
        stops = table_stops(problem)
        if stops is not None:
            out["table_stops"] = stops
        if not isinstance(world, LayerProblem):
            out["inclusions"] = [
                {
                    "center_mm": list(i.center_mm),
                    "radius_mm": i.radius_mm,
                    "modulus_kpa": i.modulus_kpa,
                }
                for i in sample.inclusions
            ]
            out["law"] = "finite elements (sim.fem) x 3-D inclusion factor (sim.fem3d)"
            out["table"] = world.key
    else:
        out["law"] = "Sneddon x Dimitriadis (sim.tissue: the estimator's own family)"
    out["viscoelastic"] = None if sls is None else {**sls.describe(), "modulus": "relaxed"}
    return out


SHORT_TABLE = 0.5
"""A table whose solve stopped before this share of the depth it was asked for is reported."""


def table_stops(problem: LayerProblem) -> dict[str, Any] | None:
    """Where the finite elements of ``problem`` stopped, when they stopped short (their solve
    did not converge, before ``SHORT_TABLE`` of the depth asked): past ``delta_over_r`` the
    world's force is an extrapolation of the table, not the FE (``sim.fem.law``). None for a
    table that reached its depth, and for one not solved yet (this never solves). Usage::

        table_stops(problem)  # a 1.6 mm sliding layer under a 10 mm tip, frictionless:
        # {'delta_over_r': 0.0018, 'asked_delta_over_r': 0.08, 'message': 'stopped at ...'}
    """
    table = solved_table(problem)
    if table is None:
        return None
    reach = float(table.depths[-1])
    if table.success or reach >= SHORT_TABLE * problem.depth_max:
        return None
    return {
        "delta_over_r": reach,
        "asked_delta_over_r": problem.depth_max,
        "message": table.message,
    }


@dataclass(frozen=True)
class RigidBlock:
    """A rigid reference sample: the tip on a steel block (Hertz on a half-space with
    E = 200 GPa, nu = 0.3; the tip itself rigid). At the sensor's 1.4 N it gives 0.2 um: the
    stage's and tube's compliance is all that remains, which is what a rigid reference is for.
    Own closed form (not the estimator's), the physics of a small contact on a thick block."""

    tip_radius: float

    @property
    def _c(self) -> float:
        reduced = STEEL_MODULUS / (1.0 - STEEL_POISSON**2)
        return 4.0 / 3.0 * reduced * math.sqrt(self.tip_radius)

    def force_and_stiffness(self, delta: ArrayLike) -> tuple[FloatArray, FloatArray]:
        d = np.asarray(delta, dtype=np.float64)
        if not np.all(np.isfinite(d)) or np.any(d < 0):
            raise ValueError("indentation depth delta must be finite and >= 0")
        root = np.sqrt(d)
        return self._c * d * root, 1.5 * self._c * root

    def inverse(self, force: ArrayLike) -> FloatArray:
        f = np.asarray(force, dtype=np.float64)
        if not np.all(np.isfinite(f)) or np.any(f < 0):
            raise ValueError("force must be finite and >= 0")
        return np.asarray(np.cbrt(f / self._c) ** 2, dtype=np.float64)

    def force_and_stiffness_at(self, delta: float) -> tuple[float, float]:
        if not (delta >= 0 and math.isfinite(delta)):
            raise ValueError("indentation depth delta must be finite and >= 0")
        root = math.sqrt(delta)
        return self._c * delta * root, 1.5 * self._c * root

    def inverse_at(self, force: float) -> float:
        if not (force >= 0 and math.isfinite(force)):
            raise ValueError("force must be finite and >= 0")
        return float((force / self._c) ** (2.0 / 3.0))

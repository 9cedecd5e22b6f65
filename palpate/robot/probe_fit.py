"""The surface that probing's touches show, and how far a pose may be from its normal.

:func:`touch_surface` fits the touches' tip centres (``estimation.pose.surface``, or a sphere of the
radius the operator believes, ``estimation.pose.surface_belief``); :func:`scaled_sigma` is the
fitted normal's 1-sigma as the touches' own scatter allows; :func:`allowed_residual` the angle a
probed pose may have from it.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from ..estimation.contact.law import MAX_MISALIGNMENT
from ..estimation.pose.surface import SurfaceFit, fit_surface
from ..estimation.pose.surface_belief import fit_sphere_of_radius

FloatArray = NDArray[np.float64]

# A pose this many of the measured normal's 1-sigma angles past the angle tolerance cannot be
# told from one within it: it is indented, and the verdict reads its residual (suspect beyond
# the tolerance) instead of the trial ending unreachable on a noisy normal.
NORMAL_SIGMAS = 2.0
# ... but never past MAX_MISALIGNMENT (5 deg), where the indentation is no longer normal (the
# estimator's validity flag): a normal so uncertain that a pose 30 deg off "cannot be told" from
# square is not measured well enough to indent on, and the trial says so before it indents.


def touch_surface(
    centres: FloatArray,
    rays: FloatArray,
    sigma: float,
    surface_radius: tuple[float, float] | None,
    tip_radius: float,
) -> SurfaceFit:
    """The surface through the touches' tip centres: a sphere of the believed radius (the
    centres' radius is the tip radius larger), else a plane or a sphere (``fit_surface``)."""
    hint, reference = -rays.mean(axis=0), centres[0]
    if surface_radius is None:
        return fit_surface(centres, sigma=sigma, hint=hint, directions=rays, reference=reference)
    radii = (surface_radius[0] + tip_radius, surface_radius[1] + tip_radius)
    return fit_sphere_of_radius(
        centres, radii, sigma=sigma, hint=hint, directions=rays, reference=reference
    )


def allowed_residual(tolerance: float, normal_sigma: float) -> float:
    """The residual angle (rad) a probed pose may have: the tolerance plus NORMAL_SIGMAS of the
    measured normal's 1-sigma, capped at the larger of the tolerance and MAX_MISALIGNMENT."""
    return min(tolerance + NORMAL_SIGMAS * normal_sigma, max(tolerance, MAX_MISALIGNMENT))


def scaled_sigma(fit: SurfaceFit, sigma: float) -> float:
    """The normal's 1-sigma angle, scaled up when the touches scatter about the fitted surface
    more than their assumed ``sigma`` (m) says (the square root of chi^2 per degree of freedom,
    as a weighted fit's uncertainty is when the a-priori sigma is in doubt; never scaled down).
    A plane has 3 parameters, a sphere 4 (3 of a believed radius); with no spare touch the
    assumed sigma stands."""
    dof = fit.points - fit.free_parameters
    if dof < 1 or not math.isfinite(fit.rms) or sigma <= 0.0:
        return fit.normal_sigma
    ratio = math.sqrt(fit.points / dof) * fit.rms / sigma
    return fit.normal_sigma * max(1.0, ratio)

"""The rig's compliance from trials on rigid references, as the campaigns and the bench use it.

A scene's ``rigid: true`` sample (a stored pose on the bench, a trial with ``rigid: true``) is a
rigid reference: a trial there fits the compliance between the stage encoder and the sensor's
clamp (``estimation.fits.compliance``) instead of a modulus. The trials on references run first; per
tube on the robot (the bench-top stage: one value), the envelope of their intervals is the
calibrated compliance (``estimation.fits.compliance.pooled``), set in the robot configuration
(``tubes[].compliance_mm_per_n``, ``calibration.stage_compliance_mm_per_n``) for the
campaign's other trials, and printed as the YAML lines to store (:func:`config_lines`).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterable, Sequence

from palpate.config.scene import SceneConfig
from palpate.config.schema import MM, StackConfig
from palpate.estimation.beam.stage import STAGE
from palpate.estimation.fits.compliance import ComplianceFit, pooled


def is_reference(scene: SceneConfig, spec: object) -> bool:
    """Whether the trial ``spec`` (a ``TrialSpec``) indents a rigid reference of ``scene``."""
    name = getattr(spec, "sample", None)
    return any(s.rigid and s.name == name for s in scene.samples)


def calibrate(
    trials: Iterable[tuple[str, ComplianceFit | None]],
) -> dict[str, tuple[float, float]]:
    """Per rig key (:func:`rig_key`), the calibrated compliance range (m/N) pooled from the
    (key, fit) of each trial on a reference; keys without a successful fit are left out."""
    by_key: dict[str, list[ComplianceFit]] = {}
    for key, fit in trials:
        if fit is not None:
            by_key.setdefault(key, []).append(fit)
    out = {}
    for key, fits in by_key.items():
        found = pooled(fits)
        if found is not None:
            out[key] = found
    return out


def with_compliance(stack: StackConfig, found: dict[str, tuple[float, float]]) -> StackConfig:
    """``stack`` with the calibrated compliances ``found`` (m/N per rig key) stored."""
    tubes = tuple(
        dataclasses.replace(t, compliance_mm_per_n=_mm(found[t.name])) if t.name in found else t
        for t in stack.tubes
    )
    calibration = stack.calibration
    if STAGE in found:
        calibration = dataclasses.replace(calibration, stage_compliance_mm_per_n=_mm(found[STAGE]))
    return dataclasses.replace(stack, tubes=tubes, calibration=calibration)


def calibrated(scene: SceneConfig, stack: StackConfig, outcomes: Sequence[object]) -> StackConfig:
    """The campaign's robot configuration once its reference trials ``outcomes``
    (``TrialOutcome``) have calibrated it (unchanged without any)."""
    trials = []
    for o in outcomes:
        spec = getattr(o, "spec", None)
        fit = getattr(o, "calibration", None)
        if spec is not None:
            trials.append((spec.stage.rig_key, fit))
    found = calibrate(trials)
    return with_compliance(stack, found) if found else stack


def config_lines(found: dict[str, tuple[float, float]]) -> list[str]:
    """The robot configuration's lines that store ``found`` (m/N per rig key)."""
    lines = []
    for key, r in sorted(found.items()):
        lo, hi = _mm(r)
        value = f"[{lo:.4g}, {hi:.4g}]"
        if key == STAGE:
            lines.append(f"calibration.stage_compliance_mm_per_n: {value}")
        else:
            lines.append(f"tubes[name={key}].compliance_mm_per_n: {value}")
    return lines


def _mm(r: tuple[float, float]) -> tuple[float, float]:
    """m/N -> mm/N."""
    return r[0] / MM, r[1] / MM

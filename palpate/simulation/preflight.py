"""Checks that a campaign can run at all, made before any port is opened (nothing moves).

A configuration can be well formed key by key and still be impossible as a whole: a tube that
cannot reach the sample within the drive's translation or roll limits. Every trial's geometry is
solved here first, so such a campaign fails with a :class:`config.loader.ConfigError` naming the
files and keys to look at, and exit code 2, instead of faulting halfway through.
"""

from __future__ import annotations

from collections.abc import Sequence

from palpate.config.loader import ConfigError
from palpate.config.scene import (
    SceneConfig,
    campaign_lengths,
    require_exposed_gratings,
    require_tip_grating,
)
from palpate.config.schema import StackConfig
from palpate.simulation.world import TrialSpec, trial_geometry


def check_campaign(
    scene: SceneConfig, stack: StackConfig, scene_source: str, robot_source: str
) -> None:
    """Raise ConfigError if the scene's campaign names a tube the robot configuration lacks,
    reads the contact or the buckling from a tip grating the sensor does not have, or presses at
    an exposed length that leaves a grating it reads inside the tube."""
    require_tip_grating(scene.campaign, stack, scene_source, robot_source)
    lengths = campaign_lengths(scene.campaign)
    require_exposed_gratings(lengths, stack, scene_source, robot_source)
    known = [t.name for t in stack.tubes]
    if not scene.campaign.on_tubes:
        return
    for i, name in enumerate(scene.campaign.tubes):
        if name not in known:
            raise ConfigError(
                scene_source,
                f"campaign.tubes[{i}]",
                f"no tube named {name!r} in {robot_source}; known: {known}",
            )


def check_reachable(
    specs: Sequence[TrialSpec], stack: StackConfig, scene_source: str, robot_source: str
) -> None:
    """Raise ConfigError for the first trial whose target the robot cannot reach."""
    for spec in specs:
        try:
            trial_geometry(stack, spec)
        except ValueError as exc:
            raise ConfigError(
                scene_source,
                "campaign",
                f"{exc} (check campaign.exposed_length_mm and campaign.tubes here, and "
                f"drive.translation_*_mm / drive.roll_*_deg / tubes in {robot_source})",
            ) from None

"""A trial run again at a shorter exposed length, where the beam buckled before its record could
be read (``campaign.retry_lengths_mm``).

The beam buckles at P_cr = 20.19 EI / L^2, so the indentation it reaches before buckling grows
as the exposed length shortens: with Hertz, delta at buckling goes as (P_cr / E)^(2/3), as
L^(-4/3). Beside the heart, a stiff sample buckles a 45 mm beam within about 0.1 mm of the
first touch, less than the beat's own excursion. The record is then read in the heart's quiet
phase (``estimation.trial.strobe``), but where the breath hold's drift brings the tissue in as
fast as the stage, too few quiet windows touch before the beam buckles (docs/invivo.md). At
30 mm the same sample is read over 1.7 times the indentation. Which length a sample needs is
not known before it is touched, so a trial that buckled and gave no estimate runs again at each
of the campaign's shorter lengths in turn, until one gives an estimate::

    outcome = chained(spec, scene.campaign, lambda s: run_sim_trial(s, scene, stack))

Each attempt writes its own log (the trial's id names its length), so nothing is lost, and
``--resume`` follows the same chain through the logs (an attempt that reads None: not run yet).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

from palpate.config.optics import MM
from palpate.config.scene import CampaignConfig
from palpate.robot.plan import State
from palpate.robot.trial.outcome import Outcome
from palpate.simulation.result import TrialOutcome
from palpate.simulation.world import TrialSpec


def buckled_unread(outcome: Outcome) -> bool:
    """The trial ran to buckling and gave no estimate: a shorter, stiffer beam may read it (a
    rigid reference's trial, which calibrates the rig instead, never asks for one)."""
    marks = outcome.marks
    buckled = marks is not None and marks.x_buckling is not None
    unread = outcome.modulus("joint") is None and outcome.calibration is None
    return outcome.state == State.DONE and buckled and unread


def retries(spec: TrialSpec, campaign: CampaignConfig) -> list[TrialSpec]:
    """``spec`` at each of ``campaign.retry_lengths`` shorter than its own length, longest
    first; each id names its length where ``spec``'s did (``...-L45`` -> ``...-L30``)."""
    lengths = sorted((x for x in campaign.retry_lengths if x < spec.exposed_length), reverse=True)
    return [at_length(spec, length) for length in lengths]


def at_length(spec: TrialSpec, length: float) -> TrialSpec:
    """``spec`` at exposed length ``length`` (m), its id's ``L<mm>`` part renamed."""
    old, new = f"L{spec.exposed_length / MM:g}", f"L{length / MM:g}"
    parts = [new if p == old else p for p in spec.trial_id.split("-")]
    if new not in parts:
        parts.append(new)
    return dataclasses.replace(spec, trial_id="-".join(parts), exposed_length=length)


def chained(
    spec: TrialSpec,
    campaign: CampaignConfig,
    attempt: Callable[[TrialSpec], TrialOutcome | None],
) -> TrialOutcome | None:
    """``attempt(spec)``, then while it buckled unread ``attempt`` of each of its
    :func:`retries` in turn: the last attempt's outcome, its ``tried`` naming those before it.
    None where an attempt gives None (a resumed chain whose next attempt has no log yet)."""
    outcome = attempt(spec)
    for retry in retries(spec, campaign):
        if outcome is None or not buckled_unread(outcome):
            break
        tried = (*outcome.tried, outcome.spec.trial_id)
        again = attempt(retry)
        outcome = None if again is None else dataclasses.replace(again, tried=tried)
    return outcome

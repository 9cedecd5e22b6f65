"""The fault campaign: inject each fault of a scene into simulated trials, then check from the
emulators and the logs (never from what the controller believes) that every trial stopped
safely and kept its data.

- :mod:`palpate.faults.injector`: the emulator hooks that fire a case's faults and record the
  ground truth;
- :mod:`palpate.faults.judge`: the definitions of a safe stop and of data kept, applied to one
  trial (also to a killed one);
- :mod:`palpate.faults.runner`: the jobs, the killed child process, the campaign, its table and
  ``palpate sim --faults``.
"""

from __future__ import annotations

from palpate.faults.injector import FaultInjector, GroundTruth, ServoSnapshot
from palpate.faults.judge import FaultJob, FaultTrialResult, judge, judge_killed
from palpate.faults.runner import (
    FaultRow,
    child_command,
    fault_jobs,
    fault_table,
    render_table,
    run_command,
    run_fault_campaign,
    run_fault_trial,
)

__all__ = [
    "FaultInjector",
    "FaultJob",
    "FaultRow",
    "FaultTrialResult",
    "GroundTruth",
    "ServoSnapshot",
    "child_command",
    "fault_jobs",
    "fault_table",
    "judge",
    "judge_killed",
    "render_table",
    "run_command",
    "run_fault_campaign",
    "run_fault_trial",
]

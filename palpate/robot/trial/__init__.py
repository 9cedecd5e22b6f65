"""The trial core: one indentation trial from plan to record, the same on the bench and in the
simulator (only the wiring differs: ``palpate.lab.trial`` and ``palpate.simulation.trial``).

- :mod:`.setup`: what a runner builds from a campaign: the sensor's section, the guards, the
  rig's settings (the control period), the stage's position tolerance, the buckling detector and
  the :class:`~robot.indentation.TrialPlan`.
- :mod:`.run`: the :class:`~.run.Rig` protocol and the control loop (:func:`~.run.run_trial`).
- :mod:`.estimate`: the estimates of a finished trial: the paper's (encoder marks, Eqs. 13-14)
  and the joint fit of the loading record; ``palpate replay`` re-runs the same functions.
- :mod:`.record`: the records of a trial log that are not per tick (header, estimate, end).
- :mod:`.session`: one trial as the bench and the simulator run it (zero, log, run, estimate).
- :mod:`.tipforce`: the tip force a recording derives at its close.

The log file, its schema and the MCAP recording are serialisation: ``robot.records``.
"""

"""The simulator's wiring: one simulated trial, wired exactly like the bench.

- :mod:`.world`: what one simulated trial is (``TrialSpec``) and the world it runs in (tissue,
  geometry, the sample's pose).
- :mod:`.placement`: where a robot trial's sample stands: the plan's target, tilted and moved.
- :mod:`.trial`: the emulators in, the control stack on top, one trial run to its outcome.
- :mod:`.result`: what a simulated trial ends with, and the estimate from what the estimator is
  told.
- :mod:`.twin`: a simulated bench for ``palpate emulate`` and ``palpate teleop``: both emulators
  and a world with tissue, on ptys.
- :mod:`.preflight`: checks that a campaign can run at all, before any port is opened.

May import: ``robot``, ``sensor``, ``sim``, ``estimation``, ``config``, ``wire`` and the
top-level helpers of ``palpate`` (``argtypes``, ``progress``, ``calibration``). Imported by the
campaigns, the reports, the benchmarks, the fault campaign and the commands; never by ``lab``.
"""

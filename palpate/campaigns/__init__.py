"""Campaigns and studies: many simulated trials, where they run and where they write.

- :mod:`.campaign`: the list of trials a scene asks for, running them, Tables I/II from them.
- :mod:`.executors`: where trials run (serial, thread, process pool, Dask), chosen by name.
- :mod:`.runs`: a new folder per run, never shared, nothing deleted.
- :mod:`.resume`: a killed campaign resumed from its trial logs.
- :mod:`.study`: a coverage study's statistics (error and interval coverage with bounds).
- :mod:`.designcheck`: a sensor design tried on simulated phantoms.

May import ``palpate.simulation`` and the top-level helpers; imported by the reports, the
benchmarks, the fault campaign and the commands.
"""

"""What a person reads after a run: tables, verdict tallies, plots and replays.

- :mod:`.verdicts`: verdict tallies (ok / suspect / none) and their column in every table.
- :mod:`.methods`: ``palpate sim --compare-methods``, the paper's estimate vs the joint fit.
- :mod:`.papertables`: ``palpate sim --compare-paper``, Tables I and II beside the simulated ones.
- :mod:`.plots`: PNG figures of a campaign.
- :mod:`.replay`: a trial log's estimates re-run and compared with the recorded ones.
- :mod:`.design`: what ``palpate design`` reports (the sensor, its checks, the simulated check).

May import ``palpate.campaigns``, ``palpate.simulation`` and the top-level helpers; imported by
the benchmarks, the fault campaign and the commands.
"""

"""A trial's records: the crash-safe JSON Lines log and its schema (:mod:`.log`,
:mod:`.logschema`), the MCAP recording beside it with ROS 2 message definitions
(:mod:`.recording`, :mod:`.ros2`, the CDR packing of :mod:`.cdr`), and the export of an
existing log to a recording (:mod:`.export`). Serialisation only: what a record means (the
tip force derived from the strains, the estimate) is computed in ``robot.trial`` and handed in.
"""

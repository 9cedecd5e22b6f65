"""The world the hardware would be: scenes, contact mechanics, virtual clock, device emulators.

Time in simulation is a virtual clock: sleeping advances it, and nothing waits for real time::

    >>> from palpate.sim.clock import VirtualClock
    >>> clock = VirtualClock()
    >>> clock.sleep(0.25)
    >>> clock.now()
    0.25
"""

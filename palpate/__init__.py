"""The ``palpate`` application: command-line entry point and the wiring of hardware or emulators."""

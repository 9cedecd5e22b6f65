"""The estimates of one finished trial, on the bench, in the simulator and in ``palpate replay``
alike: its record read into the paper's estimate, the joint fit, the lean, the relaxation, the
surface's motion and the verdict (``estimate.estimate_trial``)."""

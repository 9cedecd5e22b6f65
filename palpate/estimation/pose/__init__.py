"""Pose and geometry: the surface and its normal (``surface``, ``surface_belief``), the sensor's
lean on it (``misalignment``, ``slip_path``, both searching with ``golden``) and the surface's
motion (``motion``)."""

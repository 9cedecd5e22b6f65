"""Finite strain for the estimator's law: the neo-Hookean departure from the linear layer law."""

"""A layer of its own below estimation and the simulator: the user's cache of solved tables
(``cache``), which both read and neither owns."""

"""Contact laws: the force of an indentation depth for a tip on tissue. Hertz and Sneddon on a
half-space, the thin layer (``layer``, ``layer_exact``, ``layer_table``), the finite-strain
departure (``finite_strain``) and the law a trial's estimate uses (``law.ContactLaw``)."""

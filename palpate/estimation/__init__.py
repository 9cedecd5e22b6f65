"""Pure physics and statistics: composite section, elastica, contact, detection, stiffness fits.

Pure functions on SI values, e.g. Hertz's sphere, forwards and back (the paper's Eq. 13)::

    >>> from palpate.estimation.contact.hertz import hertz_force, hertz_modulus
    >>> P = hertz_force(300e3, 0.5e-3, 3.5e-3, 0.45)  # E (Pa), depth (m), tip radius (m), nu
    >>> round(float(P), 4), round(float(hertz_modulus(P, 0.5e-3, 3.5e-3, 0.45)))
    (0.3318, 300000)
"""

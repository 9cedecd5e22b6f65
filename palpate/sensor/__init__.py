"""FBG signal chain: board frames over pyserial, wavelength -> strain, grating averages,
detection.

E.g. the strain noise 1 pm of wavelength noise makes at the paper's 0.424 pm per microstrain::

    >>> from palpate.sensor.strain import strain_noise
    >>> round(strain_noise(1.0) * 1e6, 2)  # microstrain
    2.36
"""

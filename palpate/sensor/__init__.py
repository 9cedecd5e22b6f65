"""FBG signal chain: board frames over pyserial, wavelength -> strain, grating averages,
detection."""

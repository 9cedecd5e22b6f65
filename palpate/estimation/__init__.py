"""Pure physics and statistics: composite section, elastica, contact, detection, stiffness fits."""

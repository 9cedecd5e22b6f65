"""The sensor's beam: its section and gratings (``section``), its bending and buckling
(``model``, ``column``, ``elastica``), the states a row of strains shows (``states``) and the
stage that sets its exposed length (``stage``)."""

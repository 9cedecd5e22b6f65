"""Fits of a trial's numbers: the paper's estimate (``stiffness``), the elastica to a row of
strains (``strain_fit``), Southwell's plot (``southwell``) and the rig's compliance
(``compliance``). The joint fit and the relaxation have packages of their own."""

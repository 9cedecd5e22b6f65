"""The relaxed and instantaneous moduli of a relaxing sample, from a loading record and a hold.

A buckled beam is nearly a constant-force spring, so holding the stage after buckling is a creep
test the gratings see: the tissue creeps, the beam straightens a little, and the strains give
the load P (or a tip grating's) and the beam's end shortening e at every tick
(``estimation.beam.states``). With the contact position x0, the depth is ``delta = u - x0 - e -
c P`` as in the joint fit.

Model (quasi-linear viscoelasticity, the form-free way). With f the elastic contact law's shape
(``estimation.contact.law.ContactLaw.shape``, F = E f), a relaxation modulus written as a
spectrum of fixed time constants tau_k (a generalised Maxwell body)::

    P_i - P0 = E_inf f(delta_i) + sum_k c_k h_k(t_i),
    h_k(t) = integral_0^t exp(-(t - s)/tau_k) df(delta(s)),

is linear in (E_inf, c_k) with every term >= 0: non-negative least squares
(``scipy.optimize.nnls``) on the record weighted by its noise, for each x0 on a grid around the
joint fit's contact (x0 is profiled, the load offset P0 is the joint fit's: the samples before
contact fix it, and relaxation does not move them). ``h_k`` is the exact recursion of a
piecewise-linear f (as the world steps its own relaxation, but on the *measured* depth and on
fixed times that need not match the tissue's). The instantaneous modulus is
``E_0 = E_inf + sum_k c_k``; the relaxation parameter reported is the spectrum's mean time
``sum c_k tau_k / sum c_k``. The spectrum has four times a decade from twice the tick to
``TAIL`` times the record's span in contact: relaxation slower than the record can show is
allowed, so a record still creeping at its end widens E_inf's interval downward rather than
reading the modulus at the end of the hold as the relaxed one. The estimator assumes neither
the world's exponential nor its power law.

Intervals (``confidence``): at each x0 the active set's linear least squares gives the
standard errors of E_inf and E_0, with the noise inflated by the reduced chi^2 and the residuals'
lag-1 autocorrelation (as in ``estimation.jointfit.noise``); the profile over x0 (RSS(x0) -
RSS_min within the chi^2 quantile) is projected on each modulus; the law's model-form bound
(the joint fit's ``model_form``) widens both relatively.

Verdicts. ``relaxes``: the spectrum beats the elastic law (E_inf alone, its own best x0) by
more than ``RELAXES_CHI2`` noise variances and E_0 exceeds E_inf by more than ``RELAXES_MIN``
(an elastic record: "no relaxation"). ``complete``: the spectrum cut at the record's span in
contact fits as well (within the chi^2 quantile) as the one reaching ``TAIL`` times past it: the
estimate is then the cut spectrum's; otherwise the record needs relaxation slower than itself,
the relaxed modulus is extrapolated (the interval the envelope of both) and said to be; so it
is where more than ``INCOMPLETE`` of the last sample's load is still relaxing (the interval's
low end then reaches what it would lose). The law's model-form bound and ``SPECTRUM_FORM``
(a fixed spectrum's misfit of a time constant between its own) widen both intervals.

Beliefs left open (a Poisson ratio's range, an unknown thickness): ``beliefs``
(:func:`fit_over_beliefs`) fits each hypothesis and takes the envelope of the plausible ones'
intervals, as the joint fit does.

Failure (no hold, too few points in contact, no finite solution) is a :class:`RelaxationFit`
with ``success`` False and the reason; bad input raises ValueError.

Layout: ``fit`` (the recipe, :func:`fit_relaxation`), ``beliefs`` (over hypotheses),
``spectrum`` (the fixed-time spectrum, the memory basis, one x0's non-negative least squares,
the intervals), ``result``
(:class:`RelaxationFit`, :class:`RelaxationRecord`).
"""

from __future__ import annotations

from .beliefs import fit_over_beliefs
from .fit import fit_relaxation
from .result import RelaxationFit, RelaxationRecord
from .spectrum import memory_basis

__all__ = [
    "RelaxationFit",
    "RelaxationRecord",
    "fit_over_beliefs",
    "fit_relaxation",
    "memory_basis",
]

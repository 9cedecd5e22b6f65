"""Contact-point-free stiffness: fit the modulus and the contact position jointly on a record.

The paper's estimate (Eqs. 13-14) uses two instants, contact and buckling, so an error in the
contact event goes straight into the indentation (E ~ delta^-1.5: 0.1 mm on 0.8 mm is 20 %). As
AFM tools do, we treat the contact position x0 as a free parameter and fit the whole loading
record instead: for every sample i (stage advance u_i, axial load P_i and beam shortening e_i
from the strains, ``estimation.beam.states``)::

    delta_i = u_i - x0 - e_i,        P_i = P0 + E f(delta_i)        (f = 0 for delta_i <= 0)

with f the corrected contact law (``estimation.contact.law.ContactLaw``). Samples before
contact (f = 0) pin the baseline P0; loading samples give the curve's shape (which places x0)
and its scale (E).

Why P0. The strains are zeroed on a few frames at rest (``robot.rig``: 20), so each grating
carries the zero's error, sigma/sqrt(20), on every sample of the trial: a load offset common
to the whole record (about 0.2 sigma_P, i.e. 0.01-0.04 N on the bench). It is not noise the
per-sample sigma describes: with P0 held at 0 the fit bends E and x0 to absorb it, which on
the simulated bench campaign scattered E as much as the white noise did, outside the interval
(the standardised errors had sd 1.4 instead of 1). As AFM tools fit the baseline, P0 is a
free, linear parameter; the approach samples determine it and the profile carries its
uncertainty into E's interval (``load_offset=False`` keeps the old model).

Method.
1. Scan x0 over ``contact_guess +- search`` on a grid; E and P0 are linear, so for each x0
   they have a closed form (weighted least squares): the global basin without local-minimum
   trouble.
2. Refine (log E, x0, P0) with ``scipy.optimize.least_squares`` and a robust loss (``soft_l1``,
   ``f_scale`` in noise units) on residuals standardised by the effective variance
   ``sigma_i^2 = sigma_P,i^2 + (E f'(delta_i))^2 (sigma_e,i^2 + q^2/12)``: the load's noise
   plus the depth's (the strain-inferred shortening and the encoder's quantisation q).
3. Confidence interval for E by profile likelihood over x0: with the weights frozen at the
   solution (robust weights included, i.e. the last IRLS step), for each x0 on a fine grid E
   has a closed form Ê(x0) (P0 profiled out too), the weighted residual RSS(x0) and curvature
   S(x0) (the Schur complement of the (E, P0) normal matrix); the region
   ``RSS(x0) + S(x0) (E - Ê(x0))^2 <= RSS_min + q_chi2 s^2`` projected on E is the interval,
   and projected on x0 the contact interval. ``s^2`` inflates the nominal noise by the model
   residual (reduced chi^2 when above 1) and by the residuals' lag-1 autocorrelation rho
   ((1 + rho)/(1 - rho), the effective-sample-size factor for an AR(1) misfit), so a curve the
   model does not follow gets a wider interval rather than a falsely tight one.
4. Model form: the thin-layer series was derived for a paraboloid; with Sneddon's sphere its
   layer ratio can be sqrt(R delta)/h (published, used for the estimate) or a/h, and the data
   cannot tell them apart (on the simulated bench records their best fits differ by < 0.25 in
   chi^2, against 3.84 for the interval). Each form is profiled as in 3 (same weights; its own
   best x0, E and P0), and the interval reported is the envelope of the forms' intervals (and
   of the estimate): it holds the modulus whichever form the sample follows. ``model_spread``
   is the difference between the forms' moduli. (Adding the spread in quadrature, as before,
   treats it as a zero-mean random error; it is a bias of known sign for each form, and with
   x0 held fixed the spread was also a third too small: on the bench campaign the layer-ratio
   choice alone moved E by -0.5 to -1.6 %.)

Cost: ~9 ms for a 550-sample bench record (two vectorised law evaluations per least-squares
step, a 121 x N scan, a 241 x N profile shared by the model forms; the law is evaluated only past
contact, in cache-sized blocks: see ``grid.grid_fits``).
Failure (too few points, no contact in the record, solver not converged, non-finite result) is
a :class:`JointFit` with ``success`` False and a message naming the step that failed (the steps
raise ``result.FitFailed``, the recipe turns it into the result); bad input raises ValueError.

Layout, one module per step: ``fit`` (the recipe, :func:`joint_fit`), ``record`` (input checks),
``grid`` (E and P0 in closed form on a grid of x0: steps 1 and 3), ``scan`` (1), ``refine`` (2),
``noise`` (3: the weights and noise scale the interval is drawn with), ``profile`` (3: the
profile over x0), ``envelope`` (4), ``result`` (:class:`JointFit`).
"""

from __future__ import annotations

from .fit import MIN_CONTACT_POINTS, MIN_POINTS, joint_fit
from .result import JointFit

__all__ = ["MIN_CONTACT_POINTS", "MIN_POINTS", "JointFit", "joint_fit"]

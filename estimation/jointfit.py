"""Contact-point-free stiffness: fit the modulus and the contact position jointly on a record.

The paper's estimate (Eqs. 13-14) uses two instants, contact and buckling, so an error in the
contact event goes straight into the indentation (E ~ delta^-1.5: 0.1 mm on 0.8 mm is 20 %). As
AFM tools do, we treat the contact position x0 as a free parameter and fit the whole loading
record instead: for every sample i (stage advance u_i, axial load P_i and beam shortening e_i
from the strains, ``estimation.beamstate``)::

    delta_i = u_i - x0 - e_i,        P_i = P0 + E f(delta_i)        (f = 0 for delta_i <= 0)

with f the corrected contact law (``estimation.corrections.ContactLaw``). Samples before
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
contact, in cache-sized blocks: see ``_grid_fits``).
Failure (too few points, no contact in the record, solver not converged, non-finite result) is
a :class:`JointFit` with ``success`` False and a message; bad input raises ValueError.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from statistics import NormalDist

import numpy as np
from numpy.typing import ArrayLike, NDArray

from estimation.corrections import ContactLaw, shape_values, validity_warnings
from estimation.elastica._scipy import least_squares

FloatArray = NDArray[np.float64]
_Fit = tuple[FloatArray, FloatArray, FloatArray, FloatArray]  # Ê, P̂0, RSS, S per contact position

MIN_POINTS = 20
MIN_CONTACT_POINTS = 10
SCAN_POINTS = 121
PROFILE_POINTS = 241
MAX_RHO = 0.95
MIN_SIGNIFICANCE = 5.0  # sigmas by which the contact model must beat "no load at all"
PROFILE_TRIES = 6  # grid widths tried per profile (x3 each) before calling it open at the edge
_BLOCK_ELEMENTS = 16384  # depths per block of grid rows: 128 kB arrays (see _grid_fits)


@dataclass(frozen=True)
class JointFit:
    """Result of :func:`joint_fit`; moduli in Pa, positions in m.

    Attributes:
        success: True when E and x0 were fitted (check ``warnings`` too).
        message: "ok" or what failed.
        modulus: E, or None on failure.
        contact: x0, the stage position at contact.
        load_offset: P0 (N), the fitted constant load offset (0 when not fitted).
        ci_low, ci_high: the confidence interval of E at ``confidence``.
        contact_low, contact_high: the same for x0.
        confidence: the interval's level.
        n_points: samples used; n_contact: those with delta > 0 at the solution.
        max_depth: the largest fitted indentation delta.
        rms: rms of the standardised residuals (about 1 when the noise model holds).
        noise_scale: s, the factor the nominal noise was inflated by for the interval.
        model_spread: |E(other layer ratio) - E| (Pa), each form fitted with its own x0 and P0
            (0 for a half-space); the interval is the envelope of both forms' intervals.
        nfev: residual evaluations of the refinement.
        law: the contact law's name.
        warnings: validity flags and fit diagnostics, one sentence each.
    """

    success: bool
    message: str
    modulus: float | None = None
    contact: float | None = None
    load_offset: float | None = None
    ci_low: float | None = None
    ci_high: float | None = None
    contact_low: float | None = None
    contact_high: float | None = None
    confidence: float = 0.95
    n_points: int = 0
    n_contact: int = 0
    max_depth: float | None = None
    rms: float | None = None
    noise_scale: float | None = None
    model_spread: float | None = None
    nfev: int = 0
    law: str = ""
    warnings: tuple[str, ...] = field(default=())

    def covers(self, modulus: float) -> bool:
        """Whether the interval [ci_low, ci_high] holds ``modulus`` (Pa); False without one."""
        return (
            self.ci_low is not None
            and self.ci_high is not None
            and (self.ci_low <= modulus <= self.ci_high)
        )

    def as_dict(self) -> dict[str, object]:
        """JSON-ready fields (SI units, as named)."""
        return {
            "success": self.success,
            "message": self.message,
            "modulus": self.modulus,
            "contact": self.contact,
            "load_offset": self.load_offset,
            "ci_low": self.ci_low,
            "ci_high": self.ci_high,
            "contact_low": self.contact_low,
            "contact_high": self.contact_high,
            "confidence": self.confidence,
            "n_points": self.n_points,
            "n_contact": self.n_contact,
            "max_depth": self.max_depth,
            "rms": self.rms,
            "noise_scale": self.noise_scale,
            "model_spread": self.model_spread,
            "nfev": self.nfev,
            "law": self.law,
            "warnings": list(self.warnings),
        }


def _vector(name: str, value: ArrayLike, n: int | None) -> FloatArray:
    arr = np.asarray(value, dtype=np.float64)
    if n is not None:
        if arr.ndim > 1 or arr.size not in (1, n):
            raise ValueError(f"{name} must have {n} values (one per sample), got {arr.shape}")
        arr = np.broadcast_to(arr, (n,))
    if arr.ndim != 1 or not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be a finite 1-D array (or a scalar), got shape {arr.shape}")
    return arr


def _closed_form(f: FloatArray, P: FloatArray, w: FloatArray, offset: bool = True) -> _Fit:
    """Per row of f (K, N), the weighted least squares of ``P = P0 + E f`` (P0 = 0 when not
    ``offset``): Ê, P̂0, the RSS there and the curvature S of RSS in E with P0 profiled out
    (the Schur complement ``sum w f^2 - (sum w f)^2 / sum w``), so that
    ``min over P0 of RSS(E, P0) = RSS + S (E - Ê)^2``. S = 0 where f carries no contact."""
    Sff = f * f @ w
    if offset:
        S1 = float(np.sum(w))
        Sf = f @ w
        S = Sff - Sf * Sf / S1
    else:
        S = Sff
    floor = 1e-12 * np.maximum(Sff, np.finfo(np.float64).tiny)  # S = 0 up to rounding
    ok = floor < S
    safe = np.where(ok, S, 1.0)
    if offset:
        Pc = P - float(w @ P) / S1  # centred on the weighted mean: P0 = mean(P) - E mean(f)
        E = np.where(ok, (f * Pc) @ w / safe, 0.0)
        P0 = (float(w @ P) - E * Sf) / S1
    else:
        E = np.where(ok, (f * P) @ w / safe, 0.0)
        P0 = np.zeros_like(E)
    rss = ((P - P0[:, None] - E[:, None] * f) ** 2) @ w
    return E, P0, rss, np.where(ok, S, 0.0)


def _grid_fits(
    laws: Sequence[ContactLaw],
    depth_base: FloatArray,
    P: FloatArray,
    w: FloatArray,
    grid: FloatArray,
    offset: bool,
) -> list[_Fit]:
    """:func:`_closed_form` of each law at every contact position of ``grid`` (K,): per law
    (Ê, P̂0, RSS, S), each (K,); ``depth_base``, ``P``, ``w`` are (N,).

    Why it is shaped this way (it is most of the joint fit's cost: K x N = 30k-130k depths per
    grid):
    - the samples are sorted by depth once, so at contact position x0 the touching samples are
      a suffix; a block of rows evaluates the law only from its first touching sample on, at
      max(depth, 0) (f(0) = 0 exactly), with no mask to build, gather or scatter;
    - rows go in blocks of at most _BLOCK_ELEMENTS depths, so every temporary stays under
      128 kB, glibc's mmap threshold: a larger one is mapped and page-faulted afresh each time,
      which on the 2-core VM cost more than the arithmetic (``1 - t * t`` on 1e5 elements:
      0.8 ms instead of 0.03 ms). Median joint fit per bench trial: whole (K, N) matrices
      16 ms, blocks of 16384 depths 8.7 ms, of 4096 12 ms (numpy's per-call overhead);
    - the laws share one evaluation of the half-space part
      (``estimation.corrections.shape_values``).
    The sums run in depth order instead of record order: the same fit up to rounding.
    """
    order = np.argsort(depth_base, kind="stable")
    depth_sorted, P_sorted, w_sorted = depth_base[order], P[order], w[order]
    first = np.searchsorted(depth_sorted, grid, side="right")  # first touching sample per row
    n = depth_sorted.size
    rows = max(1, _BLOCK_ELEMENTS // n)
    parts: list[list[_Fit]] = [[] for _ in laws]
    for start in range(0, grid.size, rows):
        x0 = grid[start : start + rows]
        col = int(first[start : start + rows].min())
        depth = depth_sorted[None, col:] - x0[:, None]
        for law_parts, f_touching in zip(parts, shape_values(laws, depth), strict=True):
            f = np.zeros((x0.size, n))
            f[:, col:] = f_touching
            law_parts.append(_closed_form(f, P_sorted, w_sorted, offset))
    return [_concatenate(law_parts) for law_parts in parts]


def _concatenate(blocks: list[_Fit]) -> _Fit:
    E, P0, rss, S = (np.concatenate(column) for column in zip(*blocks, strict=True))
    return E, P0, rss, S


def joint_fit(
    advance: ArrayLike,
    force: ArrayLike,
    shortening: ArrayLike,
    law: ContactLaw,
    *,
    sigma_force: ArrayLike,
    sigma_shortening: ArrayLike = 0.0,
    encoder_resolution: float = 0.0,
    contact_guess: float | None = None,
    search: float = 1.0e-3,
    confidence: float = 0.95,
    f_scale: float = 3.0,
    load_offset: bool = True,
    misalignment: float | None = None,
    min_points: int = MIN_POINTS,
    min_contact_points: int = MIN_CONTACT_POINTS,
    max_nfev: int = 200,
) -> JointFit:
    """Fit E and the contact position x0 on a loading record (see the module docstring).

    Args:
        advance: (N,) stage positions u (m), from before contact to the end of loading.
        force: (N,) axial loads P (N) inferred from the strains.
        shortening: (N,) beam end shortening e (m) inferred from the strains.
        law: the contact law ``F = E f(delta)``.
        sigma_force: (N,) or scalar standard deviation of P (N, > 0).
        sigma_shortening: (N,) or scalar standard deviation of e (m).
        encoder_resolution: one encoder count of stage advance (m); adds q^2/12 to the depth
            variance.
        contact_guess: first guess of x0 (m), e.g. the contact event or
            ``estimation.detect_contact``; None: the middle of the record's advance range.
        search: x0 is searched within contact_guess +- search (m), and within the record.
        confidence: the interval's level, in (0, 1).
        f_scale: the robust loss's soft threshold, in noise units.
        load_offset: fit a constant load offset P0 (the sensor's zero error) beside E and x0;
            False: the load is taken as exactly 0 before contact.
        misalignment: angle (rad) between the sensor axis and the surface normal, for the flags.
        min_points, min_contact_points: below these the fit is refused (success False).
        max_nfev: least-squares budget.

    Raises:
        ValueError: non-finite or mismatched arrays, non-positive sigmas, bad options.
    """
    u = _vector("advance", advance, None)
    n = u.size
    P = _vector("force", force, n)
    e = _vector("shortening", shortening, n)
    sig_p = _vector("sigma_force", sigma_force, n)
    sig_e = _vector("sigma_shortening", sigma_shortening, n)
    if np.any(sig_p <= 0) or np.any(sig_e < 0):
        raise ValueError("sigma_force must be > 0 and sigma_shortening >= 0")
    if not (0.0 < confidence < 1.0):
        raise ValueError(f"confidence must be in (0, 1), got {confidence!r}")
    if not (math.isfinite(search) and search > 0 and f_scale > 0 and encoder_resolution >= 0):
        raise ValueError("search and f_scale must be > 0, encoder_resolution >= 0")

    def failed(message: str, n_contact: int = 0, nfev: int = 0) -> JointFit:
        return JointFit(
            False,
            message,
            n_points=n,
            n_contact=n_contact,
            nfev=nfev,
            confidence=confidence,
            law=law.name,
        )

    if n < min_points:
        return failed(f"too few points: {n} samples, the fit needs {min_points}")
    depth_base = u - e  # delta = depth_base - x0
    var_depth = sig_e**2 + encoder_resolution**2 / 12.0

    # 1. scan x0 with E in closed form
    guess = 0.5 * (float(u.min()) + float(u.max())) if contact_guess is None else contact_guess
    if not math.isfinite(guess):
        raise ValueError(f"contact_guess must be finite, got {contact_guess!r}")
    lo = max(guess - search, float(u.min()) - search)
    hi = min(guess + search, float(depth_base.max()))
    if not hi > lo:
        return failed("no contact: the record ends before the contact search window")
    grid = np.linspace(lo, hi, SCAN_POINTS)
    w0 = 1.0 / sig_p**2
    [(E_grid, P0_grid, rss_grid, S_grid)] = _grid_fits([law], depth_base, P, w0, grid, load_offset)
    usable = (S_grid > 0) & (E_grid > 0)
    if not np.any(usable):
        return failed("no contact: no contact position in the window gives a positive load")
    k = int(np.argmin(np.where(usable, rss_grid, np.inf)))
    p_scale = float(np.median(sig_p))
    theta0 = np.array([math.log(E_grid[k]), grid[k], P0_grid[k] / p_scale])
    if not load_offset:
        theta0 = theta0[:2]

    # 2. robust refinement with the effective variance
    x0_scale = max(1e-6, (hi - lo) / SCAN_POINTS)

    def sigma(theta: FloatArray) -> FloatArray:
        f, df = law.shape(depth_base - theta[1])
        del f
        slope = math.exp(theta[0]) * df
        return np.asarray(np.sqrt(sig_p**2 + slope**2 * var_depth))

    def residuals(theta: FloatArray) -> FloatArray:
        f, df = law.shape(depth_base - theta[1])
        E = math.exp(theta[0])
        P0 = theta[2] * p_scale if load_offset else 0.0
        return np.asarray((P - P0 - E * f) / np.sqrt(sig_p**2 + (E * df) ** 2 * var_depth))

    n_par = theta0.size
    try:
        sol = least_squares(
            residuals,
            theta0,
            loss="soft_l1",
            f_scale=f_scale,
            bounds=([-np.inf, lo, -np.inf][:n_par], [np.inf, hi, np.inf][:n_par]),
            x_scale=np.array([1.0, x0_scale, 1.0][:n_par]),
            max_nfev=max_nfev,
        )
    except (ValueError, FloatingPointError) as exc:
        return failed(f"least squares failed: {exc}")
    if sol.status <= 0 or not np.all(np.isfinite(sol.x)):
        return failed(f"least squares did not converge: {sol.message}", nfev=int(sol.nfev))
    E_hat, x0_hat = math.exp(float(sol.x[0])), float(sol.x[1])
    P0_hat = float(sol.x[2]) * p_scale if load_offset else 0.0
    depth = depth_base - x0_hat
    n_contact = int(np.count_nonzero(depth > 0))
    if n_contact < min_contact_points:
        return failed(
            f"no contact: {n_contact} samples past the fitted contact point, the fit needs "
            f"{min_contact_points}",
            n_contact,
            int(sol.nfev),
        )

    # 3. profile likelihood over x0 with the weights frozen at the solution
    r = residuals(sol.x)
    robust = 1.0 / np.sqrt(1.0 + (r / f_scale) ** 2)  # soft_l1's IRLS weight
    w = robust / sigma(sol.x) ** 2
    dof = max(1, n - n_par)
    chi2_red = float(np.sum(robust * r * r)) / dof
    rho = _lag1(r[depth > 0])
    scale2 = max(1.0, chi2_red) * (1.0 + rho) / (1.0 - rho)
    threshold = NormalDist().inv_cdf(0.5 + 0.5 * confidence) ** 2 * scale2  # chi2(1) quantile
    # against "no contact at all": a constant load (P0 alone) or none
    null = P - float(w @ P) / float(np.sum(w)) if load_offset else P
    fitted = P - P0_hat - E_hat * law.shape(depth)[0]
    gain = float(np.sum(w * null * null) - np.sum(w * fitted * fitted))
    if gain < MIN_SIGNIFICANCE**2 * scale2:
        return failed(
            f"no contact: the fitted load is not significant (chi^2 gain {gain / scale2:.3g} "
            f"over zero load, needs {MIN_SIGNIFICANCE**2:g})",
            n_contact,
            int(sol.nfev),
        )
    jac = sol.jac  # of the standardised residuals in (log E, x0)
    try:
        cov = np.linalg.inv(jac.T @ jac) * scale2
        sd_x0 = math.sqrt(max(cov[1, 1], 0.0))
        if not math.isfinite(sd_x0):
            raise np.linalg.LinAlgError("singular")
    except np.linalg.LinAlgError:
        sd_x0 = search
    span = min(max(8.0 * sd_x0, 2e-6), search)
    forms = (law, *_other_forms(law))
    profiles = _profiles(forms, depth_base, P, w, x0_hat, span, threshold, lo, hi, load_offset)
    warnings = list(validity_warnings(law, float(depth.max()), misalignment))
    if any(prof is None for prof in profiles):
        return failed(
            "profile likelihood failed: no contact position gives a positive load",
            n_contact,
            int(sol.nfev),
        )
    ok_profiles = [prof for prof in profiles if prof is not None]
    # the envelope over the model forms (step 4 of the module docstring)
    ci_low = min(E_hat, *(prof.ci_low for prof in ok_profiles))
    ci_high = max(E_hat, *(prof.ci_high for prof in ok_profiles))
    c_low = min(prof.contact_low for prof in ok_profiles)
    c_high = max(prof.contact_high for prof in ok_profiles)
    edge = any(prof.edge for prof in ok_profiles)
    spread = max(abs(prof.modulus - ok_profiles[0].modulus) for prof in ok_profiles)
    if edge:
        warnings.append("the contact position's interval reaches the search window's edge")
    if rho > 0.5:
        warnings.append(
            f"residuals are correlated (lag-1 {rho:.2f}): the model misses part of the curve; "
            f"the interval is widened by {math.sqrt((1 + rho) / (1 - rho)):.2g}x"
        )
    if not np.all(np.isfinite([ci_low, ci_high, E_hat])):
        return failed("non-finite modulus or interval", n_contact, int(sol.nfev))
    return JointFit(
        success=True,
        message="ok",
        modulus=E_hat,
        contact=x0_hat,
        load_offset=P0_hat,
        ci_low=ci_low,
        ci_high=ci_high,
        contact_low=c_low,
        contact_high=c_high,
        confidence=confidence,
        n_points=n,
        n_contact=n_contact,
        max_depth=float(depth.max()),
        rms=float(np.sqrt(np.mean(r * r))),
        noise_scale=math.sqrt(scale2),
        model_spread=spread,
        nfev=int(sol.nfev),
        law=law.name,
        warnings=tuple(warnings),
    )


def _other_forms(law: ContactLaw) -> tuple[ContactLaw, ...]:
    """The equally defensible variants of ``law`` (the other thin-layer ratio with Sneddon's
    sphere; none when the choice does not arise)."""
    if law.thickness is None or not law.large_indentation:
        return ()
    if law.layer_ratio_from == "published":
        return (dataclasses.replace(law, layer_ratio_from="sphere"),)
    return (dataclasses.replace(law, layer_ratio_from="published"),)


def _lag1(r: FloatArray) -> float:
    """Lag-1 autocorrelation of residuals in record order, clipped to [0, MAX_RHO]."""
    if r.size < 3:
        return 0.0
    c = r - r.mean()
    denom = float(c @ c)
    if denom == 0.0:
        return 0.0
    return min(max(float(c[1:] @ c[:-1]) / denom, 0.0), MAX_RHO)


@dataclass(frozen=True)
class _Profile:
    """One model form's profile: its best E on the grid and the intervals of E and x0."""

    modulus: float
    ci_low: float
    ci_high: float
    contact_low: float
    contact_high: float
    edge: bool


def _profiles(
    laws: Sequence[ContactLaw],
    depth_base: FloatArray,
    P: FloatArray,
    w: FloatArray,
    x0_hat: float,
    span: float,
    threshold: float,
    lo: float,
    hi: float,
    offset: bool,
) -> list[_Profile | None]:
    """Each law's E and x0 intervals from its profile over x0 (None: no contact position gives
    a positive load). A law's grid, centred on ``x0_hat``, widens until its region closes (at
    most PROFILE_TRIES - 1 times, x3 each; still open then: reported as reaching the edge). The
    minimum is searched on the grid, so a law need not be the one that was fitted (the other
    model forms are profiled with the same weights ``w``).

    The laws go in lockstep: at each width, every law still open is evaluated on the same grid,
    so they share the half-space part (:func:`_grid_fits`); each law sees the same grids, hence
    the same result, as if profiled alone."""
    done: dict[int, _Profile | None] = {}
    pending = list(range(len(laws)))
    for attempt in range(PROFILE_TRIES):
        a, b = max(lo, x0_hat - span), min(hi, x0_hat + span)
        grid = np.linspace(a, b, PROFILE_POINTS)
        fits = _grid_fits([laws[i] for i in pending], depth_base, P, w, grid, offset)
        still_open = []
        for i, fit in zip(pending, fits, strict=True):
            profile, open_grid = _read_profile(fit, grid, threshold, a <= lo, b >= hi)
            if open_grid and attempt < PROFILE_TRIES - 1:
                still_open.append(i)
            else:
                done[i] = profile
        if not still_open:
            break
        pending = still_open
        span *= 3.0
    return [done[i] for i in range(len(laws))]


def _read_profile(
    fit: _Fit, grid: FloatArray, threshold: float, at_low_end: bool, at_high_end: bool
) -> tuple[_Profile | None, bool]:
    """The profile on one grid: (its intervals, whether the region is open at a grid end that
    is not the search window's, i.e. the grid should widen). ``at_low_end``/``at_high_end``:
    the grid's first/last point is the search window's edge."""
    E, _, rss, S = fit
    ok = S > 0
    if not np.any(ok):
        return None, False
    best = float(np.min(rss[ok]))
    inside = ok & (rss <= best + threshold)
    idx = np.nonzero(inside)[0]
    window_edge = bool((inside[0] and at_low_end) or (inside[-1] and at_high_end))
    open_grid = bool(inside[0] or inside[-1]) and not window_edge
    h = np.sqrt(np.maximum(best + threshold - rss[idx], 0.0) / S[idx])
    profile = _Profile(
        modulus=float(E[ok][np.argmin(rss[ok])]),
        ci_low=float(np.min(E[idx] - h)),
        ci_high=float(np.max(E[idx] + h)),
        contact_low=float(grid[idx[0]]),
        contact_high=float(grid[idx[-1]]),
        edge=window_edge or open_grid,
    )
    return profile, open_grid

"""The grid search: every hardware x tip x length candidate assessed at once, the most
central feasible one chosen (leximin on the logs of the margins), or why none is feasible."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ..estimation.beam.section import across_rigidity, composite_section
from .model import Assessment, assess, checked_range, evaluation
from .results import Check, DesignEvaluation, DesignResult
from .space import DesignConstraints, DesignSpace, SensorDesign
from .weight import linear_mass

FloatArray = NDArray[np.float64]


def _hardware(space: DesignSpace) -> list[tuple[float, int, float]]:
    """(fiber radius, wire count, wire radius) combinations; one bare fiber per fiber radius."""
    smallest = min(space.wire_diameters) / 2
    out: list[tuple[float, int, float]] = []
    for r_f in space.fiber_radii:
        for n in sorted(set(space.wire_counts)):
            radii = [smallest] if n == 0 else [d / 2 for d in space.wire_diameters]
            out.extend((r_f, int(n), r_w) for r_w in radii)
    return out


def _leximin(log_margins: FloatArray, rows: NDArray[np.intp]) -> int:
    """Row of ``rows`` whose sorted margins are lexicographically largest (1 % rounding)."""
    sub = np.sort(log_margins[rows], axis=1)
    keys = np.round(np.where(np.isfinite(sub), sub, np.sign(sub) * 1e6), 2)
    order = np.lexsort(tuple(-keys[:, j] for j in reversed(range(keys.shape[1]))))
    return int(rows[order[0]])


def _depth_window(rng: tuple[float, float], space: DesignSpace, c: DesignConstraints) -> str | None:
    """Why no sensor at all can work, if that is the case: the ceiling/floor ratio test."""
    floor = c.resolution_multiple * c.encoder_resolution
    need = (rng[1] / rng[0]) ** (2.0 / 3.0)
    best_ratio, best_r, best_ceiling = 0.0, 0.0, 0.0
    for R in space.tip_radii:
        ceiling = c.max_depth_ratio * R
        if c.thickness is not None:
            ceiling = min(ceiling, c.max_layer_strain * c.thickness)
        if ceiling / floor > best_ratio:
            best_ratio, best_r, best_ceiling = ceiling / floor, R, ceiling
    if best_ratio >= need:
        return None
    where = "" if c.thickness is None else f" on a {c.thickness * 1e3:g} mm layer"
    return (
        f"the modulus range is too wide for any sensor{where}: one sensor's indentation at "
        f"buckling scales as E**(-2/3), so E_max/E_min = {rng[1] / rng[0]:.3g} needs a depth "
        f"ratio of {need:.3g}, but the estimator's trusted domain (delta/R <= "
        f"{c.max_depth_ratio:g}"
        + ("" if c.thickness is None else f", delta/h <= {c.max_layer_strain:g}")
        + f") caps delta at {best_ceiling * 1e3:.3g} mm (best tip R = {best_r * 1e3:g} mm) and "
        f"the encoder needs delta >= {c.resolution_multiple:g} x "
        f"{c.encoder_resolution * 1e6:.3g} um = {floor * 1e3:.3g} mm: a ratio of "
        f"{best_ratio:.3g} at most. Narrow the range, or relax the limits (thicker sample, "
        f"finer encoder, fewer counts)."
    )


def _window(ok: NDArray[np.bool_], lengths: FloatArray, i: int) -> tuple[float, float]:
    lo = hi = i
    while lo > 0 and ok[lo - 1]:
        lo -= 1
    while hi < len(ok) - 1 and ok[hi + 1]:
        hi += 1
    return float(lengths[lo]), float(lengths[hi])


def _describe(ev: DesignEvaluation) -> str:
    d = ev.design
    wires = "bare fiber" if d.wire_count == 0 else f"{d.wire_count} x {d.wire_radius * 2e6:.0f} um"
    return (
        f"fiber r = {d.fiber_radius * 1e6:.1f} um, {wires} NiTi, tip R = {d.tip_radius * 1e3:g} "
        f"mm, L = {d.exposed_length * 1e3:.1f} mm (P_cr = {ev.critical_load * 1e3:.3g} mN)"
    )


def _fail_text(ch: Check) -> str:
    op = ">" if ch.upper else "<"
    return f"{ch.name} ({ch.description}): {ch.value:.3g} {op} {ch.limit:.3g}"


@dataclass(frozen=True, eq=False)
class _Candidates:
    """Every hardware x tip x length of a design space, flattened: candidate k is hardware
    ``hardware[hw[k]]`` (fiber radius, wire count, wire radius), tip radius ``tips[tip[k]]``
    and exposed length ``lengths[length[k]]``; the index arrays are (N,)."""

    space: DesignSpace
    hardware: list[tuple[float, int, float]]
    tips: FloatArray
    lengths: FloatArray
    hw: NDArray[np.intp]
    tip: NDArray[np.intp]
    length: NDArray[np.intp]

    @classmethod
    def of(cls, space: DesignSpace, lengths: FloatArray) -> _Candidates:
        hardware = _hardware(space)
        tips = np.asarray(space.tip_radii, dtype=np.float64)
        n_h, n_t, n_l = len(hardware), tips.size, lengths.size
        hw, tip, length = (x.ravel() for x in np.indices((n_h, n_t, n_l)))
        return cls(space, hardware, tips, lengths, hw, tip, length)

    @classmethod
    def reaching(cls, space: DesignSpace, c: DesignConstraints) -> _Candidates | None:
        """The candidates whose exposed length reaches past the gratings; None when no length
        of the space does."""
        lengths = space.lengths()
        lengths = lengths[lengths >= c.grating_reach]
        return cls.of(space, lengths) if lengths.size else None

    def assess(self, rng: tuple[float, float], c: DesignConstraints) -> Assessment:
        """The model of every candidate (``model.assess``), one composite section per hardware."""
        sp = self.space
        sections = [
            composite_section(r_f, sp.fiber_modulus, r_w, sp.wire_modulus, n)
            for r_f, n, r_w in self.hardware
        ]

        def per_section(attr: str) -> FloatArray:
            values = np.asarray([getattr(s, attr) for s in sections], dtype=np.float64)
            return np.asarray(values[self.hw], dtype=np.float64)

        across = np.asarray(
            [across_rigidity(r_f, sp.fiber_modulus, r_w, sp.wire_modulus, n)
             for r_f, n, r_w in self.hardware],
            dtype=np.float64,
        )  # fmt: skip
        return assess(
            per_section("EI"),
            np.asarray(across[self.hw], dtype=np.float64),
            per_section("EA"),
            per_section("fiber_offset"),
            np.asarray([h[0] for h in self.hardware], dtype=np.float64)[self.hw],
            self.tips[self.tip],
            self.lengths[self.length],
            rng,
            c,
            np.asarray([linear_mass(*h) for h in self.hardware], dtype=np.float64)[self.hw],
        )

    def design(self, k: int) -> SensorDesign:
        r_f, n, r_w = self.hardware[int(self.hw[k])]
        return SensorDesign(
            fiber_radius=r_f,
            fiber_modulus=self.space.fiber_modulus,
            wire_count=n,
            wire_radius=r_w,
            wire_modulus=self.space.wire_modulus,
            tip_radius=float(self.tips[self.tip[k]]),
            exposed_length=float(self.lengths[self.length[k]]),
        )

    def length_window(self, ok: NDArray[np.bool_], k: int) -> tuple[float, float]:
        """(min, max) exposed length (m) around candidate k's over which its hardware and tip
        pass every check (``ok``: (N,) per candidate)."""
        same = (self.hw == self.hw[k]) & (self.tip == self.tip[k])
        return _window(ok[same], self.lengths, int(self.length[k]))


def design_sensor(
    modulus_range: tuple[float, float],
    constraints: DesignConstraints | None = None,
    space: DesignSpace | None = None,
) -> DesignResult:
    """Propose fiber, wires, tip radius and exposed length for tissue in ``modulus_range`` (Pa).

    Returns:
        A :class:`DesignResult`: the most central feasible design with its evaluation and the
        window of exposed lengths over which that hardware passes, or ``success`` False with a
        message naming the failing constraint (and the closest candidate's evaluation).

    Raises:
        ValueError: a non-physical range, constraint or design space.
    """
    c = constraints or DesignConstraints()
    sp = space or DesignSpace()
    rng = checked_range(modulus_range)
    candidates = _Candidates.reaching(sp, c)
    if candidates is None:
        return DesignResult(
            False,
            f"no exposed length in the design space reaches past the gratings "
            f"({c.grating_reach * 1e3:.3g} mm from the tip)",
            None,
            None,
            0,
            0,
        )
    arrays = candidates.assess(rng, c)
    logm = arrays.log_margins()
    ok = np.all(logm >= 0.0, axis=1)
    failures = {name: int(np.sum(logm[:, j] < 0.0)) for j, name in enumerate(arrays.checks)}
    feasible = np.flatnonzero(ok)
    best = _leximin(logm, feasible if feasible.size else np.arange(ok.size))
    ev = evaluation(candidates.design(best), arrays, best, rng)
    if not feasible.size:
        return _no_design(ev, rng, sp, c, int(ok.size), failures)
    return DesignResult(
        True,
        f"{feasible.size} of {ok.size} candidates pass every check; most central: "
        f"{_describe(ev)}; worst margin {ev.worst.margin:.2f} ({ev.worst.name})",
        ev,
        candidates.length_window(ok, best),
        int(ok.size),
        int(feasible.size),
        failures,
    )


def _no_design(
    ev: DesignEvaluation,
    rng: tuple[float, float],
    space: DesignSpace,
    c: DesignConstraints,
    candidates: int,
    failures: dict[str, int],
) -> DesignResult:
    """The failed search's result: why no sensor can work at all, if that is the reason, then
    what the closest candidate ``ev`` fails."""
    reason = _depth_window(rng, space, c)
    closest = "; ".join(_fail_text(ch) for ch in ev.failed)
    closest = f"the closest candidate ({_describe(ev)}) fails {closest}."
    message = "no design satisfies the constraints: " + (
        f"{reason} {closest[0].upper()}{closest[1:]}" if reason else closest
    )
    return DesignResult(False, message, ev, None, candidates, 0, failures)


def binding_checks(
    modulus_range: tuple[float, float], constraints: DesignConstraints, space: DesignSpace
) -> tuple[str, ...]:
    """The checks that bind on ``modulus_range`` (Pa): those whose relaxing alone would let a
    candidate of ``space`` pass (each alone keeps every candidate out); when no single check
    does, those the closest candidate fails (several bind together). Empty when a candidate
    passes."""
    candidates = _Candidates.reaching(space, constraints)
    if candidates is None:
        return ()
    arrays = candidates.assess(checked_range(modulus_range), constraints)
    logm = arrays.log_margins()
    passes = logm >= 0.0
    if np.any(np.all(passes, axis=1)):
        return ()
    names = list(arrays.checks)
    alone = tuple(
        name for j, name in enumerate(names) if np.any(np.all(np.delete(passes, j, axis=1), axis=1))
    )
    if alone:
        return alone
    closest = _leximin(logm, np.arange(passes.shape[0]))
    return tuple(n for j, n in enumerate(names) if not passes[closest, j])

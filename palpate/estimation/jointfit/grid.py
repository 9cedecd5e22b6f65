"""E and P0 in closed form at every contact position of a grid (the scan's and the profile's).

Every contact law is linear in E (``F = E f(delta)``) and the offset P0 is a constant, so at a
fixed contact position x0 the weighted least squares of ``P = P0 + E f(depth_base - x0)`` has a
closed form (:func:`closed_form`); :func:`grid_fits` evaluates it on a whole grid of x0 at once.
Both the scan (step 1) and the profile likelihood (step 3) of the joint fit are grids of this.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from ..contact.law import ContactLaw, shape_values

FloatArray = NDArray[np.float64]
GridFit = tuple[FloatArray, FloatArray, FloatArray, FloatArray]
"""Ê, P̂0, RSS and S per contact position of the grid, each (K,)."""

BLOCK_ELEMENTS = 16384  # depths per block of grid rows: 128 kB arrays (see grid_fits)


def closed_form(f: FloatArray, P: FloatArray, w: FloatArray, offset: bool = True) -> GridFit:
    """Per row of f (K, N), the weighted least squares of ``P = P0 + E f`` (P0 = 0 when not
    ``offset``): Ê, P̂0, the RSS there and the curvature S of RSS in E with P0 profiled out
    (the Schur complement ``sum w f^2 - (sum w f)^2 / sum w``), so that
    ``min over P0 of RSS(E, P0) = RSS + S (E - Ê)^2``. S = 0 where f carries no contact.
    ``P`` and the weights ``w`` are (N,); the results are (K,)."""
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


def grid_fits(
    laws: Sequence[ContactLaw],
    depth_base: FloatArray,
    P: FloatArray,
    w: FloatArray,
    grid: FloatArray,
    offset: bool,
) -> list[GridFit]:
    """:func:`closed_form` of each law at every contact position of ``grid`` (K,): per law
    (Ê, P̂0, RSS, S), each (K,); ``depth_base`` (u - e, so that delta = depth_base - x0),
    ``P``, ``w`` are (N,).

    Why it is shaped this way (it is most of the joint fit's cost: K x N = 30k-130k depths per
    grid):
    - the samples are sorted by depth once, so at contact position x0 the touching samples are
      a suffix; a block of rows evaluates the law only from its first touching sample on, at
      max(depth, 0) (f(0) = 0 exactly), with no mask to build, gather or scatter;
    - rows go in blocks of at most BLOCK_ELEMENTS depths, so every temporary stays under
      128 kB, glibc's mmap threshold: a larger one is mapped and page-faulted afresh each time,
      which on the 2-core VM cost more than the arithmetic (``1 - t * t`` on 1e5 elements:
      0.8 ms instead of 0.03 ms). Median joint fit per bench trial: whole (K, N) matrices
      16 ms, blocks of 16384 depths 8.7 ms, of 4096 12 ms (numpy's per-call overhead);
    - the laws share one evaluation of the half-space part
      (``estimation.contact.law.shape_values``).
    The sums run in depth order instead of record order: the same fit up to rounding.

    Laws that differ in tip, Poisson ratio or half-space law go in one call per group: each
    law's numbers are those of a call of its own.
    """
    groups = _half_space_groups(laws)
    if len(groups) > 1:
        fits: list[GridFit | None] = [None] * len(laws)
        for idx in groups:
            group = [laws[i] for i in idx]
            for i, fit in zip(idx, grid_fits(group, depth_base, P, w, grid, offset), strict=True):
                fits[i] = fit
        return [fit for fit in fits if fit is not None]
    order = np.argsort(depth_base, kind="stable")
    depth_sorted, P_sorted, w_sorted = depth_base[order], P[order], w[order]
    first = np.searchsorted(depth_sorted, grid, side="right")  # first touching sample per row
    n = depth_sorted.size
    rows = max(1, BLOCK_ELEMENTS // n)
    parts: list[list[GridFit]] = [[] for _ in laws]
    for start in range(0, grid.size, rows):
        x0 = grid[start : start + rows]
        col = int(first[start : start + rows].min())
        depth = depth_sorted[None, col:] - x0[:, None]
        for law_parts, f_touching in zip(parts, shape_values(laws, depth), strict=True):
            f = np.zeros((x0.size, n))
            f[:, col:] = f_touching
            law_parts.append(closed_form(f, P_sorted, w_sorted, offset))
    return [_concatenate(law_parts) for law_parts in parts]


def _half_space_groups(laws: Sequence[ContactLaw]) -> list[list[int]]:
    """The indices of ``laws`` by the half-space part they share (tip, Poisson ratio, law)."""
    groups: dict[tuple[float, float, bool], list[int]] = {}
    for i, law in enumerate(laws):
        groups.setdefault((law.tip_radius, law.poisson, law.large_indentation), []).append(i)
    return list(groups.values())


def _concatenate(blocks: list[GridFit]) -> GridFit:
    E, P0, rss, S = (np.concatenate(column) for column in zip(*blocks, strict=True))
    return E, P0, rss, S

"""Records selected and scaled to a site's elastic spectrum (NTC 2018 3.2.3.6).

The code's rule for records (NTC 2018 3.2.3.6; the effects are the mean of at least 7 records,
or the most unfavourable of 3 to 6, 7.3.5): the mean of the records' 5 % spectra lies nowhere
more than 10 % below the elastic spectrum nor more than 30 % above it, over the larger of
0.15-2.0 s and 0.15 s-2 T1 (T1 the structure's fundamental period, for the ultimate limit
states). This module picks, from the records of a folder, a set of ``count`` records and a
scale factor for each that satisfies it, or says that none does.

* **The check.** Each record's 5 % pseudo-acceleration spectrum (:mod:`rockyade.motion.spectra`,
  exact between samples) on a grid of periods over the range (:data:`GRID_POINTS` log-spaced
  points and the target's corner periods inside it); r(T) = mean of the scaled spectra over
  the target. The set's *band use* is rho = max over the grid of max((1 - r) / 0.10,
  (r - 1) / 0.30): rho <= 1 is compatible, and the worst deviation is the r - 1 that sets rho.
* **The scale factors** are individual and bounded, s_i in [0.5, 2] by default: linear scaling
  by factors within 0.5-2 leaves a record's spectral shape and duration representative of
  its magnitude and distance (Bommer and Acevedo 2004, J. Earthquake Eng. 8 S1, 43-91, review
  the practice; REXEL, Iervolino, Galasso and Cosenza 2010, Bull. Earthquake Eng. 8, 339-362,
  bounds the set's mean factor instead). For a given set, the mean is linear in the factors,
  so the factors that minimise rho are a linear programme (scipy's HiGHS): minimise rho
  subject to 1 - 0.10 rho <= r(T) <= 1 + 0.30 rho at every period and the bounds; then, at
  that rho, the factors closest to 1 (least scaling; a second linear programme).
* **The search** over sets: every set of ``count`` records of the folder when there are at most
  :data:`MAX_EXHAUSTIVE` of them, else a beam search (the :data:`BEAM` best sets of each size
  grown by one record at a time). Sets are ranked first with each record at its own factor
  (the one centring its spectrum in the band in the log-mean over the range, within the
  bounds), then the :data:`REFINED` best are solved exactly by the linear programmes. Ties go
  to the set of smaller record indices (files sorted by name): the answer is deterministic.
* **No compatible set.** The answer says so, with the best band use reached, the period where
  it fails, and an estimate of how many records like these would be needed: the best rho of
  random subsets of the folder (sizes from ``count`` to all, :data:`SUBSET_DRAWS` draws each,
  seed 0) falls with the pool size n roughly as rho ~ c n^-b; the n where c n^-b = 1 is the
  estimate (none when rho does not fall with n: more records like these would not help).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from rockyade.errors import InputError
from rockyade.motion.ec8 import ElasticSpectrum
from rockyade.motion.records import Record
from rockyade.motion.spectra import response_spectrum

#: The band of NTC 2018 3.2.3.6 around the elastic spectrum: 10 % below, 30 % above.
BAND_BELOW = 0.10
BAND_ABOVE = 0.30
#: The range's ends, s: from 0.15 s to the larger of 2.0 s and 2 T1.
PERIOD_MIN_S = 0.15
PERIOD_MAX_S = 2.0
#: The longest period a record's spectrum is compared at, s (the spectra are used up to 4 s).
LONGEST_PERIOD_S = 4.0
#: Records of a set: at least 7 for the mean response; 3 to 6 with the maximum response (7.3.5).
MEAN_RULE_COUNT = 7
MIN_COUNT = 3
MAX_COUNT = 30
#: Default bounds of each record's scale factor (module docstring).
SCALE_BOUNDS = (0.5, 2.0)
#: Log-spaced periods of the check's grid.
GRID_POINTS = 60
#: Sets ranked exhaustively up to this many; beyond, a beam search of this width.
MAX_EXHAUSTIVE = 300_000
BEAM = 400
#: Sets solved by the linear programmes after the ranking.
REFINED = 40
#: Random subsets per pool size in the estimate of the records needed.
SUBSET_DRAWS = 6
#: The largest estimate given, records.
MAX_ESTIMATE = 10_000
#: Sets ranked per array operation.
_CHUNK = 20_000


def period_range(t1_s: float | None) -> tuple[float, float]:
    """The range of NTC 2018 3.2.3.6, s: 0.15 s to the larger of 2.0 s and 2 T1.

    Raises
    ------
    InputError
        T1 <= 0, or 2 T1 beyond the spectra's :data:`LONGEST_PERIOD_S`.
    """
    if t1_s is None:
        return PERIOD_MIN_S, PERIOD_MAX_S
    if isinstance(t1_s, bool) or not (isinstance(t1_s, (int, float)) and math.isfinite(t1_s) and t1_s > 0.0):
        raise InputError("--t1", f"must be a period > 0 s, got {t1_s!r}")
    if 2.0 * t1_s > LONGEST_PERIOD_S:
        raise InputError(
            "--t1",
            f"2 T1 = {2 * t1_s:g} s is beyond the range of periods the spectra are compared over (up to "
            f"{LONGEST_PERIOD_S:g} s): T1 must be at most {LONGEST_PERIOD_S / 2:g} s",
        )
    return PERIOD_MIN_S, max(PERIOD_MAX_S, 2.0 * t1_s)


def check_count(count: int, records: int, max_response: bool) -> int:
    """``count`` records of a set: 7 or more, 3 to 6 only with the maximum-response rule, and no
    more than the folder holds.

    Raises
    ------
    InputError
        Naming ``--count`` (or ``--records`` when the folder holds fewer records).
    """
    if isinstance(count, bool) or not isinstance(count, int) or not MIN_COUNT <= count <= MAX_COUNT:
        raise InputError("--count", f"must be an integer in [{MIN_COUNT}, {MAX_COUNT}] records, got {count!r}")
    if count < MEAN_RULE_COUNT and not max_response:
        raise InputError(
            "--count",
            f"must be at least {MEAN_RULE_COUNT} (NTC 2018 7.3.5: the effects are the mean of at least 7 records); "
            f"{MIN_COUNT} to {MEAN_RULE_COUNT - 1} only with --max-response (the effects are then the most "
            f"unfavourable record's), got {count}",
        )
    if count > records:
        raise InputError(
            "--records", f"the folder holds {records} record{'s' if records != 1 else ''}, fewer than --count {count}"
        )
    return count


def check_bounds(bounds: Sequence[float]) -> tuple[float, float]:
    """Scale-factor bounds lo < hi within (0, 100], else InputError naming ``--scale-bounds``."""
    lo, hi = (float(v) for v in bounds)
    if not (math.isfinite(lo) and math.isfinite(hi) and 0.0 < lo < hi <= 100.0):
        raise InputError("--scale-bounds", f"must be two factors 0 < LO < HI <= 100, got {lo:g} {hi:g}")
    return lo, hi


def check_grid(target: ElasticSpectrum, t_range: tuple[float, float], points: int = GRID_POINTS) -> NDArray[np.float64]:
    """The periods of the check: ``points`` log-spaced over the range, and the target's corner
    periods inside it, sorted, s."""
    lo, hi = t_range
    corners = [t for t in (target.TB_s, target.TC_s, target.TD_s) if lo < t < hi]
    return np.unique(np.concatenate([np.geomspace(lo, hi, points), corners]))


def spectra_of(
    records: Sequence[Record], periods_s: NDArray[np.float64], names: Sequence[str], longest_s: float
) -> NDArray[np.float64]:
    """Each record's 5 % pseudo-acceleration at ``periods_s`` (rows), m/s^2.

    Raises
    ------
    InputError
        A record not uniformly sampled, or shorter than ``longest_s`` (the range's end).
    """
    out = np.empty((len(records), periods_s.size))
    for i, (record, name) in enumerate(zip(records, names, strict=True)):
        if not record.uniform:
            raise InputError("--records", f"{name} is not uniformly sampled: its response spectrum cannot be computed")
        if record.duration_s < longest_s:
            raise InputError(
                "--records",
                f"{name} lasts {record.duration_s:g} s, less than the longest period compared ({longest_s:g} s)",
            )
        out[i] = response_spectrum(record.accel_m_s2, record.dt_s, periods_s, 0.05)[1]
    return out


def band_use(ratio: NDArray[np.float64]) -> NDArray[np.float64]:
    """rho = max over the periods (last axis) of max((1 - r) / 0.10, (r - 1) / 0.30) (module docstring)."""
    return np.max(np.maximum((1.0 - ratio) / BAND_BELOW, (ratio - 1.0) / BAND_ABOVE), axis=-1)


def _own_factors(ratios: NDArray[np.float64], bounds: tuple[float, float]) -> NDArray[np.float64]:
    """Each record's factor centring its log-mean ratio in the band, within the bounds."""
    centre = math.sqrt((1.0 - BAND_BELOW) * (1.0 + BAND_ABOVE))
    return np.clip(centre / np.exp(np.mean(np.log(ratios), axis=1)), *bounds)


def _rank(scaled: NDArray[np.float64], sets: NDArray[np.int64]) -> NDArray[np.float64]:
    """rho of each set (rows of record indices) with the records at fixed factors."""
    total = np.zeros((sets.shape[0], scaled.shape[1]))
    for column in sets.T:
        total += scaled[column]
    return band_use(total / sets.shape[1])


def _best_sets(scaled: NDArray[np.float64], count: int, keep: int) -> tuple[NDArray[np.int64], int, str]:
    """The ``keep`` best sets by :func:`_rank`, how many were ranked, and how (exhaustive or beam)."""
    n = scaled.shape[0]
    if math.comb(n, count) <= MAX_EXHAUSTIVE:
        best = np.empty((0, count), dtype=np.int64)
        best_rho = np.empty(0)
        combos = itertools.combinations(range(n), count)
        ranked = 0
        while chunk := list(itertools.islice(combos, _CHUNK)):
            sets = np.array(chunk, dtype=np.int64)
            ranked += len(sets)
            rho = np.concatenate([best_rho, _rank(scaled, sets)])
            pool = np.concatenate([best, sets])
            order = np.lexsort((np.arange(rho.size), rho))[:keep]
            best, best_rho = pool[order], rho[order]
        return best, ranked, "every set"
    beam = np.arange(n, dtype=np.int64)[:, None]
    ranked = n
    for _size in range(1, count):
        grown = np.array([[*s, j] for s in beam for j in range(int(s[-1]) + 1, n)], dtype=np.int64)
        if grown.size == 0:
            break
        ranked += len(grown)
        rho = _rank(scaled, grown)
        beam = grown[np.lexsort((np.arange(rho.size), rho))[:BEAM]]
    rho = _rank(scaled, beam)
    return beam[np.lexsort((np.arange(rho.size), rho))[:keep]], ranked, f"a beam search (width {BEAM})"


def optimal_factors(ratios: NDArray[np.float64], bounds: tuple[float, float]) -> tuple[NDArray[np.float64], float]:
    """The scale factors of a set (rows: its records' spectra over the target) that minimise rho,
    then, at that rho, their total distance from 1 (module docstring); and that rho."""
    from scipy.optimize import linprog

    k, m = ratios.shape
    mean = ratios.T / k  # (m, k): r(T) = mean @ s
    # variables (s_1..s_k, rho): r >= 1 - 0.1 rho and r <= 1 + 0.3 rho
    a_ub = np.vstack(
        [np.hstack([-mean, -BAND_BELOW * np.ones((m, 1))]), np.hstack([mean, -BAND_ABOVE * np.ones((m, 1))])]
    )
    b_ub = np.concatenate([-np.ones(m), np.ones(m)])
    c = np.zeros(k + 1)
    c[-1] = 1.0
    first = linprog(c, A_ub=a_ub, b_ub=b_ub, bounds=[bounds] * k + [(None, None)], method="highs")
    if first.status != 0:
        raise RuntimeError(f"the scale factors' linear programme failed: {first.message}")
    rho = float(first.x[-1])
    # at rho (relaxed by 1e-9), the factors closest to 1: minimise sum t_i with t_i >= |s_i - 1|
    cap = rho + 1e-9 * max(1.0, abs(rho))
    rows = [np.hstack([-mean, np.zeros((m, k))]), np.hstack([mean, np.zeros((m, k))])]
    eye = np.eye(k)
    a2 = np.vstack([*rows, np.hstack([eye, -eye]), np.hstack([-eye, -eye])])
    b2 = np.concatenate(
        [-(1.0 - BAND_BELOW * cap) * np.ones(m), (1.0 + BAND_ABOVE * cap) * np.ones(m), np.ones(k), -np.ones(k)]
    )
    second = linprog(
        np.concatenate([np.zeros(k), np.ones(k)]),
        A_ub=a2,
        b_ub=b2,
        bounds=[bounds] * k + [(0, None)] * k,
        method="highs",
    )
    factors = second.x[:k] if second.status == 0 else first.x[:k]
    return np.asarray(factors, dtype=float), float(band_use(mean @ factors))


@dataclass(frozen=True)
class Selection:
    """A set of records and their scale factors (module docstring).

    Attributes
    ----------
    indices
        The records chosen (indices into the folder's records, ascending).
    names
        Their file names.
    scale_factors
        Each record's factor.
    periods_s
        The check's periods, s.
    target_m_s2
        The elastic spectrum there, m/s^2.
    scaled_m_s2
        Each chosen record's scaled 5 % spectrum there (rows), m/s^2.
    rho
        The band use: <= 1 compatible.
    ranked, how
        Sets ranked and how they were searched.
    """

    indices: tuple[int, ...]
    names: tuple[str, ...]
    scale_factors: NDArray[np.float64]
    periods_s: NDArray[np.float64]
    target_m_s2: NDArray[np.float64]
    scaled_m_s2: NDArray[np.float64]
    rho: float
    ranked: int
    how: str
    estimate: dict[str, Any] = field(default_factory=dict)

    @property
    def mean_m_s2(self) -> NDArray[np.float64]:
        """The scaled records' mean spectrum, m/s^2."""
        return np.asarray(self.scaled_m_s2.mean(axis=0))

    @property
    def ratio(self) -> NDArray[np.float64]:
        """Mean over target at each period."""
        return np.asarray(self.mean_m_s2 / self.target_m_s2)

    @property
    def compatible(self) -> bool:
        """The mean lies within the band everywhere (rho <= 1, to 1e-9)."""
        return self.rho <= 1.0 + 1e-9

    @property
    def worst(self) -> tuple[float, float]:
        """(deviation r - 1, period s) where the band is used most."""
        r = self.ratio
        use = np.maximum((1.0 - r) / BAND_BELOW, (r - 1.0) / BAND_ABOVE)
        j = int(np.argmax(use))
        return float(r[j] - 1.0), float(self.periods_s[j])

    def summary(self) -> str:
        """One line: compatible or not, and the worst deviation."""
        dev, period = self.worst
        lo, hi = float(self.ratio.min() - 1.0), float(self.ratio.max() - 1.0)
        verdict = "compatible" if self.compatible else "NOT compatible"
        return (
            f"{len(self.names)} records: {verdict} with the site's spectrum over {self.periods_s[0]:g}-"
            f"{self.periods_s[-1]:g} s (NTC 2018 3.2.3.6: mean within -10 %/+30 %): worst deviation "
            f"{100 * dev:+.1f} % at {period:.3g} s (mean from {100 * lo:+.1f} % to {100 * hi:+.1f} %; band use "
            f"{self.rho:.2f})"
        )


def select(
    spectra_m_s2: NDArray[np.float64],
    names: Sequence[str],
    target: ElasticSpectrum,
    periods_s: NDArray[np.float64],
    count: int,
    bounds: tuple[float, float] = SCALE_BOUNDS,
    estimate: bool = True,
) -> Selection:
    """The best set of ``count`` records and their factors (module docstring).

    Parameters
    ----------
    spectra_m_s2
        Each record's 5 % spectrum at ``periods_s`` (rows), m/s^2 (:func:`spectra_of`).
    names
        The records' names, in the same order.
    target
        The site's elastic spectrum (5 %).
    periods_s
        The check's periods (:func:`check_grid`), s.
    count
        Records of the set.
    bounds
        Each factor's bounds.
    estimate
        When no set is compatible, estimate the records needed (``Selection.estimate``).
    """
    target_m_s2 = target.psa(periods_s)
    ratios = spectra_m_s2 / target_m_s2
    scaled = ratios * _own_factors(ratios, bounds)[:, None]
    sets, ranked, how = _best_sets(scaled, count, REFINED)
    best: tuple[float, tuple[int, ...], NDArray[np.float64]] | None = None
    for s in sets:
        factors, rho = optimal_factors(ratios[s], bounds)
        key = (round(rho, 12), tuple(int(i) for i in s))
        if best is None or key < (round(best[0], 12), best[1]):
            best = (rho, key[1], factors)
    assert best is not None
    rho, chosen, factors = best
    idx = list(chosen)
    out = Selection(
        tuple(chosen),
        tuple(names[i] for i in idx),
        factors,
        periods_s,
        target_m_s2,
        spectra_m_s2[idx] * factors[:, None],
        rho,
        ranked,
        how,
    )
    if estimate and not out.compatible:
        out.estimate.update(records_needed(ratios, count, bounds))
    return out


def _best_rho(ratios: NDArray[np.float64], count: int, bounds: tuple[float, float]) -> float:
    """The best band use of sets of ``count`` among ``ratios``' records (a few sets refined)."""
    scaled = ratios * _own_factors(ratios, bounds)[:, None]
    sets, _, _ = _best_sets(scaled, count, 4)
    return min(optimal_factors(ratios[s], bounds)[1] for s in sets)


def records_needed(ratios: NDArray[np.float64], count: int, bounds: tuple[float, float]) -> dict[str, Any]:
    """How many records like the folder's would give a compatible set (module docstring)."""
    n = ratios.shape[0]
    if n <= count:
        return {
            "records_needed": None,
            "why": f"the folder holds {n} records, as many as --count: there is no choice of set, so no trend to "
            "extrapolate; add records of other shapes",
        }
    rng = np.random.default_rng(0)
    sizes = sorted({int(v) for v in np.rint(np.geomspace(count, n, min(6, n - count + 1)))} | {n})
    points = []
    for size in sizes:
        draws = 1 if size == n else SUBSET_DRAWS
        values = [_best_rho(ratios[np.sort(rng.choice(n, size, replace=False))], count, bounds) for _ in range(draws)]
        points.append((size, float(np.median(values))))
    x = np.log([p[0] for p in points])
    y = np.log([max(p[1], 1e-6) for p in points])
    slope, intercept = np.polyfit(x, y, 1) if len(points) > 1 else (0.0, y[0])
    trend = [{"pool": s, "best_band_use": r} for s, r in points]
    if slope > -0.02:
        return {
            "records_needed": None,
            "trend": trend,
            "why": f"the best band use does not fall as records are added (from {points[0][1]:.2f} with "
            f"{points[0][0]} to {points[-1][1]:.2f} with {points[-1][0]}): more records like these would not help; "
            "records of other spectral shapes are needed",
        }
    needed = math.exp(-intercept / slope)
    trend_words = (
        f"the best band use of random subsets of the folder falls as rho ~ n^-{-slope:.2f} "
        f"({', '.join(f'{r:.2f} with {s}' for s, r in points)})"
    )
    if needed > MAX_ESTIMATE:
        return {
            "records_needed": None,
            "trend": trend,
            "exponent": float(-slope),
            "why": f"{trend_words}: it would reach 1 only beyond {MAX_ESTIMATE} records like these; records of other "
            "spectral shapes are needed",
        }
    return {
        "records_needed": math.ceil(needed),
        "trend": trend,
        "exponent": float(-slope),
        "why": f"{trend_words}, which reaches 1 at about n = {math.ceil(needed)} records like these",
    }


__all__ = [
    "BAND_ABOVE",
    "BAND_BELOW",
    "MEAN_RULE_COUNT",
    "SCALE_BOUNDS",
    "Selection",
    "band_use",
    "check_bounds",
    "check_count",
    "check_grid",
    "optimal_factors",
    "period_range",
    "records_needed",
    "select",
    "spectra_of",
]

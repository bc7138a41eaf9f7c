"""The numbers of a cross-check of solvers under earthquakes (``rockyade crosscheck``).

Rocking near collapse is chaotic, so solvers are compared over a set of records, never run
by run (docs/verification.md):

* **Collapse intensity** of a record for a solver: the smallest scale of the record, in an
  intensity measure, at which the scene collapses. Found by a scan over common levels, then
  bisection (in the logarithm of the level) between the highest level that stood below the
  first collapse and that collapse, until the bracket's ratio is at most 1 + ``resolution``
  (:func:`next_levels`, :func:`collapse_summary`). The collapse intensity reported is the
  bracket's top: a level at which a run collapsed; the threshold lies in the bracket. The
  overturning region is not simply connected (a stronger scaling can stand), so the fraction
  of scanned levels above the first collapse that stood is reported beside it.
* **Paired ratios**: for two solvers, per record the ratio of their collapse intensities
  (records where both have one); their median and its bootstrap interval
  (:func:`median_interval`, :func:`scipy.stats.bootstrap`, percentile method, seeded).
  Paired by record, the ratios scatter far less than two fragility medians fitted apart.
* **Verdict agreement**: the share of (record, level) runs of the scan where two solvers
  give the same verdict (collapse or not).
* **Convergence**: the same ratio between a solver at half its time step and at its own
  step; a difference between solvers smaller than a solver's own change with dt says
  nothing (:func:`pair_verdict`).

Everything here is arithmetic on outcomes: no solver runs (the study, :mod:`rockyade.studies.crosscheck`).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from scipy import stats

#: Default resolution of the bisection: the bracket's ratio at most 1 + this.
RESOLUTION = 0.01
#: Ratio of an extension level to the end of the levels run, and the most extensions a side.
EXTEND_RATIO = 2.0
MAX_EXTENSIONS = 3
#: The bootstrap of a median: draws, two-sided level and seed.
BOOTSTRAP_RESAMPLES = 2000
CONFIDENCE = 0.95
BOOTSTRAP_SEED = 20261127
#: Default tolerance on a median ratio (5 %); the interval must lie within twice it.
TOLERANCE = 0.05
#: Records a paired ratio needs before its interval means anything (as a fragility fit,
#: :mod:`rockyade.assess.stripe_fit`, refuses fewer than 5 records and warns below 10).
MIN_RECORDS = 5
ADVISED_RECORDS = 10

#: Status of a collapse search.
BRACKETED, ABOVE, BELOW, NO_RUNS, ALL_FAILED = (
    "bracketed",
    "no collapse up to the top level",
    "collapsed at the lowest level",
    "no runs",
    "every run failed",
)


def scan_levels(low: float, high: float, count: int) -> list[float]:
    """``count`` levels from ``low`` to ``high`` in geometric progression (any unit).

    Parameters
    ----------
    low, high
        The first and last level, 0 < low < high.
    count
        Levels, at least 2.
    """
    if not (0.0 < low < high and math.isfinite(high)) or count < 2:
        raise ValueError(f"scan_levels needs 0 < low < high and count >= 2, got {low!r}, {high!r}, {count!r}")
    return [float(v) for v in np.geomspace(low, high, count)]


def _known(outcomes: Mapping[float, bool | None]) -> list[tuple[float, bool]]:
    """The levels with a verdict (failed runs, None, left out), sorted."""
    return sorted((float(k), bool(v)) for k, v in outcomes.items() if v is not None)


def next_levels(
    outcomes: Mapping[float, bool | None],
    scan: Sequence[float],
    resolution: float = RESOLUTION,
    lowest: float = 0.0,
    highest: float = math.inf,
) -> list[float]:
    """The levels to run next in one collapse search (module docstring); empty when done.

    Parameters
    ----------
    outcomes
        Level -> collapsed (True), stood (False) or failed (None), of every run so far.
    scan
        The scan's levels (run first, all at once).
    resolution
        The bisection stops when the bracket's ratio is at most 1 + ``resolution``.
    lowest, highest
        Levels the search may not go below or above when it extends the scan (a record's
        load factor has limits).

    Returns
    -------
    list of float
        The scan's levels not yet run; else one level: below the scan (divided by
        :data:`EXTEND_RATIO`) when the lowest level collapsed, above it when none collapsed
        (at most :data:`MAX_EXTENSIONS` each way), or the geometric middle of the bracket.
    """
    todo = [float(v) for v in scan if float(v) not in outcomes]
    if todo:
        return todo
    known = _known(outcomes)
    if not known:
        return []
    collapses = [level for level, c in known if c]
    if not collapses:
        top = known[-1][0]
        extended = sum(1 for level, _ in known if level > max(scan) * (1 + 1e-12))
        nxt = top * EXTEND_RATIO
        return [nxt] if extended < MAX_EXTENSIONS and nxt <= highest else []
    first = collapses[0]
    below = [level for level, c in known if level < first and not c]
    if not below:
        extended = sum(1 for level, _ in known if level < min(scan) * (1 - 1e-12))
        nxt = first / EXTEND_RATIO
        return [nxt] if extended < MAX_EXTENSIONS and nxt >= lowest else []
    low = below[-1]
    if first / low <= 1.0 + resolution * (1 + 1e-9):
        return []
    return [math.sqrt(low * first)]


@dataclass(frozen=True)
class CollapseSearch:
    """What a collapse search found (module docstring).

    Attributes
    ----------
    collapse_intensity
        The lowest level at which a run collapsed, with a level that stood just below it
        (NaN when not bracketed).
    bracket_low, bracket_high
        The bracket: the highest level that stood below the first collapse, and that
        collapse (NaN where there is none: 0 and inf are not levels run).
    survived_above_fraction
        Of the scan's levels above the scan's first collapse, the fraction that stood (NaN
        with none).
    status
        :data:`BRACKETED`, :data:`ABOVE`, :data:`BELOW`, :data:`NO_RUNS` (none made) or
        :data:`ALL_FAILED` (runs made, none with a verdict).
    runs, failed
        Runs of the search, and those that failed (no verdict).
    """

    collapse_intensity: float
    bracket_low: float
    bracket_high: float
    survived_above_fraction: float
    status: str
    runs: int
    failed: int


def collapse_summary(outcomes: Mapping[float, bool | None], scan: Sequence[float]) -> CollapseSearch:
    """The collapse intensity and its bracket from a search's outcomes (module docstring).

    Parameters
    ----------
    outcomes
        Level -> collapsed (True), stood (False) or failed (None).
    scan
        The scan's levels.
    """
    known = _known(outcomes)
    failed = sum(1 for v in outcomes.values() if v is None)
    if not known:
        status = ALL_FAILED if outcomes else NO_RUNS
        return CollapseSearch(math.nan, math.nan, math.nan, math.nan, status, len(outcomes), failed)
    collapses = [level for level, c in known if c]
    if not collapses:
        return CollapseSearch(math.nan, known[-1][0], math.nan, math.nan, ABOVE, len(outcomes), failed)
    first = collapses[0]
    scanned = [(float(v), outcomes.get(float(v))) for v in sorted(scan)]
    first_scanned = next((v for v, c in scanned if c), math.inf)
    above = [bool(c) for v, c in scanned if v > first_scanned and c is not None]
    survived = float(np.mean([not c for c in above])) if above else math.nan
    below = [level for level, c in known if level < first and not c]
    if not below:
        return CollapseSearch(math.nan, math.nan, first, survived, BELOW, len(outcomes), failed)
    return CollapseSearch(first, below[-1], first, survived, BRACKETED, len(outcomes), failed)


@dataclass(frozen=True)
class MedianInterval:
    """A median and its bootstrap interval.

    Attributes
    ----------
    median
        The sample's median.
    low, high
        The bootstrap interval (NaN with fewer than 2 values).
    n
        Values.
    """

    median: float
    low: float
    high: float
    n: int


def median_interval(
    values: Iterable[float],
    confidence: float = CONFIDENCE,
    seed: int = BOOTSTRAP_SEED,
    resamples: int = BOOTSTRAP_RESAMPLES,
) -> MedianInterval:
    """The median of ``values`` (NaN left out) and its bootstrap interval
    (:func:`scipy.stats.bootstrap`, percentile method: a median's BCa interval is unstable
    for the small, tied samples a record set gives; seeded, so the same values give the
    same interval).

    Parameters
    ----------
    values
        The sample (e.g. per-record ratios).
    confidence
        Two-sided level of the interval.
    seed, resamples
        The bootstrap's seed and draws.
    """
    x = np.asarray([v for v in values if math.isfinite(v)], dtype=float)
    if x.size == 0:
        return MedianInterval(math.nan, math.nan, math.nan, 0)
    median = float(np.median(x))
    if x.size < 2 or np.all(x == x[0]):
        same = median if x.size >= 2 else math.nan
        return MedianInterval(median, same, same, int(x.size))
    res = stats.bootstrap(
        (x,),
        np.median,
        confidence_level=confidence,
        n_resamples=resamples,
        method="percentile",
        random_state=np.random.default_rng(seed),
    )
    return MedianInterval(median, float(res.confidence_interval.low), float(res.confidence_interval.high), int(x.size))


def paired_ratios(a: Mapping[str, float], b: Mapping[str, float]) -> dict[str, float]:
    """Per record, ``a[record] / b[record]`` where both are finite and positive."""
    out = {}
    for record, va in a.items():
        vb = b.get(record, math.nan)
        if math.isfinite(va) and math.isfinite(vb) and va > 0 and vb > 0:
            out[record] = va / vb
    return out


def verdict_agreement(
    a: Mapping[tuple[str, float], bool | None], b: Mapping[tuple[str, float], bool | None]
) -> tuple[int, int]:
    """(runs with the same verdict, runs compared) over the (record, level) both ran
    without failing."""
    common = [k for k in a if k in b and a[k] is not None and b[k] is not None]
    return sum(1 for k in common if bool(a[k]) == bool(b[k])), len(common)


@dataclass(frozen=True)
class PairVerdict:
    """How far two solvers agree (:func:`pair_verdict`).

    Attributes
    ----------
    verdict
        ``agree``, ``differ``, ``unresolved`` (the difference is below a solver's own change
        with dt) or ``inconclusive`` (the interval is too wide to say).
    sentence
        The verdict in words, with the numbers.
    """

    verdict: str
    sentence: str


def ratio_decimals(resolution: float) -> int:
    """Decimals a median ratio of collapse intensities found to ``resolution`` supports: the
    resolution's own decimal place, and one more (a median over records is finer than one
    bracket), at least 1: 3 at 1 %, 2 at 5 % or 10 %, 1 at 50 %."""
    if not (math.isfinite(resolution) and resolution > 0):
        return 3
    return max(1, round(-math.log10(resolution)) + 1)


def without_interval(ratio: MedianInterval) -> MedianInterval:
    """``ratio`` with no interval below :data:`MIN_RECORDS` records (too few to bound a
    median; every table, file and figure then shows none)."""
    if ratio.n >= MIN_RECORDS:
        return ratio
    return MedianInterval(ratio.median, math.nan, math.nan, ratio.n)


def too_few_note(n: int) -> str:
    """Why a ratio of ``n`` records has no interval."""
    return f"no interval: {n} record(s), fewer than the {MIN_RECORDS} an interval needs"


def pair_verdict(
    a: str,
    b: str,
    ratio: MedianInterval,
    tolerance: float = TOLERANCE,
    dt_change: Mapping[str, float] | None = None,
    decimals: int = 3,
) -> PairVerdict:
    """The verdict on the median ratio of collapse intensities ``a`` / ``b``.

    * ``agree``: the median within ``tolerance`` of 1 and its interval within twice it;
    * ``unresolved``: the difference |median - 1| is smaller than a solver's own change with
      dt halved (``dt_change``: solver -> |median of its dt ratio - 1|): it says nothing;
    * ``differ``: the interval excludes 1 +/- ``tolerance``;
    * ``inconclusive`` otherwise;
    * ``too few records``: fewer than :data:`MIN_RECORDS` paired records (no interval, no verdict).

    Parameters
    ----------
    a, b
        The solvers (ratio a / b).
    ratio
        The median ratio and its interval.
    tolerance
        The tolerance on the median ratio (0.05: 5 %).
    dt_change
        Each solver's own change with dt halved (NaN or absent: not measured).
    decimals
        Decimals of the ratios in the sentence (:func:`ratio_decimals` of the resolution).
    """
    dt_change = dict(dt_change or {})
    m, lo, hi = ratio.median, ratio.low, ratio.high
    if not math.isfinite(m):
        return PairVerdict("inconclusive", f"{a} / {b}: no record with a collapse intensity from both")
    diff = abs(m - 1.0)
    if ratio.n < MIN_RECORDS:
        return PairVerdict(
            "too few records",
            f"{a} / {b} = {m:.{decimals}f} from {ratio.n} record(s): too few for an interval or a verdict "
            f"(at least {MIN_RECORDS} records, {ADVISED_RECORDS} or more advised)",
        )
    d = decimals
    text = f"{a} / {b} = {m:.{d}f} (95 % interval {lo:.{d}f}-{hi:.{d}f}, {ratio.n} records)"
    if ratio.n < ADVISED_RECORDS:
        text += f"; fewer than {ADVISED_RECORDS} records: a rough interval"
    moved = {s: c for s, c in dt_change.items() if s in (a, b) and math.isfinite(c)}
    loudest = max(moved, key=lambda s: moved[s]) if moved else None
    dt_note = ""
    if loudest is not None:
        dt_note = f"; {loudest} moves by {100 * moved[loudest]:.1f} % with dt halved"
    inside = math.isfinite(lo) and 1 - 2 * tolerance <= lo and hi <= 1 + 2 * tolerance
    if diff <= tolerance and inside:
        caveat = ""
        if loudest is not None and moved[loudest] > tolerance:
            caveat = f", but {loudest} is not converged in dt (it moves by more than the tolerance)"
        return PairVerdict("agree", f"{text}: agree within {100 * tolerance:g} %{dt_note}{caveat}")
    if loudest is not None and diff < moved[loudest]:
        return PairVerdict(
            "unresolved",
            f"{text}: the difference ({100 * diff:.1f} %) is smaller than {loudest}'s own change with dt halved "
            f"({100 * moved[loudest]:.1f} %): it says nothing until the step is converged",
        )
    if math.isfinite(lo) and (lo > 1 + tolerance or hi < 1 - tolerance):
        return PairVerdict("differ", f"{text}: differ by {100 * (m - 1):+.1f} %, beyond {100 * tolerance:g} %{dt_note}")
    return PairVerdict("inconclusive", f"{text}: the interval is too wide to say within {100 * tolerance:g} %{dt_note}")


__all__ = [
    "ABOVE",
    "ALL_FAILED",
    "BELOW",
    "BRACKETED",
    "NO_RUNS",
    "CollapseSearch",
    "MedianInterval",
    "PairVerdict",
    "collapse_summary",
    "median_interval",
    "next_levels",
    "pair_verdict",
    "paired_ratios",
    "ratio_decimals",
    "scan_levels",
    "too_few_note",
    "verdict_agreement",
    "without_interval",
]

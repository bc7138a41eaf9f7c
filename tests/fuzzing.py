"""Shared pieces of the fuzz suite (tests/test_fuzz_*.py): outcome counting and settings.

Every fuzz case ends in one of: ``accepted`` (the input was valid), ``clean error`` (a
:class:`~rockyade.errors.RockyadeError` naming the field, or argparse's usage error), a
``traceback`` (any other exception: the test fails), a ``hang`` (over :data:`HANG_S` of CPU
time: the test fails) or ``data lost`` (a damaged record read as if whole: the test fails).

``ROCKYADE_FUZZ_EXAMPLES`` sets the number of cases per test (default: quick enough for
``make test``); ``pytest -s`` prints the counts.
"""

from __future__ import annotations

import collections
import contextlib
import os
import time
from collections.abc import Callable
from typing import Any

from hypothesis import HealthCheck, settings

from rockyade.errors import RockyadeError

#: CPU seconds of this process after which one case counts as a hang. CPU time, not wall
#: time: a busy machine (CI beside other jobs) stretches a case's wall time many times over,
#: not the work it does; a loop that never ends runs past any bound of either.
HANG_S = 60.0

COUNTS: dict[str, collections.Counter[str]] = collections.defaultdict(collections.Counter)


def fuzz_settings(default: int) -> settings:
    """Hypothesis settings of a fuzz test: ``default`` cases unless the environment says."""
    examples = int(os.environ.get("ROCKYADE_FUZZ_EXAMPLES", default))
    return settings(
        max_examples=examples,
        deadline=None,
        suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large, HealthCheck.filter_too_much],
        database=None,
        derandomize=os.environ.get("ROCKYADE_FUZZ_RANDOM") is None,
    )


def outcome(
    suite: str,
    call: Callable[[], Any],
    clean: tuple[type[BaseException], ...] = (RockyadeError,),
    compiles: bool = False,
) -> Any:
    """Run one case, count its outcome, re-raise anything that is not a clean error.

    ``compiles``: the case may be the first to need some of numba's kernels, whose compilation
    (tens of seconds on a fresh clone on a busy machine) is not a hang: a case over
    :data:`HANG_S` is run and timed again, and is a hang only if it is slow again.
    """
    start = time.process_time()
    try:
        value = call()
    except clean:
        COUNTS[suite]["clean error"] += 1
        _check_time(suite, start, call if compiles else None, clean)
        return None
    except BaseException:
        COUNTS[suite]["traceback"] += 1
        raise
    COUNTS[suite]["accepted"] += 1
    _check_time(suite, start, call if compiles else None, clean)
    return value


def _check_time(
    suite: str, start: float, again: Callable[[], Any] | None = None, clean: tuple[type[BaseException], ...] = ()
) -> None:
    elapsed = time.process_time() - start
    if elapsed > HANG_S and again is not None:
        start = time.process_time()
        with contextlib.suppress(*clean):  # the same outcome as the first call's, already counted
            again()
        elapsed = time.process_time() - start
    if elapsed > HANG_S:
        COUNTS[suite]["hang"] += 1
        raise AssertionError(f"{suite}: a case took {elapsed:.1f} s of CPU (a hang)")


def report(suite: str) -> str:
    """One line of counts for a suite."""
    c = COUNTS[suite]
    tried = sum(c[k] for k in ("accepted", "clean error", "traceback"))
    return (
        f"fuzz {suite}: {tried} cases, {c['accepted']} accepted, {c['clean error']} clean errors, "
        f"{c['traceback']} tracebacks, {c['hang']} hangs, {c['data lost']} data lost"
    )

"""Identification of alpha, p, mu from free-rocking records made by Housner's solver.

100 seeded trials over the paper's four specimens (Table 3, E columns): sampling at 100,
200, 500 or 1000 Hz, white noise of 0.2-1 % of alpha, a sensor offset of up to 2 % of alpha,
a hold of 0.2-1 s before a release that falls between samples, a release tilt of 0.3-0.7
alpha on either side, 8 s records. Reports the recovery errors, the coverage of the 95 %
intervals (with its own Wilson interval) and the time per identification; then the same
with coloured (AR(1), lag-1 correlation 0.8) noise, where the prewhitened Newey-West
intervals apply.

    .venv/bin/python benchmarks/bench_identify.py [--trials 100] [--ar1-trials 40] [--quick]

``--quick``: 2 trials and 1 with AR(1) noise (a test runs it so that it cannot rot).
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np

from rockyade import paper
from rockyade.identification.fit import CLASSICAL, identify, synthetic_measurement
from rockyade.identification.measurement import measured_history
from rockyade.probability.fragility_curves import wilson_interval

RATES_HZ = (100.0, 200.0, 500.0, 1000.0)


def trial(seed: int, ar1: float = 0.0):
    """One seeded trial: (truth, identification, seconds)."""
    rng = np.random.default_rng(seed)
    spec = paper.specimen(paper.SINGLE_SPECIMENS[seed % 4])
    truth = spec.experimental
    a = truth["alpha_rad"]
    rate = float(rng.choice(RATES_HZ))
    noise = rng.uniform(0.002, 0.01) * a
    ratio = rng.uniform(0.3, 0.7)
    history = synthetic_measurement(
        truth["alpha_rad"],
        truth["p_rad_s"],
        truth["mu"],
        theta0_rad=ratio * a * rng.choice([-1.0, 1.0]),
        rate_hz=rate,
        duration_s=8.0,
        hold_s=rng.uniform(0.2, 1.0),
        release_offset_s=rng.uniform(0.0, 1.0 / rate),
        offset_rad=rng.uniform(-0.02, 0.02) * a,
        noise_rad=0.0 if ar1 else noise,
        seed=seed,
    )
    theta = history.theta_rad
    if ar1:
        e = np.empty(theta.size)
        w = rng.standard_normal(theta.size) * noise * math.sqrt(1 - ar1**2)
        e[0] = noise * rng.standard_normal()
        for i in range(1, e.size):
            e[i] = ar1 * e[i - 1] + w[i]
        history = measured_history(history.t_s, theta + e, "ar1")
    start = time.perf_counter()
    result = identify(history)
    return truth, result, time.perf_counter() - start, rate, ratio


def report(label: str, seeds, ar1: float = 0.0) -> None:
    errors = {k: [] for k in CLASSICAL}
    covered = {k: 0 for k in CLASSICAL}
    times, by_rate, unidentified, methods, tilts = [], {}, 0, {}, []
    for seed in seeds:
        truth, result, seconds, rate, tilt = trial(seed, ar1)
        tilts.append(tilt)
        times.append(seconds)
        by_rate.setdefault(rate, []).append(seconds)
        method = result.ci_method.split(" (")[0]
        methods[method] = methods.get(method, 0) + 1
        if result.unidentifiable:
            unidentified += 1
        for k in CLASSICAL:
            value = getattr(result.fit, k)
            errors[k].append(abs(value / truth[k] - 1.0))
            lo, hi = result.ci[k]
            covered[k] += lo <= truth[k] <= hi
    n = len(times)
    print(f"{label}: {n} trials")
    for k in CLASSICAL:
        e = 100 * np.array(errors[k])
        clo, chi = wilson_interval(covered[k], n)
        print(
            f"  {k:9s} |error| max {e.max():.3f} %, 95th pct {np.percentile(e, 95):.3f} %, "
            f"median {np.median(e):.4f} %; "
            f"95 % interval covers the truth in {covered[k]}/{n} ({100 * clo:.0f}-{100 * chi:.0f} % Wilson)"
        )
    print(f"  flagged unidentifiable: {unidentified}/{n}; interval methods: {methods}")
    tilts = np.array(tilts)
    for lo, hi in ((0.3, 0.4), (0.4, 0.55), (0.55, 0.7)):
        sel = (tilts >= lo) & (tilts < hi)
        if sel.any():
            ea = 100 * np.array(errors["alpha_rad"])[sel]
            ep = 100 * np.array(errors["p_rad_s"])[sel]
            em = 100 * np.array(errors["mu"])[sel]
            print(
                f"  release at {lo:.2f}-{hi:.2f} alpha ({sel.sum()} trials): max |error| alpha {ea.max():.2f} %, "
                f"p {ep.max():.2f} %, mu {em.max():.3f} %"
            )
    rates = ", ".join(f"{r:.0f} Hz {np.mean(v):.2f} s" for r, v in sorted(by_rate.items()))
    print(f"  time per identification: mean {np.mean(times):.2f} s, max {np.max(times):.2f} s ({rates})")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--trials", type=int, default=100)
    parser.add_argument("--ar1-trials", type=int, default=100)
    parser.add_argument("--quick", action="store_true", help="2 trials and 1 with AR(1) noise")
    args = parser.parse_args()
    if args.quick:
        args.trials, args.ar1_trials = 2, 1
    identify(synthetic_measurement(0.2, 4.0, 0.95, theta0_rad=0.1, noise_rad=1e-4))  # compile the kernel
    report("white noise 0.2-1 % of alpha", range(args.trials))
    if args.ar1_trials:
        report("AR(1) noise (lag-1 correlation 0.8), 0.2-1 % of alpha", range(1000, 1000 + args.ar1_trials), ar1=0.8)


if __name__ == "__main__":
    main()

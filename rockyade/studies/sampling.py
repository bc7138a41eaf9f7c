"""Distributions of the classical parameters and their Latin hypercube samples.

Each of alpha_rad, p_rad_s, mu is fixed or drawn from a normal, lognormal or uniform
distribution truncated to the range a scene takes (:func:`parameter_ranges`: alpha in
[0.001, pi/2 - 0.001] rad, mu in [0.05, 0.9999], p in [0.01, 0.99] sqrt(g / R) for the block);
or the three are drawn jointly from the normal distribution of an identification (its
estimate and covariance, ``rockyade identify --out``). Samples are a Latin hypercube
(McKay, Beckman & Conover 1979; :class:`scipy.stats.qmc.LatinHypercube`) with an explicit
seed, mapped through each marginal's quantile function; the joint normal maps its
stratified standard normals through the Cholesky factor of the covariance.

Study-file tables (one per parameter, under ``[parameters]``)::

    [parameters.alpha_rad]
    distribution = "normal"      # normal | lognormal | uniform | fixed
    mean = 0.235                 # normal, lognormal: mean and one of std, cov, ci95 = [lo, hi]
    cov = 0.02                   #   (lognormal with ci95: median sqrt(lo hi), sigma ln(hi/lo) / 3.92)
    # uniform: low and high, or mean and plus_minus_pct (e.g. 5 for +/-5 %); fixed: value
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy import stats
from scipy.stats import qmc

from rockyade.errors import InputError, InputNote
from rockyade.io.fields import TableReader
from rockyade.scene.bounds import BOUNDS

PARAMETERS = ("alpha_rad", "p_rad_s", "mu")
DISTRIBUTIONS = ("normal", "lognormal", "uniform", "fixed")
Z95 = float(stats.norm.ppf(0.975))
#: A distribution cut by more than this fraction of its mass at its parameter's range is said.
CUT_NOTE = 0.01
#: A parameter's closed range [lo, hi].
Ranges = dict[str, tuple[float, float]]


def parameter_ranges(p_rad_s: tuple[float, float] = (0.0, math.inf)) -> Ranges:
    """The range a sample of each parameter may take: a scene's (:data:`rockyade.scene.bounds.BOUNDS`)
    for alpha_rad (rad) and mu, and ``p_rad_s`` (rad/s) for p, whose range is the block's
    (:func:`rockyade.scene.bounds.p_range`), so that every sample is a block a scene takes."""
    alpha, mu = BOUNDS["alpha_rad"], BOUNDS["mu"]
    return {"alpha_rad": (alpha.lo, alpha.hi), "p_rad_s": p_rad_s, "mu": (mu.lo, mu.hi)}


@dataclass(frozen=True)
class Marginal:
    """One parameter's distribution.

    Attributes
    ----------
    name
        alpha_rad, p_rad_s or mu.
    kind
        normal, lognormal, uniform or fixed.
    a, b
        normal: mean, std; lognormal: median, log standard deviation; uniform: low, high;
        fixed: value, value.
    """

    name: str
    kind: str
    a: float
    b: float

    def _frozen(self):
        if self.kind == "normal":
            return stats.norm(loc=self.a, scale=self.b)
        if self.kind == "lognormal":
            return stats.lognorm(s=self.b, scale=self.a)
        return stats.uniform(loc=self.a, scale=self.b - self.a)

    def quantile(self, u: NDArray[np.float64], ranges: Ranges | None = None) -> NDArray[np.float64]:
        """Values at probabilities ``u`` of the distribution truncated to the parameter's range
        (``ranges``, default :func:`parameter_ranges`)."""
        if self.kind == "fixed":
            return np.full(np.shape(u), self.a)
        dist = self._frozen()
        lo, hi = (ranges or parameter_ranges())[self.name]
        f_lo, f_hi = float(dist.cdf(lo)), float(dist.cdf(hi))
        if f_hi - f_lo < 0.5:
            raise InputError(
                f"parameters.{self.name}",
                f"the {self.kind} distribution has {100 * (1 - (f_hi - f_lo)):.0f} % of its mass outside "
                f"the range [{lo:.6g}, {hi:.6g}] a block takes: check its mean and spread",
            )
        if f_hi - f_lo < 1.0 - CUT_NOTE:
            warnings.warn(
                InputNote(
                    f"parameters.{self.name}",
                    f"{100 * (1 - (f_hi - f_lo)):.0f} % of the {self.kind} distribution's mass lies outside "
                    f"[{lo:.6g}, {hi:.6g}], the range a block takes: drawn truncated to it (its mean and spread "
                    "are then not those given)",
                ),
                stacklevel=2,
            )
        x = dist.ppf(f_lo + np.asarray(u) * (f_hi - f_lo))
        return np.clip(x, lo, hi)

    def describe(self) -> str:
        """Short text, e.g. ``normal(mean 0.235, std 0.0047)``."""
        if self.kind == "fixed":
            return f"fixed {self.a:.6g}"
        if self.kind == "normal":
            return f"normal(mean {self.a:.6g}, std {self.b:.3g})"
        if self.kind == "lognormal":
            return f"lognormal(median {self.a:.6g}, sigma_ln {self.b:.3g})"
        return f"uniform({self.a:.6g}, {self.b:.6g})"


def parse_marginal(r: TableReader, name: str) -> Marginal:
    """A parameter's distribution from its study-file table (module docstring)."""
    kind = r.string("distribution", choices=DISTRIBUTIONS)
    if kind == "fixed":
        value = r.number("value")
        r.finish()
        return Marginal(name, kind, value, value)
    if kind == "uniform":
        low, high = r.number("low", None), r.number("high", None)
        mean, pct = r.number("mean", None), r.number("plus_minus_pct", None, lo=0.0, hi=100.0, lo_open=True)
        if low is not None and high is not None and mean is None and pct is None:
            pass
        elif mean is not None and pct is not None and low is None and high is None:
            low, high = mean * (1 - pct / 100), mean * (1 + pct / 100)
        else:
            raise r.error("distribution", "uniform takes low and high, or mean and plus_minus_pct")
        if not low < high:
            raise r.error("high", f"must be above low ({low:g}), got {high:g}")
        r.finish()
        return Marginal(name, kind, float(low), float(high))
    mean = r.number("mean", None, lo=0.0, lo_open=True)
    std = r.number("std", None, lo=0.0, lo_open=True)
    cov = r.number("cov", None, lo=0.0, lo_open=True)
    ci = r.number_list("ci95", None, min_len=2)
    given = [k for k, v in (("std", std), ("cov", cov), ("ci95", ci)) if v is not None]
    if len(given) != 1:
        raise r.error("distribution", f"{kind} takes a mean and exactly one of std, cov, ci95 (got {given or 'none'})")
    if ci is not None:
        if len(ci) != 2 or not 0 < ci[0] < ci[1]:
            raise r.error("ci95", f"must be [lo, hi] with 0 < lo < hi, got {ci}")
        if mean is not None:
            raise r.error("mean", "is implied by ci95 (its centre); give one of them")
    elif mean is None:
        raise r.error("mean", "is required with std or cov")
    r.finish()
    if kind == "normal":
        if ci is not None:
            return Marginal(name, kind, 0.5 * (ci[0] + ci[1]), (ci[1] - ci[0]) / (2 * Z95))
        return Marginal(name, kind, mean, std if std is not None else cov * mean)
    if ci is not None:
        return Marginal(name, kind, math.sqrt(ci[0] * ci[1]), math.log(ci[1] / ci[0]) / (2 * Z95))
    c = (std / mean) if std is not None else cov
    sigma = math.sqrt(math.log1p(c * c))
    return Marginal(name, kind, mean * math.exp(-0.5 * sigma * sigma), sigma)


@dataclass(frozen=True)
class JointNormal:
    """alpha, p, mu drawn jointly: normal with an identification's estimate and covariance.

    Attributes
    ----------
    mean
        (alpha_rad, p_rad_s, mu).
    covariance
        3 x 3 covariance (already multiplied by ``std_factor`` squared).
    source
        Where the values came from.
    """

    mean: tuple[float, float, float]
    covariance: tuple[tuple[float, ...], ...]
    source: str = ""

    def sample(self, u: NDArray[np.float64], ranges: Ranges | None = None) -> NDArray[np.float64]:
        """Values (n, 3) from stratified probabilities ``u`` (n, 3); refused where one falls
        outside its range (``ranges``, default :func:`parameter_ranges`)."""
        z = stats.norm.ppf(u)
        cov = np.array(self.covariance)
        w, v = np.linalg.eigh(cov)
        factor = v * np.sqrt(np.maximum(w, 0.0))  # cov = factor factor^T (also when singular)
        x = np.array(self.mean) + z @ factor.T
        ranges = ranges or parameter_ranges()
        for k, name in enumerate(PARAMETERS):
            lo, hi = ranges[name]
            if np.any(x[:, k] < lo) or np.any(x[:, k] > hi):
                raise InputError(
                    f"parameters.{name}",
                    f"the identified distribution {self.source} draws values outside [{lo:.6g}, {hi:.6g}]: "
                    "give this parameter its own truncated distribution instead",
                )
        return x

    def describe(self) -> str:
        """Short text."""
        sd = np.sqrt(np.diag(np.array(self.covariance)))
        parts = ", ".join(f"{n} {m:.5g} +/- {s:.2g}" for n, m, s in zip(PARAMETERS, self.mean, sd, strict=True))
        return f"joint normal from {self.source}: {parts} (1 std)"


def joint_from_identified(data: dict[str, Any], std_factor: float = 1.0, source: str = "") -> JointNormal:
    """The joint normal of an identification (``covariance_alpha_p_mu``; without it, independent
    normals from the 95 % intervals)."""
    mean = tuple(float(data[k]) for k in PARAMETERS)
    if "covariance_alpha_p_mu" in data:
        cov = np.array(data["covariance_alpha_p_mu"], dtype=float)
        if cov.shape != (3, 3) or not np.all(np.isfinite(cov)):
            raise InputError("parameters.identified", "covariance_alpha_p_mu must be a 3 x 3 matrix", source)
    else:
        sd = [(data[f"{k}_ci"][1] - data[f"{k}_ci"][0]) / (2 * Z95) for k in PARAMETERS]
        cov = np.diag(np.square(sd))
    cov = 0.5 * (cov + cov.T) * std_factor**2
    return JointNormal(mean, tuple(tuple(row) for row in cov.tolist()), source)  # type: ignore[arg-type]


def latin_hypercube(n: int, dimensions: int, seed: int) -> NDArray[np.float64]:
    """(n, dimensions) stratified probabilities in (0, 1), reproducible from ``seed``."""
    if n < 1:
        raise InputError("samples", f"must be >= 1, got {n}")
    if dimensions == 0:
        return np.zeros((n, 0))
    return qmc.LatinHypercube(d=dimensions, rng=np.random.default_rng(seed)).random(n)


def draw_parameters(
    n: int,
    seed: int,
    marginals: dict[str, Marginal] | None = None,
    joint: JointNormal | None = None,
    extra_dimensions: int = 0,
    ranges: Ranges | None = None,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Latin hypercube samples of (alpha_rad, p_rad_s, mu), and ``extra_dimensions`` more
    stratified probabilities (e.g. to draw a record per sample).

    Parameters
    ----------
    n, seed
        Samples, and the seed that makes them.
    marginals, joint
        One distribution per parameter, or the three drawn jointly.
    extra_dimensions
        Stratified probabilities drawn beside them.
    ranges
        The range of each parameter (default :func:`parameter_ranges`: p unbounded above).

    Returns
    -------
    values
        (n, 3) alpha_rad, p_rad_s, mu.
    extra
        (n, extra_dimensions) probabilities in (0, 1).
    """
    u = latin_hypercube(n, 3 + extra_dimensions, seed)
    if joint is not None:
        values = joint.sample(u[:, :3], ranges)
    else:
        assert marginals is not None
        values = np.column_stack([marginals[name].quantile(u[:, k], ranges) for k, name in enumerate(PARAMETERS)])
    return values, u[:, 3:]

"""Whether two reproductions of one experiment agree: the numbers a reproduction keeps across machines and versions.

With the same versions on the same kind of machine a reproduction is found again bit for bit. Elsewhere contacts
make single interactions chaotic, so what holds is statistical: each headline number of ``results.json`` lies within
:data:`Z` standard errors of the reference's, and never closer than :data:`FLOOR` is asked of it. The standard error
of a difference has two parts, added in quadrature:

- the learning's own randomness (a mean over trials: uniformity at each k, SVM accuracy at each k and r), from the
  trials' spread: ``std_a**2 / trials + std_b**2 / trials``;
- the interactions' (a share of the interactions behind it: a few change their outcome, as contacts decide),
  that of the difference of two binomial shares: ``p (1 - p) (1 / n_a + 1 / n_b)``.

A number whose own learning trials spread by more than :data:`UNSTABLE_SPREAD` is shown but held to no tolerance:
the map the SOM finds then depends on the data, and a few interactions that end otherwise move the mean over trials
by as much as the trials' spread. Measured: between MuJoCo 3.17 and 4.0, the grasp's uniformity (trials spread by
10-33 points at k >= 3) moved by up to 27 points at one k, while every number of the tap and the grasp's share of
successes, uniformity at k = 2 and SVM accuracies stayed within their tolerances; between OpenBLAS's Haswell and
SkylakeX kernels (before the simulation was made independent of them) the tap's uniformity moved by at most 1.5
points and its SVM accuracy by at most 2.5.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from affordance_learning.common.exceptions import InvalidValueError
from affordance_learning.paper.results import Config, PerK, PerRK, Results, as_results

#: Standard errors a number may move by (two-sided, about 0.3 % by chance for a normal difference).
Z = 3.0
#: The smallest tolerance [fraction]: one point, the resolution the reports print.
FLOOR = 0.01
#: A mean over trials whose trials spread (standard deviation) by more than this [fraction] in either run is not
#: held to a tolerance: it varies with the data as much as with the trials.
UNSTABLE_SPREAD = 0.10


@dataclass(frozen=True)
class Comparison:
    """One number of two reproductions: its name, the reference's value, the value found and the tolerance."""

    name: str
    reference: float
    found: float
    tolerance: float
    spread: float = 0.0

    @property
    def held(self) -> bool:
        """Whether the number is held to its tolerance (its trials agree: spread at most :data:`UNSTABLE_SPREAD`)."""
        return self.spread <= UNSTABLE_SPREAD

    @property
    def ok(self) -> bool:
        return not self.held or abs(self.found - self.reference) <= self.tolerance

    def __str__(self) -> str:
        text = f"{self.name}: {100 * self.found:.1f} % against {100 * self.reference:.1f} % "
        if not self.held:
            return text + f"(not held to a tolerance: its trials spread by {100 * self.spread:.0f} points)"
        return text + f"(tolerance {100 * self.tolerance:.1f} points){'' if self.ok else ' -- outside'}"


def _tolerance(p: float, n_a: int, n_b: int, std_a: float = 0.0, std_b: float = 0.0, trials: int = 1) -> float:
    """:data:`Z` standard errors of the difference of two numbers that are shares ``p`` of ``n_a`` and ``n_b``
    interactions, and means over ``trials`` learning trials of spread ``std_a`` and ``std_b``; at least
    :data:`FLOOR`."""
    p = min(max(p, 0.0), 1.0)
    variance = p * (1.0 - p) * (1.0 / max(n_a, 1) + 1.0 / max(n_b, 1)) + (std_a ** 2 + std_b ** 2) / max(trials, 1)
    return max(FLOOR, Z * math.sqrt(variance))


def compare_results(reference: Results | Mapping[str, Any], found: Results | Mapping[str, Any]) -> list[Comparison]:
    """Every headline number of ``found`` beside ``reference`` (two ``results.json`` of ``affordance reproduce``
    for one behaviour, or their :class:`~affordance_learning.paper.results.Results`), with its tolerance. Raises
    InvalidValueError when they are not the same experiment, or lack what is compared (naming it)."""
    reference, found = as_results(reference), as_results(found)
    uniformity, accuracy, n_a, share_a = _compared_parts("reference", reference)
    found_uniformity, _, n_b, share_b = _compared_parts("found", found)
    ca, cb = reference.config, found.config
    same = ("behavior", "seed", "episodes", "ks", "relevancies", "range_noise")
    differ = [f"{key} {cb.get(key)!r} (reference {ca.get(key)!r})" for key in same if ca.get(key) != cb.get(key)]
    if differ:
        raise InvalidValueError(f"the results are not of the same experiment: {', '.join(differ)}.")
    trials = min(_trials(ca), _trials(cb))

    def compared(name: str, a: float, b: float, std_a: float | None = None, std_b: float | None = None) -> Comparison:
        spread_a, spread_b = std_a or 0.0, std_b or 0.0
        return Comparison(name, a, b, _tolerance(0.5 * (a + b), n_a, n_b, spread_a, spread_b, trials),
                          max(spread_a, spread_b))

    out = [compared("share of successes", share_a, share_b)]
    for k, a in uniformity.items():
        b = found_uniformity.get(k)
        if a.mean is not None and b is not None and b.mean is not None:
            out.append(compared(f"uniformity at k = {k}", a.mean, b.mean, a.std, b.std))
    for r, by_k in accuracy.items():
        for k, a in by_k.items():
            b = found.accuracy(r).get(k)
            if a.mean is not None and b is not None and b.mean is not None:
                out.append(compared(f"SVM accuracy at k = {k}, r = {r}", a.mean, b.mean, a.std, b.std))
    return out


def _compared_parts(which: str, results: Results) -> tuple[PerK, PerRK, int, float]:
    """What :func:`compare_results` reads of one run: its uniformity and SVM accuracy, its interactions and its
    share of successes; InvalidValueError naming all it lacks (``which`` run: the reference or the one found)."""
    uniformity, accuracy = results.uniformity, results.svm_accuracy
    n_rows, share = results.config.n_rows, results.config.success_fraction
    if uniformity is None or accuracy is None or n_rows is None or share is None:
        missing = [name for name, value in (("uniformity", uniformity), ("svm_accuracy", accuracy),
                                            ("config.n_rows", n_rows), ("config.success_fraction", share))
                   if value is None]
        raise InvalidValueError(f"the {which} results lack {', '.join(missing)}: compare the results.json of "
                                "`affordance reproduce` of this version (older ones: run it again).")
    return uniformity, accuracy, n_rows, share


def _trials(config: Config) -> int:
    """The learning trials a run's means are over (``n_trials``, or ``trials`` of ``affordance reproduce``)."""
    return int(config.n_trials or config.get("trials") or 1)

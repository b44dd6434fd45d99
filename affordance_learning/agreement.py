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

from affordance_learning.exceptions import InvalidValueError
from affordance_learning.results import current_results

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


def compare_results(reference: Mapping[str, Any], found: Mapping[str, Any]) -> list[Comparison]:
    """Every headline number of ``found`` beside ``reference`` (two ``results.json`` of ``affordance reproduce``
    for one behaviour), with its tolerance. Raises ValueError when they are not the same experiment."""
    reference, found = current_results(reference), current_results(found)
    for which, results in (("reference", reference), ("found", found)):
        config = results.get("config")
        missing = [key for key in ("uniformity", "svm_accuracy") if not isinstance(results.get(key), Mapping)]
        missing += [f"config.{key}" for key in ("n_rows", "success_fraction")
                    if not isinstance(config, Mapping) or not isinstance(config.get(key), int | float)]
        if missing:
            raise InvalidValueError(f"the {which} results lack {', '.join(missing)}: compare the results.json of "
                                    "`affordance reproduce` of this version (older ones: run it again).")
    ca, cb = reference["config"], found["config"]
    same = ("behavior", "seed", "episodes", "ks", "relevancies", "range_noise")
    differ = [f"{key} {cb.get(key)!r} (reference {ca.get(key)!r})" for key in same if ca.get(key) != cb.get(key)]
    if differ:
        raise InvalidValueError(f"the results are not of the same experiment: {', '.join(differ)}.")
    trials = min(int(ca.get("n_trials") or ca.get("trials") or 1), int(cb.get("n_trials") or cb.get("trials") or 1))
    n_a, n_b = int(ca["n_rows"]), int(cb["n_rows"])

    def compared(name: str, a: Mapping[str, Any], b: Mapping[str, Any]) -> Comparison:
        p = 0.5 * (a["mean"] + b["mean"])
        std_a, std_b = float(a.get("std") or 0.0), float(b.get("std") or 0.0)
        return Comparison(name, a["mean"], b["mean"], _tolerance(p, n_a, n_b, std_a, std_b, trials),
                          max(std_a, std_b))

    out = [compared("share of successes", {"mean": float(ca["success_fraction"])},
                    {"mean": float(cb["success_fraction"])})]
    for k, a in reference["uniformity"].items():
        b = found["uniformity"].get(k, {})
        if a.get("mean") is not None and b.get("mean") is not None:
            out.append(compared(f"uniformity at k = {k}", a, b))
    for r, by_k in reference["svm_accuracy"].items():
        for k, a in by_k.items():
            b = found["svm_accuracy"].get(r, {}).get(k, {})
            if a.get("mean") is not None and b.get("mean") is not None:
                out.append(compared(f"SVM accuracy at k = {k}, r = {r}", a, b))
    return out

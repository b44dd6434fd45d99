"""The paper's statements as claims with numeric rules, and their verdicts on our numbers.

Each statement of Akgun et al. 2009 (section V) becomes a :class:`Claim` with a stated, numeric rule. The
verdict is "agrees" or "disagrees" by that rule, or "not computable" when the results lack what the rule
needs (for example k = 4 was not run). The rules are judgement calls written in the report beside each
verdict, so a reader can disagree with a rule without having to trust prose.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

AGREES = "agrees"
DISAGREES = "disagrees"
NOT_COMPUTABLE = "not computable"

_ROLLING = ("sphere", "horizontal_cylinder")
_RESTING = ("box", "vertical_cylinder")


@dataclass(frozen=True)
class Claim:
    """One statement of the paper set beside our numbers.

    Attributes:
        topic: Short name of the statement.
        paper: What the paper says.
        rule: The numeric rule our verdict follows.
        ours: Our numbers, as text.
        verdict: "agrees", "disagrees" or "not computable".
    """

    topic: str
    paper: str
    rule: str
    ours: str
    verdict: str


class _Missing(Exception):
    """The results lack what a rule needs."""


def _outcome_words(results: Mapping[str, Any]) -> tuple[str, str]:
    """How a success and a failure read, from the results' config ("success" / "fail" when it does not say)."""
    config = results.get("config", {})
    return config.get("success_label", "success"), config.get("fail_label", "fail")


def _mean(per_k: Mapping[str, Mapping[str, Any]], k: int | str) -> float:
    entry = per_k.get(str(k))
    if entry is None or entry.get("mean") is None:
        raise _Missing(f"no value for k = {k}")
    return float(entry["mean"])


def _curve(per_k: Mapping[str, Mapping[str, Any]]) -> tuple[list[int], np.ndarray]:
    ks = sorted(int(k) for k in per_k)
    if not ks:
        raise _Missing("no k")
    return ks, np.array([_mean(per_k, k) for k in ks])


def _section(results: Mapping[str, Any], key: str) -> Any:
    if key not in results:
        raise _Missing(f"results have no {key!r}")
    return results[key]


def _ranks(values: Sequence[float]) -> np.ndarray:
    """Ranks 1..n, ties sharing their mean rank."""
    values = np.asarray(values, dtype=float)
    ranks = np.empty(values.size)
    ranks[np.argsort(values, kind="stable")] = np.arange(1, values.size + 1)
    for v in np.unique(values):
        ranks[values == v] = ranks[values == v].mean()
    return ranks


def _rho(x: Sequence[float], y: Sequence[float]) -> float:
    """Spearman rank correlation of x and y; 0 when y is constant (no trend either way)."""
    if len(x) < 3 or np.ptp(np.asarray(x, dtype=float)) == 0:
        raise _Missing("fewer than 3 distinct values: no trend to measure")
    if np.ptp(np.asarray(y, dtype=float)) == 0:
        return 0.0
    return float(np.corrcoef(_ranks(x), _ranks(y))[0, 1])


def _fmt(values: Sequence[float], digits: int = 1) -> str:
    return ", ".join(f"{v:.{digits}f}" for v in values)


def _uniformity_average(results: Mapping[str, Any]) -> tuple[str, bool]:
    ks, u = _curve(_section(results, "uniformity"))
    return f"mean over k = {ks[0]}..{ks[-1]}: {u.mean():.1f} % (per k: {_fmt(u)})", bool(u.mean() > 80.0)


def _uniformity_rises(results: Mapping[str, Any]) -> tuple[str, bool]:
    ks, u = _curve(_section(results, "uniformity"))
    rho = _rho(ks, u)
    if np.ptp(u) == 0:
        return f"U is {u[0]:.1f} % for every k: no rise (rho taken as 0)", False
    return (
        f"Spearman rho(k, U) = {rho:+.2f}; U from {u[0]:.1f} % (k = {ks[0]}) to {u[-1]:.1f} % (k = {ks[-1]})",
        rho >= 0.5,
    )


def _uniformity_peak(results: Mapping[str, Any]) -> tuple[str, bool]:
    ks, u = _curve(_section(results, "uniformity"))
    best = int(np.argmax(u))
    return f"highest mean uniformity {u[best]:.1f} % at k = {ks[best]}", bool(u[best] >= 90.0)


def _by_r(results: Mapping[str, Any], key: str) -> dict[float, tuple[list[int], np.ndarray]]:
    section = _section(results, key)
    if not section:
        raise _Missing(f"{key!r} is empty")
    return {float(r): _curve(per_k) for r, per_k in section.items()}


def _shape_dominates(results: Mapping[str, Any]) -> tuple[str, bool]:
    curves = _by_r(results, "shape_fraction")
    means = {r: 100.0 * v.mean() for r, (_, v) in sorted(curves.items())}
    positive = {r: m for r, m in means.items() if r > 0}
    if not positive:
        raise _Missing("no relevancy r > 0")
    text = "mean shape share over k: " + ", ".join(f"r = {r}: {m:.0f} %" for r, m in means.items())
    return text, all(m > 50.0 for m in positive.values())


def _shape_share_falls_with_lower_r(results: Mapping[str, Any]) -> tuple[str, bool]:
    curves = _by_r(results, "shape_fraction")
    rs = sorted(curves)
    means = [curves[r][1].mean() for r in rs]
    rho = _rho(rs, means)
    return f"Spearman rho(r, mean shape share) = {rho:+.2f}", rho > 0


def _count_falls_with_r(results: Mapping[str, Any]) -> tuple[str, bool]:
    curves = _by_r(results, "n_selected")
    rs = sorted(curves)
    if len(rs) < 2:
        raise _Missing("fewer than 2 relevancy values")
    table = np.array([curves[r][1] for r in rs])  # (r, k)
    monotone = bool(np.all(np.diff(table, axis=0) <= 1e-9) and np.all(table[-1] < table[0]))
    means = table.mean(axis=1)
    text = "mean number over k: " + ", ".join(f"r = {r}: {m:.1f}" for r, m in zip(rs, means, strict=True))
    return text, monotone


def _count_constant_in_k(results: Mapping[str, Any]) -> tuple[str, bool]:
    curves = _by_r(results, "n_selected")
    parts, ok = [], True
    for r, (ks, values) in sorted(curves.items()):
        upper = np.array([v for k, v in zip(ks, values, strict=True) if k >= 4])
        if upper.size < 2:
            raise _Missing("fewer than 2 values of k >= 4")
        cv = float(upper.std() / upper.mean()) if upper.mean() > 0 else 0.0
        parts.append(f"r = {r}: {_fmt(upper)} (CV {cv:.2f})")
        ok &= cv <= 0.15
    return "number for k >= 4 per r: " + "; ".join(parts), ok


def _case(results: Mapping[str, Any], k: int) -> list[Mapping[str, Any]]:
    clusters = _section(results, "case_studies").get(str(k))
    if not clusters:
        raise _Missing(f"no case study for k = {k}")
    return clusters


def _two_cluster_types(results: Mapping[str, Any]) -> tuple[str, bool]:
    clusters = _case(results, 2)
    types = sorted({t for c in clusters for t in c["types"]})
    if not set(_ROLLING + _RESTING) <= set(types):
        raise _Missing("the case study lacks one of the four object types")
    home, share = {}, {}
    for t in types:
        counts = np.array([c["types"].get(t, 0) for c in clusters])
        home[t] = int(clusters[int(np.argmax(counts))]["cluster"])
        share[t] = counts.max() / max(counts.sum(), 1)
    table = "; ".join(
        f"cluster {c['cluster']}: " + ", ".join(f"{t} {c['types'].get(t, 0)}" for t in types)
        for c in clusters
    )
    rolling = {home[t] for t in _ROLLING}
    resting = {home[t] for t in _RESTING}
    ok = len(rolling) == 1 and len(resting) == 1 and rolling != resting
    ok = ok and all(share[t] >= 0.75 for t in _ROLLING + _RESTING)
    shares = ", ".join(f"{t} {100 * share[t]:.0f} %" for t in _ROLLING + _RESTING)
    return f"{table} (share of each type in its majority cluster: {shares})", bool(ok)


def _two_cluster_sizes(results: Mapping[str, Any]) -> tuple[str, bool]:
    clusters = [c for c in _case(results, 2) if c["sizes"]]
    everything = np.concatenate([np.asarray(c["sizes"], dtype=float) for c in clusters])
    span = np.ptp(everything)
    if span == 0:
        raise _Missing("all objects have the same size")
    cover = [np.ptp(np.asarray(c["sizes"], dtype=float)) / span for c in clusters]
    text = "; ".join(
        f"cluster {c['cluster']}: {100 * min(c['sizes']):.1f}-{100 * max(c['sizes']):.1f} cm "
        f"({100 * f:.0f} % of "
        "the size range)"
        for c, f in zip(clusters, cover, strict=True)
    )
    return text, len(clusters) == 2 and all(f >= 0.75 for f in cover)


def _four_cluster_split(results: Mapping[str, Any]) -> tuple[str, bool]:
    clusters = _case(results, 4)
    success_label, fail_label = _outcome_words(results)
    success = sum(c["success"] > c["fail"] for c in clusters)
    fail = sum(c["fail"] > c["success"] for c in clusters)
    text = "; ".join(
        f"cluster {c['cluster']}: {c['success']} {success_label} / {c['fail']} {fail_label}" for c in clusters
    )
    return f"{text} -> {success} success and {fail} fail clusters", success == 2 and fail == 2


def _accuracy_falls(results: Mapping[str, Any]) -> tuple[str, bool]:
    curves = _by_r(results, "svm_accuracy")
    rhos = {r: _rho(ks, v) for r, (ks, v) in sorted(curves.items())}
    text = "Spearman rho(k, accuracy): " + ", ".join(f"r = {r}: {rho:+.2f}" for r, rho in rhos.items())
    return text, all(rho <= -0.5 for rho in rhos.values())


def _bump_at_four(results: Mapping[str, Any]) -> tuple[str, bool]:
    section = _section(results, "svm_accuracy")
    parts, bumps = [], 0
    for r in sorted(section, key=float):
        a3, a4 = _mean(section[r], 3), _mean(section[r], 4)
        parts.append(f"r = {r}: {100 * a3:.1f} -> {100 * a4:.1f} %")
        bumps += a4 > a3
    return "accuracy k = 3 -> 4: " + "; ".join(parts), bumps * 2 >= len(section)


def _accuracy_by_r(results: Mapping[str, Any]) -> dict[float, float]:
    return {r: float(v.mean()) for r, (_, v) in _by_r(results, "svm_accuracy").items()}


def _low_r_alike(results: Mapping[str, Any]) -> tuple[str, bool]:
    accuracy = _accuracy_by_r(results)
    low = {r: a for r, a in accuracy.items() if r in (0.0, 0.2, 0.4)}
    if len(low) < 2:
        raise _Missing("fewer than 2 of r = 0, 0.2, 0.4")
    spread = 100 * (max(low.values()) - min(low.values()))
    text = ", ".join(f"r = {r}: {100 * a:.1f} %" for r, a in sorted(low.items()))
    return f"mean accuracy over k: {text} (spread {spread:.1f} points)", spread <= 2.0


def _best_r(results: Mapping[str, Any]) -> tuple[str, bool]:
    accuracy = _accuracy_by_r(results)
    counts = {r: float(v.mean()) for r, (_, v) in _by_r(results, "n_selected").items()}
    top = max(accuracy.values())
    near = [r for r, a in accuracy.items() if a >= top - 0.01]
    choice = max(near)
    text = ", ".join(
        f"r = {r}: {100 * accuracy[r]:.1f} % with {counts.get(r, float('nan')):.1f} features"
        for r in sorted(accuracy)
    )
    return f"{text}; fewest features within 1 point of the best accuracy: r = {choice}", choice == 0.4


_CLAIMS: tuple[tuple[str, str, str, Callable[[Mapping[str, Any]], tuple[str, bool]]], ...] = (
    (
        "Uniformity on average",
        "The average uniformity is above 80 % for tapping.",
        "mean over k of the mean uniformity > 80 %",
        _uniformity_average,
    ),
    (
        "Uniformity rises with k",
        "Uniformity of clusters increases with the number of clusters.",
        "Spearman rank correlation of k and mean uniformity >= 0.5",
        _uniformity_rises,
    ),
    (
        "Uniformity peak",
        "It can reach up to 95 %.",
        "highest mean uniformity over k >= 90 %",
        _uniformity_peak,
    ),
    (
        "Shape features dominate",
        "Shape features dominate the selected features.",
        "for every r > 0, the mean over k of the shape share of the selected features > 50 %",
        _shape_dominates,
    ),
    (
        "Shape share and r",
        "When the relevancy threshold is decreased ... the percentage of shape features decreases.",
        "Spearman rank correlation of r and the mean shape share > 0",
        _shape_share_falls_with_lower_r,
    ),
    (
        "Fewer features as r rises",
        "The number of selected features tends to be inversely proportional to r.",
        "for every k the mean number never grows with r, and is lower at the largest r than at the smallest",
        _count_falls_with_r,
    ),
    (
        "Number constant in k",
        "The number of selected features remains the same above some number of clusters.",
        "for every r, the coefficient of variation over k >= 4 of the mean number <= 0.15",
        _count_constant_in_k,
    ),
    (
        "1 x 2 map: object types",
        "One cluster holds spheres and horizontal cylinders (rollable), the other boxes and "
        "vertical cylinders.",
        "spheres and lying cylinders share a majority cluster, boxes and standing cylinders the "
        "other, each type with >= 75 % of its objects there (first trial)",
        _two_cluster_types,
    ),
    (
        "1 x 2 map: sizes",
        "Both clusters have instances from the whole size range.",
        "each of the 2 clusters spans >= 75 % of the range of object sizes (first trial)",
        _two_cluster_sizes,
    ),
    (
        "1 x 4 map: success/fail",
        "Two of the four clusters are success clusters, the other two fail clusters.",
        "exactly 2 clusters with more successes (rolled) than failures and 2 with more failures (first trial)",
        _four_cluster_split,
    ),
    (
        "SVM accuracy falls with k",
        "SVM prediction accuracy decreases as the number of effect categories grows.",
        "for every r, Spearman rank correlation of k and mean accuracy <= -0.5",
        _accuracy_falls,
    ),
    (
        "Bump at k = 4",
        "Accuracy increases at 4 clusters against the decreasing trend (four object types).",
        "mean accuracy at k = 4 above that at k = 3 for at least half of the r values",
        _bump_at_four,
    ),
    (
        "r = 0, 0.2, 0.4 alike",
        "Accuracy is almost the same for relevancy values of 0 %, 20 % and 40 %.",
        "mean accuracy over k of these r within 2 percentage points",
        _low_r_alike,
    ),
    (
        "r = 0.4 best",
        "40 % is the best relevancy: maximum accuracy with the highest perceptual economy.",
        "the largest r whose mean accuracy over k is within 1 point of the best r's is 0.4",
        _best_r,
    ),
)


def evaluate_claims(results: Mapping[str, Any]) -> list[Claim]:
    """Every claim of the paper with our numbers and a verdict computed from them."""
    claims = []
    for topic, paper, rule, judge in _CLAIMS:
        try:
            ours, ok = judge(results)
            verdict = AGREES if ok else DISAGREES
        except _Missing as why:
            ours, verdict = f"({why})", NOT_COMPUTABLE
        claims.append(Claim(topic=topic, paper=paper, rule=rule, ours=ours, verdict=verdict))
    return claims

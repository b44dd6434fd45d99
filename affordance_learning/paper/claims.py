"""The paper's statements as claims with numeric rules, and their verdicts on our numbers.

Each statement of Akgun et al. 2009 (section V) becomes a :class:`~affordance_learning.common.verdicts.Spec`
with a stated, numeric rule, judged by the one rule both experiments share (:mod:`affordance_learning.common.verdicts`):
"met" or "missed" by the rule, "too few data" when it was applied to less data than :data:`MIN_TRIALS` and
:data:`MIN_INTERACTIONS` ask for, or "not measured" when the results lack what the rule needs (for example k = 4 was
not run); a missed claim says why from the data where it can. Every verdict carries its n: the trials and
interactions (or, for a map of the first trial, the interactions in it) it was judged on. The rules are judgement
calls written in the report beside each verdict, so a reader can disagree with a rule without having to trust
prose.

The paper reports two behaviours, and the claims are chosen by the behaviour of the results
(``results["config"]["behavior"]``, see :func:`claims_for`):

- ``tap``: its 14 statements on tapping (uniformity, selected features, the 1 x 2 and 1 x 4 maps, the SVM).
- ``grasp``: its statements on grasping (average uniformity, the fall at k = 3, the critical size, the 1 x 3
  category that straddles it, size deciding the grasp) with those on the method that hold for any behaviour.
- any other behaviour: only the statements on the method.

Each claim is specified once, as a ``Spec`` (topic, the paper's statement, the rule, the function that
applies it and the one that says what it is judged on), and judged on :class:`~.results.Results`.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np

from affordance_learning.common.verdicts import Basis, Count, Judgement, NotMeasured, Spec, Verdict, judge_all
from affordance_learning.paper.results import Cluster, PerK, PerRK, Results, as_results

# The least data a verdict is given on; below it the verdict is "too few".
#: A claim on means over trials needs at least this many trials: the standard error of a mean over n trials is the
#: standard deviation between trials over sqrt(n), under a third of it from 10 trials on (the shipped grasp's
#: uniformity at one k has a standard deviation of up to 32 points between trials).
MIN_TRIALS = 10
#: Every claim needs at least this many interactions (those of a run, or of the map of the first trial the claim
#: reads): a share of them is then known within +-7 points (Wilson 95 % interval at 50 %), finer than the rules'
#: margins of 20 to 25 %.
MIN_INTERACTIONS = 200

_ROLLING = ("sphere", "horizontal_cylinder")
_RESTING = ("box", "vertical_cylinder")

# Each rule's thresholds, one value read by the check and written into the rule's text.
#: The tap's average uniformity is above this [%].
TAP_UNIFORMITY = 80.0
#: A trend counts at a Spearman rank correlation of at least this (uniformity rising with k), or of at most minus
#: this (accuracy falling with k).
TREND_RHO = 0.5
#: The highest mean uniformity over k reaches at least this [%] (the paper: "up to 95 %").
UNIFORMITY_PEAK = 90.0
#: A group of features dominates the selection when its share is above this [%].
DOMINANT_SHARE = 50.0
#: The number of selected features is constant in k from this k on, within this coefficient of variation.
CONSTANT_FROM_K, CONSTANT_CV = 4, 0.15
#: In the 1 x 2 map every type has at least this share of its objects in its majority cluster, and each cluster
#: spans at least this share of the range of object sizes.
TYPE_SHARE, SIZE_SPAN = 0.75, 0.75
#: Accuracy at r = 0, 0.2 and 0.4 is alike within this many percentage points ...
ALIKE_POINTS = 2.0
#: ... and the best r is the largest within this many points of the best accuracy: the paper's 0.4.
BEST_R_POINTS, BEST_R = 1.0, 0.4


def _mean(per_k: PerK, k: int) -> float:
    """The mean at ``k``; missing when k was not run or no trial gave a value."""
    entry = per_k.get(k)
    if entry is None or entry.mean is None:
        raise NotMeasured(f"no value for k = {k}")
    return entry.mean


def _curve(per_k: PerK) -> tuple[list[int], np.ndarray]:
    """k ascending and the mean at each."""
    ks = sorted(per_k)
    if not ks:
        raise NotMeasured("no k")
    return ks, np.array([_mean(per_k, k) for k in ks])


def _section(section: Any, key: str) -> Any:
    """A section of the results (``key`` names it); missing when the results lack it."""
    if section is None:
        raise NotMeasured(f"results have no {key!r}")
    return section


def _rho(x: Sequence[float], y: Sequence[float]) -> float:
    """Spearman rank correlation of x and y (:func:`scipy.stats.spearmanr`: ties share their mean rank); 0 when y
    is constant (no trend either way)."""
    from scipy.stats import spearmanr

    if len(x) < 3 or np.ptp(np.asarray(x, dtype=float)) == 0:
        raise NotMeasured("fewer than 3 distinct values: no trend to measure")
    if np.ptp(np.asarray(y, dtype=float)) == 0:
        return 0.0
    return float(spearmanr(np.asarray(x, dtype=float), np.asarray(y, dtype=float)).statistic)


def _fmt(values: Sequence[float], digits: int = 1) -> str:
    return ", ".join(f"{v:.{digits}f}" for v in values)


def _uniformity_curve(results: Results) -> tuple[list[int], np.ndarray]:
    """k and the mean uniformity per k, in percent (the results hold fractions), as the paper states it."""
    ks, u = _curve(_section(results.uniformity, "uniformity"))
    return ks, 100.0 * u


def _uniformity_average(results: Results) -> Judgement:
    ks, u = _uniformity_curve(results)
    return Judgement(f"mean over k = {ks[0]}..{ks[-1]}: {u.mean():.1f} % (per k: {_fmt(u)})",
                     u.mean() > TAP_UNIFORMITY)


def _uniformity_rises(results: Results) -> Judgement:
    ks, u = _uniformity_curve(results)
    rho = _rho(ks, u)
    if np.ptp(u) == 0:
        return Judgement(f"U is {u[0]:.1f} % for every k: no rise (rho taken as 0)", False)
    return Judgement(
        f"Spearman rho(k, U) = {rho:+.2f}; U from {u[0]:.1f} % (k = {ks[0]}) to {u[-1]:.1f} % (k = {ks[-1]})",
        rho >= TREND_RHO)


def _uniformity_peak(results: Results) -> Judgement:
    ks, u = _uniformity_curve(results)
    best = int(np.argmax(u))
    return Judgement(f"highest mean uniformity {u[best]:.1f} % at k = {ks[best]}", bool(u[best] >= UNIFORMITY_PEAK))


def _by_r(section: PerRK | None, key: str) -> dict[float, tuple[list[int], np.ndarray]]:
    """Per r, k ascending and the mean at each, of the section ``key``."""
    section = _section(section, key)
    if not section:
        raise NotMeasured(f"{key!r} is empty")
    return {r: _curve(per_k) for r, per_k in section.items()}


def _group_dominates(shares: PerRK | None, group: str) -> Judgement:
    """Whether the features of ``group`` ("shape", "size"; ``shares``: their share of the selected ones per r and
    k) dominate the selection at every r > 0."""
    curves = _by_r(shares, f"{group}_fraction")
    means = {r: 100.0 * v.mean() for r, (_, v) in sorted(curves.items())}
    positive = {r: m for r, m in means.items() if r > 0}
    if not positive:
        raise NotMeasured("no relevancy r > 0")
    text = f"mean {group} share over k: " + ", ".join(f"r = {r}: {m:.0f} %" for r, m in means.items())
    return Judgement(text, all(m > DOMINANT_SHARE for m in positive.values()))


def _shape_dominates(results: Results) -> Judgement:
    return _group_dominates(results.shape_fraction, "shape")


def _size_dominates(results: Results) -> Judgement:
    return _group_dominates(results.size_fraction, "size")


def _shape_share_falls_with_lower_r(results: Results) -> Judgement:
    curves = _by_r(results.shape_fraction, "shape_fraction")
    rs = sorted(curves)
    means = [curves[r][1].mean() for r in rs]
    rho = _rho(rs, means)
    return Judgement(f"Spearman rho(r, mean shape share) = {rho:+.2f}", rho > 0)


def _count_falls_with_r(results: Results) -> Judgement:
    curves = _by_r(results.n_selected, "n_selected")
    rs = sorted(curves)
    if len(rs) < 2:
        raise NotMeasured("fewer than 2 relevancy values")
    table = np.array([curves[r][1] for r in rs])  # (r, k)
    monotone = bool(np.all(np.diff(table, axis=0) <= 1e-9) and np.all(table[-1] < table[0]))
    means = table.mean(axis=1)
    text = "mean number over k: " + ", ".join(f"r = {r}: {m:.1f}" for r, m in zip(rs, means, strict=True))
    return Judgement(text, monotone)


def _count_constant_in_k(results: Results) -> Judgement:
    curves = _by_r(results.n_selected, "n_selected")
    parts, ok = [], True
    for r, (ks, values) in sorted(curves.items()):
        upper = np.array([v for k, v in zip(ks, values, strict=True) if k >= CONSTANT_FROM_K])
        if upper.size < 2:
            raise NotMeasured(f"fewer than 2 values of k >= {CONSTANT_FROM_K}")
        cv = float(upper.std() / upper.mean()) if upper.mean() > 0 else 0.0
        parts.append(f"r = {r}: {_fmt(upper)} (CV {cv:.2f})")
        ok &= cv <= CONSTANT_CV
    return Judgement(f"number for k >= {CONSTANT_FROM_K} per r: " + "; ".join(parts), ok)


def _case(results: Results, k: int) -> tuple[Cluster, ...]:
    """The clusters of the 1 x k map of the first trial; missing when it was not described."""
    clusters = _section(results.case_studies, "case_studies").get(k)
    if not clusters:
        raise NotMeasured(f"no case study for k = {k}")
    return clusters


def _two_cluster_types(results: Results) -> Judgement:
    clusters = _case(results, 2)
    types = sorted({t for c in clusters for t in c.types})
    if not set(_ROLLING + _RESTING) <= set(types):
        raise NotMeasured("the case study lacks one of the four object types")
    home, share = {}, {}
    for t in types:
        counts = np.array([c.types.get(t, 0) for c in clusters])
        home[t] = clusters[int(np.argmax(counts))].index
        share[t] = counts.max() / max(counts.sum(), 1)
    table = "; ".join(
        f"cluster {c.index}: " + ", ".join(f"{t} {c.types.get(t, 0)}" for t in types)
        for c in clusters
    )
    rolling = {home[t] for t in _ROLLING}
    resting = {home[t] for t in _RESTING}
    ok = len(rolling) == 1 and len(resting) == 1 and rolling != resting
    ok = ok and all(share[t] >= TYPE_SHARE for t in _ROLLING + _RESTING)
    shares = ", ".join(f"{t} {100 * share[t]:.0f} %" for t in _ROLLING + _RESTING)
    return Judgement(f"{table} (share of each type in its majority cluster: {shares})", bool(ok))


def _two_cluster_sizes(results: Results) -> Judgement:
    clusters = [c for c in _case(results, 2) if c.sizes]
    everything = np.concatenate([np.asarray(c.sizes, dtype=float) for c in clusters])
    span = np.ptp(everything)
    if span == 0:
        raise NotMeasured("all objects have the same size")
    cover = [np.ptp(np.asarray(c.sizes, dtype=float)) / span for c in clusters]
    text = "; ".join(
        f"cluster {c.index}: {100 * min(c.sizes):.1f}-{100 * max(c.sizes):.1f} cm "
        f"({100 * f:.0f} % of "
        "the size range)"
        for c, f in zip(clusters, cover, strict=True)
    )
    return Judgement(text, len(clusters) == 2 and all(f >= SIZE_SPAN for f in cover))


def _four_cluster_split(results: Results) -> Judgement:
    clusters = _case(results, 4)
    success_label, fail_label = results.config.success_label, results.config.fail_label
    success = sum(c.success > c.fail for c in clusters)
    fail = sum(c.fail > c.success for c in clusters)
    text = "; ".join(
        f"cluster {c.index}: {c.success} {success_label} / {c.fail} {fail_label}" for c in clusters
    )
    return Judgement(f"{text} -> {success} success and {fail} fail clusters", success == 2 and fail == 2)


def _accuracy_falls(results: Results) -> Judgement:
    curves = _by_r(results.svm_accuracy, "svm_accuracy")
    rhos = {r: _rho(ks, v) for r, (ks, v) in sorted(curves.items())}
    text = "Spearman rho(k, accuracy): " + ", ".join(f"r = {r}: {rho:+.2f}" for r, rho in rhos.items())
    return Judgement(text, all(rho <= -TREND_RHO for rho in rhos.values()))


def _bump_at_four(results: Results) -> Judgement:
    section = _section(results.svm_accuracy, "svm_accuracy")
    parts, bumps = [], 0
    for r in sorted(section):
        a3, a4 = _mean(section[r], 3), _mean(section[r], 4)
        parts.append(f"r = {r}: {100 * a3:.1f} -> {100 * a4:.1f} %")
        bumps += a4 > a3
    return Judgement("accuracy k = 3 -> 4: " + "; ".join(parts), bumps * 2 >= len(section))


def _accuracy_by_r(results: Results) -> dict[float, float]:
    return {r: float(v.mean()) for r, (_, v) in _by_r(results.svm_accuracy, "svm_accuracy").items()}


def _low_r_alike(results: Results) -> Judgement:
    accuracy = _accuracy_by_r(results)
    low = {r: a for r, a in accuracy.items() if r in (0.0, 0.2, 0.4)}
    if len(low) < 2:
        raise NotMeasured("fewer than 2 of r = 0, 0.2, 0.4")
    spread = 100 * (max(low.values()) - min(low.values()))
    text = ", ".join(f"r = {r}: {100 * a:.1f} %" for r, a in sorted(low.items()))
    return Judgement(f"mean accuracy over k: {text} (spread {spread:.1f} points)", spread <= ALIKE_POINTS)


def _best_r(results: Results) -> Judgement:
    accuracy = _accuracy_by_r(results)
    counts = {r: float(v.mean()) for r, (_, v) in _by_r(results.n_selected, "n_selected").items()}
    top = max(accuracy.values())
    near = [r for r, a in accuracy.items() if a >= top - BEST_R_POINTS / 100]
    choice = max(near)
    text = ", ".join(
        f"r = {r}: {100 * accuracy[r]:.1f} % with {counts.get(r, float('nan')):.1f} features"
        for r in sorted(accuracy)
    )
    return Judgement(f"{text}; fewest features within {BEST_R_POINTS:g} point(s) of the best accuracy: r = {choice}",
            choice == BEST_R)


# --- the grasp ----------------------------------------------------------------------------------------------
#: The grasp's average uniformity: above the paper's 70 % and not above the tap's 80 %, which it sets apart.
GRASP_UNIFORMITY = (70.0, TAP_UNIFORMITY)
#: A 1 x 3 category straddles the critical size when at least this share of its objects lies on each side
#: of it, and at least this share of its members has its less common outcome.
STRADDLE_SHARE = 0.2
#: ... and it is a category, not a handful of outliers: it holds at least this share of all interactions; so does
#: each of the other categories, the two it steals from.
STRADDLE_MIN_SIZE = 0.1
#: ... and it is a minority: it holds less than this share of all interactions. The paper's category "falls near
#: this region, stealing from both" a success and a fail category; one that holds most interactions is the bulk of
#: the map, from which the others split off a few, and any size boundary runs through it.
STRADDLE_MAX_SIZE = 0.5
#: The critical size decides the grasp when successes are this much more common below it than above it.
CRITICAL_SIZE_CONTRAST = 0.5


def _grasp_uniformity_average(results: Results) -> Judgement:
    ks, u = _uniformity_curve(results)
    low, high = GRASP_UNIFORMITY
    return Judgement(f"mean over k = {ks[0]}..{ks[-1]}: {u.mean():.1f} % (per k: {_fmt(u)})",
                     low < u.mean() <= high)


def _fall_at_three(results: Results) -> Judgement:
    section = _section(results.uniformity, "uniformity")
    u2, u3, u4 = (100.0 * _mean(section, k) for k in (2, 3, 4))
    return Judgement(f"mean uniformity at k = 2, 3, 4: {u2:.1f}, {u3:.1f}, {u4:.1f} %", u3 < u2 and u3 < u4)


def _critical_size(results: Results) -> Judgement:
    section = _section(results.size_success, "size_success")
    fit, critical, test = section.logistic, section.critical_size, section.test
    if fit is None:
        return Judgement("one outcome only: no size separates success from failure", False)
    if test is not None and not test.depends_on_size:
        return Judgement(f"success does not depend on size: the fit (slope {fit.slope / 100:+.2f} per cm of logit) "
                         "changes "
                f"the share of successes by {100 * test.span:+.0f} points across the sizes seen "
                f"(likelihood-ratio test p = {test.p_value:.2g})", False)
    if critical is None:
        return Judgement(f"the logistic fit (slope {fit.slope / 100:+.2f} per cm of logit) does not cross 50 % within "
                "the sizes seen", False)
    below, above = section.below, section.above
    if below is None or above is None or below.success is None or above.success is None:
        raise NotMeasured("no object on one side of the critical size")
    contrast = below.success - above.success
    text = (f"the fit crosses 50 % at {100 * critical:.1f} cm (slope {fit.slope / 100:+.2f} per cm of logit); "
            f"successes below it {100 * below.success:.0f} % of {below.n}, above it "
            f"{100 * above.success:.0f} % of {above.n}")
    return Judgement(text, bool(fit.slope < 0 and contrast >= CRITICAL_SIZE_CONTRAST))


def _straddling_cluster(results: Results) -> Judgement:
    critical = _section(results.size_success, "size_success").critical_size
    if critical is None:
        raise NotMeasured("no critical size: success does not depend on size, or the fit of success on size does not "
                       "cross 50 % within the sizes seen")
    success_label, fail_label = results.config.success_label, results.config.fail_label
    clusters = _case(results, 3)
    total = max(sum(c.n for c in clusters), 1)
    parts, straddling, why_not = [], [], []
    for c in clusters:
        sizes = np.asarray(c.sizes, dtype=float)
        share = c.n / total
        if sizes.size == 0:
            parts.append(f"cluster {c.index}: empty")
            continue
        below = float(np.mean(sizes < critical))
        minority = min(c.success, c.fail) / c.n
        parts.append(f"cluster {c.index} ({c.n} interactions, {100 * share:.1f} %): "
                     f"{100 * sizes.min():.1f}-{100 * sizes.max():.1f} cm, {100 * below:.0f} % below; "
                     f"{c.success} {success_label} / {c.fail} {fail_label}")
        if min(below, 1.0 - below) < STRADDLE_SHARE or minority < STRADDLE_SHARE:
            continue  # neither its objects nor its outcomes lie on both sides
        others = [o for o in clusters if o is not c]
        sides = {(o.success > o.fail) - (o.fail > o.success) for o in others}  # 1: mostly successes
        if not STRADDLE_MIN_SIZE <= share < STRADDLE_MAX_SIZE:
            why_not.append(f"cluster {c.index} lies on both sides but holds {100 * share:.0f} % of the "
                           f"interactions: a straddling category holds >= {100 * STRADDLE_MIN_SIZE:.0f} % and < "
                           f"{100 * STRADDLE_MAX_SIZE:.0f} %")
        elif not {1, -1} <= sides or any(o.n < STRADDLE_MIN_SIZE * total for o in others):
            why_not.append(f"cluster {c.index} lies on both sides but the others are not a success and a fail "
                           f"category of >= {100 * STRADDLE_MIN_SIZE:.0f} % each")
        else:
            straddling.append(str(c.index))
    text = (f"critical size {100 * critical:.1f} cm; " + "; ".join(parts)
            + f" -> straddling: {', '.join(straddling) or 'none'}"
            + ("" if straddling or not why_not else f" ({'; '.join(why_not)})"))
    return Judgement(text, bool(straddling))


def _over_trials(results: Results) -> Basis:
    """A claim on means over trials: n is the trials, each over all the run's interactions."""
    return Basis((Count(results.config.n_trials, MIN_TRIALS, "trials"),
                  Count(results.config.n_rows, MIN_INTERACTIONS, "interactions")))


def _in_map(k: int) -> Callable[[Results], Basis]:
    """A claim on the 1 x k map of the first trial: n is the interactions in it."""
    def basis(results: Results) -> Basis:
        clusters = results.clusters(k)
        n = sum(c.n for c in clusters)
        return Basis((Count(n if clusters else None, MIN_INTERACTIONS, "interactions"),),
                     f"{n} interactions in the 1 x {k} map of the first trial")
    return basis


def _over_sizes(results: Results) -> Basis:
    """A claim on success by object size: n is the interactions binned by size."""
    bins = results.size_success.bins if results.size_success is not None else ()
    return Basis((Count(sum(b.n for b in bins) if bins else None, MIN_INTERACTIONS, "interactions"),))


# --- why a claim is missed, from the data -----------------------------------------------------------------------
def _categories(results: Results, k: int) -> str:
    """The 1 x k map of the first trial, category by category: its interactions, their outcomes and its
    prototype effect (the 3-D motion of the object's seen centre [cm] and the change of its pixel count)."""
    clusters = results.clusters(k)
    rows = (results.prototypes or {}).get(k)
    names = results.feature_names or ()
    parts = []
    for c in clusters:
        text = f"{c.n} ({c.success} {results.config.success_label}, {c.fail} {results.config.fail_label})"
        if rows is not None and c.index < len(rows) and {"mean_x", "mean_y", "mean_z", "pixel_count"} <= set(names):
            row = np.asarray(rows[c.index], dtype=float)
            motion = np.linalg.norm([row[names.index(n)] for n in ("mean_x", "mean_y", "mean_z")])
            text += f", its prototype moved {100 * motion:.1f} cm and {row[names.index('pixel_count')]:+.0f} pixels"
        parts.append(text)
    return f"the first trial's 1 x {k} map holds " + "; ".join(parts)


def _spread_at(results: Results, section: PerK | None, k: int, what: str) -> str:
    entry = (section or {}).get(k)
    if entry is None or entry.mean is None:
        return ""
    std = "" if entry.std is None else f" +- {100 * entry.std:.1f}"
    return f"{what} at k = {k} is {100 * entry.mean:.1f}{std} % over {results.config.n_trials} trials"


def _map_why(k: int) -> Callable[[Results], str | None]:
    """Why a claim on the 1 x k map is missed: what the map's categories hold, and how much the uniformity of a
    1 x k map varies between trials (the first trial's map is one of them)."""
    def why(results: Results) -> str | None:
        if not results.clusters(k):
            return None
        spread = _spread_at(results, results.uniformity, k, "uniformity")
        return _categories(results, k) + (f"; {spread}, so the maps of other trials may split otherwise"
                                          if spread else "")
    return why


def _group_why(group: str) -> Callable[[Results], str | None]:
    """Why a group of features does not dominate the selection: at each r where it does not, what the selection
    holds instead, and how many features it keeps."""
    def why(results: Results) -> str | None:
        shares = {"shape": results.shape_fraction, "size": results.size_fraction}
        total = results.config.entries.get("feature_groups") or {}
        parts = []
        for r, per_k in sorted((shares[group] or {}).items()):
            mine = float(np.mean([e.mean for e in per_k.values() if e.mean is not None]))
            if r == 0 or mine > DOMINANT_SHARE / 100:
                continue
            other = "size" if group == "shape" else "shape"
            theirs = [e.mean for e in (shares[other] or {}).get(r, {}).values() if e.mean is not None]
            counts = [e.mean for e in (results.n_selected or {}).get(r, {}).values() if e.mean is not None]
            parts.append(f"at r = {r} the selection keeps {np.mean(counts):.1f} features on average, "
                         f"{100 * mine:.0f} % {group}, {100 * float(np.mean(theirs)):.0f} % {other} and "
                         f"{100 * (1 - mine - float(np.mean(theirs))):.0f} % hand-object relation")
        if not parts:
            return None
        of_all = (f" ({total[group]} of the {sum(total.values())} features are {group} features)"
                  if group in total else "")
        return "; ".join(parts) + of_all
    return why


def _curve_why(section_name: str, what: str) -> Callable[[Results], str | None]:
    """Why a trend over k is missed: the means per k, with the spread between trials at each."""
    def why(results: Results) -> str | None:
        section = getattr(results, section_name)
        if not section:
            return None
        per_r = section if section_name != "uniformity" else {None: section}
        parts = []
        for r, per_k in sorted(per_r.items(), key=lambda item: -1 if item[0] is None else item[0]):
            values = ", ".join(f"{100 * e.mean:.1f}" + ("" if e.std is None else f"+-{100 * e.std:.1f}")
                               for _, e in sorted(per_k.items()) if e.mean is not None)
            parts.append(("" if r is None else f"r = {r}: ") + values)
        ks = sorted(next(iter(per_r.values())))
        return (f"{what} per k = {ks[0]}..{ks[-1]} (mean +- standard deviation over "
                f"{results.config.n_trials} trials, %): " + "; ".join(parts))
    return why


def _count_why(results: Results) -> str | None:
    """Why the number of selected features is not as the claim says: the mean number per r and k."""
    curves = _by_r(results.n_selected, "n_selected") if results.n_selected else {}
    if not curves:
        return None
    return "mean number of selected features per k: " + "; ".join(
        f"r = {r}: " + ", ".join(f"{v:.1f}" for v in values) for r, (_, values) in sorted(curves.items()))


def _grasp_average_why(results: Results) -> str | None:
    """Why the grasp's average uniformity lies outside the band: from which k on the categories separate held
    from not held, and the 1 x 2 map that keeps the average down, if any."""
    ks, u = _uniformity_curve(results)
    high = [k for k, v in zip(ks, u, strict=True) if v >= UNIFORMITY_PEAK]
    from_k = next((k for k in ks if all(v >= UNIFORMITY_PEAK for kk, v in zip(ks, u, strict=True) if kk >= k)),
                  None)
    text = (f"uniformity is >= {UNIFORMITY_PEAK:.0f} % at {len(high)} of the {len(ks)} values of k"
            + (f" (every k >= {from_k})" if from_k is not None else ""))
    if 2 in ks:
        text += f"; {_categories(results, 2)}" if results.clusters(2) else ""
    return text + (": the grasp's effect categories separate held from not held almost perfectly once a map has "
                   "a few nodes (an average of about 70 % needs categories that mix the two)")


def _fall_why(results: Results) -> str | None:
    """Why there is no fall at k = 3: the 1 x 3 map and the uniformity's spread at k = 2 and 3."""
    spreads = [t for k in (2, 3) if (t := _spread_at(results, results.uniformity, k, "uniformity"))]
    text = "; ".join(spreads)
    if results.clusters(3):
        text += ("; " if text else "") + _categories(results, 3)
    return text or None


def _size_bins_why(results: Results) -> str | None:
    """Why no critical size decides the outcome: the share of successes in each size bin."""
    bins = results.size_success.bins if results.size_success is not None else ()
    if not bins:
        return None
    return "successes by object size: " + ", ".join(
        f"{100 * b.low:.1f}-{100 * b.high:.1f} cm " + ("-" if b.success is None else f"{100 * b.success:.0f} %")
        + f" of {b.n}" for b in bins)


def _bump_why(results: Results) -> str | None:
    """Why there is no bump at k = 4: whether the 1 x 4 map's categories are the four object types."""
    clusters = results.clusters(4)
    if not clusters:
        return None
    mixed = ", ".join(f"category {c.index}: " + ", ".join(f"{t} {n}" for t, n in c.types.items() if n)
                      for c in clusters)
    return (f"the first trial's 1 x 4 map does not sort the four object types into four categories ({mixed}), "
            "so k = 4 gives the classifier no class per type to gain from")



_UNIFORMITY_RISES = Spec(
    "Uniformity rises with k",
    "Uniformity of clusters increases with the number of clusters.",
    f"Spearman rank correlation of k and mean uniformity >= {TREND_RHO}",
    _uniformity_rises,
    _over_trials,
    why=_curve_why("uniformity", "mean uniformity"),
)
_UNIFORMITY_PEAK = Spec(
    "Uniformity peak",
    "It can reach up to 95 %.",
    f"highest mean uniformity over k >= {UNIFORMITY_PEAK:.0f} %",
    _uniformity_peak,
    _over_trials,
    why=_curve_why("uniformity", "mean uniformity"),
)
_FEWER_FEATURES = Spec(
    "Fewer features as r rises",
    "The number of selected features tends to be inversely proportional to r.",
    "for every k the mean number never grows with r, and is lower at the largest r than at the smallest",
    _count_falls_with_r,
    _over_trials,
    why=_count_why,
)
_NUMBER_CONSTANT = Spec(
    "Number constant in k",
    "The number of selected features remains the same above some number of clusters.",
    f"for every r, the coefficient of variation over k >= {CONSTANT_FROM_K} of the mean number <= {CONSTANT_CV}",
    _count_constant_in_k,
    _over_trials,
    why=_count_why,
)
_ACCURACY_FALLS = Spec(
    "SVM accuracy falls with k",
    "SVM prediction accuracy decreases as the number of effect categories grows.",
    f"for every r, Spearman rank correlation of k and mean accuracy <= {-TREND_RHO}",
    _accuracy_falls,
    _over_trials,
    why=_curve_why("svm_accuracy", "mean SVM accuracy"),
)

#: The paper's statements on the method, which do not depend on the behaviour.
METHOD_CLAIMS: tuple[Spec[Results], ...] = (_UNIFORMITY_RISES, _FEWER_FEATURES, _NUMBER_CONSTANT, _ACCURACY_FALLS)

GRASP_CLAIMS: tuple[Spec[Results], ...] = (
    Spec(
        "Uniformity on average",
        "The average uniformity is above ... 70 % for grasping.",
        f"mean over k of the mean uniformity > {GRASP_UNIFORMITY[0]:.0f} % and <= {GRASP_UNIFORMITY[1]:.0f} % "
        "(the paper sets the grasp's average apart from the tap's 'above 80 %')",
        _grasp_uniformity_average,
        _over_trials,
        why=_grasp_average_why,
    ),
    _UNIFORMITY_RISES,
    _UNIFORMITY_PEAK,
    Spec(
        "Fall at k = 3",
        "There is a fall in the general trend of increase in the grasp behaviour for the 3 cluster case.",
        "mean uniformity at k = 3 below both k = 2 and k = 4",
        _fall_at_three,
        _over_trials,
        why=_fall_why,
    ),
    Spec(
        "Critical size",
        "The grasping behaviour is affected mostly by the size of the object ... there is a critical size value "
        "determining the graspability.",
        "a logistic fit of success on object size crosses 50 % within the sizes seen (the critical size), "
        "success falls with size, and the share of successes below the critical size is at least "
        f"{100 * CRITICAL_SIZE_CONTRAST:.0f} points above that above it",
        _critical_size,
        _over_sizes,
        why=_size_bins_why,
    ),
    Spec(
        "1 x 3 map: a category straddles the critical size",
        "One of the clusters falls near this region, stealing from both and therefore decreasing uniformity.",
        f"a cluster of the 1 x 3 map (first trial) with >= {100 * STRADDLE_MIN_SIZE:.0f} % and < "
        f"{100 * STRADDLE_MAX_SIZE:.0f} % of the interactions (a minority, not a handful) has "
        f">= {100 * STRADDLE_SHARE:.0f} % of its objects on each side of the critical size and "
        f">= {100 * STRADDLE_SHARE:.0f} % of its members with its less common outcome; each other cluster holds "
        f">= {100 * STRADDLE_MIN_SIZE:.0f} % of the interactions, one mostly successes and one mostly failures "
        "(the two it steals from)",
        _straddling_cluster,
        _in_map(3),
        why=_map_why(3),
    ),
    Spec(
        "Size features dominate",
        "The grasping behaviour is affected mostly by the size of the object to be grasped.",
        f"for every r > 0, the mean over k of the size share of the selected features > {DOMINANT_SHARE:.0f} % "
        "(18 of the 49 features are size features)",
        _size_dominates,
        _over_trials,
        why=_group_why("size"),
    ),
    _FEWER_FEATURES,
    _NUMBER_CONSTANT,
    _ACCURACY_FALLS,
)

TAP_CLAIMS: tuple[Spec[Results], ...] = (
    Spec(
        "Uniformity on average",
        "The average uniformity is above 80 % for tapping.",
        f"mean over k of the mean uniformity > {TAP_UNIFORMITY:.0f} %",
        _uniformity_average,
        _over_trials,
        why=_curve_why("uniformity", "mean uniformity"),
    ),
    _UNIFORMITY_RISES,
    _UNIFORMITY_PEAK,
    Spec(
        "Shape features dominate",
        "Shape features dominate the selected features.",
        f"for every r > 0, the mean over k of the shape share of the selected features > {DOMINANT_SHARE:.0f} %",
        _shape_dominates,
        _over_trials,
        why=_group_why("shape"),
    ),
    Spec(
        "Shape share and r",
        "When the relevancy threshold is decreased ... the percentage of shape features decreases.",
        "Spearman rank correlation of r and the mean shape share > 0",
        _shape_share_falls_with_lower_r,
        _over_trials,
        why=_curve_why("shape_fraction", "mean shape share"),
    ),
    _FEWER_FEATURES,
    _NUMBER_CONSTANT,
    Spec(
        "1 x 2 map: object types",
        "One cluster holds spheres and horizontal cylinders (rollable), the other boxes and "
        "vertical cylinders.",
        "spheres and lying cylinders share a majority cluster, boxes and standing cylinders the "
        f"other, each type with >= {100 * TYPE_SHARE:.0f} % of its objects there (first trial)",
        _two_cluster_types,
        _in_map(2),
        why=_map_why(2),
    ),
    Spec(
        "1 x 2 map: sizes",
        "Both clusters have instances from the whole size range.",
        f"each of the 2 clusters spans >= {100 * SIZE_SPAN:.0f} % of the range of object sizes (first trial)",
        _two_cluster_sizes,
        _in_map(2),
        why=_map_why(2),
    ),
    Spec(
        "1 x 4 map: success/fail",
        "Two of the four clusters are success clusters, the other two fail clusters.",
        "exactly 2 clusters with more successes (rolled) than failures and 2 with more failures (first trial)",
        _four_cluster_split,
        _in_map(4),
        why=_map_why(4),
    ),
    _ACCURACY_FALLS,
    Spec(
        "Bump at k = 4",
        "Accuracy increases at 4 clusters against the decreasing trend (four object types).",
        "mean accuracy at k = 4 above that at k = 3 for at least half of the r values",
        _bump_at_four,
        _over_trials,
        why=_bump_why,
    ),
    Spec(
        "r = 0, 0.2, 0.4 alike",
        "Accuracy is almost the same for relevancy values of 0 %, 20 % and 40 %.",
        f"mean accuracy over k of these r within {ALIKE_POINTS:g} percentage points",
        _low_r_alike,
        _over_trials,
        why=_curve_why("svm_accuracy", "mean SVM accuracy"),
    ),
    Spec(
        "r = 0.4 best",
        "40 % is the best relevancy: maximum accuracy with the highest perceptual economy.",
        f"the largest r whose mean accuracy over k is within {BEST_R_POINTS:g} point of the best r's is {BEST_R}",
        _best_r,
        _over_trials,
        why=_curve_why("svm_accuracy", "mean SVM accuracy"),
    ),
)


#: The claims of each behaviour the paper reports on; any other behaviour gets :data:`METHOD_CLAIMS`.
CLAIM_SETS: dict[str, tuple[Spec[Results], ...]] = {"tap": TAP_CLAIMS, "grasp": GRASP_CLAIMS}


def results_behavior(results: Results | Mapping[str, Any]) -> str:
    """The behaviour of results (``config["behavior"]``); results without it, written before the behaviour was
    recorded, are the tap's."""
    return as_results(results).behavior


def claims_scope(behavior: str) -> str:
    """Which of the paper's statements are checked for ``behavior``, as a sentence for the reports."""
    if behavior == "tap":
        return "The paper's statements on tapping (section V)."
    if behavior == "grasp":
        return ("The paper's statements on grasping (section V.B), and those on the method that hold for any "
                "behaviour (sections V.B, V.C, V.E).")
    return (f"The paper reports on tapping and grasping only; for {behavior} only its statements on the method, "
            "which hold for any behaviour, are checked (sections V.B, V.C, V.E).")


def claims_for(behavior: str) -> tuple[Spec[Results], ...]:
    """The claims checked for ``behavior``: its own set in :data:`CLAIM_SETS`, else :data:`METHOD_CLAIMS`."""
    return CLAIM_SETS.get(behavior, METHOD_CLAIMS)


def evaluate_claims(results: Results | Mapping[str, Any], behavior: str | None = None) -> list[Verdict]:
    """The paper's claims on a behaviour with our numbers and a verdict computed from them
    (:func:`affordance_learning.common.verdicts.judge`).

    A verdict is "met" or "missed" only on enough data (:data:`MIN_TRIALS` trials of :data:`MIN_INTERACTIONS`
    interactions for a claim on means over trials, :data:`MIN_INTERACTIONS` interactions for one on a map or on
    sizes), else "too few data"; "not measured" when the results lack what the rule needs, or do not say how much
    data they hold. A missed claim says why from the data where its spec can.

    Args:
        results: :class:`~affordance_learning.paper.results.Results`, or their JSON dict.
        behavior: Whose claims to check; by default the results' own (:func:`results_behavior`).

    Raises:
        InvalidValueError: The results are of a newer format, or hold a section that is not of the format.
    """
    results = as_results(results)
    return judge_all(claims_for(results.behavior if behavior is None else behavior), results)

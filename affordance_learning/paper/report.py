"""REPORT.md: our numbers beside the paper's statements, with a verdict per claim computed from the numbers.

The claims, their rules and verdicts are :mod:`affordance_learning.paper.claims`; this module sets them out with
the tables of the numbers they are computed from, read through :class:`~affordance_learning.paper.results.Results`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from affordance_learning.common.exceptions import InvalidValueError
from affordance_learning.common.verdicts import MET, TOO_FEW, Verdict, tally_text
from affordance_learning.paper.claims import MIN_INTERACTIONS, MIN_TRIALS, claims_scope, evaluate_claims
from affordance_learning.paper.results import (
    UNIFORMITY_DEFINITION,
    UNITS,
    PerK,
    PerRK,
    Results,
    SizeSuccess,
    Stat,
    as_results,
)

#: The relevancy threshold whose SVM accuracy the overview shows: the paper's best.
HEADLINE_R = 0.4


def _cell(entry: Stat | None, scale: float, digits: int) -> str:
    """A mean over trials and its standard deviation, times ``scale``; "-" when there is none."""
    if entry is None or entry.mean is None or entry.std is None:
        return "-"
    return f"{scale * entry.mean:.{digits}f} ± {scale * entry.std:.{digits}f}"


def _table_k(rows: Sequence[tuple[PerK | None, str, float, int]]) -> list[str]:
    """A table of numbers per k, a row for each (section, label, scale, digits) the results hold."""
    held = [(section, label, scale, digits) for section, label, scale, digits in rows if section is not None]
    ks = sorted({k for section, *_ in held for k in section})
    lines = ["| | " + " | ".join(f"k = {k}" for k in ks) + " |", "|---" * (len(ks) + 1) + "|"]
    for section, label, scale, digits in held:
        cells = [_cell(section.get(k), scale, digits) for k in ks]
        lines.append(f"| {label} | " + " | ".join(cells) + " |")
    return lines


def _table_rk(section: PerRK, scale: float, digits: int) -> list[str]:
    """A table of numbers per r (rows) and k (columns)."""
    ks = sorted({k for per_k in section.values() for k in per_k})
    lines = ["| r | " + " | ".join(f"k = {k}" for k in ks) + " |", "|---" * (len(ks) + 1) + "|"]
    for r in sorted(section):
        lines.append(
            f"| {r} | " + " | ".join(_cell(section[r].get(k), scale, digits) for k in ks) + " |"
        )
    return lines


def _case_tables(results: Results) -> list[str]:
    """Per 1 x k map of the first trial, its clusters: outcomes, object types, sizes [cm], objects that left."""
    lines: list[str] = []
    success_label, fail_label = results.config.success_label, results.config.fail_label
    for k, clusters in sorted((results.case_studies or {}).items()):
        types = list(dict.fromkeys(t for c in clusters for t in c.types))
        left = all(c.left_view is not None for c in clusters)  # results of format 1 did not count them
        lines += [f"### 1 x {k} map (first trial)", ""]
        lines.append(f"| cluster | {success_label} | {fail_label} | " + " | ".join(types) + " | sizes [cm] |"
                     + (" object left the view |" if left else ""))
        lines.append("|---" * (4 + len(types) + left) + "|")
        for c in clusters:
            sizes = np.asarray(c.sizes, dtype=float) * 100
            spread = (
                f"{sizes.min():.1f}-{sizes.max():.1f} (median {np.median(sizes):.1f})" if sizes.size else "-"
            )
            counts = " | ".join(str(c.types.get(t, 0)) for t in types)
            lines.append(f"| {c.index} | {c.success} | {c.fail} | {counts} | {spread} |"
                         + (f" {c.left_view} |" if left else ""))
        lines.append("")
    return lines


def _tally(claims: Sequence[Verdict]) -> str:
    """How many claims got each verdict, and the least data a verdict is given on."""
    return (f"**{tally_text(claims, 'claims')}.** A verdict is given on at least "
            f"{MIN_TRIALS} trials of {MIN_INTERACTIONS} interactions (a claim on means over trials) or "
            f"{MIN_INTERACTIONS} interactions (a claim on one map of the first trial, or on sizes); each shows its "
            "n.")


def _claim_rows(claims: Sequence[Verdict]) -> list[str]:
    """The claims' table: each with the paper's statement, the rule, our numbers and the verdict with its n; then,
    for each missed claim, why from the data."""
    rows = ["| claim | the paper | rule | ours | verdict |", "|---|---|---|---|---|"]
    rows += [f"| {c.topic} | {c.statement} | {c.rule} | {c.ours} | **{c.word}** ({c.n_text}) |" for c in claims]
    missed = [c for c in claims if c.why]
    if missed:
        rows += ["", "Why the missed claims are missed, from the data:", ""]
        rows += [f"- **{c.topic}**: {c.why}." for c in missed]
    return rows


def _pct(value: float | None) -> str:
    return "-" if value is None else f"{100 * value:.0f} %"


def _num(value: float | None, scale: float = 1.0, digits: int = 1) -> str:
    return "-" if value is None else f"{scale * value:.{digits}f}"


def _effects_section(results: Results) -> list[str]:
    """What the effects contain: the numbers a reviewer asks for before any verdict."""
    effects = results.effects
    if effects is None:
        return []
    success_label = results.config.success_label
    lines = [
        "## What the effects contain",
        "",
        "An effect is final minus initial features. It carries what happened only if the final snapshot sees the "
        "object where it stopped; an object that left the table or the view has the documented not-visible "
        "features (zeros), so its effect is just minus its initial features.",
        "",
        f"- Successes ({success_label}) whose object is seen in the final snapshot: "
        f"**{_pct(effects.success_visible)}** (at rest and seen: "
        f"{_pct(effects.success_rest_visible)}); successes whose effect is minus their initial features "
        f"(the object vanished): {_pct(effects.success_effect_is_minus_initial)}.",
        f"- Spearman correlation of the true travel with the 3-D motion seen (norm of the effect on mean_x, "
        f"mean_y, mean_z), over the objects seen at the end: "
        f"**{_num(effects.travel_vs_seen_motion, digits=2)}**.",
        "",
        f"| type | n | {success_label} | at rest | seen at the end | left the table | travel [cm] | motion seen [cm] | "
        "pixel count change | normal histogram change |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for t, row in effects.by_type.items():
        lines.append(
            f"| {t.replace('_', ' ')} | {row.n} | {_pct(row.success)} | {_pct(row.rest)} | "
            f"{_pct(row.visible_final)} | {_pct(row.off_table)} | {_num(row.displacement, 100)} | "
            f"{_num(row.seen_motion, 100)} | {_num(row.pixel_count_change, 1, 0)} | "
            f"{_num(row.shape_change, 1, 3)} |"
        )
    lines += ["", "Medians per type; the normal histogram change is the sum of |effect| over the 24 shape "
              "features (each histogram sums to 1).", ""]
    if results.prototypes and results.feature_names is not None:  # drawn by write_figures from the same results
        lines += ["What each effect category is, as its map prototype in feature units:", "",
                  "![prototypes](prototypes.png)", ""]
    return lines


def _size_section(results: Results) -> list[str]:
    """How success depends on object size, and the critical size where a logistic fit crosses 50 %."""
    section = results.size_success
    if section is None:
        return []
    success_label = results.config.success_label
    fit, critical, test = section.logistic, section.critical_size, section.test
    if fit is None:
        found = "Only one outcome: no logistic fit, no critical size."
    elif test is not None and not test.depends_on_size:
        found = (f"Success does not depend on object size: the logistic fit of success on size (slope "
                 f"{fit.slope / 100:+.2f} per cm of logit) changes the share of successes by "
                 f"{100 * test.span:+.0f} points across the sizes seen (likelihood-ratio test p = "
                 f"{test.p_value:.2g}). A critical size is reported only where success depends on size "
                 f"({test.rule}): none here.")
    elif critical is None:
        found = (f"A logistic fit of success on size (slope {fit.slope / 100:+.2f} per cm of logit) does not "
                 "cross 50 % within the sizes seen: no critical size.")
    else:
        found = (f"A logistic fit of success on size crosses 50 % at **{100 * critical:.1f} cm** (slope "
                 f"{fit.slope / 100:+.2f} per cm of logit: success "
                 f"{'falls' if fit.slope < 0 else 'rises'} with size).")
    lines = ["## Success by object size", "", found, "",
             "| size [cm] | " + " | ".join(f"{100 * b.low:.1f}-{100 * b.high:.1f}" for b in section.bins)
             + " |", "|---" * (len(section.bins) + 1) + "|",
             "| interactions | " + " | ".join(str(b.n) for b in section.bins) + " |",
             f"| {success_label} | " + " | ".join(_pct(b.success) for b in section.bins) + " |", "",
             "![size_success](size_success.png)", ""]  # drawn by write_figures from the same results
    return lines


def render_report(results: Results | Mapping[str, Any], figures: Sequence[str] = ()) -> str:
    """The Markdown text of the report (see :func:`write_report`)."""
    results = as_results(results)
    claims = evaluate_claims(results)
    config = results.config
    behavior = results.behavior
    success_label, fail_label = config.success_label, config.fail_label
    lines = [
        f"# Reproduction of Akgun et al. 2009, {behavior}: our numbers beside the paper's",
        "",
        f"{config.get('n_rows', '?')} interactions, {config.get('n_trials', '?')} trials, "
        f"k = {config.get('ks', '?')}, r = {config.get('relevancies', '?')}, "
        f"seed {config.get('random_state', '?')}. Success/fail labels: {success_label} / {fail_label} "
        f"(the {config.get('label', 'success')!r} column, measured by the simulator); "
        f"{_pct(results.success_share)} of the interactions succeeded.",
        "",
        f"{UNIFORMITY_DEFINITION} Shares are shown in percent here; `results.json` holds them as fractions "
        f"({UNITS}).",
        "",
        f"{_tally(claims)} Each verdict follows the rule beside it, applied to the numbers below (means over "
        f"trials). {claims_scope(behavior)}",
        "",
        *_claim_rows(claims),
    ]
    lines += [""] + _effects_section(results) + _size_section(results)
    lines += ["## Effect clusters", ""]
    lines += _table_k(
        [
            (results.uniformity, "uniformity [%]", 100.0, 1),
            (results.purity, "purity vs object type", 1.0, 2),
            (results.adjusted_rand, "adjusted Rand vs object type", 1.0, 2),
            (results.n_categories, "non-empty clusters", 1.0, 1),
        ],
    )
    lines += [""] + _case_tables(results)
    for section, title, scale, digits in (
        (results.shape_fraction, "Shape share of the selected features [%]", 100.0, 0),
        (results.size_fraction, "Size share of the selected features [%]", 100.0, 0),
        (results.n_selected, "Number of selected features", 1.0, 1),
        (results.svm_accuracy, "SVM accuracy on held-out interactions [%]", 100.0, 1),
    ):
        if section is not None:
            lines += [f"## {title}", ""] + _table_rk(section, scale, digits) + [""]
    if results.svm_baseline is not None:
        lines += ["Always answering the most common training category:", ""]
        lines += _table_k([(results.svm_baseline, "baseline accuracy [%]", 100.0, 1)]) + [""]
    above = {"prototypes.png"} if results.effects is not None else set()
    above |= {"size_success.png"} if results.size_success is not None else set()
    shown = [f for f in figures if Path(f).name not in above]  # shown above
    if shown:
        lines += ["## Figures", ""] + [f"![{Path(f).stem}]({Path(f).name})" for f in shown] + [""]
    settings = list(config.items())
    if settings:
        lines += ["## Configuration", ""] + [f"- {key}: {value}" for key, value in settings] + [""]
    return "\n".join(lines)


def write_report(results: Results | Mapping[str, Any], out_dir: str | Path) -> Path:
    """Write ``REPORT.md`` into ``out_dir`` (created if needed), linking the PNG figures found there.

    Args:
        results: The :class:`~affordance_learning.paper.results.Results` of
            :func:`affordance_learning.paper.protocol.run_protocol`, or their dict (a ``results.json`` read back).
        out_dir: Output directory.

    Returns:
        The path of ``REPORT.md``.

    Raises:
        InvalidValueError: ``results`` are not the protocol's: no uniformity, or a section not of the format.
    """
    if not isinstance(results, Results | Mapping):
        raise InvalidValueError(f"results must be the results of run_protocol (Results or its dict), got "
                                f"{type(results).__name__}.")
    results = as_results(results)
    if results.uniformity is None:
        raise InvalidValueError("results must be the results of run_protocol (these have no 'uniformity').")
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    figures = sorted(p.name for p in out.glob("*.png"))
    path = out / "REPORT.md"
    path.write_text(render_report(results, figures))
    return path


def headline_accuracy(results: Results) -> PerK:
    """The SVM accuracy per k that headlines a run [fraction]: at r = :data:`HEADLINE_R`, or at the first r the
    results hold when that was not run."""
    return results.accuracy(HEADLINE_R) or next(iter((results.svm_accuracy or {}).values()), {})


def _headline(results: Results) -> dict[str, str]:
    """One behaviour's headline numbers as short texts, for the overview."""
    config = results.config
    uniformity = {k: 100.0 * v.mean for k, v in (results.uniformity or {}).items() if v.mean is not None}
    acc = {k: v.mean for k, v in headline_accuracy(results).items() if v.mean is not None}
    best = max(uniformity, key=uniformity.get) if uniformity else None
    return {
        "interactions": str(config.get("n_rows", "?")),
        "success": f"{_pct(results.success_share)} {config.success_label}",
        "uniformity": f"{np.mean(list(uniformity.values())):.1f} %" if uniformity else "-",
        "peak": f"{uniformity[best]:.1f} % (k = {best})" if best is not None else "-",
        "accuracy": (f"{100 * acc[min(acc)]:.1f} % (k = {min(acc)}) to {100 * acc[max(acc)]:.1f} % "
                     f"(k = {max(acc)})" if acc else "-"),
        "critical": _critical_text(results.size_success),
    }


def _critical_text(sizes: SizeSuccess | None) -> str:
    """The critical size [cm] and the shares of successes below and above it, for the overview; "-" without
    one."""
    if sizes is None or sizes.critical_size is None:
        return "-"
    below, above = (None if side is None else side.success for side in (sizes.below, sizes.above))
    return f"{100 * sizes.critical_size:.1f} cm ({_pct(below)} below, {_pct(above)} above)"


def render_overview(runs: Mapping[str, Results | Mapping[str, Any]],
                    figures: Mapping[str, Sequence[str]] | None = None) -> str:
    """The Markdown text of the overview over behaviours (see :func:`write_overview`); ``figures``: the PNG
    file names in each behaviour's directory."""
    read = {behavior: as_results(results) for behavior, results in runs.items()}
    names, figures = list(read), figures or {}
    lines = [
        f"# Reproduction of Akgun et al. 2009: {', '.join(names)}",
        "",
        "One model per behaviour, as the paper proposes (\"a separate SOM and SVM for each behavior\"): each "
        "behaviour's interactions are collected, clustered by their effects, weighed and learned on their own, "
        "and set beside what the paper says of that behaviour. Means over trials; the full numbers, tables and "
        "figures are in each behaviour's report.",
        "",
        UNIFORMITY_DEFINITION + " A critical size is shown only for a behaviour whose success depends on object "
        "size (a test on the logistic fit of success on size, in each report).",
        "",
        "| behaviour | interactions | successes | uniformity, mean over k | highest uniformity | "
        f"SVM accuracy at r = {HEADLINE_R} | critical size (success crosses 50 %) | claims met |",
        "|---|---|---|---|---|---|---|---|",
    ]
    claims = {b: evaluate_claims(results) for b, results in read.items()}
    for behavior, results in read.items():
        h = _headline(results)
        agree = sum(c.word == MET for c in claims[behavior])
        few = sum(c.word == TOO_FEW for c in claims[behavior])
        lines.append(f"| [{behavior}]({behavior}/REPORT.md) | {h['interactions']} | {h['success']} | "
                     f"{h['uniformity']} | {h['peak']} | {h['accuracy']} | {h['critical']} | "
                     f"{agree} of {len(claims[behavior])}" + (f" ({few} on too few data)" if few else "") + " |")
    lines.append("")
    for behavior, found in claims.items():
        shown = sorted(Path(f).name for f in figures.get(behavior, ()))
        lines += [f"## {behavior}", "", f"[Full report]({behavior}/REPORT.md)"
                  + (" · figures: " + ", ".join(f"[{Path(f).stem}]({behavior}/{f})" for f in shown) if shown else ""),
                  "", f"{_tally(found)} {claims_scope(behavior)}", "", *_claim_rows(found), ""]
    return "\n".join(lines)


def write_overview(runs: Mapping[str, Results | Mapping[str, Any]], out_dir: str | Path) -> Path:
    """Write ``REPORT.md`` into ``out_dir`` over several behaviours: for each, its headline numbers, its claims
    with their verdicts, and links to its report and figures in ``out_dir/<behavior>/``.

    Args:
        runs: The results of each behaviour (:func:`affordance_learning.paper.protocol.run_protocol`, Results or
            their dict), by behaviour, in the order to show them.
        out_dir: Output directory, holding one directory per behaviour.

    Returns:
        The path of ``REPORT.md``.
    """
    if not runs or not all(isinstance(r, Results | Mapping) for r in runs.values()):
        raise InvalidValueError("runs must map each behaviour to the results of run_protocol.")
    read = {behavior: as_results(results) for behavior, results in runs.items()}
    if not all(results.uniformity is not None for results in read.values()):
        raise InvalidValueError("runs must map each behaviour to the results of run_protocol.")
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    figures = {b: sorted(p.name for p in (out / b).glob("*.png")) for b in read}
    path = out / "REPORT.md"
    path.write_text(render_overview(read, figures))
    return path
